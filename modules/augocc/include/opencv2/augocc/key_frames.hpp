// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_KEY_FRAMES_HPP
#define OPENCV_AUGOCC_KEY_FRAMES_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/io.hpp"

/*
Key-frame suggestions (the paper's Section 5 advice: key frames where the object's appearance
changes most, i.e. where facets appear or disappear and where the viewing direction turns).

Appearance change between two frames is measured as
- view change: the angle between the two cameras' optical axes, in degrees, divided by a scale
  (a turn of `degreesPerChange` counts as a complete change);
- visibility change: the Jaccard distance 1 - |A n B| / |A u B| between the sets of the object's
  tracks observed in the two frames (a facet that turns into view brings new tracks, one that
  turns away loses them).
Key frames are then chosen so that the largest change between consecutive key frames is as small
as possible (a bottleneck partition of the sequence, solved exactly by dynamic programming); among
the choices with that smallest bottleneck, the one with the least sum of squared changes is
returned. The first and the last frame are always key frames.
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Chooses key frames from a matrix of pairwise appearance changes.
@param change N x N CV_64F (or CV_32F), change(a, b) >= 0 between frames a and b (only a < b is
read); finite.
@param count number of key frames wanted (at least 2 unless N == 1; clamped to N).
@return sorted indices into 0..N-1, the first 0 and the last N-1.
*/
CV_EXPORTS std::vector<int> selectKeyFrames(InputArray change, int count);

/** @brief Pairwise view change: angle in degrees between the optical axes of the cameras of a
reconstruction, in the order of `rec.cameras`.
@param rec cameras.
@return N x N CV_64F, N = rec.cameras.size().
*/
CV_EXPORTS Mat viewChangeMatrix(const Reconstruction& rec);

/** @brief Pairwise visibility change: Jaccard distance between the sets of tracks observed in
two frames.
@param tracks the tracks (rows are frames).
@param objectTracks optional, one flag per track: only flagged tracks count (the object's own);
empty = every track.
@return F x F CV_64F; two frames that both observe none of the tracks have change 0.
*/
CV_EXPORTS Mat visibilityChangeMatrix(const Tracks& tracks,
                                      const std::vector<uchar>& objectTracks =
                                          std::vector<uchar>());

/** @brief The tracks that belong to an object, from its silhouettes in some frames.

With a reconstruction, a track belongs to the object when its 3D point projects inside the
silhouette in every masked frame that has a camera (the point lies in the silhouettes' visual
hull, so points on facets hidden in those frames count too). Without one (or for a track without
a 3D point), when it is observed inside the silhouette in at least one masked frame and outside
it in none.
@param tracks the tracks.
@param masks the object's masks (frame index -> CV_8U, > 127 inside), sizes equal to the frames.
@param rec optional reconstruction whose `points` rows match the tracks' columns (may be null).
@return one flag per track (1 = the object's).
*/
CV_EXPORTS std::vector<uchar> objectTracksFromMasks(const Tracks& tracks, const FrameMasks& masks,
                                                    const Reconstruction* rec = nullptr);

/** @brief Suggests key frames from the cameras alone: where the viewing direction turns.
@param rec reconstruction (at least one camera).
@param count number of key frames wanted (first and last included).
@return frame indices (camera frame numbers), sorted.
*/
CV_EXPORTS std::vector<int> suggestKeyFrames(const Reconstruction& rec, int count);

/** @brief Suggests key frames from tracks alone: where the set of visible tracks changes.
@param tracks the tracks.
@param count number of key frames wanted (first and last included).
@param objectTracks optional per-track flags restricting to one object (see
objectTracksFromMasks()).
@return frame indices, sorted.
*/
CV_EXPORTS std::vector<int> suggestKeyFrames(const Tracks& tracks, int count,
                                             const std::vector<uchar>& objectTracks =
                                                 std::vector<uchar>());

/** @brief Suggests key frames from tracks and cameras: change(a, b) = max(view change /
degreesPerChange, visibility change of the object's tracks).
@param tracks the tracks the reconstruction came from.
@param rec the reconstruction; only frames with a camera are candidates.
@param count number of key frames wanted (first and last camera frames included).
@param objectMasks optional silhouettes of the object in some frames: restricts the visibility
change to its tracks (objectTracksFromMasks()); empty = every track.
@param degreesPerChange turn of the view direction that counts as a complete change, degrees,
> 0 (lower gives the view change more weight against the visibility change).
@return frame indices, sorted.
*/
CV_EXPORTS std::vector<int> suggestKeyFrames(const Tracks& tracks, const Reconstruction& rec,
                                             int count,
                                             const FrameMasks& objectMasks = FrameMasks(),
                                             double degreesPerChange = 30.0);

//! @}

} // namespace augocc
} // namespace cv

#endif
