// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CLONE_CODEC_HPP
#define OPENCV_AUGOCC_CLONE_CODEC_HPP

#include <cstdint>
#include <vector>
#include <opencv2/core.hpp>

/*
Compact binary payloads of the clones file, written into the FileStorage file as base64 text in
strings of at most kChunkChars characters (FileStorage's string limit is 4096). OpenCV 4.6's own
matrix writer (text or base64) needs ~3 us per element, far too slow for voxel grids.
*/

namespace cv {
namespace augocc {
namespace detail {

const size_t kChunkChars = 4000;

//! Appends an unsigned LEB128 varint.
CV_EXPORTS void putVarint(std::vector<uchar>& out, uint64_t v);
//! Reads an unsigned LEB128 varint; throws StsParseError naming `what` past the end.
CV_EXPORTS uint64_t getVarint(const std::vector<uchar>& in, size_t& pos, const String& what);
inline uint64_t zigzag(int64_t v) { return ((uint64_t)v << 1) ^ (uint64_t)(v >> 63); }
inline int64_t unzigzag(uint64_t v) { return (int64_t)(v >> 1) ^ -(int64_t)(v & 1); }

//! Writes bytes as a sequence of base64 strings under `key`.
CV_EXPORTS void writeBlob(FileStorage& fs, const String& key, const std::vector<uchar>& bytes);
//! Reads what writeBlob() wrote; throws StsParseError naming `what` on bad base64.
CV_EXPORTS std::vector<uchar> readBlob(const FileNode& node, const String& what);

/** @brief Voxel grid (0/1 bytes, rows of nx along x) as per-row run boundaries, each boundary
delta-coded against the same boundary of the previous row (neighbouring rows of a carved solid
differ little, so the stream is mostly zeros and gzip shrinks it well). */
CV_EXPORTS std::vector<uchar> encodeGrid(const std::vector<uchar>& data, int nx, int rows);
CV_EXPORTS void decodeGrid(const std::vector<uchar>& bytes, int nx, int rows,
                           std::vector<uchar>& data,
                const String& what);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
