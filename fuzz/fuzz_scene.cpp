// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// libFuzzer harness: the scene file, with the meshes it names. Beside it lie the test meshes
// (tetra.ply, quad.obj with its material and texture) that the seeds refer to, so the fuzzer
// reaches mesh loading, texture reading and the placement keys.

#include "fuzz_common.hpp"

#include <opencv2/augocc.hpp>

#ifndef AUGOCC_TEST_DATA
#error "AUGOCC_TEST_DATA: the folder of the test meshes"
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    static const bool copied = [] {
        for (const char* f : {"tetra.ply", "quad.obj", "quad.mtl", "quad_tex.png"})
            std::filesystem::copy_file(std::string(AUGOCC_TEST_DATA) + "/" + f,
                                       augocc_fuzz::folder() + "/" + f,
                                       std::filesystem::copy_options::overwrite_existing);
        return true;
    }();
    (void)copied;
    const std::string path = augocc_fuzz::writeInput(data, size, "scene.yml");
    augocc_fuzz::readSafely([&] { cv::augocc::readScene(path); });
    return 0;
}
