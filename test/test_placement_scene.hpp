// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The shot the PlacementEditor tests place objects in (headless tests and the Xvfb test of
// `augocc place`): a small synthesized scene with its true cameras, clones from its key frames
// and a scene file with one object beside the building.

#ifndef OPENCV_AUGOCC_TEST_PLACEMENT_SCENE_HPP
#define OPENCV_AUGOCC_TEST_PLACEMENT_SCENE_HPP

#include <opencv2/augocc.hpp>

namespace opencv_test {

struct PlacementShot
{
    cv::augocc::SyntheticScene scene;
    cv::Ptr<cv::augocc::CloneSet> clones;
    cv::augocc::VirtualScene virtualScene;  // a box beside the building (a helper), a dome
    double sceneSize = 0;  //!< truth: diagonal of the real objects' footprint on y = 0
};

//! Built once per test binary (6 frames of 320x240, 3 key frames; a few seconds).
const PlacementShot& placementShot();

/** The truth under a pixel: the true camera's ray through px meets the true ground y = 0
(SceneSynthesizer's world). */
cv::Vec3d trueGroundPoint(const cv::augocc::Camera& camera, const cv::Point2d& px);

} // namespace opencv_test

#endif
