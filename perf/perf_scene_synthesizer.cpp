// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "perf_precomp.hpp"

namespace {
using namespace cv;
using namespace cv::augocc;

/* Synthesizing one frame with its masks and depth (the target: <= 50 ms at 640x480 on
2 cores): the shaded render read back as BGR + labels, camera-space depth, every object's whole
silhouette, and the visible masks derived from the labels. The synthesizer, its textures and its
OpenGL context are made outside the loop (once per data set in synthesize()). */
void Augocc_SceneSynthesizer_renderFrame(benchmark::State& state)
{
    SceneSynthesizer::Params p;
    p.imageSize = Size((int)state.range(0), (int)state.range(1));
    Ptr<SceneSynthesizer> synth = SceneSynthesizer::create(p);
    Mat image, depth, labels;
    std::vector<Mat> whole, visible(synth->getObjectNames().size());
    synth->renderFrame(0, image, depth, labels, whole);  // warm-up: textures uploaded
    int frame = 0;
    for (auto _ : state)
    {
        synth->renderFrame(frame, image, depth, labels, whole);
        for (size_t i = 0; i < visible.size(); i++)
            cv::compare(labels, Scalar((double)(i + 1)), visible[i], CMP_EQ);
        benchmark::DoNotOptimize(image.data);
        benchmark::DoNotOptimize(depth.data);
        frame = (frame + 1) % p.frames;
    }
    if (image.empty() || depth.empty() || whole.empty())
        state.SkipWithError("empty output");
}
BENCHMARK(Augocc_SceneSynthesizer_renderFrame)
    ->Name("Augocc_SceneSynthesizer/renderFrame")
    ->ArgNames({"w", "h"})
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/* The whole data set, per frame: synthesize() of 30 frames at 640x480 (textures, rendering,
masks, tracks), time divided by the frames through the items-per-second counter. */
void Augocc_SceneSynthesizer_synthesize(benchmark::State& state)
{
    SceneSynthesizer::Params p;
    p.frames = (int)state.range(0);
    p.numKeyFrames = 2;
    p.partialFraction = 0.3;
    p.outlierFraction = 0.05;
    for (auto _ : state)
    {
        Ptr<SceneSynthesizer> synth = SceneSynthesizer::create(p);
        SyntheticScene scene;
        synth->synthesize(scene);
        benchmark::DoNotOptimize(scene.frames.back().data);
    }
    state.SetItemsProcessed(state.iterations() * p.frames);
}
BENCHMARK(Augocc_SceneSynthesizer_synthesize)
    ->Name("Augocc_SceneSynthesizer/synthesize")
    ->ArgNames({"frames"})
    ->Args({30})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace
