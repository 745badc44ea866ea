// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SCENE_DETAIL_HPP
#define OPENCV_AUGOCC_SCENE_DETAIL_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

//! The scene file's `rotation`: Euler angles in degrees, R = Rz * Ry * Rx.
Matx33d eulerDegToRotation(const Vec3d& deg);
/** The inverse of eulerDegToRotation() for a rotation matrix: y in [-90, 90], x and z in
(-180, 180]; at y = +-90 (gimbal lock) z is 0. */
Vec3d rotationToEulerDeg(const Matx33d& R);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
