// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Beyond the paper, for what no frame can see. A part of the visual hull that is behind another
// object or behind the object's own near side in every frame of the video (the lower back of a
// tower behind a building in the first key frames and behind its own shaft in the last) is not
// constrained by any silhouette: the hull keeps it at its largest, a wedge along the lines of
// sight of the key frames that see the part. Since no frame sees it, it changes no composite of
// the video; but it is conjecture, and in the object's matte as if alone (and in any view beyond
// the video) it shows as a bulge. The prior taken here is support along the vertical: the clone's
// voxels are cut into vertical runs (the grid axis nearest the vertical the cameras give), and a
// run none of whose voxels any frame shows (first along its line of sight among every clone's
// voxels, in UnobservedParams::views evenly spaced frames and every key frame) goes. The inside
// of a building under its seen roof, the hidden back of a shaft under its seen cap, stay (their
// run holds a seen voxel); a wedge with air above it and the ground below goes. The unseen runs
// are opened first (UnobservedParams::keepNearSeen, regrowFromUnseen): one beside a seen run
// stays unless a wide unseen region is near, since under a top seen at a grazing angle only some
// top voxels pass the depth test.

#include "precomp.hpp"
#include "clone/passes.hpp"
#include "clone/key_frame_coverage.hpp"

#include <set>

namespace cv {
namespace augocc {
namespace detail {

ObservedSurfaces observeSurfaces(const CloneSetImpl& clones, const Reconstruction& rec,
                                 const CloneBuilder::UnobservedParams& params,
                                 const Mat* inFrame)
{
    std::vector<const Camera*> cams = evenlySpacedCameras(rec, params.views);
    std::set<int> have;
    for (const Camera* c : cams)
        have.insert(c->frame);
    for (const auto& o : clones.objects())
        for (const auto& m : o.second.masks)
            if (!have.count(m.first))
            {
                have.insert(m.first);
                cams.push_back(&rec.camera(m.first));
            }
    std::vector<String> names;
    for (const auto& o : clones.objects())
        names.push_back(o.first);
    // Per frame and object, the surface voxels seen (frames in parallel, merged in order).
    std::vector<std::vector<std::vector<uint32_t> > > seenIn(
        cams.size(), std::vector<std::vector<uint32_t> >(names.size()));
    const Size size = rec.imageSize;
    parallel_for_(Range(0, (int)cams.size()), [&](const Range& r) {
        for (int ci = r.start; ci < r.end; ci++)
        {
            const Camera& cam = *cams[ci];
            Mat zbuf(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
            std::vector<VoxelProjector> projs(names.size());
            for (size_t n = 0; n < names.size(); n++)
            {
                const ObjectClone& obj = clones.get(names[n]);
                if (obj.grid.empty())
                    continue;
                projs[n] = obj.grid.projector(cam, size);
                splatVoxels(projs[n], obj.surface.ijk.data(), obj.surface.faces.data(),
                            obj.surface.size(), true, zbuf, nullptr, Point());
            }
            for (size_t n = 0; n < names.size(); n++)
            {
                const ObjectClone& obj = clones.get(names[n]);
                if (obj.grid.empty())
                    continue;
                const double tol = params.depthTolVoxels * obj.grid.h;
                for (size_t q = 0; q < obj.surface.size(); q++)
                {
                    int i, j, k;
                    unpackVoxel(obj.surface.ijk[q], i, j, k);
                    Point px;
                    if (!projs[n].centrePixel(i, j, k, px) || px.x < 0 || px.y < 0 ||
                        px.x >= size.width || px.y >= size.height ||
                        (inFrame && !inFrame->at<uchar>(px)))
                        continue;
                    const double z = projs[n].Z.dot(Vec3d(i, j, k)) + projs[n].z0;
                    if (z <= zbuf.at<float>(px) + tol)
                        seenIn[ci][n].push_back((uint32_t)q);
                }
            }
        }
    });
    ObservedSurfaces out;
    for (size_t n = 0; n < names.size(); n++)
    {
        std::vector<uint32_t>& s = out.seen[names[n]];
        for (size_t ci = 0; ci < cams.size(); ci++)
            s.insert(s.end(), seenIn[ci][n].begin(), seenIn[ci][n].end());
    }
    return out;
}

int64 passUnobserved(ObjectClone& obj, const PassContext& ctx)
{
    const CloneBuilder::UnobservedParams& p = ctx.params.unobserved;
    const Vec3d up = estimateVertical(ctx.rec);
    VoxelGrid& g = obj.grid;
    int64 count = 0;
    if (g.empty())
        return 0;
    int axis = 0;
    double best = 0;
    for (int a = 0; a < 3; a++)
    {
        const double c = std::abs(up.dot(Vec3d(g.Rbox(0, a), g.Rbox(1, a), g.Rbox(2, a))));
        if (c > best)
        {
            best = c;
            axis = a;
        }
    }
    if (best < std::cos(p.maxTiltDeg * CV_PI / 180))
        return 0;
    std::vector<uchar> sn(g.data.size(), 0);
    for (uint32_t q : ctx.observed->seen.at(obj.name))
    {
        int i, j, k;
        unpackVoxel(obj.surface.ijk[q], i, j, k);
        sn[g.index(i, j, k)] = 1;
    }
    // The runs of every column (a, b) across the axis: [t0, t1) along it, seen or not.
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = g.dims[u], nv = g.dims[v], nt = g.dims[axis];
    struct Run
    {
        int t0, t1;
        bool seen;
        bool core;  // unseen, and no seen run within keepNearSeen columns (the erosion's)
    };
    std::vector<std::vector<Run> > cols((size_t)nu * nv);
    parallel_for_(Range(0, nv), [&](const Range& r) {
        for (int b = r.start; b < r.end; b++)
            for (int a = 0; a < nu; a++)
            {
                std::vector<Run>& runs = cols[(size_t)b * nu + a];
                int idx[3];
                idx[u] = a;
                idx[v] = b;
                int start = -1;
                bool any = false;
                for (int t = 0; t <= nt; t++)
                {
                    bool in = false;
                    size_t id = 0;
                    if (t < nt)
                    {
                        idx[axis] = t;
                        id = g.index(idx[0], idx[1], idx[2]);
                        in = g.data[id] != 0;
                    }
                    if (in)
                    {
                        if (start < 0)
                        {
                            start = t;
                            any = false;
                        }
                        any = any || sn[id];
                        continue;
                    }
                    if (start >= 0)
                        runs.push_back(Run{start, t, any, false});
                    start = -1;
                }
            }
    });
    // Has a column within `reach` of (a, b) (not itself) a run with `flag` overlapping [t0, t1)?
    auto near = [&](int a, int b, int t0, int t1, bool Run::*flag, int reach) {
        for (int bb = std::max(0, b - reach); bb <= std::min(nv - 1, b + reach); bb++)
            for (int aa = std::max(0, a - reach); aa <= std::min(nu - 1, a + reach); aa++)
            {
                if (aa == a && bb == b)
                    continue;
                for (const Run& o : cols[(size_t)bb * nu + aa])
                    if (o.*flag && o.t0 < t1 && t0 < o.t1)
                        return true;
            }
        return false;
    };
    // The unseen runs, opened: eroded (one beside a seen run within keepNearSeen columns stays:
    // under a roof seen at a grazing angle only some tops pass the depth test, and runs under the
    // others would leave the clone riddled with shafts), then grown back (one within
    // regrowFromUnseen columns of a run the erosion left goes: the thin edges of a hidden wedge).
    // Each step reads one flag and writes another, so the columns go in parallel.
    parallel_for_(Range(0, nv), [&](const Range& r) {
        for (int b = r.start; b < r.end; b++)
            for (int a = 0; a < nu; a++)
                for (Run& R : cols[(size_t)b * nu + a])
                    R.core = !R.seen && !near(a, b, R.t0, R.t1, &Run::seen, p.keepNearSeen);
    });
    std::vector<int64> perSlice(nv, 0);
    parallel_for_(Range(0, nv), [&](const Range& r) {
        for (int b = r.start; b < r.end; b++)
            for (int a = 0; a < nu; a++)
                for (const Run& R : cols[(size_t)b * nu + a])
                {
                    if (R.seen ||
                        !(R.core || near(a, b, R.t0, R.t1, &Run::core, p.regrowFromUnseen)))
                        continue;
                    int idx[3];
                    idx[u] = a;
                    idx[v] = b;
                    for (int w = R.t0; w < R.t1; w++)
                    {
                        idx[axis] = w;
                        g.data[g.index(idx[0], idx[1], idx[2])] = 0;
                    }
                    perSlice[b] += R.t1 - R.t0;
                }
    });
    for (int64 c : perSlice)
        count += c;
    if (count > 0)
        obj.surface = g.surface();
    return count;
}

} // namespace detail
} // namespace augocc
} // namespace cv
