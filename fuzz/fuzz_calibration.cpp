// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// libFuzzer harness: the calibration file (OpenCV's calibrateCamera output), at the frames' size and its own.

#include "fuzz_common.hpp"

#include <opencv2/augocc.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const std::string path = augocc_fuzz::writeInput(data, size, "calibration.yml");
    augocc_fuzz::readSafely([&] { cv::augocc::readCalibration(path, cv::Size(640, 360)); });
    augocc_fuzz::readSafely([&] { cv::augocc::readCalibration(path); });
    return 0;
}
