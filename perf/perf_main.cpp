// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "perf_precomp.hpp"

#include <opencv2/core/utils/logger.hpp>

namespace {

// Calibration: a fixed amount of OpenCV work (a 640x480 Gaussian blur and a 256x256 matrix
// product) run in the same process as the benchmarks. tools/perf_compare.py divides every median
// by this one, so that a slower or busier machine does not read as a regression.
void Augocc_Calibration(benchmark::State& state)
{
    cv::Mat img(480, 640, CV_8UC3), dst;
    cv::randu(img, 0, 255);
    cv::Mat a(256, 256, CV_32F), b(256, 256, CV_32F), c;
    cv::randu(a, -1, 1);
    cv::randu(b, -1, 1);
    for (auto _ : state)
    {
        cv::GaussianBlur(img, dst, cv::Size(7, 7), 2.0);
        cv::gemm(a, b, 1.0, cv::noArray(), 0.0, c);
        benchmark::DoNotOptimize(dst.data);
        benchmark::DoNotOptimize(c.data);
    }
}
BENCHMARK(Augocc_Calibration)->Name("Augocc_Calibration")->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace

int main(int argc, char** argv)
{
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
