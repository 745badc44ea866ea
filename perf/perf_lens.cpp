// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// What lens distortion costs (issue 15): the clone stage and the compositor at 1280x720 with a
// phone's barrel lens (arg lens = 1) against the same scene through a pinhole (lens = 0). The
// silhouettes are the same images in both (a frame pixel is in when its ray meets a box), so
// the grids and the work are comparable; the lens adds the warps into and out of the ideal
// view (lens.hpp).

#include "perf_precomp.hpp"

namespace {

using namespace cv;
using namespace cv::augocc;

const Size kSize(1280, 720);

Camera lensOrbit(double azDeg, int frame, bool lens)
{
    const double a = azDeg * CV_PI / 180, e = 20 * CV_PI / 180, dist = 13;
    const Vec3d target(0, 1.2, 0);
    const Vec3d C = target + dist * Vec3d(std::cos(e) * std::sin(a), std::sin(e),
                                          std::cos(e) * std::cos(a));
    Vec3d f = target - C;
    f /= cv::norm(f);
    Vec3d x = f.cross(Vec3d(0, 1, 0));
    x /= cv::norm(x);
    const Vec3d y = f.cross(x);
    const Matx33d R(x[0], x[1], x[2], y[0], y[1], y[2], f[0], f[1], f[2]);
    Camera c = Camera::perspective(R, -(R * C), Matx33d(1000, 0, 639.5, 0, 1000, 359.5, 0, 0, 1),
                                   frame);
    if (lens)
        c.distortion = {-0.12, 0.02, 0, 0, 0};
    return c;
}

// Silhouette of boxes in the frame of `cam` (its lens included).
Mat boxSilhouette(const Camera& cam, const std::vector<std::pair<Vec3d, Vec3d> >& boxes)
{
    Mat m(kSize, CV_8U, Scalar(0));
    const Camera pin = cam.pinhole();
    for (const auto& b : boxes)
    {
        std::vector<Point2f> c, hull;
        for (int q = 0; q < 8; q++)
        {
            const Vec3d X(q & 1 ? b.second[0] : b.first[0], q & 2 ? b.second[1] : b.first[1],
                          q & 4 ? b.second[2] : b.first[2]);
            const Point2d uv = pin.project(X);
            c.push_back(Point2f((float)uv.x, (float)uv.y));
        }
        convexHull(c, hull);
        parallel_for_(Range(0, kSize.height), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
                for (int x = 0; x < kSize.width; x++)
                {
                    const Point2d q = cam.undistortPixel(Point2d(x, y));
                    if (pointPolygonTest(hull, Point2f((float)q.x, (float)q.y), false) >= 0)
                        m.at<uchar>(y, x) = 255;
                }
        });
    }
    return m;
}

// Two pixels per voxel edge: the default (one) makes 9.4M-voxel clones here, a minute per
// build on this machine; the ratio lens / pinhole is what is measured.
Ptr<CloneBuilder> builder()
{
    CloneBuilder::Params p;
    p.voxelPixels = 2.0;
    return CloneBuilder::create(p);
}

struct LensProblem
{
    Reconstruction rec;
    ObjectMasks masks;
    Ptr<CloneSet> clones;
};

// A tower and a slab, 6 key frames over 40 degrees, masks made once through the lens and used
// by both cases.
const LensProblem& lensProblem(bool lens)
{
    static LensProblem problems[2];
    LensProblem& p = problems[lens ? 1 : 0];
    if (!p.rec.cameras.empty())
        return p;
    const std::vector<std::pair<Vec3d, Vec3d> > tower = {{Vec3d(-1.5, 0, -1.5), Vec3d(0.5, 4, 0.5)}};
    const std::vector<std::pair<Vec3d, Vec3d> > slab = {{Vec3d(1, 0, -2), Vec3d(4, 1.5, 1)}};
    p.rec.model = PERSPECTIVE;
    p.rec.imageSize = kSize;
    for (int f = 0; f < 6; f++)
        p.rec.cameras.push_back(lensOrbit(-20 + 8 * f, f, lens));
    const LensProblem* other = lens ? nullptr : &lensProblem(true);
    for (int f = 0; f < 6; f++)
    {
        if (other)
        {
            p.masks["slab"][f] = other->masks.at("slab").at(f);
            p.masks["tower"][f] = other->masks.at("tower").at(f);
            continue;
        }
        const Mat t = boxSilhouette(p.rec.cameras[f], tower);
        const Mat s = boxSilhouette(p.rec.cameras[f], slab);
        p.masks["tower"][f] = t;
        p.masks["slab"][f] = s & ~t;
    }
    p.clones = builder()->build(p.rec, p.masks);
    return p;
}

void Augocc_Lens_cloneBuild(benchmark::State& state)
{
    const bool lens = state.range(0) != 0;
    const LensProblem& p = lensProblem(lens);
    Ptr<CloneBuilder> b = builder();
    for (auto _ : state)
    {
        Ptr<CloneSet> c = b->build(p.rec, p.masks);
        benchmark::DoNotOptimize(c.get());
    }
    state.counters["voxels"] = (double)(p.clones->voxelCount("tower") +
                                        p.clones->voxelCount("slab"));
}
BENCHMARK(Augocc_Lens_cloneBuild)->Name("Augocc_Lens/clone_build_6keys_1280x720")
    ->ArgNames({"lens"})->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void Augocc_Lens_render(benchmark::State& state)
{
    const bool lens = state.range(0) != 0;
    const LensProblem& p = lensProblem(lens);
    const Camera cam = lensOrbit(-2, 7, lens);  // between key frames
    Mat matte, depth;
    for (auto _ : state)
    {
        p.clones->render("tower", 7, cam, kSize, matte, depth);
        benchmark::DoNotOptimize(matte.data);
    }
}
BENCHMARK(Augocc_Lens_render)->Name("Augocc_Lens/clone_render_1280x720")
    ->ArgNames({"lens"})->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void Augocc_Lens_composite(benchmark::State& state)
{
    const bool lens = state.range(0) != 0;
    const LensProblem& p = lensProblem(lens);
    const Camera cam = lensOrbit(-2, 7, lens);
    Mat frame(kSize, CV_8UC3);
    randu(frame, 0, 255);
    // A dome behind the tower, 20k triangles, half hidden.
    Mesh dome = Mesh::dome(2.5f, 128, 40);
    dome.transform(Matx44d(1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, -4, 0, 0, 0, 1));
    Ptr<Compositor> comp = Compositor::create();
    comp->setVirtualObjects({dome});
    Mat result;
    comp->composite(frame, 7, cam, *p.clones, result);  // context, upload, lens maps
    for (auto _ : state)
    {
        comp->composite(frame, 7, cam, *p.clones, result);
        benchmark::DoNotOptimize(result.data);
    }
}
BENCHMARK(Augocc_Lens_composite)->Name("Augocc_Lens/composite_clones_1280x720")
    ->ArgNames({"lens"})->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
