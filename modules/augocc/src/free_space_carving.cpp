// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Free-space carving of the clones from the tracks (beyond the paper). A point tracked in frame f
// is seen there, so the line of sight between the camera and the point is empty: the visibility
// constraint of surface reconstruction from structure from motion (@cite Faugeras1990;
// @cite Labatut2007). Single lines of sight are too sparse to carve a
// solid volume (a voxel's rays hit a feature in about one frame in 300 on the synthesized
// scene), so, as those methods do with their triangulations, the free space is spread over the
// Delaunay triangles of an object's points in the image: a triangle is taken as empty in front
// of its nearest corner, less a margin that grows with its size (a triangle that spans a convex
// corner passes in front of the corner). The visual hull from a narrow orbit is deep along the
// lines of sight (a box seen over 50 degrees keeps a wedge in front of its facade) and fills
// concavities (an L-shaped block's inner corner); these phantoms hide virtual objects that
// stand in front of the real ones, and free space removes them where the object has texture.
// Only each object's own points (Step 1) carve its grid, so a featureless object in front of a
// textured one is not carved by the other's triangles.

#include "precomp.hpp"
#include "clone_internal.hpp"
#include "key_frame_coverage.hpp"

namespace cv {
namespace augocc {
namespace detail {

namespace {

// One frame's free-space map for one object: per pixel, the camera depth in front of which the
// line of sight is empty (-inf where nothing is known). Observations farther than maxReprojPx
// from their point's projection (a track that slid along an occluding contour) are left out.
Mat freeDepthMap(const Reconstruction& rec, const Tracks& tracks, const std::vector<int>& pts,
                 const Camera& cam, double h, const FreeSpaceParams& params)
{
    const int f = cam.frame;
    const Size size = rec.imageSize;
    const Rect img(0, 0, size.width, size.height);
    std::vector<Point2f> px;
    std::vector<double> z;
    const double r2 = params.maxReprojPx * params.maxReprojPx;
    for (int p : pts)
    {
        if (f >= tracks.frames() || !tracks.observed(f, p))
            continue;
        const double* X = rec.points.ptr<double>(p);
        const Vec3d Xw(X[0], X[1], X[2]);
        const Point2f o = tracks.at(f, p);
        const Point2d q = cam.project(Xw);
        const double dx = q.x - o.x, dy = q.y - o.y;
        const double d = cam.depth(Xw);
        if (dx * dx + dy * dy > r2 || !img.contains(Point(cvFloor(o.x), cvFloor(o.y))) ||
            (cam.model == PERSPECTIVE && !(d > 0)))
            continue;
        px.push_back(o);
        z.push_back(d);
    }
    if (px.size() < 3)
        return Mat();
    Subdiv2D sub(Rect(-1, -1, size.width + 2, size.height + 2));
    // Vertex position -> depth (the nearest of coincident points).
    std::map<std::pair<float, float>, double> depthOf;
    for (size_t q = 0; q < px.size(); q++)
    {
        const std::pair<float, float> key(px[q].x, px[q].y);
        auto it = depthOf.find(key);
        if (it == depthOf.end())
        {
            sub.insert(px[q]);
            depthOf[key] = z[q];
        }
        else
            it->second = std::min(it->second, z[q]);
    }
    std::vector<Vec6f> tris;
    sub.getTriangleList(tris);
    struct Tri
    {
        Point v[3];
        float value;
    };
    std::vector<Tri> keep;
    std::vector<double> edges, depths;
    for (const Vec6f& t : tris)
    {
        Tri tri;
        double zmin = std::numeric_limits<double>::infinity(), edge = 0;
        bool ok = true;
        for (int c = 0; c < 3 && ok; c++)
        {
            const Point2f a(t[2 * c], t[2 * c + 1]), b(t[(2 * c + 2) % 6], t[(2 * c + 3) % 6]);
            edge = std::max(edge, (double)cv::norm(a - b));
            auto it = depthOf.find(std::pair<float, float>(a.x, a.y));
            ok = it != depthOf.end();
            if (ok)
                zmin = std::min(zmin, it->second);
            tri.v[c] = Point(cvRound(a.x * 16), cvRound(a.y * 16));
        }
        if (!ok)
            continue;
        keep.push_back(tri);
        edges.push_back(edge);
        depths.push_back(zmin);
    }
    if (keep.empty())
        return Mat();
    // Triangles much longer than is typical for this frame's points span gaps (between two parts
    // of the object, across a notch): they are left out. Relative, so that the rule does not
    // depend on the image size or on how many tracks the tracker keeps.
    std::vector<double> sorted = edges;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double maxEdge = params.maxEdgeRatio * sorted[sorted.size() / 2];
    size_t w = 0;
    for (size_t q = 0; q < keep.size(); q++)
    {
        if (edges[q] > maxEdge)
            continue;
        const double ppu = cam.pixelsPerUnit(depths[q]);
        const double margin =
            std::max(params.marginVoxels * h, params.edgeMargin * edges[q] / ppu);
        keep[w] = keep[q];
        keep[w].value = (float)(depths[q] - margin);
        w++;
    }
    keep.resize(w);
    if (keep.empty())
        return Mat();
    // Nearer values last: a pixel shared by two triangles keeps the nearer (conservative).
    std::stable_sort(keep.begin(), keep.end(),
                     [](const Tri& a, const Tri& b) { return a.value > b.value; });
    Mat free(size, CV_32F, Scalar(-std::numeric_limits<float>::infinity()));
    for (const Tri& t : keep)
        fillConvexPoly(free, t.v, 3, Scalar(t.value), LINE_8, 4);
    return free;
}

} // namespace

std::map<String, int64> freeSpaceCarve(CloneSetImpl& set, const Reconstruction& rec,
                                       const Tracks& tracks,
                                       const std::map<String, std::vector<int> >& members,
                                       const FreeSpaceParams& params)
{
    std::map<String, int64> carved;
    if (rec.points.empty() || params.minViews <= 0)
        return carved;
    const std::vector<const Camera*> cams = evenlySpacedCameras(rec, params.maxViews);
    for (auto& o : set.objects)
    {
        ObjectClone& obj = o.second;
        VoxelGrid& g = obj.grid;
        carved[o.first] = 0;
        auto mit = members.find(o.first);
        if (g.empty() || mit == members.end() || mit->second.size() < 3)
            continue;
        std::vector<Mat> free(cams.size());
        std::vector<VoxelProjector> proj(cams.size());
        parallel_for_(Range(0, (int)cams.size()), [&](const Range& r) {
            for (int q = r.start; q < r.end; q++)
            {
                free[q] = freeDepthMap(rec, tracks, mit->second, *cams[q], g.h, params);
                proj[q] = g.projector(*cams[q], rec.imageSize);
            }
        });
        // A voxel is free when at least minViews frames' free space holds its centre. Only the
        // voxels the peel reaches are asked (the surface, then what each carve exposes), in
        // waves: the wave's answers in parallel, then its carves in order (deterministic).
        auto isFree = [&](int i, int j, int k) {
            int votes = 0;
            for (size_t q = 0; q < proj.size(); q++)
            {
                if (free[q].empty())
                    continue;
                Point px;
                if (!proj[q].centrePixel(i, j, k, px) || px.x < 0 || px.y < 0 ||
                    px.x >= free[q].cols || px.y >= free[q].rows)
                    continue;
                const double zv = proj[q].Z.dot(Vec3d(i, j, k)) + proj[q].z0;
                if (zv < free[q].at<float>(px) && ++votes >= params.minViews)
                    return true;
            }
            return false;
        };
        std::vector<uchar> queued(g.data.size(), 0);
        std::vector<Vec3i> wave;
        for (uint32_t v : obj.surface.ijk)
        {
            int i, j, k;
            unpackVoxel(v, i, j, k);
            wave.push_back(Vec3i(i, j, k));
            queued[g.index(i, j, k)] = 1;
        }
        KeyFrameCoverage cov(g, obj, rec);
        int64 n = 0;
        std::vector<uchar> answer;
        while (!wave.empty())
        {
            answer.assign(wave.size(), 0);
            parallel_for_(Range(0, (int)wave.size()), [&](const Range& r) {
                for (int q = r.start; q < r.end; q++)
                    answer[q] = isFree(wave[q][0], wave[q][1], wave[q][2]);
            });
            std::vector<Vec3i> next;
            for (size_t q = 0; q < wave.size(); q++)
            {
                const Vec3i& v = wave[q];
                if (!answer[q] || !g.data[g.index(v[0], v[1], v[2])] ||
                    !cov.isSurface(v[0], v[1], v[2]) || !cov.tryCarve(v[0], v[1], v[2]))
                    continue;
                n++;
                for (const Vec3i& e : cov.exposed())
                {
                    const size_t idx = g.index(e[0], e[1], e[2]);
                    if (!queued[idx])
                    {
                        queued[idx] = 1;
                        next.push_back(e);
                    }
                }
            }
            wave.swap(next);
        }
        if (n > 0)
            obj.surface = g.surface();
        carved[o.first] = n;
    }
    return carved;
}

} // namespace detail
} // namespace augocc
} // namespace cv
