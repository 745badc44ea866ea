// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// VoxelGrid: the module's one voxel grid. Over 800 lines in one file because carving,
// surface extraction, footprints and splatting are one data structure's operations sharing its
// projector and inner loops; the passes that use them live in src/clone/.

#include "precomp.hpp"
#include "voxel_grid.hpp"

#include <climits>
#include <cstring>
#include <memory>

namespace cv {
namespace augocc {
namespace detail {

namespace {

// Margin subtracted from distances before skipping, so that rounding never lets a skip cross a
// label change (distances are integers; steps are in pixels).
const double kSkipEps = 1e-6;
// Affine views: rows walked in lockstep by one thread (independent walks overlap cache misses).
const int kLanes = 8;
// Perspective rows: the footprint radius changes along a row; its bound from the two ends is
// widened by this factor (the radius varies as 1/w, monotonic along a row, plus the Jacobian's
// change, a few percent for voxels far from the camera).
const double kPerspectiveRadiusMargin = 1.1;

} // namespace

Mat labelDistance(const Mat& label)
{
    // Two raster passes (exact for the chessboard metric): a pixel next to the other label is at
    // 1, otherwise one more than its nearest same-label neighbour's distance. The ball of radius
    // D - 1 around a pixel at distance D holds only its own label, so propagating through
    // same-label pixels loses nothing. (cv::distanceTransform(DIST_C) twice took ~10x longer.)
    CV_CheckTypeEQ(label.type(), CV_8UC1, "label image");
    const int W = label.cols, H = label.rows;
    const ushort kInf = std::numeric_limits<ushort>::max() - 1;
    Mat dist(label.size(), CV_16U, Scalar(kInf));
    for (int y = 0; y < H; y++)
    {
        const uchar* l = label.ptr<uchar>(y);
        const uchar* lu = y > 0 ? label.ptr<uchar>(y - 1) : nullptr;
        ushort* d = dist.ptr<ushort>(y);
        const ushort* du = y > 0 ? dist.ptr<ushort>(y - 1) : nullptr;
        for (int x = 0; x < W; x++)
        {
            const bool a = l[x] != 0;
            int best = d[x];
            if (x > 0)
                best = std::min(best, (l[x - 1] != 0) != a ? 1 : d[x - 1] + 1);
            if (lu)
            {
                for (int dx = -1; dx <= 1; dx++)
                {
                    const int xx = x + dx;
                    if (xx < 0 || xx >= W)
                        continue;
                    best = std::min(best, (lu[xx] != 0) != a ? 1 : du[xx] + 1);
                }
            }
            d[x] = (ushort)std::min(best, (int)kInf);
        }
    }
    for (int y = H - 1; y >= 0; y--)
    {
        const uchar* l = label.ptr<uchar>(y);
        const uchar* ld = y + 1 < H ? label.ptr<uchar>(y + 1) : nullptr;
        ushort* d = dist.ptr<ushort>(y);
        const ushort* dd = y + 1 < H ? dist.ptr<ushort>(y + 1) : nullptr;
        for (int x = W - 1; x >= 0; x--)
        {
            const bool a = l[x] != 0;
            int best = d[x];
            if (x + 1 < W)
                best = std::min(best, (l[x + 1] != 0) != a ? 1 : d[x + 1] + 1);
            if (ld)
            {
                for (int dx = -1; dx <= 1; dx++)
                {
                    const int xx = x + dx;
                    if (xx < 0 || xx >= W)
                        continue;
                    best = std::min(best, (ld[xx] != 0) != a ? 1 : dd[xx] + 1);
                }
            }
            d[x] = (ushort)std::min(best, (int)kInf);
        }
    }
    return dist;
}

void VoxelGrid::create(const Vec3i& d, const Matx33d& R, const Vec3d& o, double edge, uchar value)
{
    CV_CheckGT(d[0], 0, "grid dims");
    CV_CheckGT(d[1], 0, "grid dims");
    CV_CheckGT(d[2], 0, "grid dims");
    CV_CheckLE(std::max(d[0], std::max(d[1], d[2])), kMaxGridDim, "grid dims");
    CV_CheckGT(edge, 0.0, "voxel size");
    dims = d;
    Rbox = R;
    origin = o;
    h = edge;
    data.assign((size_t)total(), value);
}

int64 VoxelGrid::count() const
{
    int64 n = 0;
    for (uchar v : data)
        n += v != 0;
    return n;
}

VoxelProjector VoxelGrid::projector(const Camera& camera, Size imageSize) const
{
    // The row walk is the pinhole's: a lens is handled by the ideal view (clone/ideal_space.hpp,
    // CloneSet::render), never here.
    CV_Assert(!camera.hasDistortion());
    VoxelProjector p;
    const Matx34d P = camera.projectionMatrix();
    const Matx33d P3(P(0, 0), P(0, 1), P(0, 2), P(1, 0), P(1, 1), P(1, 2), P(2, 0), P(2, 1),
                     P(2, 2));
    const Vec3d p4(P(0, 3), P(1, 3), P(2, 3));
    p.M = P3 * Rbox * h;
    const Vec3d c0 = centre(0, 0, 0);
    p.c = P3 * c0 + p4;
    const Vec3d r2(camera.R(2, 0), camera.R(2, 1), camera.R(2, 2));
    const Matx33d RbT = Rbox.t();
    p.Z = (RbT * r2) * h;
    p.z0 = r2.dot(c0) + camera.t[2];
    p.affine = camera.model == SCALED_ORTHOGRAPHIC;
    p.size = imageSize;
    p.viewDir = RbT * camera.viewDirection();
    p.camVoxel = toVoxel(camera.center());
    p.dims = dims;
    if (p.affine)
    {
        // Half extents of the projected cube: half the sum of |edge projections| (exact).
        p.ruAffine = 0.5 * (std::abs(p.M(0, 0)) + std::abs(p.M(0, 1)) + std::abs(p.M(0, 2)));
        p.rvAffine = 0.5 * (std::abs(p.M(1, 0)) + std::abs(p.M(1, 1)) + std::abs(p.M(1, 2)));
    }
    return p;
}

void quadrantDistance(const Mat& label, const Rect& roi, int sx, int sy, Mat& dist)
{
    CV_CheckTypeEQ(label.type(), CV_8UC1, "label image");
    CV_Assert(dist.type() == CV_8SC1 && dist.size() == label.size());
    CV_Assert((roi & Rect(Point(0, 0), label.size())) == roi);
    if (roi.empty())
        return;
    const uchar kSat = 127;
    const int w = roi.width;
    const int xs = sx > 0 ? roi.x + roi.width - 1 : roi.x;
    const int ys = sy > 0 ? roi.y + roi.height - 1 : roi.y;
    // Two one-label distances, to the nearest outside pixel (dk) and to the nearest kept pixel
    // (dout), in processing order t (t = 0 at the far corner's column), with a sentinel at t = -1
    // and a sentinel row before the first: no source beyond the roi.
    std::vector<uchar> buf(4 * (w + 1), kSat);
    uchar* pk = &buf[0] + 1;
    uchar* po = &buf[w + 1] + 1;
    uchar* ck = &buf[2 * (w + 1)] + 1;
    uchar* co = &buf[3 * (w + 1)] + 1;
    for (int r = 0; r < roi.height; r++)
    {
        const int y = ys - sy * r;
        const uchar* l = label.ptr<uchar>(y) + xs;
        schar* d = dist.ptr<schar>(y) + xs;
        const int step = -sx;
        for (int t = 0; t < w; t++)
        {
            const bool kept = l[step * t] != 0;
            const int mk = std::min(std::min((int)ck[t - 1], (int)pk[t]), (int)pk[t - 1]) + 1;
            const int mo = std::min(std::min((int)co[t - 1], (int)po[t]), (int)po[t - 1]) + 1;
            const uchar vk = kept ? (uchar)std::min(mk, (int)kSat) : (uchar)0;
            const uchar vo = kept ? (uchar)0 : (uchar)std::min(mo, (int)kSat);
            ck[t] = vk;
            co[t] = vo;
            d[step * t] = kept ? (schar)vk : (schar)(-(int)vo);
        }
        std::swap(pk, ck);
        std::swap(po, co);
    }
}

CarveView VoxelGrid::carveView(const Camera& camera, const Mat& keep) const
{
    CV_CheckTypeEQ(keep.type(), CV_8UC1, "keep mask");
    CarveView v;
    v.proj = projector(camera, keep.size());
    // Padding: footprints reach at most about one pixel beyond the pixel of the centre; pixels
    // off the image are unknown (kept), so a few keep pixels around the image suffice.
    v.pad = 4;
    Mat k01 = keep != 0;
    copyMakeBorder(k01, v.keep, v.pad, v.pad, v.pad, v.pad, BORDER_CONSTANT, Scalar(255));
    const Rect all(Point(0, 0), v.keep.size());
    // The distances are needed only where footprints fall: the grid's image bounds (not clipped
    // to the image), in padded coordinates.
    v.roi = all;
    {
        int x0 = INT_MAX, y0 = INT_MAX, x1 = INT_MIN, y1 = INT_MIN;
        bool ok = true;
        for (int c = 0; c < 8 && ok; c++)
        {
            int a0 = 0, a1 = 0, b0 = 0, b1 = 0;
            double z = 0;
            ok = v.proj.footprint(c & 1 ? dims[0] - 1 : 0, c & 2 ? dims[1] - 1 : 0,
                                  c & 4 ? dims[2] - 1 : 0, a0, a1, b0, b1, z);
            x0 = std::min(x0, a0 - 2);
            y0 = std::min(y0, b0 - 2);
            x1 = std::max(x1, a1 + 2);
            y1 = std::max(y1, b1 + 2);
        }
        if (ok)
            v.roi = Rect(Point(x0 + v.pad, y0 + v.pad), Point(x1 + v.pad + 1, y1 + v.pad + 1)) & all;
    }
    v.dist.create(v.keep.size(), CV_8SC1);
    v.dist.setTo(Scalar(1));
    if (v.roi.empty())
        return v;
    if (v.proj.affine)
    {
        // Every row steps by (M00, M10) per voxel: only the quadrant ahead matters.
        v.quadrant = true;
        v.sx = v.proj.M(0, 0) >= 0 ? 1 : -1;
        v.sy = v.proj.M(1, 0) >= 0 ? 1 : -1;
        v.rad = (int)std::floor(0.5 + std::max(v.proj.ruAffine, v.proj.rvAffine));
        quadrantDistance(v.keep, v.roi, v.sx, v.sy, v.dist);
        // Outside the roi: "kept, q unknown" (forces the exact test), no neighbour outside.
        v.walk.create(v.keep.size(), CV_8UC2);
        v.walk.setTo(Scalar(0, 0));
        const int W = v.keep.cols, H = v.keep.rows;
        for (int y = v.roi.y; y < v.roi.y + v.roi.height; y++)
        {
            const schar* d = v.dist.ptr<schar>(y);
            const uchar* k = v.keep.ptr<uchar>(y);
            const uchar* ku = y > 0 ? v.keep.ptr<uchar>(y - 1) : nullptr;
            const uchar* kd = y + 1 < H ? v.keep.ptr<uchar>(y + 1) : nullptr;
            const int qy = y - v.sy * v.rad;
            const bool qyIn = qy >= v.roi.y && qy < v.roi.y + v.roi.height;
            const schar* dq = qyIn ? v.dist.ptr<schar>(qy) : nullptr;
            uchar* w = v.walk.ptr<uchar>(y);
            for (int x = v.roi.x; x < v.roi.x + v.roi.width; x++)
            {
                if (!k[x])
                {
                    w[2 * x] = (uchar)d[x];
                    w[2 * x + 1] = 0;
                    continue;
                }
                const int qx = x - v.sx * v.rad;
                int sq = 0;
                if (dq && qx >= v.roi.x && qx < v.roi.x + v.roi.width)
                    sq = std::max((int)dq[qx], 0);
                w[2 * x] = (uchar)(schar)sq;
                w[2 * x + 1] = 0;
                if (sq > 2 * v.rad)
                    continue;  // the walk skips here; no exact test needs the neighbours
                // Neighbours off the padded image are unknown (kept).
                auto out = [&](const uchar* r, int xx) {
                    return r && xx >= 0 && xx < W && !r[xx];
                };
                const int nb = out(ku, x - 1) | out(ku, x) << 1 | out(ku, x + 1) << 2 |
                               out(k, x - 1) << 3 | out(k, x + 1) << 4 |
                               out(kd, x - 1) << 5 | out(kd, x) << 6 | out(kd, x + 1) << 7;
                w[2 * x + 1] = (uchar)nb;
            }
        }
        return v;
    }
    // Signed, saturated distance in one byte per pixel (one cache line serves both the label and
    // the distance): +D where kept, -D outside; skips are capped at 127 pixels.
    const Mat kr = v.keep(v.roi);
    const Mat d16 = labelDistance(kr);
    for (int y = 0; y < kr.rows; y++)
    {
        const ushort* d = d16.ptr<ushort>(y);
        const uchar* k = kr.ptr<uchar>(y);
        schar* o = v.dist.ptr<schar>(y + v.roi.y) + v.roi.x;
        for (int x = 0; x < kr.cols; x++)
        {
            const int c = std::min((int)d[x], 127);
            o[x] = (schar)(k[x] ? c : -c);
        }
    }
    return v;
}

bool VoxelGrid::footprintKept(const CarveView& view, int i, int j, int k) const
{
    int x0, x1, y0, y1;
    double z;
    if (!view.proj.footprint(i, j, k, x0, x1, y0, y1, z))
        return true;
    const int W = view.keep.cols, H = view.keep.rows;
    for (int y = y0 + view.pad; y <= y1 + view.pad; y++)
    {
        if (y < 0 || y >= H)
            continue;
        const uchar* row = view.keep.ptr<uchar>(y);
        for (int x = x0 + view.pad; x <= x1 + view.pad; x++)
            if (x >= 0 && x < W && !row[x])
                return false;
    }
    return true;
}

namespace {

// VoxelGrid::footprintKept, inlined for the row walk.
inline bool footprintKeptFast(const CarveView& view, int i, int j, int k)
{
    int x0, x1, y0, y1;
    double z;
    if (!view.proj.footprint(i, j, k, x0, x1, y0, y1, z))
        return true;
    const int W = view.keep.cols, H = view.keep.rows;
    x0 = std::max(x0 + view.pad, 0);
    x1 = std::min(x1 + view.pad, W - 1);
    y0 = std::max(y0 + view.pad, 0);
    y1 = std::min(y1 + view.pad, H - 1);
    for (int y = y0; y <= y1; y++)
    {
        const uchar* r = view.keep.ptr<uchar>(y);
        for (int x = x0; x <= x1; x++)
            if (!r[x])
                return false;
    }
    return true;
}

// Carves voxels lo..hi of one voxel row (j, k) with one view (perspective views; affine views
// use AffineWalk). Walks the alive voxels, and uses the symmetric
// chessboard distance of the pixel under the current voxel to skip every following voxel that
// provably has the same outcome: moving the projected centre by delta (L-inf) moves its rounded
// pixel by at most floor(delta) + 1, and footprints lie within `rad` of that pixel.
void carveRow(const VoxelGrid& g, const CarveView& view, int j, int k, uchar* row, int lo, int hi)
{
    const VoxelProjector& P = view.proj;
    const int nx = g.dims[0];
    const double A0 = P.M(0, 1) * j + P.M(0, 2) * k + P.c[0];
    const double A1 = P.M(1, 1) * j + P.M(1, 2) * k + P.c[1];
    const double A2 = P.M(2, 1) * j + P.M(2, 2) * k + P.c[2];
    const double B0 = P.M(0, 0), B1 = P.M(1, 0), B2 = P.M(2, 0);
    double step, rmax;
    if (P.affine)
    {
        step = std::max(std::abs(B0), std::abs(B1));
        rmax = std::max(P.ruAffine, P.rvAffine);
    }
    else
    {
        const double w0 = A2, w1 = A2 + B2 * (nx - 1);
        const double wmin = std::min(w0, w1);
        if (!(wmin > 1e-12))
            return;  // part of the row is behind the camera: no evidence, keep
        // u(i) = (A0 + B0 i) / (A2 + B2 i): du/di = (B0 A2 - A0 B2) / w^2, largest at wmin.
        step = std::max(std::abs(B0 * A2 - A0 * B2), std::abs(B1 * A2 - A1 * B2)) /
               (wmin * wmin);
        double r = 0;
        for (int e = 0; e < 2; e++)
        {
            const int i = e == 0 ? 0 : nx - 1;
            const double w = A2 + B2 * i;
            const double u = (A0 + B0 * i) / w, v = (A1 + B1 * i) / w;
            const double ru = 0.5 / w * (std::abs(P.M(0, 0) - u * P.M(2, 0)) +
                                         std::abs(P.M(0, 1) - u * P.M(2, 1)) +
                                         std::abs(P.M(0, 2) - u * P.M(2, 2)));
            const double rv = 0.5 / w * (std::abs(P.M(1, 0) - v * P.M(2, 0)) +
                                         std::abs(P.M(1, 1) - v * P.M(2, 1)) +
                                         std::abs(P.M(1, 2) - v * P.M(2, 2)));
            r = std::max(r, std::max(ru, rv));
        }
        rmax = r * kPerspectiveRadiusMargin;
    }
    step = std::max(step, 1e-9);
    const double inv = 1.0 / step;
    const int rad = (int)std::floor(0.5 + rmax);
    const int pad = view.pad;
    const int W = view.keep.cols, H = view.keep.rows;
    const schar* dist = view.dist.ptr<schar>();
    const size_t dstep = view.dist.step[0];
    const int end = hi + 1;
    int i = lo;
    while (i < end)
    {
        if (!row[i])
        {
            const void* nxt = std::memchr(row + i, 1, (size_t)(end - i));
            if (!nxt)
                break;
            i = (int)((const uchar*)nxt - row);
            continue;
        }
        double u = A0 + B0 * i, v = A1 + B1 * i;
        if (!P.affine)
        {
            const double iw = 1.0 / (A2 + B2 * i);
            u *= iw;
            v *= iw;
        }
        const int px = cvRound(u) + pad, py = cvRound(v) + pad;
        if (px < 0 || py < 0 || px >= W || py >= H)
        {
            // Off the padded image: unknown, kept; skip while the footprint stays off the image
            // or in the keep border.
            const int dOut = std::max(std::max(-px, px - (W - 1)), std::max(-py, py - (H - 1)));
            const int n = (int)((dOut + pad - 1 - rad - kSkipEps) * inv);
            i += std::max(n, 0) + 1;
            continue;
        }
        // One signed byte per pixel: +D in the keep region, -D outside (see CarveView).
        const int sd = dist[(size_t)py * dstep + px];
        if (sd > 0)
        {
            if (sd > rad)
            {
                const int n = (int)((sd - 1 - rad - kSkipEps) * inv);
                i += std::max(n, 0) + 1;
            }
            else
            {
                if (!footprintKeptFast(view, i, j, k))
                    row[i] = 0;
                i++;
            }
        }
        else
        {
            const int n = std::max((int)((-sd - 1 - kSkipEps) * inv), 0);
            const int e = std::min(end, i + n + 1);
            std::memset(row + i, 0, (size_t)(e - i));
            i = e;
        }
    }
}

// Affine (quadrant) views: the row walk with everything that does not depend on the row
// precomputed, and the skip lengths as integer tables of the map value. Same rules as carveRow's
// quadrant branch.
class AffineWalk
{
public:
    AffineWalk(const CarveView& view) : view_(view)
    {
        const VoxelProjector& P = view.proj;
        B0_ = P.M(0, 0);
        B1_ = P.M(1, 0);
        const double inv = 1.0 / std::max(std::max(std::abs(B0_), std::abs(B1_)), 1e-9);
        rad_ = view.rad;
        pad_ = view.pad;
        W_ = view.keep.cols;
        H_ = view.keep.rows;
        rx0_ = view.roi.x;
        ry0_ = view.roi.y;
        rw_ = (unsigned)view.roi.width;
        rh_ = (unsigned)view.roi.height;
        walk_ = view.walk.ptr<uchar>();
        wstep_ = view.walk.step[0];
        inv_ = inv;
        for (int d = 0; d < 128; d++)
        {
            // Outside: the next n voxels are outside too; kept (d > 2 rad): the next n are kept.
            skipOut_[d] = 1 + std::max((int)std::floor((d - 1 - kSkipEps) * inv), 0);
            skipIn_[d] = 1 + std::max((int)std::floor((d - 1 - 2 * rad_ - kSkipEps) * inv), 0);
        }
    }

    //! One row's walk: voxels [i, end) of `row` are left.
    struct State
    {
        uchar* row;
        int j, k, i, end;
        double A0, A1;
    };

    void begin(State& st, int j, int k, uchar* row, int lo, int hi) const
    {
        const VoxelProjector& P = view_.proj;
        st.row = row;
        st.j = j;
        st.k = k;
        st.i = lo;
        st.end = hi + 1;
        st.A0 = P.M(0, 1) * j + P.M(0, 2) * k + P.c[0];
        st.A1 = P.M(1, 1) * j + P.M(1, 2) * k + P.c[1];
    }

    //! Advances the walk by one decision; false when the row is done.
    inline bool step(State& st) const
    {
        uchar* row = st.row;
        const int j = st.j, k = st.k, end = st.end;
        const double A0 = st.A0, A1 = st.A1;
        int i = st.i;
        do  // one decision; `continue` ends it
        {
            if (i >= end)
                break;
            if (!row[i])
            {
                const void* nxt = std::memchr(row + i, 1, (size_t)(end - i));
                i = nxt ? (int)((const uchar*)nxt - row) : end;
                continue;
            }
            const int px = cvRound(A0 + B0_ * i) + pad_, py = cvRound(A1 + B1_ * i) + pad_;
            if ((unsigned)(px - rx0_) >= rw_ || (unsigned)(py - ry0_) >= rh_)
            {
                if (px < 0 || py < 0 || px >= W_ || py >= H_)
                {
                    // Off the padded image: unknown, kept (as carveRow).
                    const int dOut = std::max(std::max(-px, px - (W_ - 1)),
                                              std::max(-py, py - (H_ - 1)));
                    const int n = (int)std::floor((dOut + pad_ - 1 - rad_ - kSkipEps) * inv_);
                    i += std::max(n, 0) + 1;
                }
                else
                {
                    // Not reached (footprints lie in the roi), but stay exact if it were.
                    if (!footprintKeptFast(view_, i, j, k))
                        row[i] = 0;
                    i++;
                }
                continue;
            }
            const uchar* wp = walk_ + (size_t)py * wstep_ + 2 * px;
            const int sv = (schar)wp[0];
            if (sv < 0)
            {
                const int e = std::min(end, i + skipOut_[-sv]);
                if (e - i <= 8)
                    for (; i < e; i++)
                        row[i] = 0;
                else
                {
                    std::memset(row + i, 0, (size_t)(e - i));
                    i = e;
                }
                continue;
            }
            if (sv > 2 * rad_)
            {
                i += skipIn_[sv];
                continue;
            }
            if (!exactKept(wp, px, py, i, j, k))
                row[i] = 0;
            i++;
        } while (false);
        st.i = i;
        return i < end;
    }

private:
    inline bool exactKept(const uchar* wp, int px, int py, int i, int j, int k) const
    {
        // px, py are the footprint's own rounded centre (same arithmetic), and footprints lie
        // within rad of it: with no outside neighbour there is nothing to test.
        if (rad_ <= 1 && wp[1] == 0)
            return true;
        int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
        double z = 0;
        view_.proj.footprint(i, j, k, x0, x1, y0, y1, z);
        x0 -= px - pad_;
        x1 -= px - pad_;
        y0 -= py - pad_;
        y1 -= py - pad_;
        if (x0 >= -1 && x1 <= 1 && y0 >= -1 && y1 <= 1)
        {
            int m9 = 0;
            for (int yy = y0; yy <= y1; yy++)
                for (int xx = x0; xx <= x1; xx++)
                    m9 |= 1 << ((yy + 1) * 3 + xx + 1);
            const int m8 = (m9 & 15) | ((m9 >> 5) << 4);
            return (wp[1] & m8) == 0;  // the centre is kept (sv >= 0)
        }
        return footprintKeptFast(view_, i, j, k);
    }

    const CarveView& view_;
    double B0_, B1_, inv_;
    int rad_, pad_, W_, H_, rx0_, ry0_;
    unsigned rw_, rh_;
    const uchar* walk_;
    size_t wstep_;
    int skipOut_[128], skipIn_[128];
};

// Last alive voxel of row[lo..hi], or lo - 1 when none.
inline int lastAlive(const uchar* row, int lo, int hi)
{
    while (hi >= lo + 7)
    {
        uint64_t w;
        std::memcpy(&w, row + hi - 7, 8);
        if (w)
            break;
        hi -= 8;
    }
    while (hi >= lo && !row[hi])
        hi--;
    return hi;
}

} // namespace

void VoxelGrid::carve(const std::vector<CarveView>& views)
{
    if (views.empty() || data.empty())
        return;
    const int nx = dims[0], ny = dims[1];
    // The views that carve most go first, so that most rows die (or shrink) early: the fraction of
    // outside pixels in the grid's image bounds. The order does not change the result (carving is
    // an intersection).
    std::vector<std::pair<double, int> > strength(views.size());
    for (size_t q = 0; q < views.size(); q++)
    {
        const CarveView& v = views[q];
        const Rect roi = (imageBounds(v.proj) + Point(v.pad, v.pad)) &
                         Rect(Point(0, 0), v.keep.size());
        const double out = roi.area() > 0 ? 1.0 - countNonZero(v.keep(roi)) / (double)roi.area()
                                          : 0.0;
        strength[q] = std::make_pair(-out, (int)q);
    }
    std::sort(strength.begin(), strength.end());
    // Per z slice, view by view (the view's maps stay in cache over the slice), each row only over
    // its alive span; a row that dies needs no further view. Rows are independent, so the result
    // does not depend on the partition into threads.
    std::vector<std::unique_ptr<AffineWalk> > affine(views.size());
    for (size_t q = 0; q < views.size(); q++)
        if (views[q].quadrant)
            affine[q].reset(new AffineWalk(views[q]));
    parallel_for_(Range(0, dims[2]), [&](const Range& r) {
        std::vector<int> lo(ny), hi(ny);
        for (int k = r.start; k < r.end; k++)
        {
            for (int j = 0; j < ny; j++)
            {
                const uchar* row = &data[index(0, j, k)];
                const void* first = std::memchr(row, 1, (size_t)nx);
                lo[j] = first ? (int)((const uchar*)first - row) : nx;
                hi[j] = first ? lastAlive(row, lo[j], nx - 1) : -1;
            }
            for (const auto& s : strength)
            {
                const CarveView& view = views[s.second];
                const AffineWalk* aw = affine[s.second].get();
                bool any = false;
                auto update = [&](int jj) {
                    const uchar* rr = &data[index(0, jj, k)];
                    const void* f = std::memchr(rr + lo[jj], 1, (size_t)(hi[jj] - lo[jj] + 1));
                    if (!f)
                    {
                        lo[jj] = nx;
                        hi[jj] = -1;
                        return;
                    }
                    lo[jj] = (int)((const uchar*)f - rr);
                    hi[jj] = lastAlive(rr, lo[jj], hi[jj]);
                    any = true;
                };
                for (int j = 0; j < ny; j++)
                {
                    if (lo[j] > hi[j])
                        continue;
                    if (!aw)
                    {
                        carveRow(*this, view, j, k, &data[index(0, j, k)], lo[j], hi[j]);
                        update(j);
                        continue;
                    }
                    // Several rows walked in lockstep: their cache misses overlap.
                    AffineWalk::State st[kLanes];
                    int rows[kLanes], n = 0;
                    for (int jj = j; jj < ny && n < kLanes; jj++)
                        if (lo[jj] <= hi[jj])
                        {
                            aw->begin(st[n], jj, k, &data[index(0, jj, k)], lo[jj], hi[jj]);
                            rows[n++] = jj;
                        }
                    bool more = true;
                    while (more)
                    {
                        more = false;
                        for (int l = 0; l < n; l++)
                            more |= aw->step(st[l]);
                    }
                    for (int l = 0; l < n; l++)
                        update(rows[l]);
                    j = rows[n - 1];
                }
                if (!any)
                    break;
            }
        }
    });
}

SurfaceVoxels VoxelGrid::surface() const
{
    const int nx = dims[0], ny = dims[1], nz = dims[2];
    std::vector<SurfaceVoxels> slices(nz);
    parallel_for_(Range(0, nz), [&](const Range& r) {
        for (int k = r.start; k < r.end; k++)
        {
            SurfaceVoxels& s = slices[k];
            for (int j = 0; j < ny; j++)
            {
                const uchar* row = &data[index(0, j, k)];
                const uchar* rowYm = j > 0 ? row - nx : nullptr;
                const uchar* rowYp = j + 1 < ny ? row + nx : nullptr;
                const uchar* rowZm = k > 0 ? row - (size_t)nx * ny : nullptr;
                const uchar* rowZp = k + 1 < nz ? row + (size_t)nx * ny : nullptr;
                const uint64_t kOnes = 0x0101010101010101ULL;
                int i = 0;
                for (; i < nx; i++)
                {
                    // Eight voxels at a time: skip empty chunks and chunks whose voxels and
                    // neighbours are all inside.
                    if ((i & 7) == 0 && i + 8 < nx)
                    {
                        uint64_t c, a = kOnes;
                        std::memcpy(&c, row + i, 8);
                        if (c == 0)
                        {
                            i += 7;
                            continue;
                        }
                        if (c == kOnes && i > 0 && row[i - 1] && row[i + 8])
                        {
                            uint64_t t;
                            if (rowYm) { std::memcpy(&t, rowYm + i, 8); a &= t; } else a = 0;
                            if (rowYp) { std::memcpy(&t, rowYp + i, 8); a &= t; } else a = 0;
                            if (rowZm) { std::memcpy(&t, rowZm + i, 8); a &= t; } else a = 0;
                            if (rowZp) { std::memcpy(&t, rowZp + i, 8); a &= t; } else a = 0;
                            if (a == kOnes)
                            {
                                i += 7;
                                continue;
                            }
                        }
                    }
                    if (!row[i])
                        continue;
                    uchar f = 0;
                    if (i == 0 || !row[i - 1]) f |= 1;
                    if (i + 1 == nx || !row[i + 1]) f |= 2;
                    if (!rowYm || !rowYm[i]) f |= 4;
                    if (!rowYp || !rowYp[i]) f |= 8;
                    if (!rowZm || !rowZm[i]) f |= 16;
                    if (!rowZp || !rowZp[i]) f |= 32;
                    if (f)
                    {
                        s.ijk.push_back(packVoxel(i, j, k));
                        s.faces.push_back(f);
                    }
                }
            }
        }
    });
    SurfaceVoxels out;
    size_t n = 0;
    for (const SurfaceVoxels& s : slices)
        n += s.size();
    out.ijk.reserve(n);
    out.faces.reserve(n);
    for (const SurfaceVoxels& s : slices)
    {
        out.ijk.insert(out.ijk.end(), s.ijk.begin(), s.ijk.end());
        out.faces.insert(out.faces.end(), s.faces.begin(), s.faces.end());
    }
    return out;
}

namespace {

// Corner offsets (in voxel units from the centre) of face f (-x,+x,-y,+y,-z,+z), counter-clockwise
// seen from outside.
void faceCorners(int f, Vec3d c[4])
{
    const int axis = f / 2;
    const double s = (f % 2) ? 0.5 : -0.5;
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    const double q[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    for (int m = 0; m < 4; m++)
    {
        const int mm = s > 0 ? m : 3 - m;
        Vec3d p;
        p[axis] = s;
        p[a1] = q[mm][0];
        p[a2] = q[mm][1];
        c[m] = p;
    }
}

void appendFace(const VoxelGrid& g, int i, int j, int k, int f, Mesh& mesh)
{
    Vec3d c[4];
    faceCorners(f, c);
    const int base = (int)mesh.vertices.size();
    for (int m = 0; m < 4; m++)
    {
        const Vec3d X = g.centre(i + c[m][0], j + c[m][1], k + c[m][2]);
        mesh.vertices.push_back(Vec3f((float)X[0], (float)X[1], (float)X[2]));
    }
    mesh.faces.push_back(Vec3i(base, base + 1, base + 2));
    mesh.faces.push_back(Vec3i(base, base + 2, base + 3));
}

} // namespace

Mesh VoxelGrid::surfaceMesh(const SurfaceVoxels& s) const
{
    Mesh mesh;
    for (size_t n = 0; n < s.size(); n++)
    {
        int i, j, k;
        unpackVoxel(s.ijk[n], i, j, k);
        for (int f = 0; f < 6; f++)
            if (s.faces[n] & (1 << f))
                appendFace(*this, i, j, k, f, mesh);
    }
    return mesh;
}

Mesh VoxelGrid::cubesMesh(const std::vector<uint32_t>& voxels) const
{
    Mesh mesh;
    for (uint32_t p : voxels)
    {
        int i, j, k;
        unpackVoxel(p, i, j, k);
        for (int f = 0; f < 6; f++)
            appendFace(*this, i, j, k, f, mesh);
    }
    return mesh;
}

namespace {

// What a splat writes, one footprint row at a time: the nearest (and farthest) centre depth, or
// only coverage (255), a quarter of the memory, for the mattes that need no depth.
struct DepthSpans
{
    DepthSpans(Mat& zmin_, Point offset_, Mat* zmax_ = nullptr)
        : zmin(zmin_), zmax(zmax_), offset(offset_) {}
    Mat& zmin;
    Mat* zmax;
    Point offset;
    bool affineFast() const { return zmax == nullptr; }
    void span(int y, int x0, int x1, float z) const
    {
        float* zr = zmin.ptr<float>(y - offset.y) - offset.x;
        float* zx = zmax ? zmax->ptr<float>(y - offset.y) - offset.x : nullptr;
        for (int x = x0; x <= x1; x++)
        {
            if (z < zr[x])
                zr[x] = z;
            if (zx && z > zx[x])
                zx[x] = z;
        }
    }
};

struct CoverSpans
{
    CoverSpans(Mat& cover_, Point offset_) : cover(cover_), offset(offset_) {}
    Mat& cover;
    Point offset;
    bool affineFast() const { return true; }
    void span(int y, int x0, int x1, float) const
    {
        if (x1 >= x0)
            std::memset(cover.ptr<uchar>(y - offset.y) - offset.x + x0, 255, x1 - x0 + 1);
    }
};

/* The voxels i of a grid row (homogeneous centre (m i + a, ., mw i + aw), w > 0 over the row;
affine: mw = 0, aw = 1) whose footprint can meet the pixels [P0, P1] along one image axis: the
footprint's pixels lie within [u - r - 0.5, u + r + 0.5] (VoxelProjector::footprint: the ceiling
of u - r or the rounded centre, the floor of u + r or the rounded centre), r its half width or a
bound of it over the row, so a voxel is drawn only when u lies within [P0 - r - 1, P1 + r + 1]
(a pixel of margin); u >= L is (m - L mw) i + (a - L aw) >= 0, linear in i. [iLo, iHi], empty
when iLo > iHi, widened by one voxel against the rounding of the division. */
void rowRange(double m, double a, double r, int P0, int P1, double mw, double aw, int& iLo,
              int& iHi)
{
    double lo = -2, hi = kMaxGridDim + 3;
    auto atLeast = [&](double c1, double c0) {  // c1 i + c0 >= 0
        if (c1 == 0)
        {
            if (!(c0 >= 0))
                hi = lo - 1;
            return;
        }
        const double t = -c0 / c1;
        if (c1 > 0)
            lo = std::max(lo, t - 1);
        else
            hi = std::min(hi, t + 1);
    };
    const double L0 = P0 - r - 1.0, L1 = P1 + r + 1.0;
    atLeast(m - L0 * mw, a - L0 * aw);    // u >= L0
    atLeast(L1 * mw - m, L1 * aw - a);    // u <= L1
    if (!(lo <= hi) || !(L0 <= L1))
    {
        iLo = 0;
        iHi = -1;
        return;
    }
    iLo = (int)std::floor(lo);
    iHi = (int)std::ceil(hi);
}

template <class Spans>
void splat(const VoxelProjector& proj, const uint32_t* ijk, const uchar* faces, size_t n,
           bool frontOnly, Size buffer, const Spans& out)
{
    const Point offset = out.offset;
    // Pixels written: the image, intersected with the buffer placed at `offset`.
    const int X0 = std::max(0, offset.x), Y0 = std::max(0, offset.y);
    const int X1 = std::min(proj.size.width, offset.x + buffer.width) - 1;
    const int Y1 = std::min(proj.size.height, offset.y + buffer.height) - 1;
    // Affine: the faces turned to the camera are fixed (outward normal . viewDir < 0).
    uchar frontMask = 0;
    if (proj.affine)
        for (int a = 0; a < 3; a++)
        {
            if (proj.viewDir[a] > 0) frontMask |= (uchar)(1 << (2 * a));
            if (proj.viewDir[a] < 0) frontMask |= (uchar)(1 << (2 * a + 1));
        }
    const bool cull = frontOnly && faces;
    // Row bounds only when the buffer can clip a footprint away: a matte over the whole image
    // holds every footprint, and rows of a surface list are short (the bounds cost about as
    // much as the footprints they save).
    const Rect window(Point(X0, Y0), Point(X1 + 1, Y1 + 1));
    const Rect all = projectedBounds(proj);
    const bool bounded = (all & window) != all;
    if (proj.affine && out.affineFast())
    {
        // The renderer's path: VoxelProjector::footprint's arithmetic term for term (so key
        // frames stay exact), with the row part computed once per voxel row (voxels come sorted),
        // and with it the voxels of the row whose footprint can meet the buffer: the others are
        // passed over without one (half of a 1080p composite's voxels, drawn over the part of
        // the frame the virtual objects cover).
        const double ru = proj.ruAffine, rv = proj.rvAffine;
        const Matx33d& M = proj.M;
        uint32_t lastRow = ~0u;
        double a0 = 0, a1 = 0, az = 0;
        int iLo = 0, iHi = kMaxGridDim;
        for (size_t q = 0; q < n; q++)
        {
            if (cull && !(faces[q] & frontMask))
                continue;
            const uint32_t p = ijk[q];
            const int i = (int)(p & 1023u);
            if ((p >> 10) != lastRow)
            {
                lastRow = p >> 10;
                const int j = (int)(lastRow & 1023u), k = (int)(lastRow >> 10);
                a0 = M(0, 1) * j + M(0, 2) * k + proj.c[0];
                a1 = M(1, 1) * j + M(1, 2) * k + proj.c[1];
                az = proj.Z[1] * j + proj.Z[2] * k + proj.z0;
                if (bounded)  // else iLo, iHi hold every i
                {
                    int lo2, hi2;
                    rowRange(M(0, 0), a0, ru, X0, X1, 0, 1, iLo, iHi);
                    rowRange(M(1, 0), a1, rv, Y0, Y1, 0, 1, lo2, hi2);
                    iLo = std::max(iLo, lo2);
                    iHi = std::min(iHi, hi2);
                }
            }
            if (i < iLo || i > iHi)
                continue;
            const double u = M(0, 0) * i + a0, v = M(1, 0) * i + a1;
            const int pu = cvRound(u), pv = cvRound(v);
            const int x0 = std::max(std::min(cvCeil(u - ru), pu), X0);
            const int x1 = std::min(std::max(cvFloor(u + ru), pu), X1);
            const int y0 = std::max(std::min(cvCeil(v - rv), pv), Y0);
            const int y1 = std::min(std::max(cvFloor(v + rv), pv), Y1);
            const float z = (float)(proj.Z[0] * i + az);
            for (int y = y0; y <= y1; y++)
                out.span(y, x0, x1, z);
        }
        return;
    }
    const Matx33d& M = proj.M;
    const double S0 = std::abs(M(0, 0)) + std::abs(M(0, 1)) + std::abs(M(0, 2));
    const double S1 = std::abs(M(1, 0)) + std::abs(M(1, 1)) + std::abs(M(1, 2));
    const double S2 = std::abs(M(2, 0)) + std::abs(M(2, 1)) + std::abs(M(2, 2));
    const int iMax = std::max(0, std::min(proj.dims[0], kMaxGridDim + 1) - 1);
    uint32_t lastRow = ~0u;
    int iLo = 0, iHi = kMaxGridDim;
    for (size_t q = 0; q < n; q++)
    {
        int i, j, k;
        unpackVoxel(ijk[q], i, j, k);
        if (bounded && !proj.affine && (ijk[q] >> 10) != lastRow)
        {
            // The row's voxels whose footprint can meet the buffer (as in the affine path).
            // Where the row is in front of the camera (w > 0 at both ends of the grid's row,
            // hence between), |u| <= max |u w| / min w and the footprint's half width
            // 0.5 / w sum_a |M(0,a) - u M(2,a)| <= 0.5 (S0 + |u| S2) / min w: a bound for the
            // whole row; then u w - (X w) >= 0 at the row's bounds is linear in i.
            lastRow = ijk[q] >> 10;
            const double b0 = M(0, 1) * j + M(0, 2) * k + proj.c[0];
            const double b1 = M(1, 1) * j + M(1, 2) * k + proj.c[1];
            const double b2 = M(2, 1) * j + M(2, 2) * k + proj.c[2];
            const double wA = b2, wB = M(2, 0) * iMax + b2, wMin = std::min(wA, wB);
            iLo = 0;
            iHi = kMaxGridDim;
            if (wMin > 1e-9)
            {
                const double uMax = std::max(std::abs(b0), std::abs(M(0, 0) * iMax + b0)) / wMin;
                const double vMax = std::max(std::abs(b1), std::abs(M(1, 0) * iMax + b1)) / wMin;
                const double ruB = 0.5 * (S0 + uMax * S2) / wMin;
                const double rvB = 0.5 * (S1 + vMax * S2) / wMin;
                rowRange(M(0, 0), b0, ruB, X0, X1, M(2, 0), b2, iLo, iHi);
                int lo2, hi2;
                rowRange(M(1, 0), b1, rvB, Y0, Y1, M(2, 0), b2, lo2, hi2);
                iLo = std::max(iLo, lo2);
                iHi = std::min(iHi, hi2);
            }
        }
        if (!proj.affine && (i < iLo || i > iHi))
            continue;
        if (cull)
        {
            uchar m = frontMask;
            if (!proj.affine)
            {
                // Face +x at i + 0.5 is seen when the camera is beyond it, and so on.
                m = 0;
                const double ii[3] = {(double)i, (double)j, (double)k};
                for (int a = 0; a < 3; a++)
                {
                    if (proj.camVoxel[a] < ii[a] - 0.5) m |= (uchar)(1 << (2 * a));
                    if (proj.camVoxel[a] > ii[a] + 0.5) m |= (uchar)(1 << (2 * a + 1));
                }
            }
            if (!(faces[q] & m))
                continue;
        }
        int x0, x1, y0, y1;
        double zd;
        if (!proj.footprint(i, j, k, x0, x1, y0, y1, zd))
            continue;
        x0 = std::max(x0, X0);
        y0 = std::max(y0, Y0);
        x1 = std::min(x1, X1);
        y1 = std::min(y1, Y1);
        const float z = (float)zd;
        for (int y = y0; y <= y1; y++)
            out.span(y, x0, x1, z);
    }
}

} // namespace

void splatVoxels(const VoxelProjector& proj, const uint32_t* ijk, const uchar* faces, size_t n,
                 bool frontOnly, Mat& zmin, Mat* zmax, Point offset)
{
    CV_Assert(zmin.type() == CV_32FC1);
    CV_Assert(!zmax || (zmax->type() == CV_32FC1 && zmax->size() == zmin.size()));
    splat(proj, ijk, faces, n, frontOnly, zmin.size(), DepthSpans(zmin, offset, zmax));
}

Rect projectedBounds(const VoxelProjector& proj)
{
    // Footprints of the corner voxels bound every footprint (projection of a box is the hull of
    // its corners; the footprint adds at most the corner voxel's own extent).
    const Vec3i& dims = proj.dims;
    int x0 = INT_MAX, y0 = INT_MAX, x1 = INT_MIN, y1 = INT_MIN;
    for (int c = 0; c < 8; c++)
    {
        int a0, a1, b0, b1;
        double z;
        if (!proj.footprint(c & 1 ? dims[0] - 1 : 0, c & 2 ? dims[1] - 1 : 0,
                            c & 4 ? dims[2] - 1 : 0, a0, a1, b0, b1, z))
            return Rect(Point(0, 0), proj.size);
        x0 = std::min(x0, a0 - 1);
        y0 = std::min(y0, b0 - 1);
        x1 = std::max(x1, a1 + 1);
        y1 = std::max(y1, b1 + 1);
    }
    return Rect(Point(x0, y0), Point(x1 + 1, y1 + 1)) & Rect(Point(0, 0), proj.size);
}

namespace {

/* The renderer over several voxel lists: `out` (`type`, `empty` where no footprint falls) over
the grid's image bounds. The voxels are split in chunks, each splatted into its own buffer
(the first straight into `out`), then merged (`merge(dst, buffer)`): the result does not depend
on the chunking, hence on the thread count. */
template <class Spans, class Merge>
void renderChunked(const VoxelGrid& grid, const VoxelProjector& proj,
                   const std::vector<VoxelList>& lists, Mat& out, int type, const Scalar& empty,
                   Merge merge)
{
    out.create(proj.size, type);
    out.setTo(empty);
    const Rect roi = grid.imageBounds(proj);
    if (roi.empty())
        return;
    size_t total = 0;
    for (const VoxelList& l : lists)
        total += l.n;
    const size_t kChunk = 65536;
    const int chunks = (int)std::min<size_t>((size_t)std::max(1, getNumThreads()),
                                             total / kChunk + 1);
    std::vector<Mat> bufs(chunks);
    parallel_for_(Range(0, chunks), [&](const Range& r) {
        for (int c = r.start; c < r.end; c++)
        {
            Mat b = c == 0 ? out(roi) : Mat(roi.size(), type, empty);
            const Spans spans(b, roi.tl());
            for (const VoxelList& l : lists)
            {
                const size_t a = l.n * c / chunks, e = l.n * (c + 1) / chunks;
                splat(proj, l.ijk + a, l.faces ? l.faces + a : nullptr, e - a, l.frontOnly,
                      b.size(), spans);
            }
            bufs[c] = b;
        }
    });
    Mat dst = out(roi);
    for (int c = 1; c < chunks; c++)
        merge(dst, bufs[c]);
}

} // namespace

void renderDepth(const VoxelGrid& grid, const VoxelProjector& proj,
                 const std::vector<VoxelList>& lists, Mat& zmin)
{
    renderChunked<DepthSpans>(grid, proj, lists, zmin, CV_32F,
                              Scalar(std::numeric_limits<float>::infinity()),
                              [](Mat& dst, const Mat& b) { cv::min(dst, b, dst); });
}

void renderCoverage(const VoxelGrid& grid, const VoxelProjector& proj,
                    const std::vector<VoxelList>& lists, Mat& cover)
{
    renderChunked<CoverSpans>(grid, proj, lists, cover, CV_8U, Scalar(0),
                              [](Mat& dst, const Mat& b) { cv::bitwise_or(dst, b, dst); });
}

} // namespace detail
} // namespace augocc
} // namespace cv
