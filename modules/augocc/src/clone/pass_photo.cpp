// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Photo-consistency carving of the clones beyond the visual hull (CloneBuilder::refine): space
// carving @cite Kutulakos2000 by plane sweeps with voxel colouring's visibility bookkeeping
// @cite Seitz1999, on every frame with a camera, under the key-frame silhouettes' protection.

#include "precomp.hpp"
#include "clone/passes.hpp"
#include "clone/key_frame_coverage.hpp"
#include "stats.hpp"

namespace cv {
namespace augocc {
namespace detail {

namespace {

// A sweep uses the cameras that look along its direction by at least this cosine (about 75
// degrees): the plane order is then a visibility order for them (ordinal visibility, K&S
// Section 5), with a margin against cameras that graze the planes.
const double kMinSweepCos = 0.25;
// Depth tolerance of the visibility test, in voxel edges: a voxel is seen when no nearer surface
// covers its centre pixel by more than this (neighbours on the same surface differ by up to about
// one voxel edge along the view; two keep a sloped surface visible).
const double kVisibilityTolVoxels = 2.0;
// Exposure: a view's colour may be scaled by up to this factor (either way) to match the others
// (automatic exposure between frames of real footage).
const double kExposureTolerance = 0.1;
// Below this many candidates a plane's work runs on the calling thread (same results).
const int kMinParallelItems = 512;


// Colour match of view pixel p against ref within `threshold` per channel, after the best gain.
inline bool matches(const uchar* p, const float* ref, double threshold)
{
    const double cr = p[0] * ref[0] + p[1] * ref[1] + p[2] * ref[2];
    const double cc = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    double g = cc > 0 ? cr / cc : 1.0;
    g = std::min(1.0 + kExposureTolerance, std::max(1.0 / (1.0 + kExposureTolerance), g));
    return std::abs(g * p[0] - ref[0]) <= threshold && std::abs(g * p[1] - ref[1]) <= threshold &&
           std::abs(g * p[2] - ref[2]) <= threshold;
}

// Colour agreement of one voxel over its views (K&S's consistency check). Samples: the voxel's
// centre pixel, and with patchStep > 0 also the four pixels patchStep away along the image axes
// (a sparse patch: texture above and below a uniform band still tells a phantom voxel, which
// sees the texture slide, from a surface voxel). The reference of each sample is the per-channel
// median over the views; a view agrees when every sample has a pixel in its 3x3 neighbourhood
// (half-pixel projection, texture aliasing) within `threshold` per channel of the reference,
// after the pixel's best exposure gain within kExposureTolerance. Consistent when at least
// minAgreement of the views agree.
bool consistent(const std::vector<Point>& px, const std::vector<const Mat*>& img, double threshold,
                double minAgreement, int patchStep, std::vector<float>& scratch)
{
    const int n = (int)px.size();
    const int s = patchStep;
    const int nk = s > 0 ? 5 : 1;
    const Point offs[5] = {Point(0, 0), Point(0, -s), Point(0, s), Point(-s, 0), Point(s, 0)};
    float ref[5][3];
    scratch.resize(n);
    for (int k = 0; k < nk; k++)
        for (int c = 0; c < 3; c++)
        {
            for (int v = 0; v < n; v++)
            {
                const Point q = px[v] + offs[k];
                scratch[v] = img[v]->ptr<uchar>(q.y)[3 * q.x + c];
            }
            ref[k][c] = medianInPlace(scratch);
        }
    const int need = (int)std::ceil(minAgreement * n - 1e-9);
    int agree = 0;
    for (int v = 0; v < n; v++)
    {
        bool all = true;
        for (int k = 0; k < nk && all; k++)
        {
            const Point q = px[v] + offs[k];
            bool ok = false;
            for (int dy = -1; dy <= 1 && !ok; dy++)
            {
                const uchar* row = img[v]->ptr<uchar>(q.y + dy) + 3 * q.x;
                ok = matches(row - 3, ref[k], threshold) || matches(row, ref[k], threshold) ||
                     matches(row + 3, ref[k], threshold);
            }
            all = ok;
        }
        agree += all;
        if (agree >= need)
            return true;
        if (agree + (n - 1 - v) < need)
            return false;
    }
    return agree >= need;
}

// Cameras that may take part in a sweep along +-axis `axis` of the grid.
std::vector<int> sweepCameras(const VoxelGrid& g, int axis, int sign, const PhotoObjectViews& ov)
{
    std::vector<int> cams;
    for (size_t c = 0; c < ov.proj.size(); c++)
    {
        const VoxelProjector& pr = ov.proj[c];
        bool ok = true;
        if (pr.affine)
            ok = sign * pr.viewDir[axis] >= kMinSweepCos * cv::norm(pr.viewDir);
        else
            for (int q = 0; q < 8 && ok; q++)
            {
                // Every point of the grid ahead of the camera along the sweep.
                const Vec3d X(q & 1 ? g.dims[0] - 0.5 : -0.5, q & 2 ? g.dims[1] - 0.5 : -0.5,
                              q & 4 ? g.dims[2] - 0.5 : -0.5);
                const Vec3d d = X - pr.camVoxel;
                ok = sign * d[axis] >= kMinSweepCos * cv::norm(d);
            }
        if (ok && !ov.roi[c].empty())
            cams.push_back((int)c);
    }
    return cams;
}

// One plane sweep of space carving over one object's grid along +-axis `axis` (K&S Section 5.2):
// planes in order of increasing distance along the sweep, cameras that look along it. A surface
// voxel is seen in a camera when no kept voxel of an earlier plane (by the ordinal visibility
// constraint, the only possible occluders) and no other clone covers its centre pixel nearer
// than the tolerance. Inconsistent voxels go (KeyFrameCoverage permitting); carving exposes the
// voxels behind them in the plane, which are checked in turn, then the plane's kept surface is
// drawn into the cameras' cover maps. `surface` (packed voxels, every surface voxel of the
// grid, possibly carved ones too) is where a plane's candidates come from, so that the sweep's
// cost follows the surface, not the volume (scanning every plane for its surface voxels took a
// third of the sweeps' time at 1080p); the voxels carving brings to the surface are added to it.
// Returns the number of voxels carved.
int64 sweep(VoxelGrid& g, int axis, int sign, const std::vector<int>& cams,
            const PhotoObjectViews& ov, KeyFrameCoverage& cov,
            const CloneBuilder::PhotoParams& p, std::vector<uint32_t>& surface)
{
    const int nv = (int)cams.size();
    std::vector<Mat> cover(nv);
    for (int v = 0; v < nv; v++)
        cover[v] = Mat(ov.roi[cams[v]].size(), CV_32F,
                       Scalar(std::numeric_limits<float>::infinity()));
    const double tol = kVisibilityTolVoxels * g.h;
    // Per view: raw pointers for the inner loop.
    struct ViewData
    {
        const VoxelProjector* proj;
        Rect roi;
        int maxX, maxY;
        const float* cover;
        size_t coverStep;
        const float* others;
        size_t othersStep;
        const Mat* image;
    };
    const int margin = p.patchStep + 1;
    std::vector<ViewData> views(nv);
    for (int v = 0; v < nv; v++)
    {
        const int c = cams[v];
        ViewData& vd = views[v];
        vd.proj = &ov.proj[c];
        vd.roi = ov.roi[c];
        vd.maxX = vd.proj->size.width - margin;
        vd.maxY = vd.proj->size.height - margin;
        vd.cover = cover[v].ptr<float>();
        vd.coverStep = cover[v].step1();
        vd.others = ov.others[c].empty() ? nullptr : ov.others[c].ptr<float>();
        vd.othersStep = ov.others[c].empty() ? 0 : ov.others[c].step1();
        vd.image = ov.image[c];
    }
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    const int n1 = g.dims[a1], n2 = g.dims[a2], np = g.dims[axis];
    std::vector<uchar> mark((size_t)n1 * n2);
    int64 carved = 0;

    // 0 keep, 1 carve.
    auto evaluate = [&](const std::vector<Vec3i>& work, std::vector<uchar>& carve) {
        carve.assign(work.size(), 0);
        auto body = [&](const Range& r) {
            std::vector<Point> px;
            std::vector<const Mat*> img;
            std::vector<float> scratch;
            for (int q = r.start; q < r.end; q++)
            {
                const Vec3i& w = work[q];
                px.clear();
                img.clear();
                for (int v = 0; v < nv; v++)
                {
                    const ViewData& vd = views[v];
                    const VoxelProjector& pr = *vd.proj;
                    Point pt;
                    if (!pr.centrePixel(w[0], w[1], w[2], pt))
                        continue;
                    const int x = pt.x - vd.roi.x, y = pt.y - vd.roi.y;
                    if (pt.x < margin || pt.y < margin || pt.x >= vd.maxX || pt.y >= vd.maxY ||
                        x < 0 || y < 0 || x >= vd.roi.width || y >= vd.roi.height)
                        continue;
                    const double z = pr.Z[0] * w[0] + (pr.Z[1] * w[1] + pr.Z[2] * w[2] + pr.z0);
                    if (z > vd.cover[(size_t)y * vd.coverStep + x] + tol)
                        continue;
                    if (vd.others && z > vd.others[(size_t)y * vd.othersStep + x] + tol)
                        continue;
                    px.push_back(pt);
                    img.push_back(vd.image);
                }
                if ((int)px.size() < p.minViews)
                    continue;
                carve[q] = !consistent(px, img, p.threshold, p.minAgreement, p.patchStep, scratch);
            }
        };
        if ((int)work.size() >= kMinParallelItems)
            parallel_for_(Range(0, (int)work.size()), body);
        else
            body(Range(0, (int)work.size()));
    };

    // The surface voxels by plane (carving only removes voxels and brings others to the
    // surface: a plane's surface when its turn comes is its bucket plus what was exposed).
    std::vector<std::vector<uint32_t>> bucket(np);
    {
        size_t alive = 0;
        for (uint32_t v : surface)
        {
            int w[3];
            unpackVoxel(v, w[0], w[1], w[2]);
            if (!g.data[g.index(w[0], w[1], w[2])])
                continue;  // carved by an earlier sweep
            surface[alive++] = v;
            bucket[w[axis]].push_back(v);
        }
        surface.resize(alive);
    }
    std::vector<Vec3i> work, next, kept;
    std::vector<uchar> carve;
    std::vector<std::pair<int, uint32_t>> order;
    for (int s = 0; s < np; s++)
    {
        const int plane = sign > 0 ? s : np - 1 - s;
        std::fill(mark.begin(), mark.end(), 0);
        work.clear();
        kept.clear();
        // In the plane's scan order (a2 outer, a1 inner), as the carving's outcome depends on it.
        order.clear();
        for (uint32_t v : bucket[plane])
        {
            int w[3];
            unpackVoxel(v, w[0], w[1], w[2]);
            order.emplace_back(w[a2] * n1 + w[a1], v);
        }
        std::vector<uint32_t>().swap(bucket[plane]);
        std::sort(order.begin(), order.end());
        for (const auto& o : order)
        {
            Vec3i w;
            unpackVoxel(o.second, w[0], w[1], w[2]);
            work.push_back(w);
            mark[o.first] = 1;
        }
        while (!work.empty())
        {
            evaluate(work, carve);
            next.clear();
            for (size_t q = 0; q < work.size(); q++)
            {
                const Vec3i& w = work[q];
                if (!carve[q] || !cov.tryCarve(w[0], w[1], w[2]))
                {
                    kept.push_back(w);
                    continue;
                }
                carved++;
                for (const Vec3i& e : cov.exposed())
                {
                    const uint32_t packed = packVoxel(e[0], e[1], e[2]);
                    surface.push_back(packed);
                    if (sign * (e[axis] - plane) > 0)
                        bucket[e[axis]].push_back(packed);  // a plane still to come
                }
                for (int d = 0; d < 4; d++)
                {
                    Vec3i u = w;
                    u[d < 2 ? a1 : a2] += d % 2 ? 1 : -1;
                    if (!g.inside(u[0], u[1], u[2]) || !g.data[g.index(u[0], u[1], u[2])])
                        continue;
                    uchar& m = mark[(size_t)u[a2] * n1 + u[a1]];
                    if (m)
                        continue;
                    m = 1;
                    next.push_back(u);
                }
            }
            work.swap(next);
        }
        // The plane's kept surface now hides what lies behind it.
        auto draw = [&](const Range& r) {
            for (int v = r.start; v < r.end; v++)
            {
                const VoxelProjector& pr = ov.proj[cams[v]];
                const Rect& roi = ov.roi[cams[v]];
                Mat& cv_ = cover[v];
                for (const Vec3i& w : kept)
                {
                    int x0, x1, y0, y1;
                    double z;
                    if (!pr.footprint(w[0], w[1], w[2], x0, x1, y0, y1, z))
                        continue;
                    x0 = std::max(x0, roi.x) - roi.x;
                    y0 = std::max(y0, roi.y) - roi.y;
                    x1 = std::min(x1, roi.x + roi.width - 1) - roi.x;
                    y1 = std::min(y1, roi.y + roi.height - 1) - roi.y;
                    const float zf = (float)z;
                    for (int y = y0; y <= y1; y++)
                    {
                        float* row = cv_.ptr<float>(y);
                        for (int x = x0; x <= x1; x++)
                            row[x] = std::min(row[x], zf);
                    }
                }
            }
        };
        if (!kept.empty())
        {
            if ((int)kept.size() * nv >= kMinParallelItems)
                parallel_for_(Range(0, nv), draw);
            else
                draw(Range(0, nv));
        }
    }
    return carved;
}

} // namespace

PhotoViews preparePhotoViews(const CloneSetImpl& clones, const Reconstruction& rec,
                             const std::vector<Mat>& frames,
                             const CloneBuilder::PhotoParams& p, const Mat* inFrame)
{
    const std::vector<String> names = clones.objectNames();
    PhotoViews views;
    // The cameras compared.
    views.cameras = evenlySpacedCameras(rec, p.maxViews);
    const std::vector<const Camera*>& use = views.cameras;
    const int nc = (int)use.size();
    const int no = (int)names.size();
    const Size size = rec.imageSize;
    std::vector<PhotoObjectViews*> ov(no);
    for (int o = 0; o < no; o++)
    {
        const VoxelGrid& g = clones.get(names[o]).grid;
        PhotoObjectViews& v = views.objects[names[o]];
        ov[o] = &v;
        v.proj.resize(nc);
        v.roi.resize(nc);
        v.others.resize(nc);
        v.image.resize(nc);
        for (int c = 0; c < nc; c++)
        {
            v.proj[c] = g.projector(*use[c], size);
            v.roi[c] = g.imageBounds(v.proj[c]);
            v.image[c] = &frames[use[c]->frame];
        }
    }
    // Objects hide each other: per camera, the nearest depth of the other clones as they
    // stand (the renderer of the compositor; objects only shrink, so this is conservative).
    // Where the ideal view of a lens sees beyond the frame (inFrame), every voxel counts as
    // hidden (depth -inf): that view has no colour for it.
    if (no > 1 || inFrame)
        parallel_for_(Range(0, nc), [&](const Range& r) {
            std::vector<Mat> depth(no);
            for (int c = r.start; c < r.end; c++)
            {
                const Camera& cam = *use[c];
                if (no > 1)
                    for (int o = 0; o < no; o++)
                        clones.render(names[o], cam.frame, cam, size, noArray(), depth[o]);
                for (int a = 0; a < no; a++)
                {
                    const Rect& roi = ov[a]->roi[c];
                    if (roi.empty())
                        continue;
                    Mat m(roi.size(), CV_32F, Scalar(std::numeric_limits<float>::infinity()));
                    for (int o = 0; o < no; o++)
                        if (o != a)
                            cv::min(m, depth[o](roi), m);
                    if (inFrame)
                        m.setTo(Scalar(-std::numeric_limits<float>::infinity()),
                                (*inFrame)(roi) == 0);
                    ov[a]->others[c] = m;
                }
            }
        });
    return views;
}

int64 passPhoto(ObjectClone& obj, const PassContext& ctx)
{
    const CloneBuilder::PhotoParams& p = ctx.params.photo;
    const PhotoObjectViews& ov = ctx.photo->objects.at(obj.name);
    // The key-frame protection, from the surface as it stands (what the last round left).
    KeyFrameCoverage cov(obj.grid, obj, ctx.rec);
    // Sweeps with the most cameras first; the others catch what they expose.
    std::vector<std::pair<int, int> > order;  // (-cameras, 2 * axis + (sign > 0))
    std::vector<std::vector<int> > cams(6);
    for (int d = 0; d < 6; d++)
    {
        cams[d] = sweepCameras(obj.grid, d / 2, d % 2 ? 1 : -1, ov);
        if ((int)cams[d].size() >= p.minViews)
            order.push_back(std::make_pair(-(int)cams[d].size(), d));
    }
    std::sort(order.begin(), order.end());
    int64 n = 0;
    std::vector<uint32_t> surface = obj.grid.surface().ijk;
    std::vector<std::vector<int> > done;
    for (const auto& d : order)
    {
        // Two opposite sweeps can share their cameras (all of them, when the camera moves
        // little): the second would re-check the same voxels with the same views and carved
        // about 1% more on the synthesized scene, at the cost of a sweep.
        if (std::find(done.begin(), done.end(), cams[d.second]) != done.end())
            continue;
        done.push_back(cams[d.second]);
        n += sweep(obj.grid, d.second / 2, d.second % 2 ? 1 : -1, cams[d.second], ov, cov, p,
                   surface);
    }
    if (n > 0)
        obj.surface = obj.grid.surface();
    return n;
}

} // namespace detail
} // namespace augocc
} // namespace cv
