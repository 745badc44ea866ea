// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "gl_context.hpp"

#include <GL/gl.h>
#include <opencv2/highgui.hpp>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// Draws the world-space quad (four corners) in a flat colour through the camera.
void drawQuad(const Camera& cam, Size size, double zNear, double zFar, const Vec3d q[4],
              const Vec3f& rgb)
{
    const Matx44d P = augocc::detail::glProjection(cam, size, zNear, zFar);
    const Matx44d MV = augocc::detail::glModelView(cam);
    glMatrixMode(GL_PROJECTION);
    glLoadTransposeMatrixd(P.val);
    glMatrixMode(GL_MODELVIEW);
    glLoadTransposeMatrixd(MV.val);
    glColor3f(rgb[0], rgb[1], rgb[2]);
    glBegin(GL_QUADS);
    for (int i = 0; i < 4; i++)
        glVertex3d(q[i][0], q[i][1], q[i][2]);
    glEnd();
}

class Augocc_GlContext_P : public testing::TestWithParam<int> {};

// A square whose projected corners fall on pixel-centre half-way points covers exactly the
// pixels the contract's convention says; its depth reads back as its camera-space z.
TEST_P(Augocc_GlContext_P, accuracy)
{
    const Size size(64, 48);
    const double zNear = 1, zFar = 100;
    Camera cam;
    if (GetParam() == SCALED_ORTHOGRAPHIC)
        cam = Camera::orthographic(Matx33d::eye(), Vec3d(0, 0, 0), 2.0, Point2d(31.5, 23.5));
    else
        cam = Camera::perspective(Matx33d::eye(), Vec3d(0, 0, 0),
                                  Matx33d(40, 0, 31.5, 0, 40, 23.5, 0, 0, 1));
    augocc::detail::GlContext gl(size);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);

    // Pixels u in [10, 19], v in [5, 14] -> edges at u = 9.5 and 19.5, v = 4.5 and 14.5.
    const double z = 20;
    const Point2d a(9.5, 4.5), b(19.5, 14.5);
    Vec3d q[4] = {cam.unproject(a, z), cam.unproject(Point2d(b.x, a.y), z), cam.unproject(b, z),
                  cam.unproject(Point2d(a.x, b.y), z)};
    drawQuad(cam, size, zNear, zFar, q, Vec3f(1, 0, 0));
    Mat bgr, depth01, zc;
    gl.readColor(bgr);
    gl.readDepth(depth01);
    augocc::detail::windowDepthToCameraZ(cam, depth01, zNear, zFar, zc);

    Mat expected = Mat::zeros(size, CV_8UC3);
    expected(Rect(10, 5, 10, 10)).setTo(Scalar(0, 0, 255));
    EXPECT_MAT_NEAR(bgr, expected, 0);
    // 24-bit depth: orthographic error (far-near)/2^24; perspective at z=20 is ~z^2/near/2^24.
    const double kDepthTol = GetParam() == SCALED_ORTHOGRAPHIC ? 1e-4 : 5e-4;
    EXPECT_NEAR(zc.at<float>(8, 12), z, kDepthTol * z);
    EXPECT_TRUE(std::isinf(zc.at<float>(0, 0)));
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_GlContext_P,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

// PITFALLS.md: highgui pulls libGL beside OSMesa; gl* must still bind to OSMesa in a binary that
// uses highgui. This binary links highgui; render a known colour and read it back.
TEST(Augocc_GlContext, osmesa_beside_highgui)
{
    (void)cv::getBuildInformation(); // keep highgui/core linked
    const int wk = cv::waitKey(1);   // a highgui call, no window needed
    (void)wk;
    augocc::detail::GlContext gl(Size(8, 8));
    glClearColor(0.0f, 1.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    Mat bgr;
    gl.readColor(bgr);
    EXPECT_EQ(bgr.at<Vec3b>(3, 3), Vec3b(0, 255, 0));
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    ASSERT_TRUE(renderer != nullptr);
    EXPECT_NE(std::string(renderer).find("llvmpipe"), std::string::npos) << renderer;
}

} // namespace
} // namespace opencv_test
