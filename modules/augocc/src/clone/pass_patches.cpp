// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Step 5 of the paper's Section 6 @cite Ong1998: per key frame, the patch voxels that make the
// clone cover the silhouette exactly (the two-pass depth estimate of the missing pixels, then
// voxels along several rays per pixel).

#include "precomp.hpp"
#include "clone/passes.hpp"

#include <unordered_map>

namespace cv {
namespace augocc {
namespace detail {

namespace {

// Step 5: extra rounds of candidate patch voxels for pixels the first round left uncovered, each
// with one more ray per pixel along each axis and the depth range widened by one voxel; in the
// last round each ray takes, over its whole span in the grid, the one voxel nearest to the
// estimated segment whose footprint fits the silhouette. (Taking every voxel of the span that
// fits, as before, put patches of rim pixels at the far end of the grid under a perspective
// camera, where voxels project smaller: streaks far behind the object in the other frames. On
// the squirrel turntable, 9 of 36 views as key frames: held-out IoU 0.939 -> see doc/clones.md.)
const int kPatchExtraRounds = 2;
// Key-frame consistency warning: more than this fraction of a key frame's silhouette lies more
// than kDeepMissingPx inside its outline yet is carved by the other key frames (patches restore
// it). Rims miss a few pixels normally (measured on exact synthesized data: at most 2% of a
// small tower's silhouette, 0.2-1.2% on Middlebury's dino and the squirrel turntable); a mask that
// marks a region the others leave out (the CMU hotel's roof in one of three masks: 14.6%) does not.
const double kInconsistentFraction = 0.05;
const float kDeepMissingPx = 3.f;
// Samples along a ray segment per voxel edge (two: no voxel the segment crosses is skipped).
const double kSamplesPerVoxel = 2.0;

// Parameters [t0, t1] of the line a + t (b - a) inside the grid's box (voxel coordinates, centres
// at integers, so the box is [-0.5, dims - 0.5]); false when the line misses it.
bool clipToGrid(const VoxelGrid& g, const Vec3d& a, const Vec3d& b, double& t0, double& t1)
{
    t0 = -std::numeric_limits<double>::infinity();
    t1 = std::numeric_limits<double>::infinity();
    const Vec3d d = b - a;
    for (int ax = 0; ax < 3; ax++)
    {
        const double lo = -0.5, hi = g.dims[ax] - 0.5;
        if (std::abs(d[ax]) < 1e-12)
        {
            if (a[ax] < lo || a[ax] > hi)
                return false;
            continue;
        }
        double ta = (lo - a[ax]) / d[ax], tb = (hi - a[ax]) / d[ax];
        if (ta > tb)
            std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1 && std::isfinite(t0) && std::isfinite(t1);
}

const uint32_t kNoVoxel = ~0u;

// The last patch round for one ray a + t (b - a) (voxel coordinates; the estimated segment is
// t in [0, 1], the grid's span [t0, t1]): the empty voxel nearest to the segment, not yet a
// patch voxel, whose footprint fits `view`'s silhouette; kNoVoxel when none does.
uint32_t nearestFittingVoxel(const VoxelGrid& g, const CarveView& view, const Vec3d& a,
                             const Vec3d& b, double t0, double t1,
                             const std::vector<uint32_t>& accepted,
                             std::unordered_map<uint32_t, bool>& fits)
{
    const Vec3d d = b - a;
    const double len = std::max(std::abs(d[0]), std::max(std::abs(d[1]), std::abs(d[2])));
    if (!(len > 0))
        return kNoVoxel;
    const double dt = 1.0 / (len * kSamplesPerVoxel);  // parameter step: half a voxel
    const double mid = std::min(std::max(0.5, t0), t1);
    // Outwards from the segment's middle (clamped to the span), alternating both ways.
    const int nUp = (int)std::floor((t1 - mid) / dt), nDown = (int)std::floor((mid - t0) / dt);
    uint32_t last[2] = {kNoVoxel, kNoVoxel};  // per direction: samples repeat voxels
    for (int s = 0; s <= std::max(nUp, nDown); s++)
        for (int side = 0; side < (s == 0 ? 1 : 2); side++)
        {
            if ((side == 0 && s > nUp) || (side == 1 && s > nDown))
                continue;
            const double t = side == 0 ? mid + s * dt : mid - s * dt;
            const Vec3d v = a + t * d;
            const int i = cvRound(v[0]), j = cvRound(v[1]), k = cvRound(v[2]);
            if (!g.inside(i, j, k) || g.data[g.index(i, j, k)])
                continue;
            const uint32_t p = packVoxel(i, j, k);
            if (p == last[side])
                continue;
            last[side] = p;
            if (std::binary_search(accepted.begin(), accepted.end(), p))
                continue;
            // Neighbouring rays cross the same voxels: each footprint is tested once a round.
            auto it = fits.find(p);
            if (it == fits.end())
                it = fits.emplace(p, g.footprintKept(view, i, j, k)).first;
            if (it->second)
                return p;
        }
    return kNoVoxel;
}

Mat paddedKeep(const Mat& keep, int pad)
{
    Mat k01 = keep != 0, out;
    copyMakeBorder(k01, out, pad, pad, pad, pad, BORDER_CONSTANT, Scalar(255));
    return out;
}

} // namespace

std::vector<uint32_t> computePatches(const ObjectClone& obj, const Camera& camera,
                                     const Mat& silhouette, const Mat& keep, int raysPerPixel)
{
    const VoxelGrid& g = obj.grid;
    const VoxelProjector proj = g.projector(camera, silhouette.size());
    // Per-pixel work only over the silhouette's bounding box and the ring of neighbours the
    // second pass reads: buffers (and the page faults of allocating them) scale with the object,
    // not the frame. Pixel coordinates below are in the box; `origin` maps them to the image.
    Rect roi = boundingRect(silhouette);
    if (roi.empty())
        return std::vector<uint32_t>();
    roi = Rect(roi.x - 1, roi.y - 1, roi.width + 2, roi.height + 2) &
          Rect(Point(), silhouette.size());
    const Point origin = roi.tl();
    const Size size = roi.size();
    const Mat sil = silhouette(roi);
    Mat zmin(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
    splatVoxels(proj, obj.surface.ijk.data(), obj.surface.faces.data(), obj.surface.size(), true,
                zmin, nullptr, origin);
    Mat zfar(size, CV_32F, Scalar(-std::numeric_limits<float>::infinity()));
    Mat zdummy(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
    splatVoxels(proj, obj.surface.ijk.data(), nullptr, obj.surface.size(), false, zdummy, &zfar,
                origin);

    // First pass: d1 / d2 where the clone is hit; the missing pixels are the rest of the silhouette.
    const int W = size.width, H = size.height;
    Mat d1(size, CV_32F, Scalar(0)), d2(size, CV_32F, Scalar(0));
    Mat state(size, CV_8U, Scalar(0));  // 0 not in play, 1 known, 2 missing
    std::vector<Point> missing;
    double sum1 = 0, sum2 = 0;
    int nknown = 0;
    for (int y = 0; y < H; y++)
    {
        const float* zr = zmin.ptr<float>(y);
        const float* zf = zfar.ptr<float>(y);
        const uchar* s = sil.ptr<uchar>(y);
        for (int x = 0; x < W; x++)
        {
            if (zr[x] < std::numeric_limits<float>::infinity())
            {
                state.at<uchar>(y, x) = 1;
                d1.at<float>(y, x) = zr[x];
                d2.at<float>(y, x) = std::max(zf[x], zr[x]);
                sum1 += zr[x];
                sum2 += std::max(zf[x], zr[x]);
                nknown++;
            }
            else if (s[x])
            {
                state.at<uchar>(y, x) = 2;
                missing.push_back(Point(x, y));
            }
        }
    }
    if (missing.empty())
        return std::vector<uint32_t>();
    const int area = countNonZero(sil);
    if ((double)missing.size() > kInconsistentFraction * area)
    {
        Mat inside;
        distanceTransform(sil, inside, DIST_L2, 3);
        int deep = 0;
        for (const Point& p : missing)
            deep += inside.at<float>(p) > kDeepMissingPx;
        if ((double)deep > kInconsistentFraction * area)
            CV_LOG_WARNING(NULL, cv::format("augocc: object '%s', key frame %d: %.1f%% of the "
                           "silhouette (more than %.0f px inside its outline) is carved away by "
                           "the other key frames and kept by patch voxels only: the key-frame "
                           "silhouettes or the cameras disagree (check this frame's mask)",
                           obj.name.c_str(), camera.frame, 100.0 * deep / area,
                           kDeepMissingPx));
    }

    // Second pass: d1 / d2 of missing pixels from their eight neighbours, in order of distance from
    // the known pixels (one ring at a time, each ring from the rings before it only).
    std::vector<Point> ring;
    for (const Point& p : missing)
    {
        bool near = false;
        for (int dy = -1; dy <= 1 && !near; dy++)
            for (int dx = -1; dx <= 1; dx++)
            {
                const int x = p.x + dx, y = p.y + dy;
                if (x >= 0 && y >= 0 && x < W && y < H && state.at<uchar>(y, x) == 1)
                {
                    near = true;
                    break;
                }
            }
        if (near)
            ring.push_back(p);
    }
    std::vector<float> v1, v2;
    while (!ring.empty())
    {
        v1.assign(ring.size(), 0.f);
        v2.assign(ring.size(), 0.f);
        for (size_t q = 0; q < ring.size(); q++)
        {
            double a = 0, b = 0;
            int n = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                {
                    const int x = ring[q].x + dx, y = ring[q].y + dy;
                    if (x >= 0 && y >= 0 && x < W && y < H && state.at<uchar>(y, x) == 1)
                    {
                        a += d1.at<float>(y, x);
                        b += d2.at<float>(y, x);
                        n++;
                    }
                }
            v1[q] = (float)(a / n);
            v2[q] = (float)(b / n);
        }
        for (size_t q = 0; q < ring.size(); q++)
        {
            d1.at<float>(ring[q]) = v1[q];
            d2.at<float>(ring[q]) = v2[q];
            state.at<uchar>(ring[q]) = 3;  // assigned in this ring
        }
        std::vector<Point> next;
        for (const Point& p : ring)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                {
                    const int x = p.x + dx, y = p.y + dy;
                    if (x >= 0 && y >= 0 && x < W && y < H && state.at<uchar>(y, x) == 2)
                    {
                        state.at<uchar>(y, x) = 4;  // queued
                        next.push_back(Point(x, y));
                    }
                }
        for (const Point& p : ring)
            state.at<uchar>(p) = 1;
        ring.swap(next);
    }
    // Missing islands with no known pixel around: the clone's mean depth range, or the grid's.
    float f1, f2;
    if (nknown > 0)
    {
        f1 = (float)(sum1 / nknown);
        f2 = (float)(sum2 / nknown);
    }
    else
    {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (int c = 0; c < 8; c++)
        {
            const Vec3d X = g.centre(c & 1 ? g.dims[0] - 0.5 : -0.5, c & 2 ? g.dims[1] - 0.5 : -0.5,
                                     c & 4 ? g.dims[2] - 0.5 : -0.5);
            lo = std::min(lo, camera.depth(X));
            hi = std::max(hi, camera.depth(X));
        }
        f1 = (float)lo;
        f2 = (float)hi;
    }
    for (const Point& p : missing)
        if (state.at<uchar>(p) == 2)
        {
            d1.at<float>(p) = f1;
            d2.at<float>(p) = f2;
        }

    // Patch voxels: several rays per pixel, each segment [d1, d2] sampled finely enough that no
    // voxel it crosses is skipped; a candidate is kept only when its footprint stays in `keep`
    // (the carving rule), so patches never cover a pixel outside the silhouette.
    CarveView view;
    view.proj = proj;
    view.pad = 4;
    view.keep = paddedKeep(keep, view.pad);
    Mat covered = zmin.clone();
    std::vector<Point> todo = missing;
    std::vector<uint32_t> accepted;
    // The candidates, each once: the rays of neighbouring pixels and the samples along a ray
    // meet the same voxels many times (at 3840x2160, sorting the repeats out took 7% of the
    // clone stage); a bit per grid cell marks the ones already taken, cleared after each round.
    std::vector<uint64_t> taken((g.data.size() + 63) / 64, 0);
    auto cellOf = [&](uint32_t v) {
        int i, j, k;
        unpackVoxel(v, i, j, k);
        return g.index(i, j, k);
    };
    auto take = [&](std::vector<uint32_t>& list, uint32_t v) {
        const size_t idx = cellOf(v);
        uint64_t& word = taken[idx >> 6];
        const uint64_t bit = uint64_t(1) << (idx & 63);
        if (!(word & bit))
        {
            word |= bit;
            list.push_back(v);
        }
    };
    for (int round = 0; round <= kPatchExtraRounds && !todo.empty(); round++)
    {
        const int n = raysPerPixel + round;
        const double widen = g.h * round;
        std::vector<uint32_t> cand;
        std::unordered_map<uint32_t, bool> fits;
        for (const Point& p : todo)
        {
            const double z1 = d1.at<float>(p) - widen, z2 = d2.at<float>(p) + widen;
            for (int sy = 0; sy < n; sy++)
                for (int sx = 0; sx < n; sx++)
                {
                    const Point2d px(origin.x + p.x + (sx + 0.5) / n - 0.5,
                                     origin.y + p.y + (sy + 0.5) / n - 0.5);
                    Vec3d a = g.toVoxel(camera.unproject(px, z1));
                    Vec3d b = g.toVoxel(camera.unproject(px, z2));
                    // The segment, clipped to the grid; when the estimated depths miss the grid,
                    // and in the last round, the ray's whole span in the grid.
                    double t0, t1;
                    if (!clipToGrid(g, a, b, t0, t1))
                        continue;
                    if (round == kPatchExtraRounds)
                    {
                        const uint32_t v = nearestFittingVoxel(g, view, a, b, t0, t1, accepted,
                                                               fits);
                        if (v != kNoVoxel)
                            take(cand, v);
                        continue;
                    }
                    if (t1 < 0 || t0 > 1)
                    {
                        const Vec3d a0 = a;
                        a = a0 + t0 * (b - a0);
                        b = a0 + t1 * (b - a0);
                    }
                    else
                    {
                        const Vec3d a0 = a;
                        a = a0 + std::max(t0, 0.0) * (b - a0);
                        b = a0 + std::min(t1, 1.0) * (b - a0);
                    }
                    const double len = std::max(std::abs(b[0] - a[0]),
                                                std::max(std::abs(b[1] - a[1]), std::abs(b[2] - a[2])));
                    const int steps = (int)std::ceil(len * kSamplesPerVoxel);
                    for (int s = 0; s <= steps; s++)
                    {
                        const double t = steps > 0 ? (double)s / steps : 0.0;
                        const Vec3d v = a + t * (b - a);
                        const int i = cvRound(v[0]), j = cvRound(v[1]), k = cvRound(v[2]);
                        if (g.inside(i, j, k) && !g.data[g.index(i, j, k)])
                            take(cand, packVoxel(i, j, k));
                    }
                }
        }
        std::sort(cand.begin(), cand.end());
        for (uint32_t c : cand)
        {
            const size_t idx = cellOf(c);
            taken[idx >> 6] &= ~(uint64_t(1) << (idx & 63));
        }
        std::vector<uint32_t> ok;
        for (uint32_t c : cand)
        {
            if (std::binary_search(accepted.begin(), accepted.end(), c))
                continue;
            int i, j, k;
            unpackVoxel(c, i, j, k);
            if (g.footprintKept(view, i, j, k))
                ok.push_back(c);
        }
        splatVoxels(proj, ok.data(), nullptr, ok.size(), false, covered, nullptr, origin);
        std::vector<uint32_t> merged(accepted.size() + ok.size());
        std::merge(accepted.begin(), accepted.end(), ok.begin(), ok.end(), merged.begin());
        accepted.swap(merged);
        std::vector<Point> left;
        for (const Point& p : todo)
            if (!(covered.at<float>(p) < std::numeric_limits<float>::infinity()))
                left.push_back(p);
        todo.swap(left);
    }
    if (!todo.empty())
    {
        CV_LOG_DEBUG(NULL, cv::format("augocc: %s: %d silhouette pixels left uncovered by patches",
                                      obj.name.c_str(), (int)todo.size()));
    }
    return accepted;
}

int64 passPatches(ObjectClone& obj, const PassContext& ctx)
{
    std::vector<int> keys;
    for (const auto& m : obj.masks)
        keys.push_back(m.first);
    std::vector<std::vector<uint32_t> > patches(keys.size());
    parallel_for_(Range(0, (int)keys.size()), [&](const Range& r) {
        for (int q = r.start; q < r.end; q++)
        {
            const int f = keys[q];
            patches[q] = computePatches(obj, ctx.rec.camera(f), obj.masks.at(f),
                                        keepMask(obj, ctx, f), ctx.params.patches.raysPerPixel);
        }
    });
    obj.patches.clear();
    int64 n = 0;
    for (size_t q = 0; q < keys.size(); q++)
    {
        n += (int64)patches[q].size();
        obj.patches[keys[q]] = std::move(patches[q]);
    }
    return n;
}

} // namespace detail
} // namespace augocc
} // namespace cv
