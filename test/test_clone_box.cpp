// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Pass 1 (Steps 1-3): the box from the points, from the silhouettes, oriented automatically.

#include "test_clone_scenes.hpp"

namespace opencv_test {
namespace {

// Without any reconstructed point the box comes from the silhouettes alone (documented fallback).
TEST(Augocc_CloneBuilder, fallback_without_points)
{
    AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 30, 6);
    s.rec.points = Mat();
    Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
    for (const String& name : clones->objectNames())
    {
        const Figures f = measure(*clones, s, name, s.whole);
        EXPECT_GE(f.keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(f.nonKeyMean, kNonKeyMeanIoU) << name;
    }
    // One key frame cannot bound an object without points: a clear error.
    ObjectMasks one;
    one["tower"][0] = s.keyMasks["tower"][0];
    EXPECT_THROW(CloneBuilder::create()->build(s.rec, one), cv::Exception);
}

TEST(Augocc_CloneBuilder, auto_orientation_fits_rotated_box)
{
    // A box turned 30 degrees about the vertical: the automatic orientation finds its facades.
    const double th = 30 * CV_PI / 180;
    const Matx33d Ry(std::cos(th), 0, std::sin(th), 0, 1, 0, -std::sin(th), 0, std::cos(th));
    const AnalyticScene s0 = makeScene(SCALED_ORTHOGRAPHIC, {{"b", {{Vec3d(-1.5, 0, -0.6),
                                       Vec3d(1.5, 2, 0.6)}}}}, 20, 4);
    // Rotate the world: cameras and points (same images).
    AnalyticScene s = s0;
    for (Camera& c : s.rec.cameras)
        c.R = c.R * Ry.t();
    for (int p = 0; p < s.rec.points.rows; p++)
    {
        const Vec3d X = Ry * Vec3d(s.rec.points.ptr<double>(p));
        for (int a = 0; a < 3; a++)
            s.rec.points.at<double>(p, a) = X[a];
    }
    Ptr<CloneSet> autoSet = CloneBuilder::create()->build(s.rec, s.keyMasks);
    Matx33d Rb;
    Vec3d o;
    autoSet->gridPose("b", Rb, o);
    // Box axes vs the true facades (up to axis permutation and sign): within 2 degrees.
    const Matx33d D = Ry.t() * Rb;
    double worst = 0;
    for (int c = 0; c < 3; c++)
    {
        double best = 0;
        for (int r = 0; r < 3; r++)
            best = std::max(best, std::abs(D(r, c)));
        worst = std::max(worst, std::acos(std::min(1.0, best)) * 180 / CV_PI);
    }
    EXPECT_LE(worst, 2.0);
    CloneBuilder::Params p;
    p.box.orientation = CloneBuilder::ORIENT_WORLD;
    Ptr<CloneSet> worldSet = CloneBuilder::create(p)->build(s.rec, s.keyMasks);
    const Vec3i ga = autoSet->gridSize("b"), gw = worldSet->gridSize("b");
    EXPECT_LT((double)ga[0] * ga[1] * ga[2], 0.8 * gw[0] * gw[1] * gw[2]);
    const Figures f = measure(*autoSet, s, "b", s.whole);
    EXPECT_GE(f.nonKeyMean, kNonKeyMeanIoU);
}

} // namespace
} // namespace opencv_test
