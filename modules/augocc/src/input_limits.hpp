// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Bounds on what a file from outside can make a third-party reader do (OpenCV's FileStorage,
// Assimp, the image decoders), checked before the file reaches it, and the absurd-value limits of
// the readers. One place for every input limit; doc/input_limits.md lists them.

#ifndef OPENCV_AUGOCC_INPUT_LIMITS_HPP
#define OPENCV_AUGOCC_INPUT_LIMITS_HPP

#include <opencv2/core.hpp>

#include <vector>

namespace cv {
namespace augocc {
namespace detail {

//! FileStorage files (tracks, reconstructions, clones, scenes, calibration): the decompressed
//! size FileStorage may hold in memory.
const int64 kMaxStorageBytes = (int64)1 << 30;
//! Nesting depth of a FileStorage file (OpenCV 4.6's parsers recurse once per level). augocc's
//! own files nest at most 6 deep.
const int kMaxStorageDepth = 64;
//! Image decoders: each side and the pixel count (a 8192 x 8192 image) read from the header.
const int kMaxImageSide = 16384;
const int64 kMaxImagePixels = (int64)8192 * 8192;
//! Meshes: the file size, and the vertex and face count declared by a PLY header.
const int64 kMaxMeshBytes = (int64)1 << 30;
const int64 kMaxMeshElements = (int64)1 << 25;
//! Scene coordinates (camera translations, reconstructed points, scene positions, mesh vertices):
//! a magnitude beyond this is absurd in any unit augocc meets and overflows the pixel arithmetic.
const double kMaxSceneCoordinate = 1e9;
//! Pixel quantities (track coordinates, focal lengths, principal points): at most this magnitude.
const double kMaxPixelCoordinate = 1e6;

/** @brief The nesting depth of FileStorage text (YAML, JSON or XML, chosen as FileStorage does
from the first character), found by a scan that follows OpenCV 4.6's tokenizer (quoted strings,
comments, flow brackets, block collections by indentation). Never recurses; stops counting once
the depth passes `stopAt`. */
CV_EXPORTS int storageNestingDepth(const char* data, size_t size, int stopAt = INT_MAX);

/** @brief Checks a FileStorage file (plain or gzipped) before FileStorage opens it: its
decompressed size against kMaxStorageBytes and its nesting depth against kMaxStorageDepth.
Throws StsOutOfRange "<path>: <what> ..." naming the limit. */
CV_EXPORTS void checkStorageFile(const String& path, const String& what);

/** @brief Throws StsParseError "<where>: key '<k>' appears twice" when any map of the tree under
`node` holds a key twice (FileStorage silently keeps the first). */
CV_EXPORTS void checkDuplicateKeys(const FileNode& node, const String& where);

/** @brief `node >> Mat`, after checking that the node is an OpenCV matrix (rows, cols, dt, data)
whose declared rows x cols x channels matches the number of values its data holds, so that no
declared size makes OpenCV allocate more than the file holds. Errors name `where` and `key`. */
CV_EXPORTS Mat readStorageMat(const FileNode& node, const String& where, const String& key);

/** @brief Throws StsOutOfRange naming `where` when an image header (PNG or JPEG) declares more
than kMaxImageSide per side or kMaxImagePixels pixels. Other formats are left to the decoder's
own limit (CV_IO_MAX_IMAGE_PIXELS). `data` holds at least the file's first bytes. */
CV_EXPORTS void checkImageHeader(const uchar* data, size_t size, const String& where);

/** @brief imread after checkImageHeader; a decoder exception or an empty result is a
StsParseError naming the file. `requirePng`: the bytes must be a PNG. */
CV_EXPORTS Mat readImageChecked(const String& path, int flags, bool requirePng = false);

//! imdecode after checkImageHeader; errors name `where`. Returns an empty Mat on a decode failure.
CV_EXPORTS Mat decodeImageChecked(const std::vector<uchar>& bytes, int flags,
                                  const String& where);

/** @brief Pre-check of a mesh file before Assimp reads it: the size against kMaxMeshBytes; a PLY
(ASCII or binary) must have a complete header whose element counts are within kMaxMeshElements
and whose body holds exactly the declared elements, with face indices in range; a binary STL
must be 84 + 50 n bytes. Throws StsParseError / StsOutOfRange naming the file. */
CV_EXPORTS void checkMeshFile(const String& path);

//! The same on bytes already in memory; `where` names them.
CV_EXPORTS void checkMeshBytes(const char* data, size_t size, const String& ext,
                               const String& where);

//! Throws StsOutOfRange "<where>: <value> is not finite or beyond <limit>" unless |v| <= limit.
CV_EXPORTS void checkMagnitude(double v, double limit, const String& where);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
