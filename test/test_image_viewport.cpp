// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// ImageViewport: the annotate window's zoom and pan, headless. A click at view pixel p must mean
// the frame pixel the view shows there, at any zoom, for 1080p and 4K frames.

#include "test_precomp.hpp"

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// A view pixel shows the frame pixel whose area holds its centre: mapped back, its centre lies
// within half a frame pixel of that pixel's centre (per axis), at every scale. 1e-9: float noise.
const double kMaxRoundTripPx = 0.5 + 1e-9;
// viewToImage and imageToView are inverse affine maps: exact up to double rounding.
const double kMaxInverseErr = 1e-9;

// Frame whose pixel (x, y) holds its own index y * W + x (exact in 32-bit float up to 2^24,
// 3840 x 2160 = 8.3e6): what the view shows is read back as a pixel position.
Mat indexFrame(Size s)
{
    Mat m(s, CV_32F);
    for (int y = 0; y < s.height; y++)
        for (int x = 0; x < s.width; x++)
            m.at<float>(y, x) = float(y * s.width + x);
    return m;
}

TEST(Augocc_ImageViewport, fit_view_size)
{
    // 1600x844: the default window 1600x900 less annotate's status lines.
    EXPECT_EQ(Size(1500, 844), ImageViewport::fitViewSize(Size(3840, 2160), Size(1600, 844)));
    EXPECT_EQ(Size(1500, 844), ImageViewport::fitViewSize(Size(1920, 1080), Size(1600, 844)));
    // A frame that fits is shown 1:1, not enlarged.
    EXPECT_EQ(Size(640, 480), ImageViewport::fitViewSize(Size(640, 480), Size(1600, 844)));
    ImageViewport vga(Size(640, 480), Size(640, 480));
    EXPECT_DOUBLE_EQ(1.0, vga.getScale());
    EXPECT_EQ(Point(17, 33), vga.imagePixelAt(Point(17, 33)));  // 1:1 as annotate was
}

TEST(Augocc_ImageViewport, bad_arg)
{
    EXPECT_THROW(ImageViewport(Size(0, 10), Size(10, 10)), cv::Exception);
    EXPECT_THROW(ImageViewport::fitViewSize(Size(10, 10), Size(10, -1)), cv::Exception);
    ImageViewport v(Size(40, 30), Size(40, 30));
    EXPECT_THROW(v.setScale(0, Point2d()), cv::Exception);
    Mat wrong(10, 10, CV_8UC3), out;
    EXPECT_THROW(v.render(wrong, out), cv::Exception);
}

typedef testing::TestWithParam<std::tuple<Size, double>> Augocc_ImageViewport_P;

// Scale 0 stands for the fit (0.39 for 4K, 0.78 for 1080p in a 1600x844 view).
TEST_P(Augocc_ImageViewport_P, accuracy_click_maps_to_shown_pixel)
{
    const Size frame = std::get<0>(GetParam());
    const double wanted = std::get<1>(GetParam());
    const Size viewSize = ImageViewport::fitViewSize(frame, Size(1600, 844));
    ImageViewport v(frame, viewSize);
    RNG rng(7);
    // Zoom about a point off the centre, then drag: the offset is not a round number.
    if (wanted > 0)
    {
        v.setScale(wanted, Point2d(viewSize.width * 0.3, viewSize.height * 0.7));
        v.pan(Point2d(-37.3, 11.9));
        EXPECT_DOUBLE_EQ(wanted, v.getScale());
    }
    else
        EXPECT_NEAR(v.fitScale(), v.getScale(), 1e-12);
    const Mat idx = indexFrame(frame);
    Mat view;
    v.render(idx, view, Scalar(-1));
    const Rect frameRect(Point(), frame);
    double worst = 0, worstInverse = 0;
    int shownWrong = 0, n = 0;
    for (int i = 0; i < 20000; i++)
    {
        const Point p(rng.uniform(0, viewSize.width), rng.uniform(0, viewSize.height));
        const Point q = v.imagePixelAt(p);
        ASSERT_TRUE(frameRect.contains(q)) << p << " -> " << q;  // the frame covers the view
        const Point2d u = v.viewToImage(Point2d(p));
        worst = std::max(worst, std::max(std::abs(u.x - q.x), std::abs(u.y - q.y)));
        const Point2d back = v.imageToView(u);
        worstInverse = std::max(worstInverse, norm(back - Point2d(p)));
        if (v.getScale() >= 1)
        {
            // What the window draws there is that very pixel.
            shownWrong += view.at<float>(p) != idx.at<float>(q);
        }
        n++;
    }
    EXPECT_LE(worst, kMaxRoundTripPx) << "scale " << v.getScale();
    EXPECT_LE(worstInverse, kMaxInverseErr);
    EXPECT_EQ(0, shownWrong) << "of " << n;
    if (v.getScale() < 1)
    {
        // Area-averaged: a view pixel's value is an average of indices near the mapped point;
        // its column index is within one view pixel (1 / scale frame pixels) of the mapping.
        const Point p(viewSize.width / 3, viewSize.height / 2);
        const double shown = view.at<float>(p);
        const Point2d u = v.viewToImage(Point2d(p));
        const double shownY = std::floor(shown / frame.width + 0.5);
        EXPECT_NEAR(u.y, shownY, 1.0 / v.getScale() + 0.5);
    }
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_ImageViewport_P,
                         testing::Combine(testing::Values(Size(3840, 2160), Size(1920, 1080)),
                                          testing::Values(0.0, 1.0, 2.5, 8.0)));

TEST(Augocc_ImageViewport, zoom_about_cursor_and_clamped_pan)
{
    ImageViewport v(Size(3840, 2160), Size(1500, 844));
    const Point2d cursor(400.25, 300.75);
    const Point2d under = v.viewToImage(cursor);
    v.zoomBy(4.0, cursor);
    // The frame point under the cursor stays under it (away from the edges: no clamp).
    EXPECT_LE(norm(v.imageToView(under) - cursor), kMaxInverseErr);
    EXPECT_NEAR(4.0, v.getZoom(), 1e-12);
    // Zooming out beyond the fit stops at the fit, frame centred (1500/3840 = 844/2160 within
    // rounding: both axes fit, one exactly).
    v.zoomBy(1e-3, cursor);
    EXPECT_NEAR(1.0, v.getZoom(), 1e-12);
    // And in beyond the largest scale stops there.
    v.setScale(1e6, cursor);
    EXPECT_DOUBLE_EQ(ImageViewport::kMaxScale, v.getScale());
    // A drag far past the frame's edge stops with the frame's corner at the view's corner.
    v.pan(Point2d(1e7, 1e7));
    EXPECT_EQ(Point(0, 0), v.imagePixelAt(Point(0, 0)));
    v.pan(Point2d(-1e8, -1e8));
    EXPECT_EQ(Point(3839, 2159), v.imagePixelAt(Point(1499, 843)));
    // At the fit the frame's left and right edges are the view's (1500 = 3840 * 0.390625); a
    // view pixel then covers 2.56 frame pixels, and the first shows frame pixel 1 (its centre,
    // 0.78, is nearest to it); vertically the frame (843.75 view pixels) is centred in 844, the
    // first view row's centre at frame row 0.46.
    v.fit();
    EXPECT_NEAR(-0.5, v.viewToImage(Point2d(-0.5, 0)).x, kMaxInverseErr);
    EXPECT_NEAR(3839.5, v.viewToImage(Point2d(1499.5, 0)).x, kMaxInverseErr);
    EXPECT_EQ(Point(1, 0), v.imagePixelAt(Point(0, 0)));
}

} // namespace
} // namespace opencv_test
