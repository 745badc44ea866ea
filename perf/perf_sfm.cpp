// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Camera recovery: factorization (full and 50% missing), the paper's 3F+1 refinement, the full
// scaled-orthographic bundle adjustment, on 100 frames x 1000 tracks (the sizes).

#include "perf_precomp.hpp"

#include <cstdlib>
#include <string>
#include "../test/sfm_test_utils.hpp"

namespace {

using namespace cv;
using namespace cv::augocc;

opencv_test::SfmProblem makeProblem(double missing)
{
    opencv_test::SfmProblemParams p;
    p.frames = 100;
    p.points = 1000;
    if (missing > 0)
    {
        p.partialFraction = 1.0;
        p.missingFraction = missing;
    }
    return opencv_test::makeSfmProblem(p);
}

void factorization(benchmark::State& state, double missing)
{
    const opencv_test::SfmProblem pb = makeProblem(missing);
    Ptr<FactorizationSfM> sfm = FactorizationSfM::create();
    Reconstruction rec;
    for (auto _ : state)
    {
        if (!sfm->reconstruct(pb.tracks, rec))
            state.SkipWithError("factorization failed");
        benchmark::DoNotOptimize(rec.points.data);
    }
}

void Augocc_FactorizationSfM_full(benchmark::State& state) { factorization(state, 0.0); }
void Augocc_FactorizationSfM_missing50(benchmark::State& state) { factorization(state, 0.5); }

void refine(benchmark::State& state, int mode)
{
    const opencv_test::SfmProblem pb = makeProblem(0.0);
    Reconstruction start;
    if (!FactorizationSfM::create()->reconstruct(pb.tracks, start))
    {
        state.SkipWithError("factorization failed");
        return;
    }
    OrthoCameraRefiner::Params p;
    p.mode = mode;
    Ptr<OrthoCameraRefiner> refiner = OrthoCameraRefiner::create(p);
    for (auto _ : state)
    {
        Reconstruction rec = start;
        if (!refiner->refine(pb.tracks, rec))
            state.SkipWithError("refinement failed");
        benchmark::DoNotOptimize(rec.points.data);
    }
}

void Augocc_OrthoCameraRefiner_positionZoom(benchmark::State& state)
{
    refine(state, OrthoCameraRefiner::POSITION_ZOOM);
}
void Augocc_OrthoCameraRefiner_fullBA(benchmark::State& state)
{
    refine(state, OrthoCameraRefiner::FULL_BA);
}
void Augocc_OrthoCameraRefiner_perspectiveBA(benchmark::State& state)
{
    refine(state, OrthoCameraRefiner::PERSPECTIVE_BA);
}

BENCHMARK(Augocc_FactorizationSfM_full)->Name("Augocc_FactorizationSfM/full_100x1000")
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Augocc_FactorizationSfM_missing50)
    ->Name("Augocc_FactorizationSfM/missing50_100x1000")
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Augocc_OrthoCameraRefiner_positionZoom)
    ->Name("Augocc_OrthoCameraRefiner/position_zoom_100x1000")
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Augocc_OrthoCameraRefiner_fullBA)->Name("Augocc_OrthoCameraRefiner/full_ba_100x1000")
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Augocc_OrthoCameraRefiner_perspectiveBA)
    ->Name("Augocc_OrthoCameraRefiner/perspective_ba_100x1000")
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// Long shots (issue 16, item 3): recoverCameras on 180 and 1800 frames of tracks that live 60
// frames, about 200 of them alive in every frame, the camera orbiting 50 degrees per 180 frames.
// Counter ms_per_frame (printed with an "s", google-benchmark's unit for an inverted rate; the value
// is milliseconds): the 1800-frame figure must stay within 1.5x of the 180-frame one.
void Augocc_recoverCameras_longShot(benchmark::State& state)
{
    const int frames = (int)state.range(0), life = 60, live = 200;
    opencv_test::SfmProblemParams p;
    p.frames = frames;
    p.points = live * frames / life;
    p.orbitDegrees = 50.0 * frames / 180;
    p.partialFraction = 1.0;
    // Tracks of 60 frames on average whatever the shot's length (missingFraction would cap the
    // missing share at 90%: tracks of 10% of the shot, 180 frames long at 1800 frames, three
    // times the live tracks per frame of the 180-frame case).
    p.trackFrames = life;
    const opencv_test::SfmProblem pb = opencv_test::makeSfmProblem(p);
    SfmOptions o;
    Reconstruction rec;
    for (auto _ : state)
    {
        rec = recoverCameras(pb.tracks, o);
        benchmark::DoNotOptimize(rec.points.data);
    }
    state.counters["ms_per_frame"] = benchmark::Counter(
        (double)frames * state.iterations() / 1e3,
        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["cameras"] = (double)rec.cameras.size();
}
// The 1800-frame case takes 38 s on this machine (2026-12-04: 21.2 ms a frame; 19.7 at 540 and
// 18.0 at 1080, the incremental path; 3.5 at 180, the direct factorization), too long for the
// suite's quick pass: it runs with AUGOCC_PERF_LONG=1.
const bool kLongShotRegistered = [] {
    benchmark::internal::Benchmark* b =
        benchmark::RegisterBenchmark("Augocc_recoverCameras/long_shot",
                                     Augocc_recoverCameras_longShot)->Arg(180);
    const char* longRuns = std::getenv("AUGOCC_PERF_LONG");
    if (longRuns && std::string(longRuns) == "1")
        b->Arg(1800);
    // AUGOCC_PERF_LONG_FRAMES=N adds an N-frame case (the scaling between 180 and 1800).
    const char* frames = std::getenv("AUGOCC_PERF_LONG_FRAMES");
    if (frames && std::atoi(frames) > 0)
        b->Arg(std::atoi(frames));
    b->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
    return true;
}();

} // namespace

namespace {

// Tracking: 640x480 frames of a blurred random texture drifting by 2 px per frame with a slow
// rotation (every corner stays trackable), 1000 live tracks. Reports frames per second.
void Augocc_FeatureTracker_track(benchmark::State& state)
{
    const int w = (int)state.range(0), h = (int)state.range(1), n = 30;
    cv::RNG rng(1);
    cv::Mat noise(h * 2, w * 2, CV_8U), tex;
    rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(noise, tex, cv::Size(0, 0), 2.0);
    cv::normalize(tex, tex, 0, 255, cv::NORM_MINMAX);
    std::vector<cv::Mat> frames;
    for (int f = 0; f < n; f++)
    {
        cv::Mat A = cv::getRotationMatrix2D(cv::Point2f((float)w, (float)h), 0.2 * f, 1.0);
        A.at<double>(0, 2) += 2.0 * f - w * 0.5;
        A.at<double>(1, 2) += 0.6 * f - h * 0.5;
        cv::Mat out, bgr;
        cv::warpAffine(tex, out, A, cv::Size(w, h), cv::INTER_LINEAR, cv::BORDER_REFLECT);
        cv::cvtColor(out, bgr, cv::COLOR_GRAY2BGR);
        frames.push_back(bgr);
    }
    cv::augocc::FeatureTracker::Params p;
    p.maxTracks = 1000;
    p.winSize = cv::Size((int)state.range(2), (int)state.range(2));
    p.levels = (int)state.range(3);
    cv::Ptr<cv::augocc::FeatureTracker> tracker = cv::augocc::FeatureTracker::create(p);
    cv::augocc::Tracks tracks;
    for (auto _ : state)
    {
        tracker->track(frames, tracks);
        benchmark::DoNotOptimize(tracks.observations());
    }
    if (tracks.points() == 0)
        state.SkipWithError("no track");
    state.counters["frames_per_s"] = benchmark::Counter((double)n * state.iterations(),
                                                        benchmark::Counter::kIsRate);
}

BENCHMARK(Augocc_FeatureTracker_track)->Name("Augocc_FeatureTracker/track_30_frames")
    ->ArgNames({"w", "h", "win", "levels"})->Args({640, 480, 11, 3})->Args({640, 480, 15, 3})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
