// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// CloneSet: the clones file and the mattes folder.

#include "test_clone_scenes.hpp"

#include <filesystem>
#include <fstream>

namespace opencv_test {
namespace {

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

// writeMattes() streams batches of frames (a bounded number of mattes in memory): over several
// batches every file equals renderMattes()'s matte and depth of that frame, and no temporary is
// left beside the two folders.
TEST(Augocc_CloneBuilder, write_mattes_streams_every_frame)
{
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 40, 3);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
    ObjectMasks ref;
    std::map<String, std::map<int, Mat> > refDepth;
    renderMattes(*clones, s.rec, ref, &refDepth);
    const std::string dir = tempDir("clone_mattes_stream");
    int reports = 0;
    writeMattes(dir + "/mattes", *clones, s.rec, dir + "/depth",
                [&](const Progress&) { reports++; });
    EXPECT_GE(reports, 3);  // 40 frames: more than one batch (at most 4 x threads, at least 8)
    const ObjectMasks m = readMasks(dir + "/mattes", s.rec.imageSize);
    ASSERT_EQ(ref.size(), m.size());
    for (const auto& o : ref)
    {
        ASSERT_EQ(o.second.size(), m.at(o.first).size()) << o.first;
        for (const auto& f : o.second)
        {
            EXPECT_EQ(0, countNonZero(f.second != m.at(o.first).at(f.first)))
                << o.first << " frame " << f.first;
            const Mat d = imread(cv::format("%s/depth/%s/%04d.tiff", dir.c_str(),
                                            o.first.c_str(), f.first), IMREAD_UNCHANGED);
            ASSERT_EQ(CV_32FC1, d.type());
            EXPECT_EQ(0, countNonZero(d != refDepth.at(o.first).at(f.first)))  // +inf == +inf
                << o.first << " frame " << f.first;
        }
    }
    int entries = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir))
    {
        CV_UNUSED(e);
        entries++;
    }
    EXPECT_EQ(2, entries);  // mattes and depth, no temporary
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace opencv_test
