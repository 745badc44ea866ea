// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "perf_precomp.hpp"
// The drawn box-building frame of the unit tests (header only, no test framework needed).
#include "../test/test_silhouette_scene.hpp"

namespace {

using namespace cv;
using namespace cv::augocc;

opencv_test::SilhouetteScene perfScene(Size size)
{
    return opencv_test::drawBoxScene(opencv_test::orbitCamera(30, 25, size.height / 14.0, size),
                                     size, 1);
}

// One frame loaded into the editor (gradients for the click snap and the outline snapping).
void Augocc_SilhouetteEditor_setImage(benchmark::State& state)
{
    const Size size(int(state.range(0)), int(state.range(1)));
    const opencv_test::SilhouetteScene scene = perfScene(size);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    for (auto _ : state)
    {
        ed->setImage(scene.image);
        benchmark::DoNotOptimize(ed.get());
    }
}
BENCHMARK(Augocc_SilhouetteEditor_setImage)->Name("Augocc_SilhouetteEditor/setImage")
    ->ArgNames({"w", "h"})->Args({640, 480})->Args({1280, 720})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// One live-wire segment (what a click or a cursor move costs) between two points `d` pixels
// apart along the building's outline.
void Augocc_SilhouetteEditor_liveWire(benchmark::State& state)
{
    const Size size(640, 480);
    const opencv_test::SilhouetteScene scene = perfScene(size);
    std::vector<std::vector<Point>> contours;
    findContours(scene.mask.clone(), contours, RETR_EXTERNAL, CHAIN_APPROX_NONE);
    const std::vector<Point>& c = contours[0];
    const int d = int(state.range(0));
    const Point a = c[0], b = c[std::min<size_t>(size_t(d), c.size() - 1)];
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    ed->addPoint(a);
    std::vector<Point> path;
    for (auto _ : state)
    {
        ed->previewSegment(b, path);
        benchmark::DoNotOptimize(path.data());
    }
    if (path.empty())
        state.SkipWithError("empty live-wire path");
}
BENCHMARK(Augocc_SilhouetteEditor_liveWire)->Name("Augocc_SilhouetteEditor/liveWire")
    ->ArgNames({"d"})->Arg(50)->Arg(150)->Unit(benchmark::kMillisecond)->UseRealTime();

// A proposed outline (the true silhouette dilated by 3 px) snapped to the edges.
void Augocc_SilhouetteEditor_snapMask(benchmark::State& state)
{
    const Size size(640, 480);
    const opencv_test::SilhouetteScene scene = perfScene(size);
    Mat proposal, snapped;
    dilate(scene.mask, proposal, getStructuringElement(MORPH_ELLIPSE, Size(7, 7)));
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    for (auto _ : state)
    {
        ed->snapMask(proposal, snapped);
        benchmark::DoNotOptimize(snapped.data);
    }
    if (countNonZero(snapped) == 0)
        state.SkipWithError("empty snapped mask");
}
BENCHMARK(Augocc_SilhouetteEditor_snapMask)->Name("Augocc_SilhouetteEditor/snapMask")
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// Key-frame suggestion from F frames x 1000 partial tracks, 8 key frames.
void Augocc_KeyFrames_suggest(benchmark::State& state)
{
    const int F = int(state.range(0)), P = 1000;
    Mat m(F, P, CV_32FC2, Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    RNG rng(1);
    for (int p = 0; p < P; ++p)
    {
        const int a = rng.uniform(0, F), b = rng.uniform(a, F);
        for (int f = a; f <= b; ++f)
            m.at<Point2f>(f, p) = Point2f(float(p % 640), float(f % 480));
    }
    const Tracks t = Tracks::fromDense(Size(640, 480), m);
    for (auto _ : state)
    {
        std::vector<int> keys = suggestKeyFrames(t, 8);
        benchmark::DoNotOptimize(keys.data());
    }
}
BENCHMARK(Augocc_KeyFrames_suggest)->Name("Augocc_KeyFrames/suggest")->ArgNames({"frames"})
    ->Arg(100)->Arg(300)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
