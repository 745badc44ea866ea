// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// tracks.yml of long shots: writing and reading the dense and the sparse form, and the sizes
// of both (counters dense_bytes, sparse_bytes, bytes_per_observation), for 180 and 1800 frames
// of tracks that live 30 frames with 4 new ones a frame (a tracker's re-detection at 640x360).

#include "perf_precomp.hpp"

#include <filesystem>

namespace {

using namespace cv;
using namespace cv::augocc;

Tracks longShot(int frames)
{
    const int len = 30, perFrame = 4;
    Tracks::Builder b(Size(640, 360), frames);
    RNG rng(5);
    for (int s = 0; s + len <= frames; s++)
        for (int k = 0; k < perFrame; k++)
        {
            b.addTrack();
            Point2f q(rng.uniform(0.f, 640.f), rng.uniform(0.f, 360.f));
            for (int f = s; f < s + len; f++)
                b.add(f, q += Point2f(0.5f, 0.25f));
        }
    return b.build();
}

std::string tempFile(const char* name)
{
    return (std::filesystem::temp_directory_path() / name).string();
}

void counters(benchmark::State& state, const Tracks& t, const String& path)
{
    const double d = (double)tracksFileBytes(path, t, TRACKS_DENSE);
    const double s = (double)tracksFileBytes(path, t, TRACKS_SPARSE);
    state.counters["observations"] = t.observations();
    state.counters["dense_bytes"] = d;
    state.counters["sparse_bytes"] = s;
    state.counters["bytes_per_observation"] = std::min(d, s) / t.observations();
}

void Augocc_Tracks_write(benchmark::State& state)
{
    const Tracks t = longShot((int)state.range(0));
    const TracksForm form = (TracksForm)state.range(1);
    const std::string path = tempFile("augocc_perf_tracks_write.yml");
    for (auto _ : state)
        writeTracks(path, t, form);
    if (state.range(0) <= 180)
        counters(state, t, path);
    std::filesystem::remove(path);
}

void Augocc_Tracks_read(benchmark::State& state)
{
    const Tracks t = longShot((int)state.range(0));
    const TracksForm form = (TracksForm)state.range(1);
    const std::string path = tempFile("augocc_perf_tracks_read.yml");
    writeTracks(path, t, form);
    for (auto _ : state)
    {
        const Tracks r = readTracks(path);
        benchmark::DoNotOptimize(r.observations());
    }
    std::filesystem::remove(path);
}

} // namespace

// Dense at 1800 frames is 1800 x 7084 cells (160 MB of text): measured at 180 frames only.
BENCHMARK(Augocc_Tracks_write)->Name("Augocc_Tracks/write_dense_180")->Args({180, TRACKS_DENSE})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Augocc_Tracks_write)->Name("Augocc_Tracks/write_sparse_180")
    ->Args({180, TRACKS_SPARSE})->Unit(benchmark::kMillisecond);
BENCHMARK(Augocc_Tracks_write)->Name("Augocc_Tracks/write_sparse_1800")
    ->Args({1800, TRACKS_SPARSE})->Unit(benchmark::kMillisecond);
BENCHMARK(Augocc_Tracks_read)->Name("Augocc_Tracks/read_dense_180")->Args({180, TRACKS_DENSE})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Augocc_Tracks_read)->Name("Augocc_Tracks/read_sparse_180")
    ->Args({180, TRACKS_SPARSE})->Unit(benchmark::kMillisecond);
BENCHMARK(Augocc_Tracks_read)->Name("Augocc_Tracks/read_sparse_1800")
    ->Args({1800, TRACKS_SPARSE})->Unit(benchmark::kMillisecond);
