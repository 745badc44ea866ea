// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// libFuzzer harness: a masks folder holding one mask, the input as its PNG bytes, read without
// and with the frames' size.

#include "fuzz_common.hpp"

#include <opencv2/augocc.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const std::string mask = augocc_fuzz::writeInput(data, size, "masks/object/0000.png");
    const std::string dir = std::filesystem::path(mask).parent_path().parent_path().string();
    augocc_fuzz::readSafely([&] { cv::augocc::readMasks(dir); });
    augocc_fuzz::readSafely([&] { cv::augocc::readMasks(dir, cv::Size(64, 48)); });
    return 0;
}
