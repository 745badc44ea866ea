// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Beyond Step 3 of @cite Ong1998: the grid grows to hold the visual hull where the key frames
// need it beyond the enlarged box.

#include "precomp.hpp"
#include "clone/passes.hpp"

namespace cv {
namespace augocc {
namespace detail {

namespace {

// Beyond Step 3: the box must hold the visual hull where the key frames need it. Step 3 makes
// every silhouette pixel's ray touch the box, but the other key frames' cones may meet that ray
// only outside it: the box then cuts the object (a side facade seen in the last key frames only,
// with few tracks to place Step 1's box; a cap wider than its points suggest), and in that key
// frame patch voxels alone cover the cut, which the other frames miss. For the silhouette pixels
// more than kGrowDeepPx inside the outline that the carved clone leaves uncovered, each ray is
// walked (half-voxel steps, up to kGrowReach box diagonals beyond the box) for the point outside
// the box nearest to it that every other key frame shows in its silhouette. Positive evidence
// only, unlike carving: pixels unknown under a nearer object or off the image do not count (a
// mask with a wrong blob would otherwise grow a phantom behind the other objects, and a
// turntable's views would grow the box into space half of them do not see). Returns those
// points; none when nothing is found (the cameras or the masks disagree: Step 5's warning names
// the key frame).
const float kGrowDeepPx = 3.f;
// Uncovered deep pixels below this fraction of a silhouette are left alone (round-off).
const double kGrowMinFraction = 0.002;
// At most this many rays per key frame (evenly strided over its uncovered deep pixels).
const int kGrowMaxRays = 4000;
// The walk reaches this many box diagonals beyond the box's extent along the ray.
const double kGrowReach = 0.5;
// Candidates per ray whose path to the box is checked, nearest first.
const int kGrowMaxCandidates = 8;

std::vector<Vec3d> hullPointsOutsideBox(const Box& box, const ObjectClone& obj,
                                        const Reconstruction& rec)
{
    const VoxelGrid& g = obj.grid;
    std::vector<int> keys;
    std::vector<const Mat*> sils;
    for (const auto& m : obj.masks)
    {
        keys.push_back(m.first);
        sils.push_back(&m.second);
    }
    const double diag = cv::norm(box.hi - box.lo);
    const double step = 0.5 * g.h;
    // X projects in front of every key frame's camera, into its image and its silhouette (key
    // frame `skip` aside).
    auto inSilhouettes = [&](const Vec3d& X, int skip) {
        for (size_t o = 0; o < keys.size(); o++)
        {
            if ((int)o == skip)
                continue;
            const Camera& c2 = rec.camera(keys[o]);
            if (c2.model == PERSPECTIVE && !(c2.depth(X) > 0))
                return false;
            const Point2d p = c2.project(X);
            const Point ip(cvRound(p.x), cvRound(p.y));
            if (ip.x < 0 || ip.y < 0 || ip.x >= sils[o]->cols || ip.y >= sils[o]->rows ||
                !sils[o]->at<uchar>(ip))
                return false;
        }
        return true;
    };
    std::vector<std::vector<Vec3d> > found(keys.size());
    parallel_for_(Range(0, (int)keys.size()), [&](const Range& r) {
        for (int q = r.start; q < r.end; q++)
        {
            const Camera& cam = rec.camera(keys[q]);
            const Mat& sil = *sils[q];
            // Over the silhouette's bounding box (and a ring, so that the outline's distance is
            // right at the box's border).
            const Rect roi = Rect(boundingRect(sil) + Size(2, 2) - Point(1, 1)) &
                             Rect(Point(), sil.size());
            const VoxelProjector proj = g.projector(cam, sil.size());
            Mat zmin(roi.size(), CV_32F, Scalar(std::numeric_limits<float>::infinity()));
            splatVoxels(proj, obj.surface.ijk.data(), obj.surface.faces.data(),
                        obj.surface.size(), true, zmin, nullptr, roi.tl());
            Mat inside;
            distanceTransform(sil(roi), inside, DIST_L2, 3);
            std::vector<Point> deep;
            for (int y = 0; y < roi.height; y++)
            {
                const float* d = inside.ptr<float>(y);
                const float* z = zmin.ptr<float>(y);
                for (int x = 0; x < roi.width; x++)
                    if (d[x] > kGrowDeepPx && z[x] == std::numeric_limits<float>::infinity())
                        deep.push_back(roi.tl() + Point(x, y));
            }
            if ((double)deep.size() <= kGrowMinFraction * countNonZero(sil(roi)))
                continue;
            const size_t stride = (deep.size() + kGrowMaxRays - 1) / kGrowMaxRays;
            for (size_t d = 0; d < deep.size(); d += stride)
            {
                const Ray ray = cam.backproject(Point2d(deep[d]));
                double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
                for (int c = 0; c < 8; c++)
                {
                    const double t = (box.corner(c) - ray.origin).dot(ray.direction);
                    t0 = std::min(t0, t);
                    t1 = std::max(t1, t);
                }
                t0 -= kGrowReach * diag;
                t1 += kGrowReach * diag;
                if (cam.model == PERSPECTIVE)
                    t0 = std::max(t0, step);
                // Hull samples outside the box, nearest to it first.
                std::vector<std::pair<double, Vec3d> > cand;
                for (double t = t0; t <= t1; t += step)
                {
                    const Vec3d X = ray.at(t);
                    const double dist = box.distance(X);
                    if (dist > 0 && dist < kGrowReach * diag && inSilhouettes(X, (int)q))
                        cand.push_back(std::make_pair(dist, X));
                }
                std::stable_sort(cand.begin(), cand.end(),
                                 [](const std::pair<double, Vec3d>& u,
                                    const std::pair<double, Vec3d>& v) { return u.first < v.first; });
                // The first whose straight path to the box stays in every silhouette (this key
                // frame's too): the hull crosses the box's face there. A ghost of the visual hull
                // (or a wrong blob in a mask) beyond a gap is not taken.
                for (size_t c = 0; c < cand.size() && c < (size_t)kGrowMaxCandidates; c++)
                {
                    const Vec3d X = cand[c].second;
                    const Vec3d B = box.toWorld(box.clamp(box.toBox(X)));
                    const int n = (int)std::ceil(cv::norm(X - B) / step);
                    bool connected = true;
                    for (int k = 1; k < n && connected; k++)
                        connected = inSilhouettes(X + (B - X) * ((double)k / n), -1);
                    if (connected)
                    {
                        found[q].push_back(X);
                        break;
                    }
                }
            }
        }
    });
    std::vector<Vec3d> all;
    for (const std::vector<Vec3d>& f : found)
        all.insert(all.end(), f.begin(), f.end());
    return all;
}

// After the grid grew to hold `points`: outside `box` (and its grid margin) only the voxels next
// to those points stay, so that the larger grid does not free the rest of the visual hull beyond
// the old faces (wedges no key frame can carve: behind other objects, under the ground).
void keepOutsideBoxNear(ObjectClone& obj, const Box& box, const std::vector<Vec3d>& points)
{
    VoxelGrid& g = obj.grid;
    std::vector<uchar> near(g.data.size(), 0);
    for (const Vec3d& X : points)
    {
        const Vec3d v = g.toVoxel(X);
        const int i0 = cvRound(v[0]), j0 = cvRound(v[1]), k0 = cvRound(v[2]);
        for (int k = k0 - 1; k <= k0 + 1; k++)
            for (int j = j0 - 1; j <= j0 + 1; j++)
                for (int i = i0 - 1; i <= i0 + 1; i++)
                    if (g.inside(i, j, k))
                        near[g.index(i, j, k)] = 1;
    }
    const double margin = kGridMarginVoxels * g.h;
    parallel_for_(Range(0, g.dims[2]), [&](const Range& r) {
        for (int k = r.start; k < r.end; k++)
            for (int j = 0; j < g.dims[1]; j++)
                for (int i = 0; i < g.dims[0]; i++)
                {
                    const size_t idx = g.index(i, j, k);
                    if (!g.data[idx] || near[idx])
                        continue;
                    const Vec3d b = box.toBox(g.centre(i, j, k));
                    bool in = true;
                    for (int a = 0; a < 3 && in; a++)
                        in = b[a] >= box.lo[a] - margin && b[a] <= box.hi[a] + margin;
                    if (!in)
                        g.data[idx] = 0;
                }
    });
    obj.surface = g.surface();
}

} // namespace

int64 passGridGrowth(ObjectClone& obj, const PassContext& ctx)
{
    const Box box0 = obj.box;
    const std::vector<Vec3d> extra = hullPointsOutsideBox(box0, obj, ctx.rec);
    if (extra.empty())
        return 0;
    const int64 before = obj.grid.count();
    Box box = box0;
    for (const Vec3d& X : extra)
    {
        const Vec3d b = box.toBox(X);
        box.include(b - Vec3d::all(obj.grid.h));
        box.include(b + Vec3d::all(obj.grid.h));
    }
    CV_LOG_INFO(NULL, cv::format("augocc: object '%s': grid grown to hold the visual hull %d "
                "key-frame rays need beyond the box", obj.name.c_str(), (int)extra.size()));
    makeGrid(obj, box, ctx);
    PassContext all = ctx;
    all.carveFrame = -1;
    passCarve(obj, all);
    keepOutsideBoxNear(obj, box0, extra);
    return obj.grid.count() - before;
}

} // namespace detail
} // namespace augocc
} // namespace cv
