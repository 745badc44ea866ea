// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_FRAME_PATTERN_HPP
#define OPENCV_AUGOCC_FRAME_PATTERN_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

//! Widest `%0Nd` accepted: an int has at most 10 digits.
const int kMaxFramePatternWidth = 10;

/** @brief A printf-style frame pattern such as `frames/%04d.png`, parsed once and expanded by
this code: the user's text never reaches a printf-family call or a library that would use it as a
format (cv::format, VideoCapture's image sequences).
*/
struct CV_EXPORTS FramePattern
{
    String prefix;         //!< literal text before the conversion (`%%` already made `%`)
    String suffix;         //!< literal text after it
    int width = 0;         //!< minimum number of characters of the index
    bool zeroPad = false;  //!< pad with '0' (`%04d`), else with ' ' (`%4d`)

    //! The file name of frame `index` (>= 0), as printf would write it.
    String expand(int index) const;
};

/** @brief Parses a frame pattern: literal text, `%%` for a literal '%', and exactly one integer
conversion `%d`, `%Nd` or `%0Nd` (N at most kMaxFramePatternWidth).
@param pattern the user's text.
@return the parsed pattern.
Anything else (`%s`, `%n`, `%d%d`, `%5s`, a lone '%' ...) throws StsBadArg naming the pattern and
what is wrong with it.
*/
CV_EXPORTS FramePattern parseFramePattern(const String& pattern);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
