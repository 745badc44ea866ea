// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// What every libFuzzer harness of augocc's readers shares: the input written to a file in a
// private folder (the readers take paths), and the oracle. A reader may reject its input only
// with a cv::Exception that is a clear error (not an assertion, not "internal", not out of
// memory); anything else (a crash, a hang, another exception, a sanitizer report) is a finding.

#ifndef AUGOCC_FUZZ_COMMON_HPP
#define AUGOCC_FUZZ_COMMON_HPP

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace augocc_fuzz {

//! A folder of this process (removed at exit), made on first use.
inline const std::string& folder()
{
    static const std::string dir = [] {
        const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                        ("augocc_fuzz." + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        static struct Remover
        {
            std::filesystem::path p;
            ~Remover()
            {
                std::error_code ec;
                std::filesystem::remove_all(p, ec);
            }
        } remover{d};
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
        return d.string();
    }();
    return dir;
}

//! Writes the input to `folder()/name` and returns that path.
inline std::string writeInput(const uint8_t* data, size_t size, const std::string& name)
{
    const std::string path = folder() + "/" + name;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), (std::streamsize)size);
    return path;
}

//! Runs a reader; a rejection must be a clear error.
template <typename F>
void readSafely(F read)
{
    try
    {
        read();
    }
    catch (const cv::Exception& e)
    {
        if (e.code == cv::Error::StsAssert || e.code == cv::Error::StsInternal ||
            e.code == cv::Error::StsNoMem || e.err.empty())
        {
            std::fprintf(stderr, "augocc_fuzz: not a clear error (code %d): %s\n", e.code,
                         e.what());
            std::abort();
        }
    }
}

} // namespace augocc_fuzz

#endif
