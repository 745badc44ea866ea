// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include <opencv2/calib3d.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// ---------------------------------------------------------------------------------------------
// Analytic scenes: objects made of axis-aligned boxes (y up), silhouettes sampled exactly at
// pixel centres from the convex hull of each box's projected corners.

struct AnalyticObject
{
    String name;
    std::vector<std::pair<Vec3d, Vec3d> > boxes;
};

struct AnalyticScene
{
    Reconstruction rec;
    std::vector<AnalyticObject> objects;
    ObjectMasks whole;       // every frame
    ObjectMasks visible;     // every frame (objects listed front to back)
    ObjectMasks keyMasks;    // visible silhouettes in the key frames
    std::vector<int> keyFrames;
};

Camera orbitCamera(CameraModel model, double azimuthDeg, double elevationDeg, double dist,
                   const Vec3d& target, Size size, double pixelsPerUnit, int frame)
{
    const double a = azimuthDeg * CV_PI / 180, e = elevationDeg * CV_PI / 180;
    const Vec3d C = target + Vec3d(dist * std::cos(e) * std::sin(a), dist * std::sin(e),
                                   dist * std::cos(e) * std::cos(a));
    Vec3d f = target - C;
    f /= cv::norm(f);
    Vec3d x = f.cross(Vec3d(0, 1, 0));
    x /= cv::norm(x);
    const Vec3d y = f.cross(x);
    const Matx33d R(x[0], x[1], x[2], y[0], y[1], y[2], f[0], f[1], f[2]);
    const Vec3d t = -(R * C);
    const Point2d pp(size.width / 2.0 - 0.5, size.height / 2.0 - 0.5);
    if (model == SCALED_ORTHOGRAPHIC)
        return Camera::orthographic(R, t, pixelsPerUnit, pp, frame);
    const double fpx = pixelsPerUnit * dist;
    return Camera::perspective(R, t, Matx33d(fpx, 0, pp.x, 0, fpx, pp.y, 0, 0, 1), frame);
}

Mat silhouetteOf(const AnalyticObject& o, const Camera& cam, Size size)
{
    Mat m(size, CV_8U, Scalar(0));
    for (const auto& b : o.boxes)
    {
        std::vector<Point2f> c, hull;
        for (int q = 0; q < 8; q++)
        {
            const Vec3d X(q & 1 ? b.second[0] : b.first[0], q & 2 ? b.second[1] : b.first[1],
                          q & 4 ? b.second[2] : b.first[2]);
            const Point2d uv = cam.project(X);
            c.push_back(Point2f((float)uv.x, (float)uv.y));
        }
        convexHull(c, hull);
        const Rect r = boundingRect(hull) & Rect(Point(0, 0), size);
        for (int y = r.y; y < r.y + r.height; y++)
            for (int x = r.x; x < r.x + r.width; x++)
                if (pointPolygonTest(hull, Point2f((float)x, (float)y), false) >= 0)
                    m.at<uchar>(y, x) = 255;
    }
    return m;
}

AnalyticScene makeScene(CameraModel model, const std::vector<AnalyticObject>& objects, int frames,
                        int numKeys, double orbitDeg = 50, Size size = Size(640, 480))
{
    AnalyticScene s;
    s.objects = objects;
    s.rec.model = model;
    s.rec.imageSize = size;
    const Vec3d target(1.5, 1.0, 0.0);
    for (int f = 0; f < frames; f++)
    {
        const double az = -orbitDeg / 2 + orbitDeg * f / (frames - 1);
        s.rec.cameras.push_back(orbitCamera(model, az, 25, 40, target, size, 45, f));
    }
    for (int k = 0; k < numKeys; k++)
        s.keyFrames.push_back(cvRound((double)k * (frames - 1) / (numKeys - 1)));
    RNG rng(11);
    std::vector<Vec3d> pts;
    for (int f = 0; f < frames; f++)
    {
        Mat covered(size, CV_8U, Scalar(0));
        for (const AnalyticObject& o : objects)
        {
            const Mat w = silhouetteOf(o, s.rec.cameras[f], size);
            s.whole[o.name][f] = w;
            s.visible[o.name][f] = w & ~covered;
            covered |= w;
        }
    }
    for (int k : s.keyFrames)
        for (const AnalyticObject& o : objects)
            s.keyMasks[o.name][k] = s.visible[o.name][k];
    // Points on the objects' faces, plus ground points.
    for (const AnalyticObject& o : objects)
        for (const auto& b : o.boxes)
            for (int q = 0; q < 60; q++)
            {
                Vec3d X(rng.uniform(b.first[0], b.second[0]), rng.uniform(b.first[1], b.second[1]),
                        rng.uniform(b.first[2], b.second[2]));
                const int axis = rng.uniform(0, 3);
                X[axis] = rng.uniform(0, 2) ? b.second[axis] : b.first[axis];
                pts.push_back(X);
            }
    for (int q = 0; q < 80; q++)
        pts.push_back(Vec3d(rng.uniform(-6.0, 9.0), 0.0, rng.uniform(-6.0, 6.0)));
    s.rec.points = Mat((int)pts.size(), 3, CV_64F);
    for (size_t q = 0; q < pts.size(); q++)
        for (int a = 0; a < 3; a++)
            s.rec.points.at<double>((int)q, a) = pts[q][a];
    return s;
}

std::vector<AnalyticObject> towerAndEll()
{
    AnalyticObject tower{"tower", {{Vec3d(-1, 0, -1), Vec3d(1, 3, 1)}}};
    AnalyticObject ell{"ell", {{Vec3d(2.5, 0, -1), Vec3d(5.5, 1.5, 0)},
                               {Vec3d(4.5, 0, -1), Vec3d(5.5, 1.5, 2)}}};
    return {tower, ell};
}

// front hides part of back in every frame (listed front to back).
std::vector<AnalyticObject> frontAndBack()
{
    AnalyticObject front{"front", {{Vec3d(0.7, 0, 1.5), Vec3d(2.3, 3.0, 3)}}};
    AnalyticObject back{"back", {{Vec3d(0, 0, -4), Vec3d(3, 3, -2)}}};
    return {front, back};
}

// Mean distance (px) from the boundary pixels of `a` to the boundary of `b`.
double meanBoundaryDistance(const Mat& a, const Mat& b)
{
    Mat ea, eb;
    erode(a, ea, Mat());
    erode(b, eb, Mat());
    Mat ba = a & ~ea, bb = b & ~eb;
    Mat dt;
    distanceTransform(~bb, dt, DIST_L2, DIST_MASK_PRECISE);
    std::vector<Point> pts;
    findNonZero(ba, pts);
    if (pts.empty())
        return 0;
    double s = 0;
    for (const Point& p : pts)
        s += dt.at<float>(p);
    return s / pts.size();
}

struct Figures
{
    double keyMin = 1, nonKeyMean = 0, nonKeyMin = 1, boundaryMean = 0;
};

Figures measure(const CloneSet& clones, const AnalyticScene& s, const String& object,
                const ObjectMasks& nonKeyRef)
{
    Figures fig;
    double sumIoU = 0, sumB = 0;
    int n = 0;
    for (const Camera& cam : s.rec.cameras)
    {
        Mat matte;
        clones.render(object, cam.frame, cam, s.rec.imageSize, matte);
        const bool key = std::find(s.keyFrames.begin(), s.keyFrames.end(), cam.frame) !=
                         s.keyFrames.end();
        if (key)
        {
            // Against the key-frame silhouette, outside the pixels of nearer objects (objects are
            // listed front to back): there the clone is unknown by design (occlusion-aware
            // carving) and the nearer object's clone is in front anyway.
            const Mat& sil = s.keyMasks.at(object).at(cam.frame);
            Mat nearer(sil.size(), CV_8U, Scalar(0));
            for (const AnalyticObject& o : s.objects)
            {
                if (o.name == object)
                    break;
                nearer |= s.keyMasks.at(o.name).at(cam.frame);
            }
            fig.keyMin = std::min(fig.keyMin, maskIoU(matte & ~nearer, sil));
            continue;
        }
        const Mat& ref = nonKeyRef.at(object).at(cam.frame);
        const double iou = maskIoU(matte, ref);
        sumIoU += iou;
        sumB += meanBoundaryDistance(matte, ref);
        fig.nonKeyMin = std::min(fig.nonKeyMin, iou);
        n++;
    }
    fig.nonKeyMean = sumIoU / std::max(n, 1);
    fig.boundaryMean = sumB / std::max(n, 1);
    return fig;
}

// Key frames: the clone plus the frame's patches cover the silhouette exactly (issue 4).
const double kKeyFrameMinIoU = 0.999;
// Non-key frames of the analytic two-object scene (6 key frames over 30): the synthetic
// targets (mean 0.98, worst 0.95, boundary 1 px), which the analytic boxes meet as well.
const double kNonKeyMeanIoU = 0.98;
const double kNonKeyMinIoU = 0.95;
const double kMaxMeanBoundaryPx = 1.0;
// Occlusion case: the hidden object's clone covers its whole silhouette (issue 4: mean 0.97).
const double kHiddenMeanIoU = 0.97;

typedef testing::TestWithParam<int> Augocc_CloneBuilder_P;

TEST_P(Augocc_CloneBuilder_P, accuracy)
{
    const CameraModel model = (CameraModel)GetParam();
    const AnalyticScene s = makeScene(model, towerAndEll(), 30, 6);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
    ASSERT_FALSE(clones.empty());
    EXPECT_EQ(clones->objectNames(), std::vector<String>({"ell", "tower"}));
    for (const String& name : clones->objectNames())
    {
        const Figures f = measure(*clones, s, name, s.whole);
        std::cout << cameraModelName(model) << " " << name << ": key min IoU " << f.keyMin
                  << ", non-key mean IoU " << f.nonKeyMean << " min " << f.nonKeyMin
                  << ", boundary " << f.boundaryMean << " px, voxels " << clones->voxelCount(name)
                  << " grid " << clones->gridSize(name) << std::endl;
        EXPECT_GE(f.keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(f.nonKeyMean, kNonKeyMeanIoU) << name;
        EXPECT_GE(f.nonKeyMin, kNonKeyMinIoU) << name;
        EXPECT_LE(f.boundaryMean, kMaxMeanBoundaryPx) << name;
    }
}


// No tracked point on the back quarter of the tower (the cameras, at azimuths -25..25 degrees,
// see that part only as the roof's far edge) and a box turned 20 degrees from the facades (the
// user's --orientation): Step 3 makes every silhouette ray touch the box, yet the other key
// frames' cones meet some rays only outside it, so the box cuts the tower's back corners and in
// those key frames patch voxels alone cover them. The grid grows to hold the visual hull those
// rays need. Measured 2026-12-01 (orthographic / perspective): non-key mean IoU 0.9815 / 0.9848,
// worst frame 0.938 / 0.961, boundary 0.57 / 0.46 px; without the growth 0.9778 / 0.9791, worst
// 0.938 / 0.933, boundary 0.68 / 0.67 px.
TEST_P(Augocc_CloneBuilder_P, box_from_part_of_the_points)
{
    const CameraModel model = (CameraModel)GetParam();
    AnalyticScene s = makeScene(model, towerAndEll(), 30, 6);
    std::vector<int> keep;
    for (int q = 0; q < s.rec.points.rows; q++)
    {
        const double* X = s.rec.points.ptr<double>(q);
        const bool onTower = X[0] >= -1 && X[0] <= 1 && X[2] >= -1 && X[2] <= 1 && X[1] > 0;
        if (!onTower || X[2] > -0.5)
            keep.push_back(q);
    }
    ASSERT_LT((int)keep.size(), s.rec.points.rows);
    Mat pts((int)keep.size(), 3, CV_64F);
    for (size_t q = 0; q < keep.size(); q++)
        s.rec.points.row(keep[q]).copyTo(pts.row((int)q));
    s.rec.points = pts;
    CloneBuilder::Params p;
    p.orientation = CloneBuilder::ORIENT_USER;
    p.userRotation = Vec3d(0, 20 * CV_PI / 180, 0);
    Ptr<CloneSet> clones = CloneBuilder::create(p)->build(s.rec, s.keyMasks);
    const Figures f = measure(*clones, s, "tower", s.whole);
    std::cout << cameraModelName(model) << " tower without its back quarter's points, box turned "
              << "20 degrees: key min IoU " << f.keyMin << ", non-key mean IoU " << f.nonKeyMean
              << " min " << f.nonKeyMin << ", boundary " << f.boundaryMean << " px, grid "
              << clones->gridSize("tower") << std::endl;
    EXPECT_GE(f.keyMin, kKeyFrameMinIoU);
    EXPECT_GE(f.nonKeyMean, kNonKeyMeanIoU);
    EXPECT_LE(f.boundaryMean, kMaxMeanBoundaryPx);
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_CloneBuilder_P,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

TEST(Augocc_CloneBuilder, can_create_default)
{
    Ptr<CloneBuilder> b = CloneBuilder::create();
    ASSERT_FALSE(b.empty());
    EXPECT_EQ(b->getParams().orientation, (int)CloneBuilder::ORIENT_AUTO);
    EXPECT_EQ(b->getParams().voxelPixels, 1.0);
}

TEST(Augocc_CloneBuilder, bad_arg)
{
    CloneBuilder::Params p;
    p.voxelPixels = 0;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.raysPerPixel = 0;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.freeSpaceMinViews = -1;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.freeSpaceEdgeMargin = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.freeSpacePlanarDeg = 91;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);

    AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 12, 3);
    Ptr<CloneBuilder> b = CloneBuilder::create();
    auto expectError = [&](const ObjectMasks& m, const std::string& needle) {
        try
        {
            b->build(s.rec, m);
            ADD_FAILURE() << "no exception for " << needle;
        }
        catch (const cv::Exception& e)
        {
            EXPECT_NE(e.msg.find(needle), std::string::npos) << e.msg;
        }
    };
    ObjectMasks m = s.keyMasks;
    m["tower"][0] = Mat(s.rec.imageSize, CV_8U, Scalar(0));
    expectError(m, "empty");
    m = s.keyMasks;
    m["tower"][0] = Mat(s.rec.imageSize, CV_8U, Scalar(255));
    expectError(m, "all white");
    m = s.keyMasks;
    m["tower"][99] = s.keyMasks["tower"][0];
    expectError(m, "no camera");
    m = s.keyMasks;
    m["tower"][0] = Mat(100, 100, CV_8U, Scalar(0));
    expectError(m, "differs");
    ObjectMasks none;
    EXPECT_THROW(b->build(s.rec, none), cv::Exception);
}

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

// A nearer object's silhouette is unknown, not outside: the hidden object keeps its whole shape.
TEST(Augocc_CloneBuilder, occlusion_aware_carving)
{
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, frontAndBack(), 30, 6);
    Ptr<CloneSet> aware = CloneBuilder::create()->build(s.rec, s.keyMasks);
    const Figures f = measure(*aware, s, "back", s.whole);
    std::cout << "hidden object, occlusion-aware: non-key mean IoU vs whole " << f.nonKeyMean
              << " min " << f.nonKeyMin << ", key min " << f.keyMin << std::endl;
    EXPECT_GE(f.nonKeyMean, kHiddenMeanIoU);
    EXPECT_GE(f.keyMin, kKeyFrameMinIoU);
    CloneBuilder::Params p;
    p.occlusionAware = false;
    Ptr<CloneSet> naive = CloneBuilder::create(p)->build(s.rec, s.keyMasks);
    const Figures g = measure(*naive, s, "back", s.whole);
    std::cout << "hidden object, paper's carving: non-key mean IoU vs whole " << g.nonKeyMean
              << std::endl;
    EXPECT_LT(g.nonKeyMean, f.nonKeyMean);
}

TEST(Augocc_CloneBuilder, save_load_roundtrip)
{
    const AnalyticScene s = makeScene(PERSPECTIVE, towerAndEll(), 12, 3);
    Ptr<CloneSet> a = CloneBuilder::create()->build(s.rec, s.keyMasks);
    const std::string dir = tempDir("clone_io");
    const std::string path = dir + "/clones.yml.gz";
    a->save(path);
    Ptr<CloneSet> b = CloneSet::load(path);
    ASSERT_EQ(a->objectNames(), b->objectNames());
    for (const String& name : a->objectNames())
    {
        EXPECT_EQ(a->voxelCount(name), b->voxelCount(name));
        EXPECT_EQ(a->keyFrames(name), b->keyFrames(name));
        for (int f : {0, 5, 11})
        {
            Mat ma, mb, da, db;
            a->render(name, f, s.rec.cameras[f], s.rec.imageSize, ma, da);
            b->render(name, f, s.rec.cameras[f], s.rec.imageSize, mb, db);
            EXPECT_EQ(countNonZero(ma != mb), 0);
            Mat fin = da < 1e30f;
            EXPECT_LE(cv::norm(da, db, NORM_INF, fin), 0.0);
        }
    }
    a->exportPly(dir + "/ply");
    EXPECT_TRUE(std::filesystem::exists(dir + "/ply/tower_clone.ply"));
    EXPECT_TRUE(std::filesystem::exists(dir + "/ply/tower_patches_0000.ply"));
    // Corrupt and missing files: errors that name the file.
    {
        std::ofstream(dir + "/bad.yml") << "%YAML:1.0\nformat: something_else\n";
    }
    EXPECT_THROW(CloneSet::load(dir + "/bad.yml"), cv::Exception);
    EXPECT_THROW(CloneSet::load(dir + "/missing.yml.gz"), cv::Exception);
    std::filesystem::remove_all(dir);
}

TEST(Augocc_CloneBuilder, add_key_frame)
{
    AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 30, 3);
    Ptr<CloneBuilder> b = CloneBuilder::create();
    Ptr<CloneSet> clones = b->build(s.rec, s.keyMasks);
    const int before = clones->voxelCount("ell");
    const int f = 7;
    const Mat mask = s.visible["ell"][f];
    b->addKeyFrame(*clones, s.rec, "ell", f, mask);
    EXPECT_LE(clones->voxelCount("ell"), before);
    std::vector<int> keys = s.keyFrames;
    keys.push_back(f);
    std::sort(keys.begin(), keys.end());
    EXPECT_EQ(clones->keyFrames("ell"), keys);
    EXPECT_EQ(clones->patchFrames("ell", f), std::vector<int>(1, f));
    Mat matte;
    clones->render("ell", f, s.rec.cameras[f], s.rec.imageSize, matte);
    EXPECT_GE(maskIoU(matte, mask), kKeyFrameMinIoU);
    EXPECT_THROW(b->addKeyFrame(*clones, s.rec, "nobody", f, mask), cv::Exception);
    EXPECT_THROW(b->addKeyFrame(*clones, s.rec, "ell", 1000, mask), cv::Exception);
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
    p.orientation = CloneBuilder::ORIENT_WORLD;
    Ptr<CloneSet> worldSet = CloneBuilder::create(p)->build(s.rec, s.keyMasks);
    const Vec3i ga = autoSet->gridSize("b"), gw = worldSet->gridSize("b");
    EXPECT_LT((double)ga[0] * ga[1] * ga[2], 0.8 * gw[0] * gw[1] * gw[2]);
    const Figures f = measure(*autoSet, s, "b", s.whole);
    EXPECT_GE(f.nonKeyMean, kNonKeyMeanIoU);
}

TEST(Augocc_CloneBuilder, multithread_reproducibility)
{
    const AnalyticScene s = makeScene(PERSPECTIVE, towerAndEll(), 12, 4);
    const int threads = getNumThreads();
    setNumThreads(1);
    Ptr<CloneSet> a = CloneBuilder::create()->build(s.rec, s.keyMasks);
    setNumThreads(std::max(threads, 4));
    Ptr<CloneSet> b = CloneBuilder::create()->build(s.rec, s.keyMasks);
    setNumThreads(threads);
    for (const String& name : a->objectNames())
    {
        EXPECT_EQ(a->voxelCount(name), b->voxelCount(name));
        for (int k : a->keyFrames(name))
            EXPECT_EQ(a->patchVoxelCount(name, k), b->patchVoxelCount(name, k));
        ObjectMasks ma, mb;
        renderMattes(*a, s.rec, ma);
        renderMattes(*b, s.rec, mb);
        for (const auto& fm : ma[name])
            EXPECT_EQ(countNonZero(fm.second != mb[name][fm.first]), 0);
    }
}

TEST(Augocc_CloneBuilder, write_mattes_folder)
{
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 8, 3);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
    const std::string dir = tempDir("clone_mattes");
    writeMattes(dir + "/mattes", *clones, s.rec, dir + "/depth");
    const ObjectMasks m = readMasks(dir + "/mattes", s.rec.imageSize);
    ASSERT_EQ(m.size(), 2u);
    EXPECT_EQ(m.at("tower").size(), 8u);
    Mat ref;
    clones->render("tower", 3, s.rec.cameras[3], s.rec.imageSize, ref);
    EXPECT_EQ(countNonZero(ref != m.at("tower").at(3)), 0);
    const Mat d = imread(dir + "/depth/tower/0003.tiff", IMREAD_UNCHANGED);
    ASSERT_EQ(d.type(), CV_32FC1);
    EXPECT_EQ(countNonZero(d < 1e30f), countNonZero(ref));
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// Middlebury dinoSparseRing: 16 calibrated views on a ring (perspective), silhouettes by the data
// set's own recipe (README.txt): threshold 0.19, dilate 10 px, erode 7 px. 8 views are key frames,
// the other 8 are rendered and compared. No reconstructed points: the silhouette-only fallback.
Mat dinoSilhouette(const Mat& bgr)
{
    Mat gray, m;
    cvtColor(bgr, gray, COLOR_BGR2GRAY);
    m = gray > 0.19 * 255;
    dilate(m, m, getStructuringElement(MORPH_ELLIPSE, Size(21, 21)));
    erode(m, m, getStructuringElement(MORPH_ELLIPSE, Size(15, 15)));
    return m;
}

// Measured 0.928 mean IoU for the 8 held-out views (doc/clones.md), limited by the thresholded
// reference itself (dark shadows make holes the visual hull fills); the bound fails on a wrong
// camera convention or a broken carve (IoU < 0.5).
const double kDinoMeanIoU = 0.9;
// refine() on the dino photographs: held-out IoU gain, measured +0.030, bound at half.
const double kDinoMinPhotoGain = 0.015;

TEST(Augocc_CloneBuilder, middlebury_dino)
{
    AUGOCC_REQUIRE_SHARED_DATA(dir, "middlebury_dino");
    std::ifstream par(dir + "/dinoSR_par.txt");
    ASSERT_TRUE(par.good());
    int n = 0;
    par >> n;
    ASSERT_EQ(n, 16);
    Reconstruction rec;
    rec.model = PERSPECTIVE;
    std::vector<Mat> sil, images;
    for (int f = 0; f < n; f++)
    {
        std::string name;
        Matx33d K, R;
        Vec3d t;
        par >> name;
        for (int q = 0; q < 9; q++) par >> K.val[q];
        for (int q = 0; q < 9; q++) par >> R.val[q];
        for (int q = 0; q < 3; q++) par >> t[q];
        ASSERT_FALSE(par.fail());
        rec.cameras.push_back(Camera::perspective(R, t, K, f));
        const Mat img = imread(dir + "/" + name);
        ASSERT_FALSE(img.empty()) << name;
        rec.imageSize = img.size();
        sil.push_back(dinoSilhouette(img));
        images.push_back(img);
    }
    ObjectMasks masks;
    for (int f = 0; f < n; f += 2)
        masks["dino"][f] = sil[f];
    Ptr<CloneSet> clones = CloneBuilder::create()->build(rec, masks);
    double sum = 0, worst = 1, keyMin = 1;
    for (int f = 0; f < n; f++)
    {
        Mat matte;
        clones->render("dino", f, rec.cameras[f], rec.imageSize, matte);
        const double iou = maskIoU(matte, sil[f]);
        if (f % 2 == 0)
        {
            keyMin = std::min(keyMin, iou);
            continue;
        }
        sum += iou;
        worst = std::min(worst, iou);
        std::cout << "  view " << f + 1 << " IoU " << iou << std::endl;
        if (f == 1)
        {
            Mat vis;
            merge(std::vector<Mat>{sil[f], matte, matte & ~sil[f]}, vis);
            imwrite(tempDir("dino") + "/dino_view1.png", vis);
        }
    }
    const Vec3i d = clones->gridSize("dino");
    std::cout << "middlebury dino: grid " << d << ", key frames min IoU " << keyMin
              << ", held-out views mean IoU " << sum / 8 << " worst " << worst << std::endl;
    EXPECT_GE(keyMin, kKeyFrameMinIoU);
    EXPECT_GE(sum / 8, kDinoMeanIoU);
    // Photo-consistency carving on real photographs (all 16 views, default parameters): the
    // concavities the hull fills against the black background go (measured: held-out mean IoU
    // 0.928 -> 0.958, 3.0M voxels carved; photoMinViews 8 carves nothing here, a sweep has at
    // most 7 of the 16 cameras). It may not lose against the thresholded silhouettes.
    {
        Ptr<CloneBuilder> b = CloneBuilder::create();
        Ptr<CloneSet> refined = b->build(rec, masks);
        const int64 carved = b->refine(*refined, rec, images);
        double rsum = 0, rkeyMin = 1;
        for (int f = 0; f < n; f++)
        {
            Mat matte;
            refined->render("dino", f, rec.cameras[f], rec.imageSize, matte);
            const double iou = maskIoU(matte, sil[f]);
            if (f % 2 == 0)
                rkeyMin = std::min(rkeyMin, iou);
            else
                rsum += iou;
            if (f == 1)
            {
                Mat before, vis;
                clones->render("dino", f, rec.cameras[f], rec.imageSize, before);
                vis = images[f].clone();
                vis.setTo(Scalar(0, 0, 255), before & ~matte);   // carved by refine
                vis.setTo(Scalar(0, 255, 0), ~before & sil[f]);  // silhouette the hull misses
                imwrite(tempDir("dino") + "/dino_view1_photo.png", vis);
            }
        }
        std::cout << "middlebury dino, refine: " << carved
                  << " voxels carved, key frames min IoU " << rkeyMin
                  << ", held-out views mean IoU " << rsum / 8 << std::endl;
        EXPECT_GE(rkeyMin, kKeyFrameMinIoU);
        EXPECT_GE(rsum / 8, sum / 8 + kDinoMinPhotoGain);
    }
}

// The squirrel turntable (36 calibrated 1280x960 photographs on black, silhouettes by HSV value
// >= 30 as its SOURCE.txt says), every fourth view a key frame, the 27 others held out.
// Measured 2026-12-01: key frames 1.000; held-out mean IoU 0.958 (worst 0.926), recall 0.994.
// With the previous last patch round (every voxel of a ray's span that fits) 0.939 / 0.896:
// rim patches landed at the far end of the grid, streaks in every other view.
const double kSquirrelMeanIoU = 0.95;
const double kSquirrelRecall = 0.99;

TEST(Augocc_CloneBuilder, squirrel_turntable_held_out)
{
    AUGOCC_REQUIRE_SHARED_DATA(dir, "squirrel_turntable");
    FileStorage fs(dir + "/viff.xml", FileStorage::READ);
    ASSERT_TRUE(fs.isOpened());
    const int n = 36, step = 4;
    Reconstruction rec;
    rec.model = PERSPECTIVE;
    std::vector<Mat> sil(n);
    for (int f = 0; f < n; f++)
    {
        Mat P;
        fs[cv::format("viff%03d_matrix", f)] >> P;
        ASSERT_EQ(P.size(), Size(4, 3)) << f;
        P.convertTo(P, CV_64F);
        rec.cameras.push_back(cameraFromProjection(Matx34d(P), f));
        const Mat img = imread(cv::format("%s/image_%d.jpg", dir.c_str(), f));
        ASSERT_FALSE(img.empty()) << f;
        rec.imageSize = img.size();
        Mat hsv, ch[3];
        cvtColor(img, hsv, COLOR_BGR2HSV);
        split(hsv, ch);
        sil[f] = ch[2] >= 30;
    }
    ObjectMasks masks;
    for (int f = 0; f < n; f += step)
        masks["squirrel"][f] = sil[f];
    Ptr<CloneSet> clones = CloneBuilder::create()->build(rec, masks);
    double sum = 0, worst = 1, keyMin = 1, recall = 0;
    int held = 0;
    for (int f = 0; f < n; f++)
    {
        Mat matte;
        clones->render("squirrel", f, rec.cameras[f], rec.imageSize, matte);
        const double iou = maskIoU(matte, sil[f]);
        if (f % step == 0)
        {
            keyMin = std::min(keyMin, iou);
            continue;
        }
        sum += iou;
        worst = std::min(worst, iou);
        recall += (double)countNonZero(matte & sil[f]) / countNonZero(sil[f]);
        held++;
    }
    std::cout << "squirrel turntable: grid " << clones->gridSize("squirrel") << ", key frames min "
              << "IoU " << keyMin << ", " << held << " held-out views mean IoU " << sum / held
              << " worst " << worst << ", recall " << recall / held << std::endl;
    EXPECT_GE(keyMin, kKeyFrameMinIoU);
    EXPECT_GE(sum / held, kSquirrelMeanIoU);
    EXPECT_GE(recall / held, kSquirrelRecall);
}

// augocc clone and augocc matte end to end, and their bad-input exits.
TEST(Augocc_CloneBuilder, cli_clone_and_matte)
{
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 10, 3);
    const std::string dir = tempDir("clone_cli");
    writeReconstruction(dir + "/rec.yml", s.rec);
    writeMasks(dir + "/masks", s.keyMasks);
    const std::string bin = augoccBinary();
    std::string out;
    ASSERT_EQ(runCommand(bin + " --quiet clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/masks --out " + dir + "/clones.yml.gz --ply " + dir + "/ply", &out), 0)
        << out;
    ASSERT_EQ(runCommand(bin + " --quiet matte --reconstruction " + dir + "/rec.yml --clones " +
                         dir + "/clones.yml.gz --out " + dir + "/mattes --depth " + dir + "/depth",
                         &out), 0) << out;
    const ObjectMasks mattes = readMasks(dir + "/mattes", s.rec.imageSize);
    ASSERT_EQ(mattes.at("tower").size(), 10u);
    for (int k : s.keyFrames)
        EXPECT_GE(maskIoU(mattes.at("tower").at(k), s.keyMasks.at("tower").at(k)), kKeyFrameMinIoU);
    EXPECT_TRUE(std::filesystem::exists(dir + "/depth/ell/0009.tiff"));
    EXPECT_TRUE(std::filesystem::exists(dir + "/ply/ell_clone.ply"));
    // Bad inputs: exit 2, a message naming the problem, no output file.
    EXPECT_EQ(runCommand(bin + " clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/nowhere --out " + dir + "/c2.yml.gz", &out), 2);
    EXPECT_NE(out.find("--masks"), std::string::npos) << out;
    ObjectMasks small;
    small["tower"][0] = Mat(10, 10, CV_8U, Scalar(255));
    writeMasks(dir + "/small", small);
    EXPECT_EQ(runCommand(bin + " clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/small --out " + dir + "/c3.yml.gz", &out), 2);
    EXPECT_FALSE(std::filesystem::exists(dir + "/c3.yml.gz"));
    EXPECT_EQ(runCommand(bin + " clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/masks --out " + dir + "/c4.yml.gz --orientation 1,2", &out), 2);
    EXPECT_NE(out.find("--orientation"), std::string::npos) << out;
    // Key-frame masks that disagree (a block marked in one key frame above the tower, where no
    // other key frame, all at the same elevation, can explain it): the build succeeds, patches
    // keep that frame exact, and a warning names the frame. (A block beside the tower would be
    // explained: the other views see the space behind it inside the tower's silhouette, a ghost
    // of the visual hull that the clone takes in, as the box grows to hold the hull the key
    // frames need.)
    {
        ObjectMasks odd = s.keyMasks;
        const int kf = s.keyFrames.front();
        Mat& m = odd["tower"][kf];
        const int side = (int)std::ceil(std::sqrt(0.2 * countNonZero(m)));
        const Rect r = boundingRect(m);
        const Rect block(r.x + r.width / 2 - side / 2, r.y - side - 2, side, side);
        ASSERT_EQ(block & Rect(Point(), m.size()), block);
        m(block).setTo(255);
        writeMasks(dir + "/odd", odd);
        ASSERT_EQ(runCommand(bin + " clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                             "/odd --out " + dir + "/odd.yml.gz", &out), 0) << out;
        EXPECT_NE(out.find(cv::format("object 'tower', key frame %d:", kf)), std::string::npos)
            << out;
        EXPECT_EQ(out.find("object 'ell', key frame"), std::string::npos) << out;
        Ptr<CloneSet> c6 = CloneSet::load(dir + "/odd.yml.gz");
        Mat matte;
        c6->render("tower", kf, s.rec.cameras[kf], s.rec.imageSize, matte);
        EXPECT_GE(maskIoU(matte, m), kKeyFrameMinIoU);
    }
    // --tracks: the points' observations (exact projections here); free space on by default,
    // --no-free-space keeps the silhouettes-only clone; tracks that do not match the points: 2.
    {
        const int F = (int)s.rec.cameras.size(), P = s.rec.points.rows;
        Tracks t;
        t.imageSize = s.rec.imageSize;
        t.tracks = Mat(F, P, CV_32FC2);
        for (int f = 0; f < F; f++)
            for (int p = 0; p < P; p++)
            {
                const Point2d q = s.rec.project(f, Vec3d(s.rec.points.ptr<double>(p)));
                t.tracks.at<Vec2f>(f, p) = Vec2f((float)q.x, (float)q.y);
            }
        writeTracks(dir + "/tracks.yml", t);
        t.tracks = t.tracks.colRange(0, P / 2).clone();
        writeTracks(dir + "/half.yml", t);
    }
    ASSERT_EQ(runCommand(bin + " --quiet clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/masks --out " + dir + "/t1.yml.gz --tracks " + dir + "/tracks.yml", &out),
              0) << out;
    ASSERT_EQ(runCommand(bin + " --quiet clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/masks --out " + dir + "/t2.yml.gz --tracks " + dir +
                         "/tracks.yml --no-free-space", &out), 0) << out;
    for (const char* name : {"tower", "ell"})
        EXPECT_LE(CloneSet::load(dir + "/t1.yml.gz")->voxelCount(name),
                  CloneSet::load(dir + "/t2.yml.gz")->voxelCount(name)) << name;
    EXPECT_EQ(runCommand(bin + " clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/masks --out " + dir + "/t3.yml.gz --tracks " + dir + "/half.yml", &out), 2);
    EXPECT_NE(out.find("tracks"), std::string::npos) << out;
    EXPECT_FALSE(std::filesystem::exists(dir + "/t3.yml.gz"));
    // --input: photo-consistency carving over the frames (uniform frames: nothing to carve).
    std::filesystem::create_directories(dir + "/frames");
    std::filesystem::create_directories(dir + "/few");
    for (int f = 0; f < 10; f++)
    {
        const Mat img(s.rec.imageSize, CV_8UC3, Scalar(80, 100, 120));
        imwrite(cv::format("%s/frames/%04d.png", dir.c_str(), f), img);
        if (f < 5)
            imwrite(cv::format("%s/few/%04d.png", dir.c_str(), f), img);
    }
    ASSERT_EQ(runCommand(bin + " --quiet clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/masks --out " + dir + "/c5.yml.gz --input " + dir + "/frames", &out), 0)
        << out;
    EXPECT_EQ(CloneSet::load(dir + "/c5.yml.gz")->voxelCount("tower"),
              CloneSet::load(dir + "/clones.yml.gz")->voxelCount("tower"));
    EXPECT_EQ(runCommand(bin + " clone --reconstruction " + dir + "/rec.yml --masks " + dir +
                         "/masks --out " + dir + "/c6.yml.gz --input " + dir + "/few", &out), 2);
    EXPECT_NE(out.find("--input"), std::string::npos) << out;
    EXPECT_FALSE(std::filesystem::exists(dir + "/c6.yml.gz"));
    {
        std::ofstream(dir + "/corrupt.yml.gz") << "not a clones file";
    }
    EXPECT_EQ(runCommand(bin + " matte --reconstruction " + dir + "/rec.yml --clones " + dir +
                         "/corrupt.yml.gz --out " + dir + "/m2", &out), 2);
    EXPECT_FALSE(std::filesystem::exists(dir + "/m2"));
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// SceneSynthesizer scenes with GT cameras: the "Done when" figures.
struct SynthFigures
{
    double keyMin = 1, nonKeyMean = 0, nonKeyMin = 1, boundary = 0;
    double hiddenFraction = 0;  // mean fraction of the whole silhouette hidden in key frames
    double visibleMean = 0, visibleMin = 1;  // IoU outside pixels where other objects are seen
    double recall = 0;          // fraction of the whole silhouette the matte covers
};

SynthFigures measureSynth(const CloneSet& clones, const SyntheticScene& s, const String& object)
{
    SynthFigures fig;
    const Reconstruction& rec = s.groundTruth;
    int n = 0, nk = 0;
    for (const Camera& cam : rec.cameras)
    {
        Mat matte;
        clones.render(object, cam.frame, cam, rec.imageSize, matte);
        const Mat& whole = s.wholeMasks.at(object).at(cam.frame);
        const bool key = std::count(s.keyFrames.begin(), s.keyFrames.end(), cam.frame) > 0;
        if (key)
        {
            // Against the key-frame (visible) silhouette, outside the pixels where other objects
            // are seen (there, this clone is unknown by design and the other clone decides).
            const Mat& sil = s.keyFrameMasks.at(object).at(cam.frame);
            Mat others(sil.size(), CV_8U, Scalar(0));
            for (const auto& o : s.visibleMasks)
                if (o.first != object)
                    others |= o.second.at(cam.frame);
            fig.keyMin = std::min(fig.keyMin, maskIoU(matte & ~others, sil));
            fig.hiddenFraction += 1.0 - (double)countNonZero(sil) / std::max(1, countNonZero(whole));
            nk++;
            continue;
        }
        const double iou = maskIoU(matte, whole);
        fig.nonKeyMean += iou;
        fig.nonKeyMin = std::min(fig.nonKeyMin, iou);
        fig.boundary += meanBoundaryDistance(matte, whole);
        // Where another object is seen in front, this clone's matte decides nothing (the other
        // clone is nearer): IoU outside those pixels, and recall of the whole silhouette.
        Mat front(whole.size(), CV_8U, Scalar(0));
        for (const auto& o : s.visibleMasks)
            if (o.first != object)
                front |= o.second.at(cam.frame) & ~s.visibleMasks.at(object).at(cam.frame);
        const double visIoU = maskIoU(matte & ~front, whole & ~front);
        fig.visibleMean += visIoU;
        fig.visibleMin = std::min(fig.visibleMin, visIoU);
        fig.recall += (double)countNonZero(matte & whole) / std::max(1, countNonZero(whole));
        n++;
    }
    fig.nonKeyMean /= std::max(n, 1);
    fig.boundary /= std::max(n, 1);
    fig.visibleMean /= std::max(n, 1);
    fig.recall /= std::max(n, 1);
    fig.hiddenFraction /= std::max(nk, 1);
    return fig;
}

// Objects of the synthesized scene hidden by more than this fraction in the key frames on average
// count as "hidden" for the occlusion target (mean IoU 0.97 instead of 0.98).
const double kHiddenObjectFraction = 0.02;
// Hidden objects, mean IoU with the WHOLE true silhouette (as if alone) in non-key frames: the
// issue's 0.97. History (orthographic / perspective): voxels no key frame shows dropped: lblock
// 0.972 / 0.979, tower 0.959 / 0.959 (0.914 / 0.846 before); free-space carving: tower 0.964 /
// 0.967 (the rest is behind the building in every frame and behind the tower's own shaft in the
// others); vertical runs no frame sees dropped (2026-12-01): tower 0.972 / 0.981, lblock
// 0.972 / 0.980.
const double kHiddenWholeMeanIoU = kHiddenMeanIoU;

typedef testing::TestWithParam<int> Augocc_CloneBuilder_Synth;

TEST_P(Augocc_CloneBuilder_Synth, accuracy_gt_cameras)
{
    SceneSynthesizer::Params sp;
    sp.model = (CameraModel)GetParam();
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    for (int rule : {(int)CloneBuilder::PATCH_NEAREST, (int)CloneBuilder::PATCH_BRACKETING})
    {
        CloneBuilder::Params p;
        p.patchRule = rule;
        Ptr<CloneSet> clones = CloneBuilder::create(p)->build(s.groundTruth, s.keyFrameMasks,
                                                              &s.tracks);
        ASSERT_EQ(clones->objectNames().size(), s.objectNames.size());
        for (const String& name : clones->objectNames())
        {
            const SynthFigures f = measureSynth(*clones, s, name);
            const Vec3i d = clones->gridSize(name);
            std::cout << cameraModelName(sp.model) << (rule ? " bracketing " : " nearest ")
                      << name << ": key min IoU " << f.keyMin << ", non-key mean IoU "
                      << f.nonKeyMean << " worst " << f.nonKeyMin << ", boundary " << f.boundary
                      << " px, hidden in key frames " << f.hiddenFraction * 100 << "%, IoU "
                      << "outside others' pixels " << f.visibleMean << " worst " << f.visibleMin
                      << ", recall " << f.recall << ", grid " << d[0] << "x" << d[1] << "x"
                      << d[2] << std::endl;
            if (rule != CloneBuilder::PATCH_NEAREST)
                continue;  // the alternative rule is measured, the paper's rule is the default
            EXPECT_GE(f.keyMin, kKeyFrameMinIoU) << name;
            if (f.hiddenFraction > kHiddenObjectFraction)
            {
                // A hidden object: voxels behind the nearer object in every key frame cannot be
                // carved from silhouettes, so the raw IoU against the whole silhouette (as if
                // alone) counts pixels where the nearer clone decides anyway. Its clone must
                // cover its whole silhouette and match it where it is not behind another object.
                EXPECT_GE(f.recall, kHiddenMeanIoU) << name;
                EXPECT_GE(f.visibleMean, kHiddenMeanIoU) << name;
                EXPECT_GE(f.visibleMin, kNonKeyMinIoU) << name;
                EXPECT_GE(f.nonKeyMean, kHiddenWholeMeanIoU) << name;
            }
            else
            {
                EXPECT_GE(f.nonKeyMean, kNonKeyMeanIoU) << name;
                EXPECT_GE(f.nonKeyMin, kNonKeyMinIoU) << name;
                EXPECT_LE(f.boundary, kMaxMeanBoundaryPx) << name;
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_CloneBuilder_Synth,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

// Vertical runs of voxels that no frame sees (dropUnobserved): on the synthesized scene the
// tower's lower shaft is behind the building in the first key frames and behind its own front in
// the last, so the visual hull keeps a wedge behind it that shows in its matte as if alone. Measured
// 2026-12-01 (orthographic), tower's non-key mean IoU with its whole silhouette 0.9654 -> 0.9717
// (worst frame 0.920 -> 0.942), recall 0.99698 -> 0.99688; building and L-block within 0.0005.
// Bounds: the tower gains at least 0.005; no object's recall loses more than 0.001, nor its IoU.
TEST(Augocc_CloneBuilder_Unobserved, synth_tower)
{
    SyntheticScene s;
    SceneSynthesizer::create()->synthesize(s);
    CloneBuilder::Params keep;
    keep.dropUnobserved = false;
    Ptr<CloneSet> a = CloneBuilder::create(keep)->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    Ptr<CloneSet> b = CloneBuilder::create()->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    for (const String& name : b->objectNames())
    {
        const SynthFigures fa = measureSynth(*a, s, name), fb = measureSynth(*b, s, name);
        std::cout << name << ": non-key mean IoU " << fa.nonKeyMean << " -> " << fb.nonKeyMean
                  << ", worst " << fa.nonKeyMin << " -> " << fb.nonKeyMin << ", recall "
                  << fa.recall << " -> " << fb.recall << ", voxels " << a->voxelCount(name)
                  << " -> " << b->voxelCount(name) << std::endl;
        EXPECT_GE(fb.keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(fb.recall, fa.recall - 0.001) << name;
        EXPECT_GE(fb.nonKeyMean, fa.nonKeyMean - 0.001) << name;
        if (name == "tower")
        {
            EXPECT_GE(fb.nonKeyMean, fa.nonKeyMean + 0.005);
        }
    }
}


} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// Cameras from the factorization (and the paper's 3F+1 refinement) instead of the ground truth:
// mattes are image-space, so no alignment with the true world frame is needed.
const double kSfmMeanIoU = 0.97;  // issue 4: with cameras from augocc sfm, mean IoU >= 0.97

TEST(Augocc_CloneBuilder, accuracy_sfm_cameras)
{
    SyntheticScene s;
    SceneSynthesizer::create()->synthesize(s);
    Reconstruction rec;
    ASSERT_TRUE(FactorizationSfM::create()->reconstruct(s.tracks, rec));
    OrthoCameraRefiner::create()->refine(s.tracks, rec);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(rec, s.keyFrameMasks, &s.tracks);
    for (const String& name : clones->objectNames())
    {
        double sum = 0, visSum = 0, keyMin = 1;
        int n = 0;
        for (const Camera& cam : rec.cameras)
        {
            Mat matte;
            clones->render(name, cam.frame, cam, rec.imageSize, matte);
            const Mat& whole = s.wholeMasks.at(name).at(cam.frame);
            Mat others(whole.size(), CV_8U, Scalar(0));
            for (const auto& o : s.visibleMasks)
                if (o.first != name)
                    others |= o.second.at(cam.frame) & ~s.visibleMasks.at(name).at(cam.frame);
            if (std::count(s.keyFrames.begin(), s.keyFrames.end(), cam.frame))
            {
                const Mat& sil = s.keyFrameMasks.at(name).at(cam.frame);
                keyMin = std::min(keyMin, maskIoU(matte & ~others, sil));
                continue;
            }
            sum += maskIoU(matte, whole);
            visSum += maskIoU(matte & ~others, whole & ~others);
            n++;
        }
        std::cout << "sfm cameras " << name << ": key min IoU " << keyMin << ", non-key mean IoU "
                  << sum / n << ", outside others' pixels " << visSum / n << std::endl;
        EXPECT_GE(keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(visSum / n, kSfmMeanIoU) << name;
    }
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// Depth of a clone against the truth where the object is seen and the matte covers it: mean
// |dz| in voxel edges, and the fraction of those pixels where the clone is more than 3 voxels in
// front of the true surface (the visual hull's phantom volume, which hides virtual objects).
struct DepthFigures
{
    double meanAbs = 0, front = 0;
};

DepthFigures measureDepth(const CloneSet& clones, const SyntheticScene& s, const String& name,
                          const String& debugPng = String())
{
    DepthFigures fig;
    int64 n = 0;
    const double h = clones.voxelSize(name);
    for (const Camera& cam : s.groundTruth.cameras)
    {
        Mat mt, dp;
        clones.render(name, cam.frame, cam, s.groundTruth.imageSize, mt, dp);
        const Mat& vis = s.visibleMasks.at(name).at(cam.frame);
        const Mat& gt = s.depth[cam.frame];
        Mat dbg;
        if (!debugPng.empty() && cam.frame == 30)
            dbg = s.frames[cam.frame] / 3;
        for (int y = 0; y < dp.rows; y++)
            for (int x = 0; x < dp.cols; x++)
                if (vis.at<uchar>(y, x) && mt.at<uchar>(y, x))
                {
                    const double dz = (gt.at<float>(y, x) - dp.at<float>(y, x)) / h;
                    fig.meanAbs += std::abs(dz);
                    fig.front += dz > 3;
                    n++;
                    if (!dbg.empty())  // yellow: clone in front, blue: behind, 4 levels a voxel
                    {
                        const int c = (int)std::min(255.0, std::abs(dz) * 4);
                        dbg.at<Vec3b>(y, x) = dz > 0 ? Vec3b(0, (uchar)c, (uchar)std::max(60, c))
                                                     : Vec3b((uchar)std::max(60, c), (uchar)c, 0);
                    }
                }
        if (!dbg.empty())
            imwrite(debugPng, dbg);
    }
    fig.meanAbs /= std::max<int64>(n, 1);
    fig.front /= std::max<int64>(n, 1);
    return fig;
}

void printPhoto(const char* tag, const String& name, const SynthFigures& f, const DepthFigures& d)
{
    std::cout << tag << " " << name << ": key min IoU " << f.keyMin << ", non-key mean IoU "
              << f.nonKeyMean << " worst " << f.nonKeyMin << ", boundary " << f.boundary
              << " px, recall " << f.recall << ", depth: mean |dz| " << d.meanAbs
              << " voxels, " << d.front * 100 << "% of pixels > 3 voxels in front" << std::endl;
}

// Photo-consistency carving on the synthesized scene (GT cameras, all 60 frames), figures before
// and after refine() with the default parameters but no free-space carving (orthographic;
// measured on 2026-11-30):
//   building: non-key IoU 0.9878 -> 0.9899, recall 0.99941 -> 0.99867, |dz| 6.97 -> 6.15 voxels
//   lblock:   non-key IoU 0.9718 -> 0.9730, recall 0.99906 -> 0.99895, |dz| 42.4 -> 35.4 voxels
//   tower:    non-key IoU 0.9592 -> 0.9610, recall 0.99698 -> 0.99694, |dz| 14.4 -> 13.9 voxels
// The phantom volume in front of uniform walls and roofs stays: views spread along the orbit see
// the same colour there (a photo-consistency limit, not a tuning one).
// Key frames stay exact (the carving never uncovers a key-frame silhouette pixel).
const double kPhotoMaxRecallLoss = 0.002;  // measured 0.0007 (building), budget 3x
const double kPhotoMinIoUGain = 0.0005;    // measured +0.0012..+0.0021 per object, bound /2
const double kPhotoLblockDepthRatio = 0.92; // measured 35.4 / 42.4 = 0.83, bound + margin
// Free space (figures in the comment of Augocc_CloneBuilder_FreeSpace_P.accuracy_synth below).
const double kFreeSpaceMaxRecallLoss = 0.001;
const double kFreeSpaceMaxIoULoss = 0.001;
const double kFreeSpaceMaxDepthRatio = 0.98;
const double kFreeSpaceLblockDepthRatio = 0.5;
// Oxford dinosaur, 27 held-out views (measured 2026-12-01): IoU 0.830 -> 0.834, recall 0.9837 ->
// 0.9822 without -> with free space; with planar triangles (and single-threaded, bit-exact
// camera recovery) 0.8438 -> 0.8538, recall 0.9850 -> 0.9812. Bounds: recall may lose 0.005
// (3x the first measurement; 0.0038 now); IoU must not drop.
// The absolute IoU (worst view 0.48) is the masks': in some key frames a segmentation strip along
// the image border touches the dinosaur, and its cone becomes part of the clone; the dinosaur
// itself matches its held-out silhouettes to about a pixel (looked at, views 10 and 35).
const double kFreeSpaceRealRecallLoss = 0.005;
const double kFreeSpaceRealIoULoss = 0.0;

TEST(Augocc_CloneBuilder_Photo, accuracy_synth)
{
    SyntheticScene s;
    SceneSynthesizer::create()->synthesize(s);
    CloneBuilder::Params p;
    p.freeSpaceMinViews = 0;  // photo-consistency alone (free space: Augocc_CloneBuilder_FreeSpace)
    Ptr<CloneBuilder> b = CloneBuilder::create(p);
    Ptr<CloneSet> clones = b->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    std::map<String, SynthFigures> before;
    std::map<String, DepthFigures> beforeDepth;
    for (const String& name : clones->objectNames())
    {
        before[name] = measureSynth(*clones, s, name);
        beforeDepth[name] = measureDepth(*clones, s, name);
        printPhoto("before", name, before[name], beforeDepth[name]);
    }
    const int64 t0 = getTickCount();
    const int64 carved = b->refine(*clones, s.groundTruth, s.frames);
    std::cout << "refine: " << carved << " voxels carved in "
              << (getTickCount() - t0) * 1000.0 / getTickFrequency() << " ms" << std::endl;
    EXPECT_GT(carved, 0);
    for (const String& name : clones->objectNames())
    {
        const SynthFigures f = measureSynth(*clones, s, name);
        const DepthFigures d = measureDepth(*clones, s, name);
        printPhoto("after ", name, f, d);
        EXPECT_GE(f.keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(f.recall, before[name].recall - kPhotoMaxRecallLoss) << name;
        EXPECT_GE(f.nonKeyMean, before[name].nonKeyMean + kPhotoMinIoUGain) << name;
        EXPECT_LT(d.meanAbs, beforeDepth[name].meanAbs) << name;
        EXPECT_LT(d.front, beforeDepth[name].front) << name;
        if (name == "lblock")
        {
            EXPECT_LE(d.meanAbs, kPhotoLblockDepthRatio * beforeDepth[name].meanAbs);
        }
    }
}

// Free-space carving from the tracks (build() with tracks) on the synthesized scene, GT cameras,
// both camera models: depth of the clones against the truth without and with it, and the
// silhouette figures, which it must not spoil. Measured 2026-12-01 (orthographic / perspective),
// mean |dz| in voxels, silhouettes only -> free space with every triangle flat at its nearest
// corner (freeSpacePlanarDeg 0) -> planar triangles following their plane (default):
//   building 6.97 -> 6.56 -> 3.44 / 8.71 -> 7.76 -> 3.42, recall 0.99941 -> 0.99909 / 0.99910 ->
//            0.99825
//   lblock  42.4 -> 12.8 -> 6.70 / 49.0 -> 13.2 -> 6.70 (the inner corner's phantom), non-key IoU
//           +0.0000 / +0.0006
//   tower   14.4 -> 8.5 -> 3.81 / 15.2 -> 8.9 -> 3.76, non-key IoU 0.9658 -> 0.9717 / 0.9698 ->
//           0.9806 (with the unobserved runs)
// Pixels more than 3 voxels in front of the true surface: building 93% -> 34%, L-block 96% ->
// 40%, tower 76% -> 34% (orthographic).
// Bounds: recall and IoU may lose at most 0.001 (measured worst 0.00085, perspective building:
// corners that triangles span); every object's depth error must drop by 2% at least, the
// L-block's by half (measured 0.16 / 0.14); the planar triangles must take a fifth more off
// every object's depth error than the flat ones (measured 0.42 - 0.52).
const double kFreeSpacePlanarDepthRatio = 0.8;
typedef testing::TestWithParam<int> Augocc_CloneBuilder_FreeSpace_P;

TEST_P(Augocc_CloneBuilder_FreeSpace_P, accuracy_synth)
{
    SceneSynthesizer::Params sp;
    sp.model = (CameraModel)GetParam();
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    CloneBuilder::Params off;
    off.freeSpaceMinViews = 0;
    Ptr<CloneSet> hull = CloneBuilder::create(off)->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    CloneBuilder::Params flat;
    flat.freeSpacePlanarDeg = 0;
    Ptr<CloneSet> flatClones =
        CloneBuilder::create(flat)->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    for (const String& name : clones->objectNames())
    {
        const SynthFigures f0 = measureSynth(*hull, s, name), f = measureSynth(*clones, s, name);
        const DepthFigures d0 = measureDepth(*hull, s, name), d = measureDepth(*clones, s, name);
        const DepthFigures dflat = measureDepth(*flatClones, s, name);
        printPhoto((cameraModelName(sp.model) + " silhouettes").c_str(), name, f0, d0);
        printPhoto((cameraModelName(sp.model) + " flat free  ").c_str(), name,
                   measureSynth(*flatClones, s, name), dflat);
        printPhoto((cameraModelName(sp.model) + " free space ").c_str(), name, f, d);
        EXPECT_LE(d.meanAbs, kFreeSpacePlanarDepthRatio * dflat.meanAbs) << name;
        EXPECT_GE(f.keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(f.recall, f0.recall - kFreeSpaceMaxRecallLoss) << name;
        EXPECT_GE(f.nonKeyMean, f0.nonKeyMean - kFreeSpaceMaxIoULoss) << name;
        EXPECT_LE(d.meanAbs, kFreeSpaceMaxDepthRatio * d0.meanAbs) << name;
        if (name == "lblock")
        {
            EXPECT_LE(d.meanAbs, kFreeSpaceLblockDepthRatio * d0.meanAbs);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_CloneBuilder_FreeSpace_P,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

// Wrong points (a structure-from-motion mistake that the reprojection filter does not catch in
// every frame): 10% of the points pushed 30 voxels deeper along the first camera's line of sight.
// A triangle is free only in front of its nearest corner and only where its observations agree
// with their points, so the clones must lose nothing of their silhouettes. Measured 2026-12-01
// (76 wrong points): recall building 0.99941 -> 0.99928, lblock 0.99906 -> 0.99922, tower
// 0.99698 -> 0.99826 (the boxes change with the points; no silhouette is eaten).
const double kWrongPointsFraction = 0.1;
const double kWrongPointsDepthVoxels = 30;

TEST(Augocc_CloneBuilder_FreeSpace, robust_to_wrong_points)
{
    SyntheticScene s;
    SceneSynthesizer::create()->synthesize(s);
    CloneBuilder::Params off;
    off.freeSpaceMinViews = 0;
    Ptr<CloneSet> hull = CloneBuilder::create(off)->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    Reconstruction rec = s.groundTruth;
    rec.points = rec.points.clone();
    const Vec3d dir = rec.cameras.front().viewDirection();
    const double h = hull->voxelSize("building");
    RNG rng(7);
    int moved = 0;
    for (int p = 0; p < rec.points.rows; p++)
        if (std::isfinite(rec.points.at<double>(p, 0)) && rng.uniform(0.0, 1.0) < kWrongPointsFraction)
        {
            for (int c = 0; c < 3; c++)
                rec.points.at<double>(p, c) += kWrongPointsDepthVoxels * h * dir[c];
            moved++;
        }
    ASSERT_GT(moved, 20);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(rec, s.keyFrameMasks, &s.tracks);
    for (const String& name : clones->objectNames())
    {
        const SynthFigures f0 = measureSynth(*hull, s, name), f = measureSynth(*clones, s, name);
        std::cout << name << ": recall " << f0.recall << " -> " << f.recall << ", non-key IoU "
                  << f0.nonKeyMean << " -> " << f.nonKeyMean << " with " << moved
                  << " wrong points" << std::endl;
        EXPECT_GE(f.keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(f.recall, f0.recall - kFreeSpaceMaxRecallLoss) << name;
        EXPECT_GE(f.nonKeyMean, f0.nonKeyMean - kFreeSpaceMaxIoULoss) << name;
    }
}

// Real data: the Oxford dinosaur (36-view turntable, VGG's tracks, student-made silhouettes; see
// its SOURCE.txt). Cameras from recoverCameras() on the tracks, every fourth view a key frame, the
// other 27 held out: free-space carving from the real tracks must not eat into the real
// silhouettes it has not seen.
TEST(Augocc_CloneBuilder_FreeSpace, oxford_dinosaur_held_out)
{
    AUGOCC_REQUIRE_SHARED_DATA(path, "oxford_dinosaur/tracks.yml");
    AUGOCC_REQUIRE_SHARED_DATA(dir, "oxford_dinosaur/silhouettes");
    const Tracks tracks = readTracks(path);
    const Reconstruction rec = recoverCameras(tracks, SfmOptions());
    std::map<int, Mat> sil;
    for (const Camera& cam : rec.cameras)
    {
        const Mat m = imread(cv::format("%s/sil.%03d.png", dir.c_str(), cam.frame), IMREAD_GRAYSCALE);
        ASSERT_FALSE(m.empty()) << cam.frame;
        ASSERT_EQ(m.size(), rec.imageSize);
        // The masks have segmentation strips along the image borders (SOURCE.txt): keep the
        // largest connected component, the dinosaur.
        Mat labels, stats, centroids;
        const int nl = connectedComponentsWithStats(m > 127, labels, stats, centroids, 8);
        int best = 1;
        for (int l = 2; l < nl; l++)
            if (stats.at<int>(l, CC_STAT_AREA) > stats.at<int>(best, CC_STAT_AREA))
                best = l;
        ASSERT_GT(nl, 1);
        sil[cam.frame] = labels == best;
    }
    ObjectMasks masks;
    for (const auto& fm : sil)
        if (fm.first % 4 == 0)
            masks["dino"][fm.first] = fm.second;
    CloneBuilder::Params off;
    off.freeSpaceMinViews = 0;
    Ptr<CloneSet> hull = CloneBuilder::create(off)->build(rec, masks, &tracks);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(rec, masks, &tracks);
    double iou[2] = {0, 0}, recall[2] = {0, 0}, worst = 1;
    int n = 0;
    for (const auto& fm : sil)
    {
        if (fm.first % 4 == 0)
            continue;
        const Camera& cam = rec.camera(fm.first);
        for (int q = 0; q < 2; q++)
        {
            Mat m;
            (q ? clones : hull)->render("dino", fm.first, cam, rec.imageSize, m);
            iou[q] += maskIoU(m, fm.second);
            if (q == 1)
            {
                worst = std::min(worst, maskIoU(m, fm.second));
            }
            recall[q] += (double)countNonZero(m & fm.second) / std::max(1, countNonZero(fm.second));
        }
        n++;
    }
    ASSERT_GT(n, 0);
    std::cout << "oxford dinosaur, " << n << " held-out views: IoU " << iou[0] / n << " -> "
              << iou[1] / n << ", recall " << recall[0] / n << " -> " << recall[1] / n
              << " (silhouettes only -> with free space), worst view " << worst << "; voxels "
              << hull->voxelCount("dino")
              << " -> " << clones->voxelCount("dino") << std::endl;
    EXPECT_GE(recall[1] / n, recall[0] / n - kFreeSpaceRealRecallLoss);
    EXPECT_GE(iou[1] / n, iou[0] / n - kFreeSpaceRealIoULoss);
}

TEST(Augocc_CloneBuilder_FreeSpace, multithread_reproducibility)
{
    SceneSynthesizer::Params sp;
    sp.frames = 24;
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    const int threads = getNumThreads();
    setNumThreads(1);
    Ptr<CloneSet> a = CloneBuilder::create()->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    setNumThreads(std::max(threads, 4));
    Ptr<CloneSet> b = CloneBuilder::create()->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    setNumThreads(threads);
    for (const String& name : a->objectNames())
    {
        EXPECT_EQ(a->voxelCount(name), b->voxelCount(name)) << name;
        ObjectMasks ma, mb;
        renderMattes(*a, s.groundTruth, ma);
        renderMattes(*b, s.groundTruth, mb);
        for (const auto& fm : ma[name])
            EXPECT_EQ(countNonZero(fm.second != mb[name][fm.first]), 0) << name << " " << fm.first;
    }
}

// Figures and debug images (/tmp/photo_*.png: matte errors before | after, red = matte outside
// the truth, green = truth missed; depth errors) for both camera models and a parameter set from
// the environment (AUGOCC_PHOTO_T, _A, _PATCH).
TEST(Augocc_CloneBuilder_Photo, DISABLED_experiment)
{
    for (CameraModel model : {SCALED_ORTHOGRAPHIC, PERSPECTIVE})
    {
        SceneSynthesizer::Params sp;
        sp.model = model;
        SyntheticScene s;
        SceneSynthesizer::create(sp)->synthesize(s);
        CloneBuilder::Params p;
        if (getenv("AUGOCC_PHOTO_T"))
            p.photoThreshold = atof(getenv("AUGOCC_PHOTO_T"));
        if (getenv("AUGOCC_PHOTO_A"))
            p.photoMinAgreement = atof(getenv("AUGOCC_PHOTO_A"));
        if (getenv("AUGOCC_PHOTO_PATCH"))
            p.photoPatchStep = atoi(getenv("AUGOCC_PHOTO_PATCH"));
        Ptr<CloneBuilder> b = CloneBuilder::create(p);
        Ptr<CloneSet> clones = b->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
        const String m = cameraModelName(model);
        for (const String& name : clones->objectNames())
            printPhoto(("before " + m).c_str(), name, measureSynth(*clones, s, name),
                       measureDepth(*clones, s, name, "/tmp/photo_depth_" + name + ".png"));
        ObjectMasks m0;
        renderMattes(*clones, s.groundTruth, m0);
        const int64 t0 = getTickCount();
        const int64 n = b->refine(*clones, s.groundTruth, s.frames);
        std::cout << "refine: " << n << " voxels carved in "
                  << (getTickCount() - t0) * 1000.0 / getTickFrequency() << " ms" << std::endl;
        for (const String& name : clones->objectNames())
            printPhoto(("after  " + m).c_str(), name, measureSynth(*clones, s, name),
                       measureDepth(*clones, s, name, "/tmp/photo_depth_" + name + "_after.png"));
        ObjectMasks m1;
        renderMattes(*clones, s.groundTruth, m1);
        for (int f : {5, 30, 50})
            for (const String& name : clones->objectNames())
            {
                Mat img[2];
                const Mat& whole = s.wholeMasks.at(name).at(f);
                const Mat* mm[2] = {&m0[name][f], &m1[name][f]};
                for (int q = 0; q < 2; q++)
                {
                    img[q] = s.frames[f] / 2;
                    img[q].setTo(Scalar(0, 0, 255), *mm[q] & ~whole);
                    img[q].setTo(Scalar(0, 255, 0), whole & ~*mm[q]);
                }
                Mat both;
                hconcat(img[0], img[1], both);
                imwrite(cv::format("/tmp/photo_%s_%02d.png", name.c_str(), f), both);
            }
    }
}

TEST(Augocc_CloneBuilder_Photo, multithread_reproducibility)
{
    SceneSynthesizer::Params sp;
    sp.model = PERSPECTIVE;  // the perspective sweep test; the accuracy test is orthographic
    sp.frames = 16;
    sp.imageSize = Size(320, 240);
    sp.numKeyFrames = 4;
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    Ptr<CloneBuilder> b = CloneBuilder::create();
    const int threads = getNumThreads();
    Ptr<CloneSet> sets[2];
    int64 carved[2];
    for (int q = 0; q < 2; q++)
    {
        // Many threads first: under TBB a later request above an earlier limit is ignored.
        setNumThreads(q == 0 ? std::max(threads, 4) : 1);
        sets[q] = b->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
        carved[q] = b->refine(*sets[q], s.groundTruth, s.frames);
    }
    setNumThreads(threads);
    EXPECT_GT(carved[0], 0);
    EXPECT_EQ(carved[0], carved[1]);
    for (const String& name : sets[0]->objectNames())
    {
        EXPECT_EQ(sets[0]->voxelCount(name), sets[1]->voxelCount(name)) << name;
        for (int k : sets[0]->keyFrames(name))
            EXPECT_EQ(sets[0]->patchVoxelCount(name, k), sets[1]->patchVoxelCount(name, k));
        for (const Camera& cam : s.groundTruth.cameras)
        {
            Mat m0, m1, d0, d1;
            sets[0]->render(name, cam.frame, cam, s.groundTruth.imageSize, m0, d0);
            sets[1]->render(name, cam.frame, cam, s.groundTruth.imageSize, m1, d1);
            EXPECT_EQ(countNonZero(m0 != m1), 0) << name << " frame " << cam.frame;
            EXPECT_EQ(countNonZero(d0 != d1), 0) << name << " frame " << cam.frame;
        }
    }
}

TEST(Augocc_CloneBuilder_Photo, bad_arg)
{
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 6, 3);
    Ptr<CloneBuilder> b = CloneBuilder::create();
    Ptr<CloneSet> clones = b->build(s.rec, s.keyMasks);
    const Size size = s.rec.imageSize;
    std::vector<Mat> good(6);
    for (Mat& m : good)
        m = Mat(size, CV_8UC3, Scalar(90, 120, 60));
    auto throwsNaming = [&](const std::vector<Mat>& frames, const std::string& what) {
        try
        {
            b->refine(*clones, s.rec, frames);
        }
        catch (const cv::Exception& e)
        {
            return e.msg.find(what) != std::string::npos
                       ? ::testing::AssertionSuccess()
                       : ::testing::AssertionFailure() << "message: " << e.msg;
        }
        return ::testing::AssertionFailure() << "no exception";
    };
    EXPECT_TRUE(throwsNaming(std::vector<Mat>(), "no frames"));
    EXPECT_TRUE(throwsNaming(std::vector<Mat>(good.begin(), good.begin() + 4),
                             "camera for frame 4 but 4 frames"));
    std::vector<Mat> f = good;
    f[2] = Mat();
    EXPECT_TRUE(throwsNaming(f, "frame 2 is empty"));
    f = good;
    f[3] = Mat(size.height / 2, size.width, CV_8UC3, Scalar::all(0));
    EXPECT_TRUE(throwsNaming(f, "frame 3 is"));
    f = good;
    f[1] = Mat(size, CV_32FC3, Scalar::all(0));
    EXPECT_TRUE(throwsNaming(f, "frame 1 must be CV_8UC3"));
    CloneBuilder::Params p;
    p.photoMinAgreement = 0;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.photoMinViews = 1;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.photoMaxViews = p.photoMinViews - 1;  // fewer views than a decision needs
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p.photoMaxViews = -1;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    // Uniform frames: every voxel is consistent, nothing is carved and the clone is unchanged.
    const int before = clones->voxelCount("tower");
    EXPECT_EQ(b->refine(*clones, s.rec, good), 0);
    EXPECT_EQ(clones->voxelCount("tower"), before);
}

} // namespace
} // namespace opencv_test
