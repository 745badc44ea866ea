// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// libFuzzer harness: a mesh file through loadMeshes (the pre-check, then Assimp). The input's
// first byte picks the file name's extension (PLY or OBJ: the formats of augocc's examples and
// the ones the fuzz found Assimp hanging and aborting on); the rest is the file.

#include "fuzz_common.hpp"

#include <opencv2/augocc.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size < 1)
        return 0;
    static const char* const kNames[] = {"mesh.ply", "mesh.obj"};
    const std::string path = augocc_fuzz::writeInput(data + 1, size - 1, kNames[data[0] & 1]);
    augocc_fuzz::readSafely([&] { cv::augocc::loadMeshes(path); });
    return 0;
}
