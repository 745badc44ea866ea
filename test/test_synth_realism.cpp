// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// SceneSynthesizer's hand-held realism (issue 15, item 5): lens distortion, the hand-held path,
// exposure / white-balance drift, H.264 at a bit rate, large frames, calibration.yml.

#include "test_precomp.hpp"

#include <unistd.h>

#include <filesystem>
#include <opencv2/videoio.hpp>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

// A virtual marker's coverage centroid against Camera::project of its centre: the brief's
// bound. Measured 0.10 px at worst (bilinear warp of the 4x supersampled ideal view).
const double kMaxMarkerErrPx = 0.2;
// Silhouettes against the exact ray-box test through the lens: the nearest sample of a view
// kLensMaskSupersample = 2 times finer than the ideal view (>= the frame's density) is within
// 0.25 px of the pixel's ray, so mismatches stay in the 1 px band around the boundary ...
const int kMaskBandPx = 1;
// ... and number at most 0.25 per boundary pixel (the worst case 0.25 px shift; the mean is
// about half that).
const double kMaxMaskMismatchPerEdgePx = 0.25;
// Exposure: mean gain of the unsaturated pixels against the stated 1 + drift; 8-bit rounding of
// values ~100 moves a ratio by < 0.005.
const double kGainTol = 0.005;
// H.264 at the set bit rate against the lossless frames: x264 at 1 Mbit/s on 320x240 textured
// frames (a phone's 12 Mbit/s at 1080p is 0.23 bit per pixel; this is 0.52): measured ~37 dB.
const double kMinPsnrDb = 32.0;
// Hand-held path: the bounds stated in scene_synthesizer.hpp, + float slack.
const double kPathSlack = 1e-6;

// The building (makeBuilding() in src/scene_synthesizer.cpp): an axis-aligned box.
const Vec3d kBuildingMin(-0.8, 0.0, 1.5), kBuildingMax(2.2, 3.2, 3.5);

SceneSynthesizer::Params handheldParams()
{
    SceneSynthesizer::Params p;
    p.model = PERSPECTIVE;
    p.path = SceneSynthesizer::PATH_HANDHELD;
    p.distanceRatio = 1.5;
    p.orbitDegrees = 30;
    p.frames = 5;
    p.numKeyFrames = 2;
    p.imageSize = Size(320, 180);
    p.numTracks = 100;
    p.distortion = {-0.12, 0.02, 0.001, -0.0005, 0.0};
    p.seed = 3;
    return p;
}

bool rayHitsBox(const Ray& r, const Vec3d& lo, const Vec3d& hi)
{
    double t0 = 0, t1 = 1e30;
    for (int k = 0; k < 3; k++)
    {
        const double d = r.direction[k];
        if (std::abs(d) < 1e-15)
        {
            if (r.origin[k] < lo[k] || r.origin[k] > hi[k])
                return false;
            continue;
        }
        double a = (lo[k] - r.origin[k]) / d, b = (hi[k] - r.origin[k]) / d;
        if (a > b)
            std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    return t0 <= t1;
}

// Scene centre and size as the synthesizer derives them (scene_synthesizer.hpp: footprint
// diameter; the camera looks at the footprint's middle at 0.3 of the tallest height).
void sceneFrame(const std::vector<Mesh>& meshes, Vec3d& centre, double& size, double& top)
{
    Vec3f lo(1e9f, 1e9f, 1e9f), hi(-1e9f, -1e9f, -1e9f);
    for (const Mesh& m : meshes)
    {
        Vec3f a, b;
        m.bounds(a, b);
        for (int k = 0; k < 3; k++)
        {
            lo[k] = std::min(lo[k], a[k]);
            hi[k] = std::max(hi[k], b[k]);
        }
    }
    centre = Vec3d(0.5 * (lo[0] + hi[0]), 0.3 * hi[1], 0.5 * (lo[2] + hi[2]));
    size = std::sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) +
                     (double)(hi[2] - lo[2]) * (hi[2] - lo[2]));
    top = hi[1];
}

TEST(Augocc_SceneSynthesizer_Lens, accuracy_marker)
{
    const SceneSynthesizer::Params p = handheldParams();
    Ptr<SceneSynthesizer> s = SceneSynthesizer::create(p);
    const int f = 2;
    const Camera cam = s->getCamera(f);
    ASSERT_TRUE(cam.hasDistortion());
    EXPECT_EQ(cam.distortion, p.distortion);
    // Markers near the corners, where the lens moves pixels most (tens of pixels here).
    const Point2d targets[] = {Point2d(30, 25), Point2d(290, 25), Point2d(30, 155),
                               Point2d(290, 155), Point2d(160, 90)};
    Mat plain;
    s->renderWithVirtual(f, {}, plain, 4);
    double worst = 0;
    for (const Point2d& target : targets)
    {
        const Ray ray = cam.backproject(target);
        // 3 units away: in front of everything, the ground included (the camera is ~1.6 units
        // up, so the bottom corners' rays reach the ground ~5 units away).
        const double dist = 3.0;
        const Vec3d X = ray.at(dist / cv::norm(ray.direction));
        // A white, unlit cube ~4 px across.
        const float h = (float)(2.0 * dist / cam.K(0, 0));
        Mesh marker = Mesh::box(Vec3f(X) - Vec3f(h, h, h), Vec3f(X) + Vec3f(h, h, h));
        marker.material.ambient = Vec3f(1, 1, 1);
        marker.material.diffuse = Vec3f(0, 0, 0);
        Mat img;
        s->renderWithVirtual(f, {marker}, img, 4);
        // Coverage from the red channel: c = (img - plain) / (255 - plain).
        double sw = 0, sx = 0, sy = 0;
        for (int y = 0; y < img.rows; y++)
            for (int x = 0; x < img.cols; x++)
            {
                const double b = plain.at<Vec3b>(y, x)[2], a = img.at<Vec3b>(y, x)[2];
                if (a == b || b > 250)
                    continue;
                const double c = (a - b) / (255 - b);
                sw += c;
                sx += c * x;
                sy += c * y;
            }
        ASSERT_GT(sw, 4.0) << "marker at " << target << " not seen";
        const Point2d centroid(sx / sw, sy / sw), expected = cam.project(X);
        worst = std::max(worst, cv::norm(centroid - expected));
        EXPECT_LE(cv::norm(centroid - expected), kMaxMarkerErrPx)
            << "target " << target << " centroid " << centroid << " project " << expected
            << " (pinhole would put it at " << cam.pinhole().project(X) << ")";
    }
    RecordProperty("worst_marker_err_px", cv::format("%.4f", worst));
}

TEST(Augocc_SceneSynthesizer_Lens, accuracy_masks)
{
    const SceneSynthesizer::Params p = handheldParams();
    Ptr<SceneSynthesizer> s = SceneSynthesizer::create(p);
    SyntheticScene scene;
    s->synthesize(scene);
    for (int f : {0, p.frames - 1})
    {
        const Camera& cam = scene.groundTruth.camera(f);
        const Mat& whole = scene.wholeMasks.at("building").at(f);
        Mat exact(p.imageSize, CV_8U);
        for (int y = 0; y < exact.rows; y++)
            for (int x = 0; x < exact.cols; x++)
                exact.at<uchar>(y, x) = rayHitsBox(cam.backproject(Point2d(x, y)), kBuildingMin,
                                                   kBuildingMax) ? 255 : 0;
        Mat diff, band, inner, outer;
        cv::compare(whole, exact, diff, CMP_NE);
        cv::dilate(exact, outer, Mat(), Point(-1, -1), kMaskBandPx);
        cv::erode(exact, inner, Mat(), Point(-1, -1), kMaskBandPx);
        cv::compare(outer, inner, band, CMP_NE);
        Mat outside;
        cv::bitwise_and(diff, ~band, outside);
        EXPECT_EQ(cv::countNonZero(outside), 0) << "frame " << f;
        std::vector<std::vector<Point>> contours;
        cv::findContours(exact.clone(), contours, RETR_EXTERNAL, CHAIN_APPROX_NONE);
        ASSERT_FALSE(contours.empty());
        const double perimeter = cv::arcLength(contours[0], true);
        EXPECT_LE(cv::countNonZero(diff), kMaxMaskMismatchPerEdgePx * perimeter) << "frame " << f;
        RecordProperty(cv::format("mask_mismatch_per_edge_px_%d", f),
                       cv::format("%.4f", cv::countNonZero(diff) / perimeter));
        // Consistency: visible inside whole, labels name the visible masks, and the frame
        // shows the building where its visible mask says (not the sky's colour).
        const Mat& vis = scene.visibleMasks.at("building").at(f);
        EXPECT_EQ(cv::countNonZero(vis & ~whole), 0);
        Mat lab;
        cv::compare(scene.labels[f], 1, lab, CMP_EQ);
        EXPECT_EQ(cv::countNonZero(lab != vis), 0);
        Mat frame;
        s->renderFrame(f, frame);
        EXPECT_EQ(cv::norm(frame, scene.frames[f], NORM_INF), 0.0);
        EXPECT_TRUE(std::isfinite(scene.depth[f].at<float>(
            cvRound(cam.project(0.5 * (kBuildingMin + kBuildingMax)).y),
            cvRound(cam.project(0.5 * (kBuildingMin + kBuildingMax)).x))));
    }
    for (int f : scene.keyFrames)
        EXPECT_EQ(cv::countNonZero(scene.keyFrameMasks.at("building").at(f) !=
                                   scene.visibleMasks.at("building").at(f)), 0);
}

TEST(Augocc_SceneSynthesizer_Handheld, accuracy_path)
{
    SceneSynthesizer::Params p = handheldParams();
    p.frames = 90;
    typedef SceneSynthesizer S;
    Ptr<SceneSynthesizer> s = S::create(p);
    Vec3d centre;
    double size = 0, top = 0;
    sceneFrame(s->getObjectMeshes(), centre, size, top);
    const double D = p.distanceRatio * size, height = S::kHandheldHeightFraction * top;
    const double sway = S::kHandheldSwayUnits;
    double maxRoll = 0, maxWobble = 0, maxStepDeg = 0;
    Matx33d prevR;
    for (int f = 0; f < p.frames; f++)
    {
        const Camera c = s->getCamera(f);
        const Vec3d C = -(c.R.t() * c.t);
        const double horiz = std::hypot(C[0] - centre[0], C[2] - centre[2]);
        EXPECT_LE(std::abs(horiz - D), std::sqrt(2.0) * sway + kPathSlack) << "frame " << f;
        EXPECT_LE(std::abs(C[1] - height), sway + kPathSlack) << "frame " << f;
        EXPECT_GT(C[1], 1.0) << "a few metres above the ground";
        const Vec3d x(c.R(0, 0), c.R(0, 1), c.R(0, 2)), y(c.R(1, 0), c.R(1, 1), c.R(1, 2));
        const Vec3d z(c.R(2, 0), c.R(2, 1), c.R(2, 2));
        const Vec3d up(0, 1, 0);
        maxRoll = std::max(maxRoll, std::abs(std::atan2(x.dot(up), -y.dot(up))) * 180 / CV_PI);
        const double cosW = z.dot(cv::normalize(centre - C));
        maxWobble = std::max(maxWobble, std::acos(std::min(1.0, cosW)) * 180 / CV_PI);
        if (f > 0)
            maxStepDeg = std::max(maxStepDeg, rotationAngleDeg(c.R, prevR));
        prevR = c.R;
    }
    // Roll: the peak kHandheldRollDeg, plus the tilt pitch adds when combined with yaw (tiny).
    EXPECT_LE(maxRoll, S::kHandheldRollDeg + 0.1);
    // Present: the 0.6-cycle term (weight 0.55) peaks within any shot, the others (0.45) can
    // only partly cancel it; 0.3 of the peak is a loose floor for this seed.
    EXPECT_GE(maxRoll, 0.3 * S::kHandheldRollDeg) << "the hand rolls";
    // Aim: yaw and pitch each within kHandheldWobbleDeg -> the angle within sqrt(2) of it.
    EXPECT_LE(maxWobble, std::sqrt(2.0) * S::kHandheldWobbleDeg + 0.1);
    EXPECT_GE(maxWobble, 0.3 * S::kHandheldWobbleDeg) << "the aim wobbles";
    // Smooth: 30 degrees of walk over 89 steps plus the wobble's and roll's slopes
    // (3.2 cycles per shot at most): well under 1 degree per frame.
    EXPECT_LT(maxStepDeg, 1.0);
    // Deterministic from the seed; another seed, another hand.
    Ptr<SceneSynthesizer> again = S::create(p);
    p.seed = 4;
    Ptr<SceneSynthesizer> other = S::create(p);
    EXPECT_EQ(cv::norm(Mat(again->getCamera(40).R), Mat(s->getCamera(40).R), NORM_INF), 0.0);
    EXPECT_GT(rotationAngleDeg(other->getCamera(40).R, s->getCamera(40).R), 0.05);
}

TEST(Augocc_SceneSynthesizer_Exposure, accuracy)
{
    SceneSynthesizer::Params p = handheldParams();
    p.distortion.clear();
    Ptr<SceneSynthesizer> plain = SceneSynthesizer::create(p);
    p.exposureDrift = 0.15;
    p.whiteBalanceDrift = 0.05;
    Ptr<SceneSynthesizer> drift = SceneSynthesizer::create(p);
    Mat a0, b0, a1, b1;
    plain->renderFrame(0, a0);
    drift->renderFrame(0, b0);
    EXPECT_EQ(cv::norm(a0, b0, NORM_INF), 0.0) << "the ramp starts at gain 1";
    const int last = p.frames - 1;
    plain->renderFrame(last, a1);
    drift->renderFrame(last, b1);
    const Vec3d expected(1.15 * 0.95, 1.15, 1.15 * 1.05);
    const Vec3d gains = SceneSynthesizer::frameGains(p, last);
    for (int k = 0; k < 3; k++)
    {
        EXPECT_NEAR(gains[k], expected[k], 1e-12);
        double sa = 0, sb = 0;
        for (int y = 0; y < a1.rows; y++)
            for (int x = 0; x < a1.cols; x++)
            {
                const double v = a1.at<Vec3b>(y, x)[k];
                if (v * expected[k] >= 254.5)
                    continue;  // saturated
                sa += v;
                sb += b1.at<Vec3b>(y, x)[k];
            }
        EXPECT_NEAR(sb / sa, expected[k], kGainTol) << "channel " << k;
    }
    // Masks and geometry are not touched.
    Mat la, lb, img;
    plain->renderFrame(last, img, noArray(), la);
    drift->renderFrame(last, img, noArray(), lb);
    EXPECT_EQ(cv::norm(la, lb, NORM_INF), 0.0);
}

TEST(Augocc_SceneSynthesizer_Video, h264_bitrate_and_calibration)
{
    SceneSynthesizer::Params p = handheldParams();
    p.imageSize = Size(320, 240);
    p.frames = 10;
    p.videoBitrateMbps = 1.0;
    Ptr<SceneSynthesizer> s = SceneSynthesizer::create(p);
    SyntheticScene scene;
    s->synthesize(scene);
    const fs::path dir = fs::temp_directory_path() /
                         ("augocc_synth_h264_" + std::to_string(::getpid()));
    writeSyntheticScene(dir.string(), scene, p);
    VideoCapture cap((dir / "video.mp4").string(), CAP_FFMPEG);
    ASSERT_TRUE(cap.isOpened());
    int n = 0;
    double psnrSum = 0;
    Mat frame;
    while (cap.read(frame))
    {
        ASSERT_LT(n, p.frames);
        ASSERT_EQ(frame.size(), p.imageSize);
        psnrSum += cv::PSNR(frame, scene.frames[n]);
        n++;
    }
    EXPECT_EQ(n, p.frames);
    EXPECT_GE(psnrSum / std::max(1, n), kMinPsnrDb);
    RecordProperty("psnr_db", cv::format("%.2f", psnrSum / std::max(1, n)));

    FileStorage fsCal((dir / "calibration.yml").string(), FileStorage::READ);
    ASSERT_TRUE(fsCal.isOpened());
    Mat K, d;
    fsCal["camera_matrix"] >> K;
    fsCal["distortion_coefficients"] >> d;
    EXPECT_EQ((int)fsCal["image_width"], p.imageSize.width);
    EXPECT_EQ((int)fsCal["image_height"], p.imageSize.height);
    EXPECT_EQ(cv::norm(K, Mat(s->getCamera(0).K), NORM_INF), 0.0);
    ASSERT_EQ(d.total(), p.distortion.size());
    for (size_t i = 0; i < p.distortion.size(); i++)
        EXPECT_EQ(d.at<double>((int)i), p.distortion[i]);
    fs::remove_all(dir);
}

TEST(Augocc_SceneSynthesizer_Size, uhd)
{
    SceneSynthesizer::Params p;
    p.model = PERSPECTIVE;
    p.imageSize = Size(3840, 2160);
    p.frames = 2;
    p.numKeyFrames = 2;
    p.numTracks = 50;
    Ptr<SceneSynthesizer> s = SceneSynthesizer::create(p);
    SyntheticScene scene;
    s->synthesize(scene);
    ASSERT_EQ(scene.frames.size(), 2u);
    EXPECT_EQ(scene.frames[1].size(), p.imageSize);
    EXPECT_EQ(scene.wholeMasks.at("building").at(1).size(), p.imageSize);
    EXPECT_GT(cv::countNonZero(scene.wholeMasks.at("building").at(1)), 10000);
}

TEST(Augocc_SceneSynthesizer_Realism, bad_arg)
{
    const std::function<void(SceneSynthesizer::Params&)> bad[] = {
        [](SceneSynthesizer::Params& p) { p.imageSize = Size(3841, 2160); },
        [](SceneSynthesizer::Params& p) { p.imageSize = Size(3840, 2161); },
        [](SceneSynthesizer::Params& p) { p.model = SCALED_ORTHOGRAPHIC; },  // with a lens
        [](SceneSynthesizer::Params& p) { p.distortion = {0.1, 0.0, 0.0}; },
        [](SceneSynthesizer::Params& p) { p.distortion[0] = std::nan(""); },
        [](SceneSynthesizer::Params& p) { p.exposureDrift = 1.0; },
        [](SceneSynthesizer::Params& p) { p.whiteBalanceDrift = -1.5; },
        [](SceneSynthesizer::Params& p) { p.videoBitrateMbps = -1; },
        [](SceneSynthesizer::Params& p) { p.videoBitrateMbps = 8; p.imageSize = Size(321, 180); },
        [](SceneSynthesizer::Params& p) { p.path = (SceneSynthesizer::CameraPath)7; }};
    for (const auto& change : bad)
    {
        SceneSynthesizer::Params p = handheldParams();
        change(p);
        EXPECT_THROW(SceneSynthesizer::create(p), cv::Exception);
    }
    SceneSynthesizer::Params ortho = handheldParams();
    ortho.distortion.clear();
    ortho.model = SCALED_ORTHOGRAPHIC;
    EXPECT_THROW(SceneSynthesizer::create(ortho), cv::Exception) << "hand-held needs perspective";
    try
    {
        SceneSynthesizer::Params p = handheldParams();
        p.imageSize = Size(3841, 2160);
        SceneSynthesizer::create(p);
    }
    catch (const cv::Exception& e)
    {
        EXPECT_NE(e.err.find("imageSize"), std::string::npos) << e.err;
        EXPECT_NE(e.err.find("3841x2160"), std::string::npos) << e.err;
    }
}

} // namespace
} // namespace opencv_test
