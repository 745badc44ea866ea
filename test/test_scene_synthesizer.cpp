// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "stats.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/video/tracking.hpp>
#include <opencv2/videoio.hpp>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// GT points against their noise-free tracks: the bound. The tracks are CV_32F, whose
// rounding at 640 px is ~3e-5 px, so anything near the bound would be a real inconsistency.
const double kMaxGtReprojPx = 0.05;
// Measured track noise against the configured sigma: the issue's +-10%.
const double kNoiseRmsRelTol = 0.10;
// Silhouettes against the exact projection of the geometry (pixel centres inside projected
// triangles): differences may only lie in the 1-pixel band on either side of the boundary ...
const int kSilhouetteBandPx = 1;
// ... and only a few of them at all: centres exactly on an edge (ties broken differently).
const int kMaxSilhouetteTiePx = 10;
// Rendered depth against analytic depth (world units; the scene is ~10 units across, ~100 away):
// the 24-bit depth buffer resolves (far - near) / 2^24 < 2e-5 units (orthographic) and
// z^2 (far - near) / (far near 2^24) < 5e-5 units (perspective) here, and z is stored as float32
// (~1e-5 at z = 200); 1e-3 leaves a 20x margin.
const double kDepthTol = 1e-3;
// Textures rich enough for KLT: Shi-Tomasi corners of frame 0 tracked by pyramidal Lucas-Kanade
// into the next frame of the default orbit (0.85 degree apart) land within this median distance
// of the true flow (from depth and the GT cameras). Measured 0.08 px (translation-only LK under
// the small affine change of view and texture resampling); 0.15 px is about twice that.
const double kMaxKltMedianErrPx = 0.15;
const int kMinKltCorners = 300;  // of 500 requested, away from object outlines
// Partial tracks cover at least 20% of the sequence (Params doc).
const double kPartialMinFraction = 0.2;

// The building of the scene (see makeBuilding() in src/scene_synthesizer.cpp): an axis-aligned
// box, used for the analytic ray-box depth.
const Vec3d kBuildingMin(-0.8, 0.0, 1.5), kBuildingMax(2.2, 3.2, 3.5);

SceneSynthesizer::Params smallParams(CameraModel model)
{
    SceneSynthesizer::Params p;
    p.model = model;
    p.frames = 12;
    p.imageSize = Size(320, 240);
    p.numTracks = 400;
    p.noiseSigma = 0.5;
    p.partialFraction = 0.3;
    p.outlierFraction = 0.1;
    p.numKeyFrames = 4;
    p.seed = 7;
    return p;
}

// One synthesized scene per camera model, shared by the accuracy tests (synthesis is the slow
// part; every check reads it only).
const SyntheticScene& sharedScene(CameraModel model)
{
    static std::map<int, std::shared_ptr<SyntheticScene>> cache;
    auto it = cache.find((int)model);
    if (it != cache.end())
        return *it->second;
    auto scene = std::make_shared<SyntheticScene>();
    SceneSynthesizer::create(smallParams(model))->synthesize(*scene);
    cache[(int)model] = scene;
    return *scene;
}

bool isFinitePt(const Point2f& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y);
}

bool rayBox(const Ray& r, const Vec3d& lo, const Vec3d& hi, double& tEntry)
{
    double t0 = -1e300, t1 = 1e300;
    for (int k = 0; k < 3; k++)
    {
        if (std::abs(r.direction[k]) < 1e-15)
        {
            if (r.origin[k] < lo[k] || r.origin[k] > hi[k])
                return false;
            continue;
        }
        double a = (lo[k] - r.origin[k]) / r.direction[k];
        double b = (hi[k] - r.origin[k]) / r.direction[k];
        if (a > b)
            std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    if (t0 > t1)
        return false;
    tEntry = t0;
    return true;
}

// Rasterizes the projection of every triangle of a mesh exactly: a pixel is inside when its
// centre is inside (or on the edge of) a projected triangle. OpenGL samples pixel centres too,
// so the two can differ only where a centre lies on an edge (OpenGL's tie-breaking rule) or
// within float rounding of it.
Mat projectMesh(const Camera& cam, const Mesh& mesh, Size size)
{
    Mat mask = Mat::zeros(size, CV_8U);
    std::vector<Point2d> px(mesh.vertices.size());
    for (size_t i = 0; i < px.size(); i++)
        px[i] = cam.project(Vec3d(mesh.vertices[i]));
    for (const Vec3i& f : mesh.faces)
    {
        const Point2d a = px[f[0]], b = px[f[1]], c = px[f[2]];
        const double area = (b - a).cross(c - a);
        if (area == 0)
            continue;
        const int x0 = std::max(0, (int)std::floor(std::min({a.x, b.x, c.x})));
        const int x1 = std::min(size.width - 1, (int)std::ceil(std::max({a.x, b.x, c.x})));
        const int y0 = std::max(0, (int)std::floor(std::min({a.y, b.y, c.y})));
        const int y1 = std::min(size.height - 1, (int)std::ceil(std::max({a.y, b.y, c.y})));
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++)
            {
                const Point2d p(x, y);
                const double e0 = (b - a).cross(p - a), e1 = (c - b).cross(p - b),
                             e2 = (a - c).cross(p - c);
                const bool in = area > 0 ? (e0 >= 0 && e1 >= 0 && e2 >= 0)
                                         : (e0 <= 0 && e1 <= 0 && e2 <= 0);
                if (in)
                    mask.at<uchar>(y, x) = 255;
            }
    }
    return mask;
}

class Augocc_SceneSynthesizer_P : public testing::TestWithParam<int> {};

TEST_P(Augocc_SceneSynthesizer_P, ground_truth_tracks)
{
    const CameraModel model = (CameraModel)GetParam();
    const SceneSynthesizer::Params p = smallParams(model);
    const SyntheticScene& s = sharedScene(model);
    ASSERT_EQ((int)s.frames.size(), p.frames);
    ASSERT_NO_THROW(s.groundTruth.validate("synthesized"));
    ASSERT_NO_THROW(s.tracks.validate("tracks"));
    ASSERT_NO_THROW(s.cleanTracks.validate("cleanTracks"));
    EXPECT_EQ(s.groundTruth.model, model);
    EXPECT_EQ(s.tracks.frames(), p.frames);
    EXPECT_EQ(s.tracks.points(), p.numTracks);
    ASSERT_EQ((int)s.outlierTrack.size(), p.numTracks);
    ASSERT_EQ(s.groundTruth.points.rows, p.numTracks);

    double maxGt = 0, sumSq = 0;
    long count = 0;
    int outliers = 0, partial = 0;
    for (int t = 0; t < p.numTracks; t++)
    {
        const bool out = s.outlierTrack[t] != 0;
        outliers += out;
        const Vec3d X(s.groundTruth.points.ptr<double>(t));
        EXPECT_EQ(out, !s.groundTruth.hasPoint(t)) << "track " << t;
        int first = -1, last = -1, observed = 0;
        for (int f = 0; f < p.frames; f++)
        {
            const Point2f c = s.cleanTracks.at(f, t), m = s.tracks.at(f, t);
            ASSERT_EQ(isFinitePt(c), isFinitePt(m)) << "same NaN pattern, frame " << f;
            if (!isFinitePt(c))
                continue;
            if (first < 0)
                first = f;
            last = f;
            observed++;
            if (out)
                continue;
            const Point2d px = s.groundTruth.project(f, X);
            maxGt = std::max(maxGt, cv::norm(px - Point2d(c)));
            sumSq += (m.x - px.x) * (m.x - px.x) + (m.y - px.y) * (m.y - px.y);
            count += 2;
        }
        ASSERT_GT(observed, 0);
        EXPECT_EQ(observed, last - first + 1) << "contiguous observations, track " << t;
        if (observed < p.frames)
        {
            partial++;
            EXPECT_GE(observed, kPartialMinFraction * p.frames) << "track " << t;
        }
    }
    EXPECT_LE(maxGt, kMaxGtReprojPx);
    const double rms = std::sqrt(sumSq / count);
    std::cout << "[ MEASURE  ] " << cameraModelName(model) << ": GT points vs clean tracks max "
              << maxGt << " px; track noise RMS " << rms << " px (sigma " << p.noiseSigma
              << ")" << std::endl;
    EXPECT_NEAR(rms, p.noiseSigma, kNoiseRmsRelTol * p.noiseSigma);
    EXPECT_EQ(outliers, cvRound(p.outlierFraction * p.numTracks));
    EXPECT_EQ(partial, cvRound(p.partialFraction * p.numTracks));
}

TEST_P(Augocc_SceneSynthesizer_P, silhouettes_match_geometry)
{
    const CameraModel model = (CameraModel)GetParam();
    const SceneSynthesizer::Params p = smallParams(model);
    const SyntheticScene& s = sharedScene(model);
    ASSERT_EQ(s.objectNames.size(), (size_t)3);
    ASSERT_EQ(s.objectMeshes.size(), s.objectNames.size());
    const Mat band = getStructuringElement(MORPH_RECT, Size(2 * kSilhouetteBandPx + 1,
                                                            2 * kSilhouetteBandPx + 1));
    bool someOcclusion = false;
    int worstMismatch = 0;
    for (int f = 0; f < p.frames; f += 3)
    {
        const Camera& cam = s.groundTruth.camera(f);
        for (size_t i = 0; i < s.objectNames.size(); i++)
        {
            const String& name = s.objectNames[i];
            const Mat whole = s.wholeMasks.at(name).at(f);
            const Mat visible = s.visibleMasks.at(name).at(f);
            ASSERT_EQ(whole.size(), p.imageSize);
            ASSERT_EQ(whole.type(), CV_8UC1);
            const Mat expected = projectMesh(cam, s.objectMeshes[i], p.imageSize);
            Mat dil, ero, edge, diff, outside;
            cv::dilate(expected, dil, band);
            cv::erode(expected, ero, band);
            cv::absdiff(dil, ero, edge);
            cv::absdiff(whole, expected, diff);
            diff.setTo(0, edge);
            EXPECT_EQ(cv::countNonZero(diff), 0) << name << " frame " << f;
            const int mismatch = cv::countNonZero(whole != expected);
            worstMismatch = std::max(worstMismatch, mismatch);
            EXPECT_LE(mismatch, kMaxSilhouetteTiePx) << name << " frame " << f;
            // The visible part lies inside the whole silhouette and equals the labels.
            cv::bitwise_and(visible, ~whole, outside);
            EXPECT_EQ(cv::countNonZero(outside), 0);
            Mat lab;
            cv::compare(s.labels[f], Scalar((double)(i + 1)), lab, CMP_EQ);
            EXPECT_EQ(cv::norm(lab, visible, NORM_INF), 0);
            if (cv::countNonZero(whole) > cv::countNonZero(visible) + 50)
                someOcclusion = true;
            EXPECT_GT(cv::countNonZero(visible), 0) << "every object is seen in every frame";
        }
    }
    std::cout << "[ MEASURE  ] " << cameraModelName(model) << ": silhouette vs projected "
              << "geometry, worst " << worstMismatch << " differing pixels" << std::endl;
    EXPECT_TRUE(someOcclusion) << "objects must hide each other in some frames";
    // Key frames: evenly spaced, first and last, visible masks.
    ASSERT_EQ((int)s.keyFrames.size(), p.numKeyFrames);
    EXPECT_EQ(s.keyFrames.front(), 0);
    EXPECT_EQ(s.keyFrames.back(), p.frames - 1);
    for (const String& name : s.objectNames)
    {
        ASSERT_EQ(s.keyFrameMasks.at(name).size(), s.keyFrames.size());
        for (int k : s.keyFrames)
            EXPECT_EQ(cv::norm(s.keyFrameMasks.at(name).at(k), s.visibleMasks.at(name).at(k),
                               NORM_INF), 0);
    }
}

TEST_P(Augocc_SceneSynthesizer_P, depth_matches_geometry)
{
    const CameraModel model = (CameraModel)GetParam();
    const SceneSynthesizer::Params p = smallParams(model);
    const SyntheticScene& s = sharedScene(model);
    int building = -1;
    for (size_t i = 0; i < s.objectNames.size(); i++)
        if (s.objectNames[i] == "building")
            building = (int)i;
    ASSERT_GE(building, 0);
    for (int f : {0, p.frames - 1})
    {
        const Camera& cam = s.groundTruth.camera(f);
        const Mat& depth = s.depth[f];
        ASSERT_EQ(depth.type(), CV_32FC1);
        Mat inner;  // building pixels away from its outline
        cv::erode(s.visibleMasks.at("building").at(f), inner, Mat::ones(3, 3, CV_8U));
        Mat groundInner;
        cv::compare(s.labels[f], 0, groundInner, CMP_EQ);
        cv::erode(groundInner, groundInner, Mat::ones(3, 3, CV_8U));
        double maxGround = 0, maxBox = 0;
        int nGround = 0, nBox = 0;
        for (int v = 0; v < depth.rows; v++)
            for (int u = 0; u < depth.cols; u++)
            {
                const Ray ray = cam.backproject(Point2d(u, v));
                const float z = depth.at<float>(v, u);
                if (groundInner.at<uchar>(v, u))
                {
                    ASSERT_LT(ray.direction[1], 0);
                    const Vec3d X = ray.at(-ray.origin[1] / ray.direction[1]);
                    maxGround = std::max(maxGround, std::abs(cam.depth(X) - z));
                    nGround++;
                }
                else if (inner.at<uchar>(v, u))
                {
                    double t = 0;
                    ASSERT_TRUE(rayBox(ray, kBuildingMin, kBuildingMax, t)) << u << "," << v;
                    maxBox = std::max(maxBox, std::abs(cam.depth(ray.at(t)) - z));
                    nBox++;
                }
            }
        EXPECT_GT(nGround, depth.total() / 4);
        EXPECT_GT(nBox, 500);
        std::cout << "[ MEASURE  ] " << cameraModelName(model) << " frame " << f
                  << ": depth error max ground " << maxGround << ", building " << maxBox
                  << " units" << std::endl;
        EXPECT_LE(maxGround, kDepthTol) << "frame " << f;
        EXPECT_LE(maxBox, kDepthTol) << "frame " << f;
    }
}

TEST_P(Augocc_SceneSynthesizer_P, textures_trackable)
{
    const CameraModel model = (CameraModel)GetParam();
    // Consecutive frames of the default 60-frame orbit: 50 / 59 degrees apart.
    SceneSynthesizer::Params p = smallParams(model);
    p.frames = 2;
    p.numKeyFrames = 2;
    p.orbitDegrees = 50.0 / 59;
    SyntheticScene s;
    SceneSynthesizer::create(p)->synthesize(s);
    const Camera& c0 = s.groundTruth.camera(0);
    const Camera& c1 = s.groundTruth.camera(1);
    Mat g0, g1;
    cv::cvtColor(s.frames[0], g0, COLOR_BGR2GRAY);
    cv::cvtColor(s.frames[1], g1, COLOR_BGR2GRAY);
    // Corners away from label boundaries (occlusion edges move differently from either side).
    Mat edges, keep;
    cv::morphologyEx(s.labels[0], edges, MORPH_GRADIENT, Mat::ones(3, 3, CV_8U));
    cv::compare(edges, 0, keep, CMP_EQ);
    cv::erode(keep, keep, Mat::ones(9, 9, CV_8U));
    std::vector<Point2f> p0, p1;
    cv::goodFeaturesToTrack(g0, p0, 500, 0.01, 5, keep);
    ASSERT_GE((int)p0.size(), kMinKltCorners) << "too few corners: textures too poor";
    std::vector<uchar> status;
    std::vector<float> err;
    cv::calcOpticalFlowPyrLK(g0, g1, p0, p1, status, err, Size(21, 21), 3);
    std::vector<double> errors;
    for (size_t i = 0; i < p0.size(); i++)
    {
        if (!status[i])
            continue;
        // The corner's 3D point from the depth interpolated at its sub-pixel position (depth is
        // planar per face, and the corners are away from edges).
        Mat z;
        cv::getRectSubPix(s.depth[0], Size(1, 1), p0[i], z);
        const Vec3d X = c0.unproject(Point2d(p0[i]), z.at<float>(0, 0));
        const Point2d expected = c1.project(X) + (Point2d(p0[i]) - c0.project(X));
        errors.push_back(cv::norm(Point2d(p1[i]) - expected));
    }
    ASSERT_GE((int)errors.size(), kMinKltCorners);
    const double median = augocc::detail::median(errors);
    std::cout << "[ MEASURE  ] " << cameraModelName(model) << ": " << p0.size()
              << " corners, KLT frame 0 -> 1 median error " << median << " px" << std::endl;
    EXPECT_LE(median, kMaxKltMedianErrPx);
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_SceneSynthesizer_P,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

TEST(Augocc_SceneSynthesizer, can_create_default)
{
    Ptr<SceneSynthesizer> s = SceneSynthesizer::create();
    ASSERT_FALSE(s.empty());
    const SceneSynthesizer::Params p = s->getParams();
    EXPECT_EQ(p.frames, 60);
    EXPECT_EQ(p.imageSize, Size(640, 480));
    EXPECT_EQ(p.model, SCALED_ORTHOGRAPHIC);
    EXPECT_EQ(p.distanceRatio, 10.0);
    EXPECT_EQ(p.orbitDegrees, 50.0);
    EXPECT_EQ(p.elevationDegrees, 25.0);
    EXPECT_EQ(p.numTracks, 600);
    EXPECT_EQ(p.noiseSigma, 0.5);
    EXPECT_EQ(p.partialFraction, 0.0);
    EXPECT_EQ(p.outlierFraction, 0.0);
    EXPECT_EQ(p.numKeyFrames, 6);
    EXPECT_EQ(p.seed, (uint64)1);
    EXPECT_EQ(p.frameSupersample, 1);
    const std::vector<String> names = s->getObjectNames();
    ASSERT_EQ(names.size(), (size_t)3);
    EXPECT_EQ(names[0], "building");
    // Framing: the objects' footprint fills about 60% of the frame in both models.
    for (CameraModel m : {SCALED_ORTHOGRAPHIC, PERSPECTIVE})
    {
        SceneSynthesizer::Params q = p;
        q.model = m;
        s->setParams(q);
        Mat image, labels;
        s->renderFrame(q.frames / 2, image, noArray(), labels);
        ASSERT_EQ(image.size(), q.imageSize);
        ASSERT_EQ(image.type(), CV_8UC3);
        const Rect box = cv::boundingRect(labels > 0);
        EXPECT_GT(box.width, 0.35 * q.imageSize.width) << cameraModelName(m);
        EXPECT_LT(box.width, 0.8 * q.imageSize.width) << cameraModelName(m);
    }
}

TEST(Augocc_SceneSynthesizer, bad_arg)
{
    const SceneSynthesizer::Params good;
    EXPECT_NO_THROW(SceneSynthesizer::create(good));
    std::vector<std::function<void(SceneSynthesizer::Params&)>> breakers = {
        [](SceneSynthesizer::Params& p) { p.frames = 1; },
        [](SceneSynthesizer::Params& p) { p.imageSize = Size(0, 480); },
        [](SceneSynthesizer::Params& p) { p.imageSize = Size(640, -1); },
        [](SceneSynthesizer::Params& p) { p.model = (CameraModel)7; },
        [](SceneSynthesizer::Params& p) { p.distanceRatio = 0.5; },
        [](SceneSynthesizer::Params& p) { p.distanceRatio = std::nan(""); },
        [](SceneSynthesizer::Params& p) { p.orbitDegrees = -1; },
        [](SceneSynthesizer::Params& p) { p.elevationDegrees = 90; },
        [](SceneSynthesizer::Params& p) { p.elevationDegrees = 0; },
        [](SceneSynthesizer::Params& p) { p.numTracks = 0; },
        [](SceneSynthesizer::Params& p) { p.noiseSigma = -0.1; },
        [](SceneSynthesizer::Params& p) { p.partialFraction = 1.5; },
        [](SceneSynthesizer::Params& p) { p.partialFraction = -0.1; },
        [](SceneSynthesizer::Params& p) { p.outlierFraction = 2; },
        [](SceneSynthesizer::Params& p) { p.outlierFraction = std::nan(""); },
        [](SceneSynthesizer::Params& p) { p.numKeyFrames = 1; },
        [](SceneSynthesizer::Params& p) { p.numKeyFrames = p.frames + 1; },
        [](SceneSynthesizer::Params& p) { p.frameSupersample = 0; },
        [](SceneSynthesizer::Params& p) { p.frameSupersample = 9; },
    };
    for (size_t i = 0; i < breakers.size(); i++)
    {
        SceneSynthesizer::Params bad = good;
        breakers[i](bad);
        EXPECT_THROW(SceneSynthesizer::create(bad), cv::Exception) << "case " << i;
        Ptr<SceneSynthesizer> s = SceneSynthesizer::create(good);
        EXPECT_THROW(s->setParams(bad), cv::Exception) << "case " << i;
        EXPECT_EQ(s->getParams().frames, good.frames) << "a rejected setParams changes nothing";
    }
    Ptr<SceneSynthesizer> s = SceneSynthesizer::create(smallParams(SCALED_ORTHOGRAPHIC));
    Mat img;
    EXPECT_THROW(s->renderFrame(-1, img), cv::Exception);
    EXPECT_THROW(s->renderFrame(12, img), cv::Exception);
    EXPECT_THROW(s->renderWithVirtual(0, {}, img, 0), cv::Exception);
    EXPECT_THROW(s->getCamera(100), cv::Exception);
    const std::string dir = tempDir("write") + "/scene";
    EXPECT_THROW(writeSyntheticScene(dir, SyntheticScene(), smallParams(PERSPECTIVE)),
                 cv::Exception);
    EXPECT_FALSE(std::filesystem::exists(dir));
}

TEST(Augocc_SceneSynthesizer, regression_deterministic)
{
    SceneSynthesizer::Params p = smallParams(PERSPECTIVE);
    p.frames = 4;
    p.numKeyFrames = 2;
    SyntheticScene a, b, c;
    SceneSynthesizer::create(p)->synthesize(a);
    SceneSynthesizer::create(p)->synthesize(b);
    p.seed = 8;
    SceneSynthesizer::create(p)->synthesize(c);
    for (size_t f = 0; f < a.frames.size(); f++)
    {
        EXPECT_EQ(cv::norm(a.frames[f], b.frames[f], NORM_INF), 0) << "frame " << f;
        EXPECT_EQ(cv::norm(a.depth[f], b.depth[f], NORM_INF), 0) << "frame " << f;
    }
    EXPECT_EQ(cv::norm(a.tracks.dense() != b.tracks.dense(), NORM_INF), 0)
        << "same tracks, NaN at the same places";
    EXPECT_GT(cv::norm(a.frames[0], c.frames[0], NORM_L1), 0) << "another seed, other textures";
}

// SceneSynthesizer::write (`augocc synth`) renders and writes frame by frame; its files must be
// those of synthesize() + writeSyntheticScene() but for the depth's scale, which it takes from
// the scene's bounds (an upper bound of the depths: a scale never larger).
TEST(Augocc_SceneSynthesizer, streamed_write_equals_in_memory)
{
    namespace fs = std::filesystem;
    SceneSynthesizer::Params p = smallParams(PERSPECTIVE);
    p.frames = 10;  // more than one write batch (8 frames)
    const std::string root = tempDir("streamed");
    const std::string memDir = root + "/memory", streamDir = root + "/streamed";
    SyntheticScene scene;
    Ptr<SceneSynthesizer> synth = SceneSynthesizer::create(p);
    synth->synthesize(scene);
    writeSyntheticScene(memDir, scene, p);
    synth->write(streamDir);

    const std::vector<std::string> files = filesUnder(memDir);
    EXPECT_EQ(filesUnder(streamDir), files) << "the same files";
    ASSERT_GT(files.size(), (size_t)(10 * (2 + 2 * 3 + 1)));
    const double scaleMem = (double)FileStorage(memDir + "/gt/depth/depth.yml",
                                                FileStorage::READ)["scale"];
    const double scaleStream = (double)FileStorage(streamDir + "/gt/depth/depth.yml",
                                                   FileStorage::READ)["scale"];
    EXPECT_LE(scaleStream, scaleMem) << "the bound is at least the largest depth";
    int compared = 0;
    for (const std::string& rel : files)
    {
        const std::string a = memDir + "/" + rel, b = streamDir + "/" + rel;
        ASSERT_TRUE(fs::exists(b)) << rel;
        const std::string ext = fs::path(rel).extension().string();
        if (rel.rfind("gt/depth/", 0) == 0 && ext == ".png")
        {
            // Same zeros; z within the coarser step (values are rounded to 1 / scale).
            Mat za, zb;
            imread(a, IMREAD_UNCHANGED).convertTo(za, CV_64F, 1 / scaleMem);
            imread(b, IMREAD_UNCHANGED).convertTo(zb, CV_64F, 1 / scaleStream);
            EXPECT_EQ(cv::norm((za == 0) != (zb == 0), NORM_INF), 0) << rel;
            EXPECT_LE(cv::norm(za, zb, NORM_INF), 0.5 / scaleStream + 0.5 / scaleMem + 1e-9)
                << rel;
            compared++;
        }
        else if (ext == ".png")
        {
            const Mat ia = imread(a, IMREAD_UNCHANGED), ib = imread(b, IMREAD_UNCHANGED);
            ASSERT_FALSE(ia.empty()) << rel;
            ASSERT_EQ(ia.size(), ib.size()) << rel;
            EXPECT_EQ(cv::norm(ia, ib, NORM_INF), 0) << rel;
            compared++;
        }
        else if (ext == ".yml" && rel != "gt/depth/depth.yml")
        {
            EXPECT_EQ(fileText(a), fileText(b)) << rel;
            compared++;
        }
    }
    EXPECT_GT(compared, 10 * 9) << "frames, labels, depth and masks of every frame";
    VideoCapture va(memDir + "/video.mp4"), vb(streamDir + "/video.mp4");
    EXPECT_EQ(va.get(CAP_PROP_FRAME_COUNT), vb.get(CAP_PROP_FRAME_COUNT));
    fs::remove_all(root);
}

TEST(Augocc_SceneSynthesizer, multithread_reproducibility)
{
    SceneSynthesizer::Params p = smallParams(SCALED_ORTHOGRAPHIC);
    p.frames = 4;
    p.numKeyFrames = 2;
    SyntheticScene a, b;
    ASSERT_GT(cv::getNumThreads(), 1) << "needs the default (multi-threaded) setting";
    SceneSynthesizer::create(p)->synthesize(a);
    cv::setNumThreads(1);
    SceneSynthesizer::create(p)->synthesize(b);
    for (size_t f = 0; f < a.frames.size(); f++)
    {
        EXPECT_EQ(cv::norm(a.frames[f], b.frames[f], NORM_INF), 0);
        EXPECT_EQ(cv::norm(a.labels[f], b.labels[f], NORM_INF), 0);
        for (const String& name : a.objectNames)
            EXPECT_EQ(cv::norm(a.visibleMasks[name][(int)f], b.visibleMasks[name][(int)f],
                               NORM_INF), 0);
    }
    EXPECT_EQ(cv::norm(a.tracks.dense() != b.tracks.dense(), NORM_INF), 0);
}

TEST(Augocc_SceneSynthesizer, render_frame_and_virtual)
{
    const SceneSynthesizer::Params p = smallParams(SCALED_ORTHOGRAPHIC);
    const SyntheticScene& s = sharedScene(SCALED_ORTHOGRAPHIC);
    Ptr<SceneSynthesizer> synth = SceneSynthesizer::create(p);
    const int f = 5;
    Mat image, depth, labels;
    std::vector<Mat> whole;
    synth->renderFrame(f, image, depth, labels, whole);
    EXPECT_EQ(cv::norm(image, s.frames[f], NORM_INF), 0);
    EXPECT_EQ(cv::norm(labels, s.labels[f], NORM_INF), 0);
    ASSERT_EQ(whole.size(), s.objectNames.size());
    for (size_t i = 0; i < whole.size(); i++)
        EXPECT_EQ(cv::norm(whole[i], s.wholeMasks.at(s.objectNames[i]).at(f), NORM_INF), 0);
    const Camera cam = synth->getCamera(f);
    EXPECT_LT(cv::norm(cam.projectionMatrix() - s.groundTruth.camera(f).projectionMatrix(),
                       NORM_INF), 1e-12);

    // No virtual object: the frame itself.
    Mat plain;
    synth->renderWithVirtual(f, {}, plain, 1);
    EXPECT_EQ(cv::norm(plain, s.frames[f], NORM_INF), 0);

    // A red box just behind the building, wider and taller: hidden wherever the building is
    // seen, drawn elsewhere.
    Mesh box = Mesh::box(Vec3f(-1.5f, 0.f, 0.2f), Vec3f(3.0f, 4.0f, 1.2f));
    box.material.diffuse = Vec3f(1, 0, 0);
    box.material.ambient = Vec3f(0.3f, 0, 0);
    Mat withBox;
    synth->renderWithVirtual(f, {box}, withBox, 1);
    Mat changed;
    cv::absdiff(withBox, s.frames[f], changed);
    cv::cvtColor(changed, changed, COLOR_BGR2GRAY);
    cv::compare(changed, 0, changed, CMP_GT);
    const Mat boxAlone = projectMesh(cam, box, p.imageSize);
    Mat bad;
    cv::bitwise_and(changed, s.visibleMasks.at("building").at(f), bad);
    EXPECT_EQ(cv::countNonZero(bad), 0) << "the building hides the box";
    Mat farFromBox;
    cv::erode(~boxAlone, farFromBox, Mat::ones(3, 3, CV_8U));
    cv::bitwise_and(changed, farFromBox, bad);
    EXPECT_EQ(cv::countNonZero(bad), 0) << "only the box's pixels change";
    EXPECT_GT(cv::countNonZero(changed), 100) << "the box shows beside the building";

    // Supersampled: the same picture with softer edges.
    Mat ss;
    synth->renderWithVirtual(f, {box}, ss, 3);
    ASSERT_EQ(ss.size(), p.imageSize);
    Mat d;
    cv::absdiff(ss, withBox, d);
    EXPECT_LT(cv::mean(d)[0] + cv::mean(d)[1] + cv::mean(d)[2], 3 * 12.0)
        << "mean colour difference from the aliased render (textures are averaged too)";
}

TEST(Augocc_SceneSynthesizer, anti_aliased_frames)
{
    SceneSynthesizer::Params p = smallParams(PERSPECTIVE);
    p.frames = 3;
    p.numKeyFrames = 2;
    SyntheticScene aliased, smooth;
    SceneSynthesizer::create(p)->synthesize(aliased);
    p.frameSupersample = 3;
    Ptr<SceneSynthesizer> synth = SceneSynthesizer::create(p);
    synth->synthesize(smooth);
    for (int f = 0; f < p.frames; f++)
    {
        // Ground truth sampled at pixel centres whatever the frames' supersampling.
        EXPECT_EQ(cv::norm(aliased.labels[f], smooth.labels[f], NORM_INF), 0);
        EXPECT_EQ(cv::norm(aliased.depth[f], smooth.depth[f], NORM_INF), 0);
        // The same picture, edges and textures averaged over the pixel: close on average, and
        // not identical.
        const double meanDiff = cv::norm(aliased.frames[f], smooth.frames[f], NORM_L1) /
                                (double)aliased.frames[f].total() / 3;
        EXPECT_GT(meanDiff, 0.1);
        EXPECT_LT(meanDiff, 10.0);
    }
    Mat img;
    synth->renderWithVirtual(1, {}, img, 3);
    EXPECT_EQ(cv::norm(img, smooth.frames[1], NORM_INF), 0);
    synth->renderFrame(2, img);
    EXPECT_EQ(cv::norm(img, smooth.frames[2], NORM_INF), 0);
}

TEST(Augocc_SceneSynthesizer, synth_command_end_to_end)
{
    const std::string dir = tempDir("synth") + "/out";
    const double noise = 0.7;
    std::string out;
    const std::string cmd = augoccBinary() + " --quiet synth --out " + dir +
                            " --frames 10 --size 320x240 --seed 3 --noise 0.7 --partial 0.2"
                            " --outliers 0.05 --model perspective --contact-sheet " + dir +
                            "_sheet.png";
    ASSERT_EQ(runCommand(cmd, &out), 0) << out;
    namespace fs = std::filesystem;
    for (int f = 0; f < 10; f++)
        EXPECT_TRUE(fs::exists(dir + format("/frames/%04d.png", f)));
    EXPECT_TRUE(fs::exists(dir + "/video.mp4"));
    EXPECT_TRUE(fs::exists(dir + "_sheet.png"));
    const Tracks tracks = readTracks(dir + "/tracks.yml");
    const Reconstruction rec = readReconstruction(dir + "/gt/reconstruction.yml");
    EXPECT_EQ(rec.model, PERSPECTIVE);
    EXPECT_EQ((int)rec.cameras.size(), 10);
    ASSERT_EQ(tracks.points(), rec.points.rows);
    double sumSq = 0;
    long n = 0;
    for (int t = 0; t < tracks.points(); t++)
    {
        if (!rec.hasPoint(t))
            continue;  // outlier track
        const Vec3d X = rec.point(t);
        for (int f = 0; f < tracks.frames(); f++)
            if (tracks.observed(f, t))
            {
                const Point2d d = rec.project(f, X) - Point2d(tracks.at(f, t));
                sumSq += d.x * d.x + d.y * d.y;
                n += 2;
            }
    }
    ASSERT_GT(n, 1000);
    EXPECT_NEAR(std::sqrt(sumSq / n), noise, kNoiseRmsRelTol * noise);
    const ObjectMasks keyMasks = readMasks(dir + "/input/masks", Size(320, 240));
    ASSERT_EQ(keyMasks.size(), (size_t)3);
    EXPECT_EQ(keyMasks.at("tower").size(), (size_t)6);
    EXPECT_TRUE(keyMasks.at("tower").count(0) && keyMasks.at("tower").count(9));
    const ObjectMasks whole = readMasks(dir + "/gt/masks", Size(320, 240));
    EXPECT_EQ(whole.at("building").size(), (size_t)10);
    const ObjectMasks visible = readMasks(dir + "/gt/visible_masks", Size(320, 240));
    EXPECT_EQ(visible.at("lblock").size(), (size_t)10);
    const Mat depth = imread(dir + "/gt/depth/0000.png", IMREAD_UNCHANGED);
    EXPECT_EQ(depth.type(), CV_16UC1);
    FileStorage depthInfo(dir + "/gt/depth/depth.yml", FileStorage::READ);
    ASSERT_TRUE(depthInfo.isOpened());
    const double scale = (double)depthInfo["scale"];
    EXPECT_GT(scale, 0);
    // The depth at the image centre is near the camera distance (10 x scene size ~ 100 units).
    const double zc = depth.at<ushort>(120, 160) / scale;
    EXPECT_NEAR(zc, rec.camera(0).depth(Vec3d(0, 0, 0)), 30.0);

    // Bad input: exit 2, and no output folder left behind.
    const std::string bad = tempDir("synth_bad") + "/out";
    EXPECT_EQ(runCommand(augoccBinary() + " synth --out " + bad + " --frames 1", &out), 2) << out;
    EXPECT_FALSE(fs::exists(bad));
    EXPECT_EQ(runCommand(augoccBinary() + " synth --out " + bad + " --size 10", &out), 2) << out;
    EXPECT_EQ(runCommand(augoccBinary() + " synth --out " + bad + " --model fisheye", &out), 2);
    EXPECT_FALSE(fs::exists(bad));
    fs::remove_all(fs::path(dir).parent_path());
}

} // namespace
} // namespace opencv_test
