// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Planes through reconstructed points: the one RANSAC plane search of augocc (the ground of
// estimateGround() in scene.cpp, the depth-reversal prior's dominant plane in camera_refiner.cpp)
// and the ground plane fit built on it.

#ifndef OPENCV_AUGOCC_GROUND_PLANE_HPP
#define OPENCV_AUGOCC_GROUND_PLANE_HPP

#include <functional>
#include <vector>
#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

//! A plane `normal . X == offset` (unit normal) and the points RANSAC found on it.
struct PlaneFit
{
    Vec3d normal = Vec3d(0, 0, 0);
    double offset = 0;
    int inliers = 0;  //!< points within the band; 0 when no candidate was scored
};

/** @brief RANSAC plane search, deterministic for a given seed.

Each of `trials` candidates is the plane through three of `samples` drawn with RNG(seed) (with
replacement; collinear triples are skipped). Its unit normal is passed to `orient`, which may flip
it and returns false to skip the candidate; the offset is taken after. A candidate scores the
`points` strictly within `band` of it; the first candidate with the most wins.

@param samples the points the triples are drawn from (no trial runs with fewer than 3).
@param points the points counted as inliers (may be `samples`).
@param band inlier distance, the units of the points.
@param trials number of triples drawn.
@param seed RNG seed.
@param orient optional normal check (e.g. a tilt limit); empty: every normal, as computed.
*/
PlaneFit ransacPlane(const std::vector<Vec3d>& samples, const std::vector<Vec3d>& points,
                     double band, int trials, uint64 seed,
                     const std::function<bool(Vec3d& normal)>& orient =
                         std::function<bool(Vec3d&)>());

/** @brief The ground plane of estimateGround() (scene.hpp): a RANSAC plane whose normal lies
within 15 degrees of `up`, drawn from the lower half of the points along `up`, with inliers within
1% of the points' extent along `up`, refitted by least squares when it carries a tenth of the
points (at least 10).

@param points reconstructed points (world).
@param up in: the up direction from the cameras (unit); out: the plane's normal (signed like
`up`) when a plane is found, else unchanged.
@param height out: the plane's `up . X` when found; else the 2nd percentile of the points'
heights along `up`, or 0 with fewer than 10 points.
@return true when a plane was found.
*/
bool fitGroundPlane(const std::vector<Vec3d>& points, Vec3d& up, double& height);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
