// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_VIDEO_OUT_HPP
#define OPENCV_AUGOCC_VIDEO_OUT_HPP

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace cv {
namespace augocc {
namespace detail {

//! Whether `path` names a video the module writes (.mp4, .avi, .mkv, .mov, .m4v; any case).
bool isVideoPath(const String& path);

/** @brief The module's one video writer: H.264 first (plays everywhere), MPEG-4 part 2 when this
FFmpeg cannot encode it; `tmp` is the file written, `shown` the output named in errors. */
VideoWriter openVideo(const String& tmp, const String& shown, double fps, Size size);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
