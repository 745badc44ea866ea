// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CHUNKS_HPP
#define OPENCV_AUGOCC_CHUNKS_HPP

#include <vector>
#include <opencv2/core.hpp>

/**
@file
@brief Joining the outputs of frame chunks (a render farm's jobs, `augocc farm`, doc/farm.md).

A per-frame stage run on a frame range (`augocc composite --frames a:b --out DIR`,
`augocc matte --frames a:b`) writes a chunk: a folder of `%04d.png` frames, or a mattes tree
`DIR/<object>/%04d.png`. The functions here put the chunks of one shot together: the PNG files
are copied byte for byte, and a video is encoded once from them (no chunk is ever encoded twice).
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Joins folders of frames `%04d.png` (frame indices of the input) into one output.
@param chunkDirs the chunks' folders, any order; together they must hold every frame from the
lowest index to the highest exactly once, all of one size.
@param output a video (`.mp4`, `.avi`, `.mkv`, `.mov`, `.m4v`: H.264 through OpenCV's FFmpeg
backend, MPEG-4 part 2 when H.264 is unavailable, as compositeSequence() writes) with the frames
in index order, or a folder that receives every `%04d.png` file unchanged.
@param fps the video's frame rate (the input's, for the same video as a single-machine run).
@return the number of frames written.

The output is written all or nothing (writeAtomically()). Throws StsBadArg naming the folder
and file for a missing chunk folder, a file that is not `NNNN.png`, a frame in two chunks, a gap
in the frame indices, no frame at all; StsBadSize for a frame whose size differs from the first;
StsError when the output cannot be written.
*/
CV_EXPORTS int joinFrameChunks(const std::vector<String>& chunkDirs, const String& output,
                               double fps = 25);

/** @brief Joins mattes or masks trees `DIR/<object>/%04d.png` into one tree `output`.
@param chunkDirs the chunks' trees; an object may be absent from some; a frame of an object in
two chunks is an error.
@param output the joined tree (written all or nothing; files copied unchanged).
@return the number of files written.

Throws StsBadArg naming the folder and file for a missing chunk, a file that is not
`NNNN.png`, a frame of an object in two chunks, chunks with no object at all; StsError when the
output cannot be written.
*/
CV_EXPORTS int joinMaskChunks(const std::vector<String>& chunkDirs, const String& output);

//! @}

} // namespace augocc
} // namespace cv

#endif
