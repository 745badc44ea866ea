// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// CloneBuilder as a whole: build() on analytic, synthesized and real scenes, parameters, the CLI.

#include "test_clone_scenes.hpp"
#include <opencv2/calib3d.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace opencv_test {
namespace {

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
    p.box.orientation = CloneBuilder::ORIENT_USER;
    p.box.userRotation = Vec3d(0, 20 * CV_PI / 180, 0);
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
    EXPECT_EQ(b->getParams().box.orientation, (int)CloneBuilder::ORIENT_AUTO);
    EXPECT_EQ(b->getParams().voxelPixels, 1.0);
}

TEST(Augocc_CloneBuilder, bad_arg)
{
    CloneBuilder::Params p;
    p.voxelPixels = 0;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.patches.raysPerPixel = 0;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.freeSpace.minViews = -1;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.freeSpace.edgeMargin = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.freeSpace.planarDeg = 91;
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

// Objects of the synthesized scene hidden by more than this fraction in the key frames on average
// count as "hidden" for the occlusion target (mean IoU 0.97 instead of 0.98).
const double kHiddenObjectFraction = 0.02;
// Hidden objects, mean IoU with the WHOLE true silhouette (as if alone) in non-key frames: the
// issue's 0.97. History (orthographic / perspective): voxels no key frame shows dropped: lblock
// 0.972 / 0.979, tower 0.959 / 0.959 (0.914 / 0.846 before); free-space carving: tower 0.964 /
// 0.967 (the rest is behind the building in every frame and behind the tower's own shaft in the
// others); vertical runs no frame sees dropped (2026-12-01): tower 0.972 / 0.981, lblock
// 0.972 / 0.980; trimmed points given back at box faces no key frame sees (2026-12-02): tower
// 0.972 / 0.981, lblock 0.976 / 0.978.
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
        p.patches.rule = rule;
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
    // 0.928 -> 0.958, 3.0M voxels carved; photo.minViews 8 carves nothing here, a sweep has at
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
        Mat m(F, P, CV_32FC2);
        for (int f = 0; f < F; f++)
            for (int p = 0; p < P; p++)
            {
                const Point2d q = s.rec.project(f, Vec3d(s.rec.points.ptr<double>(p)));
                m.at<Vec2f>(f, p) = Vec2f((float)q.x, (float)q.y);
            }
        writeTracks(dir + "/tracks.yml", Tracks::fromDense(s.rec.imageSize, m));
        writeTracks(dir + "/half.yml", Tracks::fromDense(s.rec.imageSize, m.colRange(0, P / 2)));
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
