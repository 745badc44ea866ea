// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SFM_EXPORT_HPP
#define OPENCV_AUGOCC_SFM_EXPORT_HPP

#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Writes a reconstruction as a COLMAP text model: `dir/cameras.txt`, `dir/images.txt`,
`dir/points3D.txt` (COLMAP's "Output format" documentation), so that it opens in COLMAP's GUI
and in tools that read COLMAP models.

- One COLMAP camera per frame (CAMERA_ID = IMAGE_ID = frame + 1), model PINHOLE
  (fx, fy, cx, cy) for a camera without lens distortion; a distorted camera is COLMAP's
  `OPENCV` (fx, fy, cx, cy, k1, k2, p1, p2), or `FULL_OPENCV` (..., k3, k4, k5, k6) when it has
  a non-zero k3..k6: both are OpenCV's model of the normalised point, so the observations are
  written as filmed. Thin prism and tilt coefficients (s1..s4, tx, ty) have no COLMAP model:
  StsNotImplemented naming the frame, before anything is written. Skew is not written (COLMAP
  has none). Image names are `%04d.png` of the frame index (the frames folder written
  by `augocc synth`).
- COLMAP's pixel origin is the top-left corner of the image (the centre of the first pixel is
  (0.5, 0.5)); the contract's is the centre of the first pixel, so 0.5 is added to every image
  coordinate and to the principal point.
- SCALED_ORTHOGRAPHIC cameras have no COLMAP model. They are written as the PINHOLE camera that
  approximates them: the centroid of the points at distance `orthoDistanceRatio` times the
  points' RMS radius along the optical axis, focal length f = s * distance (so the image scale
  at the centroid is s). The perspective error this adds is about (radius / distance) times the
  distance of a point's image from the principal point: 0.03 px for a point 300 px off-centre
  with the default 1e4.
- points3D.txt holds the finite rows of `points` (POINT3D_ID = row + 1), colour grey unless
  `colors` is given, ERROR the mean reprojection error of the point, and its track (IMAGE_ID,
  POINT2D_IDX) over the frames that have a camera.
Each file is written atomically; `dir` is created if needed.

@param dir output folder.
@param rec the reconstruction.
@param tracks the tracks it came from (the 2D points of images.txt and the point tracks).
@param colors optional P x 1 CV_8UC3 BGR colour per track.
@param orthoDistanceRatio see above (> 1).
*/
CV_EXPORTS void writeColmapModel(const String& dir, const Reconstruction& rec,
                                 const Tracks& tracks, InputArray colors = noArray(),
                                 double orthoDistanceRatio = 1e4);

/** @brief Writes the finite points of a reconstruction as an ASCII PLY point cloud (vertices
x y z, and red green blue when `colors` is given), atomically.
@param path output file.
@param rec the reconstruction.
@param colors optional P x 1 CV_8UC3 BGR colour per point row.
*/
CV_EXPORTS void writePointsPly(const String& path, const Reconstruction& rec,
                               InputArray colors = noArray());

//! @}

} // namespace augocc
} // namespace cv

#endif
