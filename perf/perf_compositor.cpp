// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "perf_precomp.hpp"

namespace {
using namespace cv;
using namespace cv::augocc;

// A sphere of about 100k triangles filling half the frame, seen by a perspective camera; an
// occluder depth map hides the left half of it (the clones' depth, given).
struct CompositeInputs
{
    Mat frame, occluder;
    Camera camera;
    Mesh sphere;
};

CompositeInputs makeInputs(Size size, int supersample)
{
    CompositeInputs in;
    in.frame.create(size, CV_8UC3);
    randu(in.frame, 0, 255);
    const double f = 1.2 * size.width;
    in.camera = Camera::perspective(Matx33d::eye(), Vec3d(0, 0, 10),
                                    Matx33d(f, 0, size.width / 2.0, 0, f, size.height / 2.0,
                                            0, 0, 1));
    // 2 * 317 * 158 = 100172 triangles.
    in.sphere = Mesh::sphere(2.f, 317, 158);
    in.sphere.material.diffuse = Vec3f(0.8f, 0.5f, 0.3f);
    const Size rsz(size.width * supersample, size.height * supersample);
    in.occluder.create(rsz, CV_32F);
    in.occluder.setTo(std::numeric_limits<float>::infinity());
    in.occluder.colRange(0, rsz.width / 2).setTo(9.0);
    return in;
}

void Augocc_Compositor_composite(benchmark::State& state)
{
    const Size size((int)state.range(0), (int)state.range(1));
    const int k = (int)state.range(2);
    CompositeInputs in = makeInputs(size, k);
    Compositor::Params p;
    p.supersample = k;
    p.antialiasVirtual = state.range(3) != 0;
    Ptr<Compositor> comp = Compositor::create(p);
    comp->setVirtualObjects({in.sphere});
    Mat result;
    comp->composite(in.frame, in.camera, in.occluder, result);  // upload, context
    for (auto _ : state)
    {
        comp->composite(in.frame, in.camera, in.occluder, result);
        benchmark::DoNotOptimize(result.data);
    }
    if (result.empty())
        state.SkipWithError("empty composite");
}
BENCHMARK(Augocc_Compositor_composite)->Name("Augocc_Compositor/composite_100k_tris")
    ->ArgNames({"w", "h", "supersample", "antialias_virtual"})
    ->Args({640, 480, 1, 0})->Args({1280, 720, 1, 0})->Args({640, 480, 3, 0})
    ->Args({1280, 720, 3, 0})->Args({640, 480, 3, 1})->Args({1280, 720, 3, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// The same sphere under a sun (Params::sun): its shadow map, the ambient pass, the shading of
// the virtual samples and the shadow catcher on a ground plane under it (image y is down, so
// the ground's up is -y; the plane touches the sphere's bottom), occluder as above.
void Augocc_Compositor_compositeSun(benchmark::State& state)
{
    const Size size((int)state.range(0), (int)state.range(1));
    const int k = (int)state.range(2);
    CompositeInputs in = makeInputs(size, k);
    Compositor::Params p;
    p.supersample = k;
    p.sun.direction = cv::normalize(Vec3d(0.3, -0.8, -0.5));
    p.sun.penumbra = 0.05;
    p.ground.up = Vec3d(0, -1, 0);
    p.ground.right = Vec3d(1, 0, 0);
    p.ground.back = Vec3d(0, 0, -1);
    p.ground.height = -2;
    Ptr<Compositor> comp = Compositor::create(p);
    comp->setVirtualObjects({in.sphere});
    Mat result;
    comp->composite(in.frame, in.camera, in.occluder, result);  // upload, context, shadow map
    for (auto _ : state)
    {
        comp->composite(in.frame, in.camera, in.occluder, result);
        benchmark::DoNotOptimize(result.data);
    }
    if (result.empty())
        state.SkipWithError("empty composite");
}
BENCHMARK(Augocc_Compositor_compositeSun)->Name("Augocc_Compositor/composite_100k_tris_sun")
    ->ArgNames({"w", "h", "supersample"})
    ->Args({640, 480, 3})->Args({1280, 720, 3})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
