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
// corner passes in front of the corner); a triangle on one plane with its three neighbours (a
// facade) in front of its own plane, less a margin of a few voxels. The visual hull from a
// narrow orbit is deep along the lines of sight (a box seen over 50 degrees keeps a wedge in
// front of its facade) and fills
// concavities (an L-shaped block's inner corner); these phantoms hide virtual objects that
// stand in front of the real ones, and free space removes them where the object has texture.
// Only each object's own points (Step 1) carve its grid, so a featureless object in front of a
// textured one is not carved by the other's triangles.

#include "precomp.hpp"
#include "clone/passes.hpp"
#include "clone/key_frame_coverage.hpp"
#include "stats.hpp"

namespace cv {
namespace augocc {
namespace detail {

namespace {

// One frame's free-space map for one object: per pixel, the camera depth in front of which the
// line of sight is empty (-inf where nothing is known). Observations farther than maxReprojPx
// from their point's projection (a track that slid along an occluding contour) are left out.
Mat freeDepthMap(const Reconstruction& rec, const Tracks& tracks, const std::vector<int>& pts,
                 const Camera& cam, double h,
                 const CloneBuilder::FreeSpaceParams& params)
{
    const int f = cam.frame;
    const Size size = rec.imageSize;
    const Rect img(0, 0, size.width, size.height);
    std::vector<Point2f> px;
    std::vector<double> z;
    std::vector<Vec3d> Xs;
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
        Xs.push_back(Xw);
    }
    if (px.size() < 3)
        return Mat();
    Subdiv2D sub(Rect(-1, -1, size.width + 2, size.height + 2));
    // Vertex position -> its point (the nearest of coincident points).
    std::map<std::pair<float, float>, int> vertexOf;
    for (size_t q = 0; q < px.size(); q++)
    {
        const std::pair<float, float> key(px[q].x, px[q].y);
        auto it = vertexOf.find(key);
        if (it == vertexOf.end())
        {
            sub.insert(px[q]);
            vertexOf[key] = (int)q;
        }
        else if (z[q] < z[it->second])
            it->second = (int)q;
    }
    std::vector<Vec6f> tris;
    sub.getTriangleList(tris);
    struct Tri
    {
        int v[3];
        double edge = 0, zmin = 0, minCos = 1;
        Vec3d normal;
        bool planar = false;
    };
    std::vector<Tri> keep;
    for (const Vec6f& t : tris)
    {
        Tri tri;
        tri.zmin = std::numeric_limits<double>::infinity();
        bool ok = true;
        for (int c = 0; c < 3 && ok; c++)
        {
            const Point2f a(t[2 * c], t[2 * c + 1]), b(t[(2 * c + 2) % 6], t[(2 * c + 3) % 6]);
            tri.edge = std::max(tri.edge, (double)cv::norm(a - b));
            auto it = vertexOf.find(std::pair<float, float>(a.x, a.y));
            ok = it != vertexOf.end();
            if (ok)
            {
                tri.v[c] = it->second;
                tri.zmin = std::min(tri.zmin, z[it->second]);
            }
        }
        if (!ok)
            continue;
        const Vec3d n = (Xs[tri.v[1]] - Xs[tri.v[0]]).cross(Xs[tri.v[2]] - Xs[tri.v[0]]);
        const double nn = cv::norm(n);
        tri.normal = nn > 0 ? n / nn : Vec3d(0, 0, 0);
        keep.push_back(tri);
    }
    if (keep.empty())
        return Mat();
    // A triangle is planar when it and the three triangles across its edges lie on one plane
    // (normals within params.planarDeg): on a facade, not spanning a corner. Its free space
    // follows its plane (depth interpolated over the triangle, 1/z under perspective) less
    // marginVoxels, or less the bulge of a curved surface (half its edge times the sine of the
    // largest angle to its neighbours) when that is more; the others stay flat at their nearest
    // vertex less the edge margin (a triangle that spans a convex corner passes in front of the
    // corner by up to about half its edge).
    std::map<std::pair<int, int>, std::vector<int> > byEdge;
    for (size_t q = 0; q < keep.size(); q++)
        for (int c = 0; c < 3; c++)
        {
            const int a = keep[q].v[c], b = keep[q].v[(c + 1) % 3];
            byEdge[std::make_pair(std::min(a, b), std::max(a, b))].push_back((int)q);
        }
    const double cosPlanar = std::cos(params.planarDeg * CV_PI / 180);
    for (size_t q = 0; q < keep.size(); q++)
    {
        Tri& t = keep[q];
        if (params.planarDeg <= 0 || cv::norm(t.normal) == 0)
            continue;
        int across = 0;
        bool planar = true;
        for (int c = 0; c < 3 && planar; c++)
        {
            const int a = t.v[c], b = t.v[(c + 1) % 3];
            for (int o : byEdge[std::make_pair(std::min(a, b), std::max(a, b))])
                if (o != (int)q)
                {
                    across++;
                    const double cosN = std::abs(keep[o].normal.dot(t.normal));
                    t.minCos = std::min(t.minCos, cosN);
                    planar = cosN >= cosPlanar;
                }
        }
        t.planar = planar && across == 3;
    }
    // Triangles much longer than is typical for this frame's points span gaps (between two parts
    // of the object, across a notch): they are left out unless planar (on one facade with their
    // neighbours: the gap is then the facade itself, sparse in tracks). Relative, so that the
    // rule does not depend on the image size or on how many tracks the tracker keeps.
    std::vector<double> sorted;
    for (const Tri& t : keep)
        sorted.push_back(t.edge);
    const double maxEdge = params.maxEdgeRatio * medianInPlace(sorted);
    size_t w = 0;
    for (size_t q = 0; q < keep.size(); q++)
        if (keep[q].edge <= maxEdge || keep[q].planar)
            keep[w++] = keep[q];
    keep.resize(w);
    if (keep.empty())
        return Mat();
    // Flat triangles first, nearer values last (a pixel shared by two keeps the nearer:
    // conservative); then the planar ones, each pixel keeping the nearer of what it has.
    struct Flat
    {
        Point v[3];
        float value;
    };
    std::vector<Flat> flats;
    for (const Tri& t : keep)
        if (!t.planar)
        {
            const double ppu = cam.pixelsPerUnit(t.zmin);
            const double margin =
                std::max(params.marginVoxels * h, params.edgeMargin * t.edge / ppu);
            Flat fl;
            for (int c = 0; c < 3; c++)
                fl.v[c] = Point(cvRound(px[t.v[c]].x * 16), cvRound(px[t.v[c]].y * 16));
            fl.value = (float)(t.zmin - margin);
            flats.push_back(fl);
        }
    std::stable_sort(flats.begin(), flats.end(),
                     [](const Flat& u, const Flat& v) { return u.value > v.value; });
    Mat free(size, CV_32F, Scalar(-std::numeric_limits<float>::infinity()));
    for (const Flat& fl : flats)
        fillConvexPoly(free, fl.v, 3, Scalar(fl.value), LINE_8, 4);
    const bool persp = cam.model == PERSPECTIVE;
    const float none = -std::numeric_limits<float>::infinity();
    for (const Tri& t : keep)
    {
        if (!t.planar)
            continue;
        // A curved surface bulges in front of the chord plane by about half the edge times the
        // angle it turns through to the neighbours (sin of it here): that much margin too.
        const double sinTurn = std::sqrt(std::max(0.0, 1 - t.minCos * t.minCos));
        const double margin = std::max(params.marginVoxels * h,
                                       0.5 * t.edge * sinTurn / cam.pixelsPerUnit(t.zmin));
        const Point2d A(px[t.v[0]]), B(px[t.v[1]]), C(px[t.v[2]]);
        const double det = (B.x - A.x) * (C.y - A.y) - (C.x - A.x) * (B.y - A.y);
        if (std::abs(det) < 1e-9)
            continue;
        double q0 = z[t.v[0]], q1 = z[t.v[1]], q2 = z[t.v[2]];
        if (persp)
        {
            q0 = 1 / q0;
            q1 = 1 / q1;
            q2 = 1 / q2;
        }
        const int x0 = std::max(0, cvFloor(std::min(A.x, std::min(B.x, C.x))));
        const int x1 = std::min(size.width - 1, cvCeil(std::max(A.x, std::max(B.x, C.x))));
        const int y0 = std::max(0, cvFloor(std::min(A.y, std::min(B.y, C.y))));
        const int y1 = std::min(size.height - 1, cvCeil(std::max(A.y, std::max(B.y, C.y))));
        for (int y = y0; y <= y1; y++)
        {
            float* row = free.ptr<float>(y);
            for (int x = x0; x <= x1; x++)
            {
                const double l1 = ((x - A.x) * (C.y - A.y) - (C.x - A.x) * (y - A.y)) / det;
                const double l2 = ((B.x - A.x) * (y - A.y) - (x - A.x) * (B.y - A.y)) / det;
                const double l0 = 1 - l1 - l2;
                if (l0 < 0 || l1 < 0 || l2 < 0)
                    continue;
                double zi = l0 * q0 + l1 * q1 + l2 * q2;
                if (persp)
                    zi = 1 / zi;
                const float value = (float)(zi - margin);
                row[x] = row[x] == none ? value : std::min(row[x], value);
            }
        }
    }
    return free;
}

} // namespace

int64 passFreeSpace(ObjectClone& obj, const PassContext& ctx)
{
    const CloneBuilder::FreeSpaceParams& params = ctx.params.freeSpace;
    const Reconstruction& rec = ctx.rec;
    if (!ctx.tracks || rec.points.empty() || params.minViews <= 0)
        return 0;
    const Tracks& tracks = *ctx.tracks;
    const std::vector<const Camera*> cams = evenlySpacedCameras(rec, params.maxViews);
    VoxelGrid& g = obj.grid;
    if (g.empty() || obj.points.size() < 3)
        return 0;
    std::vector<Mat> free(cams.size());
    std::vector<VoxelProjector> proj(cams.size());
    parallel_for_(Range(0, (int)cams.size()), [&](const Range& r) {
        for (int q = r.start; q < r.end; q++)
        {
            free[q] = freeDepthMap(rec, tracks, obj.points, *cams[q], g.h, params);
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
    std::vector<uchar> answer, carved;
    std::vector<std::vector<Vec3i>> exposedOf;
    while (!wave.empty())
    {
        answer.assign(wave.size(), 0);
        parallel_for_(Range(0, (int)wave.size()), [&](const Range& r) {
            for (int q = r.start; q < r.end; q++)
                answer[q] = isFree(wave[q][0], wave[q][1], wave[q][2]);
        });
        // The free voxels carved in the wave's order (the key frames' counts in parallel).
        std::vector<Vec3i> cands;
        for (size_t q = 0; q < wave.size(); q++)
            if (answer[q])
                cands.push_back(wave[q]);
        cov.carveInOrder(cands, carved, exposedOf);
        std::vector<Vec3i> next;
        for (size_t q = 0; q < cands.size(); q++)
        {
            if (!carved[q])
                continue;
            n++;
            for (const Vec3i& e : exposedOf[q])
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
    return n;
}

} // namespace detail
} // namespace augocc
} // namespace cv
