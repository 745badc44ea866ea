// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "perf_precomp.hpp"
#include "clone/passes.hpp"

#include <cstdio>
#include <sys/resource.h>
#include <unistd.h>

namespace {

using namespace cv;
using namespace cv::augocc;
using namespace cv::augocc::detail;

// A 256^3 problem at 640x480: an object (a box with a dome-like stack of boxes on it) whose grid is
// about 256 voxels a side at one pixel per voxel, seen by 8 scaled-orthographic key frames.
struct CloneProblem
{
    Reconstruction rec;
    ObjectMasks masks;
    std::vector<Mat> keep;
    VoxelGrid grid;
    Ptr<CloneSet> clones;
};

Camera orbit(double azDeg, double elDeg, int frame)
{
    const double a = azDeg * CV_PI / 180, e = elDeg * CV_PI / 180;
    const Vec3d C(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
    const Vec3d f = -C;
    Vec3d x = f.cross(Vec3d(0, 1, 0));
    x /= cv::norm(x);
    const Vec3d y = f.cross(x);
    const Matx33d R(x[0], x[1], x[2], y[0], y[1], y[2], f[0], f[1], f[2]);
    return Camera::orthographic(R, -(R * (C * 50.0)), 1.0, Point2d(319.5, 239.5), frame);
}

Mat silhouette(const Camera& cam, const std::vector<std::pair<Vec3d, Vec3d> >& boxes)
{
    Mat m(480, 640, CV_8U, Scalar(0));
    for (const auto& b : boxes)
    {
        std::vector<Point> c, hull;
        for (int q = 0; q < 8; q++)
        {
            const Point2d p = cam.project(Vec3d(q & 1 ? b.second[0] : b.first[0],
                                                q & 2 ? b.second[1] : b.first[1],
                                                q & 4 ? b.second[2] : b.first[2]));
            c.push_back(Point(cvRound(p.x * 256), cvRound(p.y * 256)));
        }
        convexHull(c, hull);
        fillConvexPoly(m, hull, Scalar(255), LINE_8, 8);
    }
    return m;
}

// CPU seconds used by the whole process (every thread): on a shared machine the wall time is
// noisy, the summed CPU time much less so.
double processCpuSeconds()
{
    rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

const CloneProblem& problem()
{
    static CloneProblem p;
    if (!p.keep.empty())
        return p;
    // Units are pixels (s = 1): a 150 x 150 x 150 block with a 90-wide tower on top; its box is
    // about 250 on the long axis once enlarged, so the grid is about 256^3.
    const std::vector<std::pair<Vec3d, Vec3d> > boxes = {
        {Vec3d(-75, -125, -75), Vec3d(75, 25, 75)}, {Vec3d(-45, 25, -45), Vec3d(45, 125, 45)}};
    p.rec.model = SCALED_ORTHOGRAPHIC;
    p.rec.imageSize = Size(640, 480);
    for (int f = 0; f < 8; f++)
    {
        p.rec.cameras.push_back(orbit(-35 + 10 * f, 20 + 3 * (f % 3), f));
        p.masks["block"][f] = silhouette(p.rec.cameras.back(), boxes);
        p.keep.push_back(p.masks["block"][f]);
    }
    p.grid.create(Vec3i(256, 256, 256), Matx33d::eye(), Vec3d(-128, -128, -128), 1.0, 1);
    // The 256^3 clone itself (carved, with patches) for the render and I/O benchmarks.
    Ptr<CloneSetImpl> set = makePtr<CloneSetImpl>();
    ObjectClone& o = set->add("block");
    o.name = "block";
    o.grid = p.grid;
    o.centre = Vec3d(0, 0, 0);
    std::vector<CarveView> views;
    for (int f = 0; f < 8; f++)
    {
        views.push_back(o.grid.carveView(p.rec.cameras[f], p.keep[f]));
        o.masks[f] = p.keep[f];
    }
    o.grid.carve(views);
    o.surface = o.grid.surface();
    for (int f = 0; f < 8; f++)
        o.patches[f] = computePatches(o, p.rec.cameras[f], p.keep[f], p.keep[f], 2);
    p.clones = set;
    return p;
}

void Augocc_CloneBuilder_carve(benchmark::State& state)
{
    const CloneProblem& p = problem();
    VoxelGrid g = p.grid;
    double cpu = 0;
    for (auto _ : state)
    {
        state.PauseTiming();
        std::fill(g.data.begin(), g.data.end(), (uchar)1);
        const double c0 = processCpuSeconds();
        state.ResumeTiming();
        std::vector<CarveView> views(p.rec.cameras.size());
        parallel_for_(Range(0, (int)views.size()), [&](const Range& r) {
            for (int q = r.start; q < r.end; q++)
                views[q] = g.carveView(p.rec.cameras[q], p.keep[q]);
        });
        g.carve(views);
        benchmark::DoNotOptimize(g.data.data());
        cpu += processCpuSeconds() - c0;
    }
    state.counters["cpu_ms_all_threads"] = 1e3 * cpu / std::max<double>(1, (double)state.iterations());
    state.counters["voxels_in"] = (double)g.count();
    state.counters["bytes_per_voxel"] = (double)(g.data.size() * sizeof(uchar)) / g.total();
}
BENCHMARK(Augocc_CloneBuilder_carve)->Name("Augocc_CloneBuilder/carve_256_8views_640x480")
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void Augocc_CloneBuilder_patches(benchmark::State& state)
{
    const CloneProblem& p = problem();
    const CloneSetImpl& set = dynamic_cast<const CloneSetImpl&>(*p.clones);
    const ObjectClone& obj = set.get("block");
    const int f = 3;
    size_t n = 0;
    for (auto _ : state)
    {
        std::vector<uint32_t> v = computePatches(obj, p.rec.cameras[f], p.keep[f], p.keep[f], 2);
        n = v.size();
        benchmark::DoNotOptimize(v.data());
    }
    state.counters["patch_voxels"] = (double)n;
    state.counters["grid_voxels"] = (double)obj.grid.total();
}
BENCHMARK(Augocc_CloneBuilder_patches)->Name("Augocc_CloneBuilder/patches_one_key_frame")
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void Augocc_CloneSet_render(benchmark::State& state)
{
    const CloneProblem& p = problem();
    // A frame between two key frames.
    const Camera cam = orbit(-12, 24, 2);
    Mat matte, depth;
    const double c0 = processCpuSeconds();
    for (auto _ : state)
    {
        p.clones->render("block", 2, cam, p.rec.imageSize, matte, depth);
        benchmark::DoNotOptimize(matte.data);
    }
    state.counters["cpu_ms_all_threads"] =
        1e3 * (processCpuSeconds() - c0) / std::max<double>(1, (double)state.iterations());
    if (countNonZero(matte) == 0)
        state.SkipWithError("empty matte");
    const CloneSetImpl& set = dynamic_cast<const CloneSetImpl&>(*p.clones);
    state.counters["surface_voxels"] = (double)set.get("block").surface.size();
}
BENCHMARK(Augocc_CloneSet_render)->Name("Augocc_CloneSet/render_matte_depth_640x480")
    ->Unit(benchmark::kMillisecond)->UseRealTime();


// refine() on the synthesized scene (3 objects, 60 frames at 640x480, GT cameras): the clones are
// built once; each iteration refines a fresh copy.
struct RefineProblem
{
    SyntheticScene scene;
    CloneSetImpl built;
};

const RefineProblem& refineProblem()
{
    static RefineProblem p;
    if (!p.scene.frames.empty())
        return p;
    SceneSynthesizer::create()->synthesize(p.scene);
    Ptr<CloneSet> c = CloneBuilder::create()->build(p.scene.groundTruth, p.scene.keyFrameMasks,
                                                    &p.scene.tracks);
    p.built = dynamic_cast<const CloneSetImpl&>(*c);
    return p;
}

void Augocc_CloneBuilder_refine_synth(benchmark::State& state)
{
    const RefineProblem& p = refineProblem();
    Ptr<CloneBuilder> b = CloneBuilder::create();
    int64 carved = 0;
    double cpu = 0;
    for (auto _ : state)
    {
        state.PauseTiming();
        CloneSetImpl set = p.built;
        const double c0 = processCpuSeconds();
        state.ResumeTiming();
        carved = b->refine(set, p.scene.groundTruth, p.scene.frames);
        cpu += processCpuSeconds() - c0;
    }
    state.counters["cpu_ms_all_threads"] =
        1e3 * cpu / std::max<double>(1, (double)state.iterations());
    state.counters["carved"] = (double)carved;
    if (carved == 0)
        state.SkipWithError("nothing carved");
}
BENCHMARK(Augocc_CloneBuilder_refine_synth)
    ->Name("Augocc_CloneBuilder/refine_synth_3objects_60frames_640x480")
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// build() on the synthesized scene (3 objects, 6 key frames, 60 frames of tracks, GT cameras):
// Steps 1-5 from silhouettes only (arg 0) and with free-space carving from the tracks (arg 1).
void Augocc_CloneBuilder_build_synth(benchmark::State& state)
{
    const RefineProblem& p = refineProblem();
    CloneBuilder::Params params;
    if (state.range(0) == 0)
        params.freeSpace.minViews = 0;
    Ptr<CloneBuilder> b = CloneBuilder::create(params);
    int64 voxels = 0;
    for (auto _ : state)
    {
        Ptr<CloneSet> c = b->build(p.scene.groundTruth, p.scene.keyFrameMasks, &p.scene.tracks);
        voxels = 0;
        for (const String& name : c->objectNames())
            voxels += c->voxelCount(name);
    }
    state.counters["voxels"] = (double)voxels;
}
BENCHMARK(Augocc_CloneBuilder_build_synth)
    ->Name("Augocc_CloneBuilder/build_synth_3objects_640x480/free_space")->Arg(0)->Arg(1)
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// refine() on the 256^3 clone seen by 60 frames around the orbit, every frame one grey: every
// visible surface voxel is checked against all its views and found consistent (the cost of the
// visibility and consistency checks of a 256^3 surface; nothing is carved).
void Augocc_CloneBuilder_refine_256(benchmark::State& state)
{
    const CloneProblem& p = problem();
    const CloneSetImpl& base = dynamic_cast<const CloneSetImpl&>(*p.clones);
    Reconstruction rec = p.rec;
    std::vector<Mat> frames;
    for (int f = 8; f < 60; f++)
        rec.cameras.push_back(orbit(-35 + 70.0 * (f - 8) / 51, 22, f));
    for (int f = 0; f < 60; f++)
    {
        frames.push_back(Mat(rec.imageSize, CV_8UC3, Scalar(90, 110, 130)));
    }
    Ptr<CloneBuilder> b = CloneBuilder::create();
    int64 carved = 0;
    for (auto _ : state)
    {
        state.PauseTiming();
        CloneSetImpl set = base;
        state.ResumeTiming();
        carved = b->refine(set, rec, frames);
    }
    state.counters["carved"] = (double)carved;
    state.counters["grid_voxels"] = (double)base.get("block").grid.total();
}
BENCHMARK(Augocc_CloneBuilder_refine_256)
    ->Name("Augocc_CloneBuilder/refine_256_60frames_640x480_consistent")
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

std::string tmpPath(const char* name)
{
    return cv::format("/tmp/augocc_perf_%d_%s", (int)getpid(), name);
}

void Augocc_CloneSet_save(benchmark::State& state)
{
    const CloneProblem& p = problem();
    const std::string path = tmpPath("clones.yml.gz");
    for (auto _ : state)
        p.clones->save(path);
    std::remove(path.c_str());
}
BENCHMARK(Augocc_CloneSet_save)->Name("Augocc_CloneSet/save_256")
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void Augocc_CloneSet_load(benchmark::State& state)
{
    const CloneProblem& p = problem();
    const std::string path = tmpPath("clones_load.yml.gz");
    p.clones->save(path);
    for (auto _ : state)
    {
        Ptr<CloneSet> c = CloneSet::load(path);
        benchmark::DoNotOptimize(c.get());
    }
    std::remove(path.c_str());
}
BENCHMARK(Augocc_CloneSet_load)->Name("Augocc_CloneSet/load_256")
    ->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
