// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "voxel_grid.hpp"

#include <climits>
#include <cstring>

namespace cv {
namespace augocc {
namespace detail {

namespace {

// Margin subtracted from distances before skipping, so that rounding never lets a skip cross a
// label change (distances are integers; steps are in pixels).
const double kSkipEps = 1e-6;
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
    if (p.affine)
    {
        // Half extents of the projected cube: half the sum of |edge projections| (exact).
        p.ruAffine = 0.5 * (std::abs(p.M(0, 0)) + std::abs(p.M(0, 1)) + std::abs(p.M(0, 2)));
        p.rvAffine = 0.5 * (std::abs(p.M(1, 0)) + std::abs(p.M(1, 1)) + std::abs(p.M(1, 2)));
    }
    return p;
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
    // Signed, saturated distance in one byte per pixel (one cache line serves both the label and
    // the distance): +D where kept, -D outside; skips are capped at 127 pixels.
    const Mat d16 = labelDistance(v.keep);
    v.dist.create(v.keep.size(), CV_8SC1);
    for (int y = 0; y < v.keep.rows; y++)
    {
        const ushort* d = d16.ptr<ushort>(y);
        const uchar* k = v.keep.ptr<uchar>(y);
        schar* o = v.dist.ptr<schar>(y);
        for (int x = 0; x < v.keep.cols; x++)
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

// Carves one voxel row (j, k) with one view. Walks the alive voxels, and uses the chessboard
// distance of the pixel under the current voxel to skip every following voxel that provably has
// the same outcome: moving the projected centre by delta (L-inf) moves its rounded pixel by at
// most floor(delta) + 1, and footprints lie within `rad` of that pixel.
void carveRow(const VoxelGrid& g, const CarveView& view, int j, int k, uchar* row)
{
    const VoxelProjector& P = view.proj;
    const int nx = g.dims[0];
    const Vec3d A(P.M(0, 1) * j + P.M(0, 2) * k + P.c[0], P.M(1, 1) * j + P.M(1, 2) * k + P.c[1],
                  P.M(2, 1) * j + P.M(2, 2) * k + P.c[2]);
    const Vec3d B(P.M(0, 0), P.M(1, 0), P.M(2, 0));
    double step, rmax;
    if (P.affine)
    {
        step = std::max(std::abs(B[0]), std::abs(B[1]));
        rmax = std::max(P.ruAffine, P.rvAffine);
    }
    else
    {
        const double w0 = A[2], w1 = A[2] + B[2] * (nx - 1);
        const double wmin = std::min(w0, w1);
        if (!(wmin > 1e-12))
            return;  // part of the row is behind the camera: no evidence, keep
        // u(i) = (A0 + B0 i) / (A2 + B2 i): du/di = (B0 A2 - A0 B2) / w^2, largest at wmin.
        step = std::max(std::abs(B[0] * A[2] - A[0] * B[2]),
                        std::abs(B[1] * A[2] - A[1] * B[2])) / (wmin * wmin);
        double r = 0;
        for (int e = 0; e < 2; e++)
        {
            int x0, x1, y0, y1;
            double z;
            const int i = e == 0 ? 0 : nx - 1;
            const double w = A[2] + B[2] * i;
            const double u = (A[0] + B[0] * i) / w, v = (A[1] + B[1] * i) / w;
            (void)x0; (void)x1; (void)y0; (void)y1; (void)z;
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
    const int rad = (int)std::floor(0.5 + rmax);
    const int pad = view.pad;
    const int W = view.keep.cols, H = view.keep.rows;
    int i = 0;
    while (i < nx)
    {
        if (!row[i])
        {
            const void* nxt = std::memchr(row + i, 1, (size_t)(nx - i));
            if (!nxt)
                break;
            i = (int)((const uchar*)nxt - row);
            continue;
        }
        double u = A[0] + B[0] * i, v = A[1] + B[1] * i;
        if (!P.affine)
        {
            const double iw = 1.0 / (A[2] + B[2] * i);
            u *= iw;
            v *= iw;
        }
        const int px = cvRound(u) + pad, py = cvRound(v) + pad;
        if (px < 0 || py < 0 || px >= W || py >= H)
        {
            // Off the padded image: unknown, kept; skip while the footprint stays off the image
            // or in the keep border.
            const int dOut = std::max(std::max(-px, px - (W - 1)), std::max(-py, py - (H - 1)));
            const int n = (int)std::floor((dOut + pad - 1 - rad - kSkipEps) / step);
            i += std::max(n, 0) + 1;
            continue;
        }
        // One signed byte per pixel: +D in the keep region, -D outside (see CarveView).
        const int sd = view.dist.at<schar>(py, px);
        const int D = std::abs(sd);
        if (sd > 0)
        {
            if (D > rad)
            {
                const int n = (int)std::floor((D - 1 - rad - kSkipEps) / step);
                i += std::max(n, 0) + 1;
            }
            else
            {
                if (!g.footprintKept(view, i, j, k))
                    row[i] = 0;
                i++;
            }
        }
        else
        {
            const int n = std::max((int)std::floor((D - 1 - kSkipEps) / step), 0);
            const int end = std::min(nx, i + n + 1);
            std::memset(row + i, 0, (size_t)(end - i));
            i = end;
        }
    }
}

} // namespace

void VoxelGrid::carve(const std::vector<CarveView>& views)
{
    if (views.empty() || data.empty())
        return;
    const int ny = dims[1];
    parallel_for_(Range(0, dims[2]), [&](const Range& r) {
        // View-major within a slice: consecutive rows project to neighbouring image rows, so the
        // view's label and distance images stay in cache.
        for (int k = r.start; k < r.end; k++)
            for (const CarveView& v : views)
                for (int j = 0; j < ny; j++)
                    carveRow(*this, v, j, k, &data[index(0, j, k)]);
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

void splatVoxels(const VoxelProjector& proj, const uint32_t* ijk, const uchar* faces, size_t n,
                 bool frontOnly, Mat& zmin, Mat* zmax, Point offset)
{
    CV_Assert(zmin.type() == CV_32FC1);
    CV_Assert(!zmax || (zmax->type() == CV_32FC1 && zmax->size() == zmin.size()));
    // Pixels written: the image, intersected with the buffer placed at `offset`.
    const int X0 = std::max(0, offset.x), Y0 = std::max(0, offset.y);
    const int X1 = std::min(proj.size.width, offset.x + zmin.cols) - 1;
    const int Y1 = std::min(proj.size.height, offset.y + zmin.rows) - 1;
    // Affine: the faces turned to the camera are fixed (outward normal . viewDir < 0).
    uchar frontMask = 0;
    if (proj.affine)
        for (int a = 0; a < 3; a++)
        {
            if (proj.viewDir[a] > 0) frontMask |= (uchar)(1 << (2 * a));
            if (proj.viewDir[a] < 0) frontMask |= (uchar)(1 << (2 * a + 1));
        }
    const bool cull = frontOnly && faces;
    for (size_t q = 0; q < n; q++)
    {
        int i, j, k;
        unpackVoxel(ijk[q], i, j, k);
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
    }
}

Rect VoxelGrid::imageBounds(const VoxelProjector& proj) const
{
    // Footprints of the corner voxels bound every footprint (projection of a box is the hull of
    // its corners; the footprint adds at most the corner voxel's own extent).
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

void renderDepth(const VoxelGrid& grid, const VoxelProjector& proj,
                 const std::vector<VoxelList>& lists, Mat& zmin)
{
    zmin.create(proj.size, CV_32F);
    zmin.setTo(Scalar(std::numeric_limits<float>::infinity()));
    const Rect roi = grid.imageBounds(proj);
    if (roi.empty())
        return;
    // Split the voxels in chunks, each splatted into its own buffer over the grid's bounds, then
    // merged by min: the result does not depend on the chunking.
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
            Mat b(roi.size(), CV_32F, Scalar(std::numeric_limits<float>::infinity()));
            for (const VoxelList& l : lists)
            {
                const size_t a = l.n * c / chunks, e = l.n * (c + 1) / chunks;
                splatVoxels(proj, l.ijk + a, l.faces ? l.faces + a : nullptr, e - a, l.frontOnly,
                            b, nullptr, roi.tl());
            }
            bufs[c] = b;
        }
    });
    Mat dst = zmin(roi);
    bufs[0].copyTo(dst);
    for (int c = 1; c < chunks; c++)
        cv::min(dst, bufs[c], dst);
}

} // namespace detail
} // namespace augocc
} // namespace cv
