// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The module's video writer (compositeSequence, joinFrameChunks).

#include "precomp.hpp"

#include "atomic_write.hpp"
#include "video_out.hpp"

#include <cctype>
#include <filesystem>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {
namespace detail {

bool isVideoPath(const String& path)
{
    String e = fs::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
    return e == ".mp4" || e == ".avi" || e == ".mkv" || e == ".mov" || e == ".m4v";
}

VideoWriter openVideo(const String& tmp, const String& shown, double fps, Size size)
{
    // FFmpeg says nothing of why it cannot open a file: a folder we cannot write fails here.
    checkCreatable(tmp, shown);
    VideoWriter writer;
    // H.264 first (plays everywhere), MPEG-4 part 2 when this FFmpeg cannot encode it.
    for (const char* cc : {"avc1", "H264", "mp4v"})
    {
        writer.open(tmp, CAP_FFMPEG, VideoWriter::fourcc(cc[0], cc[1], cc[2], cc[3]), fps, size,
                    true);
        if (writer.isOpened())
            return writer;
    }
    CV_Error(Error::StsError, shown + ": cannot open a video writer (H.264 or mp4v)");
}

} // namespace detail
} // namespace augocc
} // namespace cv
