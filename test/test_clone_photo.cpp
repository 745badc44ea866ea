// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// refine(): photo-consistency carving.

#include "test_clone_scenes.hpp"
#include <opencv2/calib3d.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace opencv_test {
namespace {

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

TEST(Augocc_CloneBuilder_Photo, accuracy_synth)
{
    SyntheticScene s;
    SceneSynthesizer::create()->synthesize(s);
    CloneBuilder::Params p;
    p.freeSpace.minViews = 0;  // photo-consistency alone (free space: Augocc_CloneBuilder_FreeSpace)
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
            p.photo.threshold = atof(getenv("AUGOCC_PHOTO_T"));
        if (getenv("AUGOCC_PHOTO_A"))
            p.photo.minAgreement = atof(getenv("AUGOCC_PHOTO_A"));
        if (getenv("AUGOCC_PHOTO_PATCH"))
            p.photo.patchStep = atoi(getenv("AUGOCC_PHOTO_PATCH"));
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

TEST(Augocc_CloneBuilder_Photo, reads_only_the_frames_it_compares)
{
    // Issue 16 (streaming): refine() needs only photoFrames(); given those alone (the others
    // empty) it carves exactly what it carves with every frame, and it names a missing one.
    SceneSynthesizer::Params sp;
    sp.frames = 16;
    sp.imageSize = Size(240, 180);
    sp.numKeyFrames = 4;
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    CloneBuilder::Params p;
    p.photo.maxViews = 6;  // fewer than the 16 cameras, so some frames are not compared
    Ptr<CloneBuilder> b = CloneBuilder::create(p);
    const std::vector<int> used = b->photoFrames(s.groundTruth);
    ASSERT_EQ(6u, used.size());
    EXPECT_EQ(s.groundTruth.cameras.front().frame, used.front());
    EXPECT_EQ(s.groundTruth.cameras.back().frame, used.back());
    for (size_t i = 1; i < used.size(); i++)
        EXPECT_LT(used[i - 1], used[i]);
    std::vector<Mat> sparse(s.frames.size());
    for (int f : used)
        sparse[f] = s.frames[f];
    Ptr<CloneSet> all = b->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    Ptr<CloneSet> few = b->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    const int64 carvedAll = b->refine(*all, s.groundTruth, s.frames);
    const int64 carvedFew = b->refine(*few, s.groundTruth, sparse);
    EXPECT_GT(carvedAll, 0);
    EXPECT_EQ(carvedAll, carvedFew);
    for (const String& name : all->objectNames())
        EXPECT_EQ(all->voxelCount(name), few->voxelCount(name)) << name;
    sparse[used[3]] = Mat();
    try
    {
        b->refine(*few, s.groundTruth, sparse);
        ADD_FAILURE() << "no exception for a missing compared frame";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_NE(std::string::npos, e.msg.find(cv::format("frame %d is empty", used[3])))
            << e.msg;
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
    p.photo.minAgreement = 0;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.photo.minViews = 1;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p = CloneBuilder::Params();
    p.photo.maxViews = p.photo.minViews - 1;  // fewer views than a decision needs
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    p.photo.maxViews = -1;
    EXPECT_THROW(CloneBuilder::create(p), cv::Exception);
    // Uniform frames: every voxel is consistent, nothing is carved and the clone is unchanged.
    const int before = clones->voxelCount("tower");
    EXPECT_EQ(b->refine(*clones, s.rec, good), 0);
    EXPECT_EQ(clones->voxelCount("tower"), before);
}

} // namespace
} // namespace opencv_test
