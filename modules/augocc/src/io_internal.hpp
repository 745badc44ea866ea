// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Internals shared by the readers of the module's files (io.cpp: tracks and reconstructions,
// scene.cpp: scene files, clone_set.cpp: clones files).

#ifndef OPENCV_AUGOCC_IO_INTERNAL_HPP
#define OPENCV_AUGOCC_IO_INTERNAL_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

/** @brief Opens the cv::FileStorage file `path` (YAML, JSON, XML, optionally gzipped) for
reading, or throws naming the file.

@param path the file.
@param what what the file is, for the messages ("file", "scene file", "clones file").
@return the opened storage.

Throws StsObjectNotFound "<path>: <what> not found" when `path` is not a regular file, and
StsParseError "<path>: cannot parse <what>: <FileStorage's reason>" when FileStorage throws, or
"<path>: cannot open or parse <what> as a FileStorage file" when it does not open.
*/
CV_EXPORTS FileStorage openFileStorageForRead(const String& path, const String& what = "file");

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
