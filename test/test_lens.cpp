// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Lens distortion of Camera and the ideal view of LensView, against OpenCV's own functions.

#include "test_precomp.hpp"

#include <opencv2/calib3d.hpp>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

const Size kFrame(1280, 720);

// Coefficients of the counts OpenCV accepts: a wide phone lens (barrel) first, then more terms.
std::vector<double> coefficients(int n)
{
    const double all[14] = {-0.12, 0.03, 0.0008, -0.0005, -0.004,   // k1 k2 p1 p2 k3
                            0.01, -0.005, 0.002,                    // k4 k5 k6
                            0.0006, -0.0002, -0.0004, 0.0001,       // s1 .. s4
                            0.004, -0.003};                         // tauX, tauY (radians)
    return std::vector<double>(all, all + n);
}

Camera lensCamera(int n)
{
    return Camera::perspective(rotationFromRodrigues(Vec3d(0.2, -0.1, 0.05)), Vec3d(0.3, -0.2, 8),
                               Matx33d(1000, 0, 639.5, 0, 1000, 359.5, 0, 0, 1), 0, coefficients(n));
}

// Pixels over the whole frame, corners and border included.
std::vector<Point2d> framePixels()
{
    std::vector<Point2d> px;
    for (int j = 0; j <= 16; j++)
        for (int i = 0; i <= 16; i++)
            px.push_back(Point2d(-0.5 + (kFrame.width) * i / 16.0, -0.5 + kFrame.height * j / 16.0));
    return px;
}

class Augocc_Lens_P : public testing::TestWithParam<int> {};

// Projection is cv::projectPoints to 1e-6 px for every coefficient count (the formula is the
// same; the tolerance is rounding of a few dozen double operations at 1e3 px).
TEST_P(Augocc_Lens_P, project_matches_opencv)
{
    const Camera cam = lensCamera(GetParam());
    std::vector<Point3d> X;
    for (const Point2d& px : framePixels())
    {
        for (double z : {4.0, 9.0})
            X.push_back(Point3d(cam.pinhole().unproject(px, z)));
    }
    Vec3d rvec;
    cv::Rodrigues(cam.R, rvec);
    std::vector<Point2d> ref;
    cv::projectPoints(X, rvec, cam.t, Mat(cam.K), Mat(cam.distortion), ref);
    double worst = 0;
    for (size_t i = 0; i < X.size(); i++)
        worst = std::max(worst, cv::norm(cam.project(Vec3d(X[i])) - ref[i]));
    EXPECT_LT(worst, 1e-6) << "coefficients " << GetParam();
}

// Back-projection: the ray of a distorted pixel projects back onto it (1e-6 px), and agrees with
// cv::undistortPoints run to convergence (its default 5 iterations are not enough at the corners
// of a wide lens; OpenCV's own accuracy then is 1e-8 in normalised units).
TEST_P(Augocc_Lens_P, backproject_matches_opencv)
{
    const Camera cam = lensCamera(GetParam());
    const std::vector<Point2d> px = framePixels();
    std::vector<Point2d> ref;
    cv::undistortPoints(px, ref, Mat(cam.K), Mat(cam.distortion), noArray(), noArray(),
                        TermCriteria(TermCriteria::COUNT + TermCriteria::EPS, 500, 1e-14));
    double worstRound = 0, worstRef = 0;
    for (size_t i = 0; i < px.size(); i++)
    {
        const Ray ray = cam.backproject(px[i]);
        worstRound = std::max(worstRound, cv::norm(cam.project(ray.at(5.0)) - px[i]));
        const Point2d n = cam.undistortNormalized(Point2d((px[i].x - cam.K(0, 2)) / cam.K(0, 0),
                                                          (px[i].y - cam.K(1, 2)) / cam.K(1, 1)));
        worstRef = std::max(worstRef, cam.K(0, 0) * cv::norm(n - ref[i]));
        // depth and unproject agree with the ray
        const Vec3d X = cam.unproject(px[i], 3.0);
        EXPECT_NEAR(cam.depth(X), 3.0, 1e-9);
        EXPECT_LT(cv::norm(cam.project(X) - px[i]), 1e-6);
    }
    EXPECT_LT(worstRound, 1e-6) << "coefficients " << GetParam();
    EXPECT_LT(worstRef, 1e-5) << "coefficients " << GetParam();
}

// The ideal view: a pixel maps to the ideal pixel of the same ray and back; the frame lies inside
// the ideal image; the warps move an image by the same mapping (to interpolation accuracy).
TEST_P(Augocc_Lens_P, ideal_view)
{
    const Camera cam = lensCamera(GetParam());
    Ptr<const LensView> view = LensView::get(cam, kFrame);
    ASSERT_FALSE(view.empty());
    EXPECT_EQ(view.get(), LensView::get(cam, kFrame).get()) << "cached";
    const Camera ideal = view->idealCamera(cam);
    EXPECT_FALSE(ideal.hasDistortion());
    for (const Point2d& px : framePixels())
    {
        const Point2d q = view->frameToIdeal(px);
        EXPECT_GE(q.x, -0.5);
        EXPECT_GE(q.y, -0.5);
        EXPECT_LE(q.x, view->idealSize().width - 0.5);
        EXPECT_LE(q.y, view->idealSize().height - 0.5);
        EXPECT_LT(cv::norm(view->idealToFrame(q) - px), 1e-6);
        // the same world point: frame camera at px, ideal camera at q
        const Vec3d X = cam.unproject(px, 6.0);
        EXPECT_LT(cv::norm(ideal.project(X) - q), 1e-6);
    }
    // Warp a smooth ramp (u + 2 v in the frame) into the ideal view and back: bilinear
    // interpolation of a linear function is exact, but cv::remap rounds the map to 1/32 px
    // (INTER_TAB_SIZE): each warp is off by up to 1/64 px in x and in y, times the ramp's slopes
    // 1 and 2 (no steeper in the ideal view, which samples at least as densely): 3/64 per warp,
    // plus float rounding of the values (~3e3 * 1.2e-7).
    Mat ramp(kFrame, CV_32F);
    for (int y = 0; y < kFrame.height; y++)
        for (int x = 0; x < kFrame.width; x++)
            ramp.at<float>(y, x) = (float)(x + 2 * y);
    Mat idealImg, back;
    view->toIdeal(ramp, idealImg, INTER_LINEAR, Scalar(-1));
    EXPECT_EQ(idealImg.size(), view->idealSize());
    view->toFrame(idealImg, back, INTER_LINEAR, Scalar(-1));
    Mat diff = cv::abs(back - ramp);
    // one pixel of border where the ideal view's outside (-1) is mixed in by the interpolation
    Rect inner(2, 2, kFrame.width - 4, kFrame.height - 4);
    double maxDiff = 0;
    cv::minMaxLoc(diff(inner), nullptr, &maxDiff);
    EXPECT_LT(maxDiff, 2 * 3.0 / 64 + 1e-3);
}

INSTANTIATE_TEST_CASE_P(Augocc_Lens, Augocc_Lens_P, testing::Values(4, 5, 8, 12, 14));

// A pinhole without coefficients is the old code path to the last digit.
TEST(Augocc_Lens, zero_coefficients_are_the_pinhole)
{
    Camera a = lensCamera(5), b = a;
    a.distortion.clear();
    b.distortion.assign(5, 0.0);
    RNG rng(3);
    for (int i = 0; i < 50; i++)
    {
        const Vec3d X(rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0));
        const Point2d pa = a.project(X), pb = b.project(X);
        EXPECT_EQ(pa.x, pb.x);
        EXPECT_EQ(pa.y, pb.y);
        const Vec3d ua = a.unproject(pa, 5.0), ub = b.unproject(pa, 5.0);
        EXPECT_EQ(ua, ub);
    }
    EXPECT_FALSE(b.hasDistortion());
}

TEST(Augocc_Lens, validate_rejects_bad_coefficients)
{
    Camera c = lensCamera(5);
    c.distortion.resize(6);
    EXPECT_THROW(c.validate("cam.yml: cameras[0]"), cv::Exception);
    c.distortion = coefficients(5);
    c.distortion[1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(c.validate(), cv::Exception);
    Camera o = Camera::orthographic(Matx33d::eye(), Vec3d(0, 0, 0), 2.0, Point2d(10, 10));
    o.distortion = coefficients(4);
    EXPECT_THROW(o.validate(), cv::Exception);
    // A lens that folds over the frame (huge positive k2: the radial map turns back) is refused.
    Camera fold = lensCamera(5);
    fold.distortion = {-1.5, 0.0, 0.0, 0.0, 0.0};
    try
    {
        LensView::get(fold, kFrame);
        ADD_FAILURE() << "expected an exception";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_NE(e.err.find("folds"), String::npos) << e.err;
    }
}

// reconstruction.yml carries the coefficients; absent means none.
TEST(Augocc_Lens, reconstruction_file_round_trip)
{
    Reconstruction rec;
    rec.model = PERSPECTIVE;
    rec.imageSize = kFrame;
    rec.cameras.push_back(lensCamera(8));
    Camera second = lensCamera(8);
    second.frame = 1;
    second.distortion.clear();
    rec.cameras.push_back(second);
    const String path = cv::tempfile(".yml");
    writeReconstruction(path, rec);
    const Reconstruction back = readReconstruction(path);
    ASSERT_EQ(back.cameras.size(), 2u);
    EXPECT_EQ(back.cameras[0].distortion, rec.cameras[0].distortion);
    EXPECT_TRUE(back.cameras[1].distortion.empty());
    std::remove(path.c_str());
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {

// The slide figure: zero for the truth itself and for any similarity of it (gauge-free), large
// at the image edges when the lens is ignored.
TEST(Augocc_Lens, slide_measures_what_the_user_sees)
{
    Reconstruction truth;
    truth.model = PERSPECTIVE;
    truth.imageSize = kFrame;
    RNG rng(5);
    for (int f = 0; f < 12; f++)
    {
        const double a = (f - 6) * 2.0 * CV_PI / 180;
        const Matx33d R = rotationFromRodrigues(Vec3d(0.02 * std::sin(f), a, 0.01 * f));
        const Vec3d C(10 * std::sin(a) + 0.3 * f, 0.1 * f, -10 * std::cos(a));
        truth.cameras.push_back(Camera::perspective(R, -(R * C),
            Matx33d(1000, 0, 639.5, 0, 1000, 359.5, 0, 0, 1), f, {-0.12, 0.02, 0, 0, 0}));
    }
    truth.points = Mat(200, 3, CV_64F);
    for (int p = 0; p < 200; p++)
        for (int a = 0; a < 3; a++)
            truth.points.at<double>(p, a) = rng.uniform(-3.0, 3.0);
    const SlideStats self = measureSlide(truth, truth);
    EXPECT_GT(self.points, 50);
    EXPECT_LT(self.max, 1e-6);  // Gauss-Newton to convergence on exact pixels
    // A similarity of the world (scale 2, a rotation, a shift): the same images, no slide.
    Reconstruction moved = truth;
    const Matx33d Q = rotationFromRodrigues(Vec3d(0.3, -0.2, 0.5));
    const double sc = 2.0;
    const Vec3d T(4, -1, 2);
    for (Camera& c : moved.cameras)
    {
        // X' = sc Q X + T: R' = R Q^T, t' = sc t - R' T
        const Matx33d R2 = c.R * Q.t();
        c.t = sc * c.t - R2 * T;
        c.R = R2;
    }
    for (int p = 0; p < moved.points.rows; p++)
    {
        const Vec3d X = sc * (Q * truth.point(p)) + T;
        for (int a = 0; a < 3; a++)
            moved.points.at<double>(p, a) = X[a];
    }
    EXPECT_LT(measureSlide(moved, truth).max, 1e-5);
    // The lens ignored: the virtual points slide by pixels at the edges.
    Reconstruction ignored = truth;
    for (Camera& c : ignored.cameras)
        c.distortion.clear();
    const SlideStats bad = measureSlide(ignored, truth);
    std::cout << "  lens ignored, true poses: slide median " << bad.median << " px, p95 "
              << bad.p95 << ", max " << bad.max << std::endl;
    EXPECT_GT(bad.max, 5.0);
}

} // namespace
} // namespace opencv_test
