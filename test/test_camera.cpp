// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

Camera makeCamera(CameraModel model)
{
    const Matx33d R = rotationFromRodrigues(Vec3d(0.3, -0.2, 0.1));
    const Vec3d t(0.5, -0.3, 20.0);
    if (model == SCALED_ORTHOGRAPHIC)
        return Camera::orthographic(R, t, 25.0, Point2d(320, 240), 3);
    return Camera::perspective(R, t, Matx33d(800, 0.5, 321, 0, 790, 239, 0, 0, 1), 3);
}

class Augocc_Camera_P : public testing::TestWithParam<int> {};

TEST_P(Augocc_Camera_P, accuracy)
{
    const Camera cam = makeCamera((CameraModel)GetParam());
    RNG rng(7);
    for (int i = 0; i < 100; i++)
    {
        const Vec3d X(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
        const Point2d px = cam.project(X);
        const double z = cam.depth(X);
        EXPECT_NEAR(z, cam.toCamera(X)[2], 1e-12);
        // unproject inverts project at the same depth.
        const Vec3d back = cam.unproject(px, z);
        EXPECT_LT(cv::norm(back - X), 1e-9);
        // The back-projected ray passes through X; its direction increases depth.
        const Ray ray = cam.backproject(px);
        const Vec3d d = X - ray.origin;
        EXPECT_LT(cv::norm(d - d.dot(ray.direction) * ray.direction), 1e-9);
        EXPECT_GT(cam.depth(ray.at(1.0)), cam.depth(ray.at(0.0)));
        // projectionMatrix agrees with project.
        const Vec3d h = cam.projectionMatrix() * Vec4d(X[0], X[1], X[2], 1);
        EXPECT_NEAR(h[0] / h[2], px.x, 1e-9);
        EXPECT_NEAR(h[1] / h[2], px.y, 1e-9);
    }
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_Camera_P, testing::Values((int)SCALED_ORTHOGRAPHIC,
                                                                (int)PERSPECTIVE));

TEST(Augocc_Camera, bad_arg)
{
    Camera cam = makeCamera(SCALED_ORTHOGRAPHIC);
    EXPECT_NO_THROW(cam.validate("x"));
    Camera bad = cam;
    bad.R(0, 0) += 0.01;
    EXPECT_THROW(bad.validate("x"), cv::Exception);
    bad = cam;
    bad.s = 0;
    EXPECT_THROW(bad.validate("x"), cv::Exception);
    bad = cam;
    bad.t[1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(bad.validate("x"), cv::Exception);
    Camera p = makeCamera(PERSPECTIVE);
    p.K(1, 1) = -1;
    EXPECT_THROW(p.validate("x"), cv::Exception);
    EXPECT_THROW(parseCameraModel("fisheye"), cv::Exception);
}

TEST(Augocc_Camera, rotation_angle)
{
    const Matx33d A = rotationFromRodrigues(Vec3d(0.1, 0.2, 0.3));
    const Matx33d B = A * rotationFromRodrigues(Vec3d(0, 0, CV_PI / 180 * 2.5));
    EXPECT_NEAR(rotationAngleDeg(A, B), 2.5, 1e-9);
}

} // namespace
} // namespace opencv_test
