// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Per-object clone parts (issue 21 item 1: clone jobs per object on a farm): buildPart() of each
// object, saved, loaded and merged by mergeParts(), is build()'s set bit for bit; the merge
// refuses parts that do not belong together; a partial clones file is refused by what renders.

#include "test_clone_scenes.hpp"
#include "test_common.hpp"
#include "clone/clone_set.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>

namespace opencv_test {
namespace {

namespace fs = std::filesystem;

std::string fileBytes(const std::string& path)
{
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

// The message of the cv::Exception `fn` throws ("no error" when it returns).
template <typename Fn>
std::string errorOf(Fn fn)
{
    try
    {
        fn();
    }
    catch (const cv::Exception& e)
    {
        return e.err;
    }
    return "no error";
}

// Every voxel, patch voxel, silhouette and pose of two sets equal (what a file holds, decoded).
void expectSameClones(const CloneSet& a, const CloneSet& b)
{
    const auto& ia = dynamic_cast<const cv::augocc::detail::CloneSetImpl&>(a);
    const auto& ib = dynamic_cast<const cv::augocc::detail::CloneSetImpl&>(b);
    EXPECT_FALSE(ia.isPartial());
    EXPECT_FALSE(ib.isPartial());
    EXPECT_EQ(ia.patchRule, ib.patchRule);
    ASSERT_EQ(ia.objectNames(), ib.objectNames());
    for (const auto& it : ia.objects())
    {
        const cv::augocc::detail::ObjectClone& x = it.second;
        const cv::augocc::detail::ObjectClone& y = ib.get(it.first);
        EXPECT_EQ(x.grid.dims, y.grid.dims) << it.first;
        EXPECT_EQ(x.grid.h, y.grid.h) << it.first;
        EXPECT_EQ(x.grid.origin, y.grid.origin) << it.first;
        EXPECT_EQ(norm(Mat(x.grid.Rbox), Mat(y.grid.Rbox), NORM_INF), 0) << it.first;
        EXPECT_EQ(x.centre, y.centre) << it.first;
        EXPECT_TRUE(x.grid.data == y.grid.data) << it.first << ": voxels differ";
        EXPECT_TRUE(x.surface.ijk == y.surface.ijk) << it.first << ": surfaces differ";
        ASSERT_EQ(x.masks.size(), y.masks.size()) << it.first;
        for (const auto& m : x.masks)
            EXPECT_EQ(countNonZero(m.second != y.masks.at(m.first)), 0) << it.first;
        EXPECT_TRUE(x.patches == y.patches) << it.first << ": patch voxels differ";
    }
}

struct PartsCase
{
    const char* name;
    CameraModel model;
    std::vector<double> distortion;
    bool tracks;
};

void PrintTo(const PartsCase& c, std::ostream* os)
{
    *os << c.name;
}

typedef testing::TestWithParam<PartsCase> Augocc_CloneParts_P;

// The synthesized scene (building in front of the tower, an L-block: occlusion-aware carving
// needs the others' silhouettes and depth order) at a small size.
SyntheticScene smallScene(const PartsCase& c)
{
    SceneSynthesizer::Params sp;
    sp.model = c.model;
    sp.frames = 24;
    sp.imageSize = Size(320, 240);
    sp.numTracks = 300;
    sp.numKeyFrames = 4;
    sp.distortion = c.distortion;
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    return s;
}

TEST_P(Augocc_CloneParts_P, regression_merged_equals_build)
{
    const PartsCase c = GetParam();
    const SyntheticScene s = smallScene(c);
    const Tracks* tracks = c.tracks ? &s.tracks : nullptr;
    ASSERT_GE(s.keyFrameMasks.size(), 2u);
    Ptr<CloneBuilder> builder = CloneBuilder::create();
    const std::string dir = tempDir(std::string("clone_parts_") + c.name);

    Ptr<CloneSet> whole = builder->build(s.groundTruth, s.keyFrameMasks, tracks);
    whole->save(dir + "/whole.yml.gz");

    // One part per object, each saved and loaded (as the farm's jobs do), merged in reverse.
    std::vector<Ptr<CloneSet> > parts, inMemory;
    for (const auto& o : s.keyFrameMasks)
    {
        Ptr<CloneSet> part = builder->buildPart(s.groundTruth, s.keyFrameMasks, {o.first}, tracks);
        ASSERT_TRUE(part->isPartial());
        EXPECT_EQ(part->objectNames(), std::vector<String>({o.first}));
        const std::string path = dir + "/" + o.first + ".yml.gz";
        part->save(path);
        parts.insert(parts.begin(), CloneSet::loadPart(path));
        inMemory.push_back(part);
    }
    Ptr<CloneSet> merged = builder->mergeParts(parts, s.groundTruth, s.keyFrameMasks, tracks);
    merged->save(dir + "/merged.yml.gz");
    expectSameClones(*whole, *merged);
    // The files byte for byte (FileStorage's gzip header holds no time stamp).
    const std::string a = fileBytes(dir + "/whole.yml.gz");
    EXPECT_FALSE(a.empty());
    EXPECT_TRUE(a == fileBytes(dir + "/merged.yml.gz")) << "merged file differs from build()'s";

    // Parts kept in memory, and two parts of unequal size, give the same set.
    expectSameClones(*whole, *builder->mergeParts(inMemory, s.groundTruth, s.keyFrameMasks,
                                                  tracks));
    std::vector<String> first, rest;
    for (const auto& o : s.keyFrameMasks)
        (first.empty() ? first : rest).push_back(o.first);
    Ptr<CloneSet> p1 = builder->buildPart(s.groundTruth, s.keyFrameMasks, first, tracks);
    Ptr<CloneSet> p2 = builder->buildPart(s.groundTruth, s.keyFrameMasks, rest, tracks);
    Ptr<CloneSet> two = builder->mergeParts({p2, p1}, s.groundTruth, s.keyFrameMasks, tracks);
    expectSameClones(*whole, *two);

    // Photo-consistency after the merge as after build() (refine() sees a set identical to
    // build()'s, so only checked once, where the frames are pinhole).
    if (c.distortion.empty() && c.tracks)
    {
        EXPECT_EQ(builder->refine(*whole, s.groundTruth, s.frames),
                  builder->refine(*merged, s.groundTruth, s.frames));
        expectSameClones(*whole, *merged);
    }
    fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_CloneParts_P,
                         testing::Values(PartsCase{"ortho_tracks", SCALED_ORTHOGRAPHIC, {}, true},
                                         PartsCase{"persp_tracks", PERSPECTIVE, {}, true},
                                         PartsCase{"persp_masks_only", PERSPECTIVE, {}, false},
                                         PartsCase{"lens_tracks", PERSPECTIVE,
                                                   {-0.1, 0.01, 0, 0}, true}),
                         [](const testing::TestParamInfo<PartsCase>& i) {
                             return std::string(i.param.name);
                         });

TEST(Augocc_CloneParts, bad_arg)
{
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, frontAndBack(), 8, 3);
    Ptr<CloneBuilder> builder = CloneBuilder::create();
    const Reconstruction& rec = s.rec;
    const ObjectMasks& masks = s.keyMasks;
    std::vector<String> names;
    for (const auto& o : masks)
        names.push_back(o.first);
    ASSERT_EQ(names.size(), 2u);
    const String a = names[0], b = names[1];
    Ptr<CloneSet> pa = builder->buildPart(rec, masks, {a});
    Ptr<CloneSet> pb = builder->buildPart(rec, masks, {b});
    ASSERT_NO_THROW(builder->mergeParts({pa, pb}, rec, masks));

    // buildPart: no object, an unknown object, one given twice.
    EXPECT_NE(errorOf([&] { builder->buildPart(rec, masks, {}); }).find("no object"),
              std::string::npos);
    EXPECT_NE(errorOf([&] { builder->buildPart(rec, masks, {"nothing"}); })
                  .find("object 'nothing' is not an object of the masks"), std::string::npos);
    EXPECT_NE(errorOf([&] { builder->buildPart(rec, masks, {a, a}); })
                  .find("object '" + a + "' is given twice"), std::string::npos);

    // The same object twice, an object missing, a complete set among the parts.
    EXPECT_NE(errorOf([&] { builder->mergeParts({pa, pb, pa}, rec, masks); })
                  .find("object '" + a + "' is in two parts"), std::string::npos);
    EXPECT_NE(errorOf([&] { builder->mergeParts({pb}, rec, masks); })
                  .find("object '" + a + "' of the masks is in no part"), std::string::npos);
    Ptr<CloneSet> whole = builder->build(rec, masks);
    EXPECT_NE(errorOf([&] { builder->mergeParts({pa, whole}, rec, masks); })
                  .find("a complete clone set"), std::string::npos);
    EXPECT_NE(errorOf([&] { builder->mergeParts({}, rec, masks); }).find("no part"),
              std::string::npos);

    // Parts of other inputs: parameters (named), reconstruction, masks, tracks.
    CloneBuilder::Params p;
    p.voxelPixels = 1.5;
    Ptr<CloneSet> pbOther = CloneBuilder::create(p)->buildPart(rec, masks, {b});
    const std::string params = errorOf([&] { builder->mergeParts({pa, pbOther}, rec, masks); });
    EXPECT_NE(params.find("built with other parameters"), std::string::npos) << params;
    EXPECT_NE(params.find("voxelPixels=1.5 (here voxelPixels=1)"), std::string::npos) << params;
    Reconstruction rec2 = rec;
    rec2.cameras[1].t[0] += 1e-9;
    EXPECT_NE(errorOf([&] { builder->mergeParts({pa, pb}, rec2, masks); })
                  .find("built from another reconstruction"), std::string::npos);
    ObjectMasks masks2 = masks;
    masks2[a].begin()->second = masks.at(a).begin()->second.clone();
    Mat& m = masks2[a].begin()->second;
    const Rect r = boundingRect(m);
    m.at<uchar>(r.y + r.height / 2, r.x) = 0;  // one pixel of one silhouette
    EXPECT_NE(errorOf([&] { builder->mergeParts({pa, pb}, rec, masks2); })
                  .find("built from other key-frame masks"), std::string::npos);
    Ptr<CloneSet> pbMasks2 = builder->buildPart(rec, masks2, {b});
    EXPECT_NE(errorOf([&] { builder->mergeParts({pa, pbMasks2}, rec, masks2); })
                  .find("part 1 (objects '" + a + "'): built from other key-frame masks"),
              std::string::npos);
    {
        const int F = (int)rec.cameras.size(), P = rec.points.rows;
        ASSERT_GT(P, 0);
        Mat d(F, P, CV_32FC2);
        for (int f = 0; f < F; f++)
            for (int q = 0; q < P; q++)
            {
                const Point2d x = rec.project(f, Vec3d(rec.points.ptr<double>(q)));
                d.at<Vec2f>(f, q) = Vec2f((float)x.x, (float)x.y);
            }
        const Tracks t = Tracks::fromDense(rec.imageSize, d);
        EXPECT_NE(errorOf([&] { builder->mergeParts({pa, pb}, rec, masks, &t); })
                      .find("built without tracks"), std::string::npos);
        Ptr<CloneSet> ta = builder->buildPart(rec, masks, {a}, &t);
        EXPECT_NE(errorOf([&] { builder->mergeParts({ta}, rec, masks); })
                      .find("built with tracks"), std::string::npos);
    }

    // A partial set is refused by what needs every object; its file by CloneSet::load().
    ObjectMasks mattes;
    EXPECT_NE(errorOf([&] { renderMattes(*pa, rec, mattes); }).find("a partial clone set"),
              std::string::npos);
    std::vector<Mat> frames(rec.cameras.size(), Mat(rec.imageSize, CV_8UC3, Scalar::all(128)));
    EXPECT_NE(errorOf([&] { builder->refine(*pa, rec, frames); }).find("a partial clone set"),
              std::string::npos);
    EXPECT_NE(errorOf([&] {
                  builder->addKeyFrame(*pa, rec, a, s.keyFrames[0], masks.at(a).begin()->second);
              }).find("a partial clone set"), std::string::npos);
    const std::string dir = tempDir("clone_parts_bad");
    const std::string partFile = dir + "/part.yml.gz", wholeFile = dir + "/whole.yml.gz";
    pa->save(partFile);
    whole->save(wholeFile);
    const std::string load = errorOf([&] { CloneSet::load(partFile); });
    EXPECT_EQ(load.rfind(partFile + ": a partial clones file (objects '" + a + "'", 0), 0u)
        << load;
    EXPECT_NE(load.find("augocc clone --merge"), std::string::npos) << load;
    EXPECT_EQ(errorOf([&] { CloneSet::loadPart(wholeFile); })
                  .rfind(wholeFile + ": a complete clones file", 0), 0u);
    // A loaded part is named by its file in the merge's messages.
    Ptr<CloneSet> loaded = CloneSet::loadPart(partFile);
    EXPECT_NE(errorOf([&] { builder->mergeParts({loaded, pa, pb}, rec, masks); })
                  .find("is in two parts: " + partFile + " and part 2"), std::string::npos);
    fs::remove_all(dir);
}

// augocc clone --object per object, then clone --merge: the file plain clone writes, byte for
// byte; a partial file given to matte, a missing part, --input on a part: exit 2.
TEST(Augocc_CloneParts, cli_object_and_merge)
{
    const std::string dir = tempDir("clone_parts_cli");
    const std::string d = dir + "/";
    const std::string a = augoccBinary() + " --quiet ";
    std::string out;
    ASSERT_EQ(runCommand(a + "synth --out " + d + "src --frames 8 --size 96x72", &out), 0) << out;
    ASSERT_EQ(runCommand(a + "track --input " + d + "src/video.mp4 --out " + d + "t.yml", &out),
              0) << out;
    ASSERT_EQ(runCommand(a + "sfm --tracks " + d + "t.yml --out " + d + "r.yml", &out), 0) << out;
    const std::string clone = a + "clone --reconstruction " + d + "r.yml --masks " + d +
                              "src/input/masks --tracks " + d + "t.yml ";
    ASSERT_EQ(runCommand(clone + "--input " + d + "src/video.mp4 --out " + d + "whole.yml.gz",
                         &out), 0) << out;
    std::vector<std::string> objects;
    for (const auto& e : fs::directory_iterator(dir + "/src/input/masks"))
        if (e.is_directory())
            objects.push_back(e.path().filename().string());
    std::sort(objects.begin(), objects.end());
    ASSERT_GE(objects.size(), 2u);
    std::string parts;
    for (const std::string& o : objects)
    {
        ASSERT_EQ(runCommand(clone + "--object " + o + " --out " + d + o + ".yml.gz", &out), 0)
            << out;
        parts += " " + d + o + ".yml.gz";
    }
    ASSERT_EQ(runCommand(clone + "--input " + d + "src/video.mp4 --out " + d + "merged.yml.gz "
                         "--merge" + parts, &out), 0) << out;
    EXPECT_TRUE(fileBytes(d + "whole.yml.gz") == fileBytes(d + "merged.yml.gz"))
        << "clone --merge of the parts differs from plain clone";
    // Two objects in one part, the rest in another: the same file.
    std::string others;
    for (size_t i = 1; i < objects.size(); i++)
        others += " --object " + objects[i];
    ASSERT_EQ(runCommand(clone + others + " --out " + d + "rest.yml.gz", &out), 0) << out;
    ASSERT_EQ(runCommand(clone + "--input " + d + "src/video.mp4 --out " + d + "m2.yml.gz "
                         "--merge " + d + "rest.yml.gz " + d + objects[0] + ".yml.gz", &out), 0)
        << out;
    EXPECT_TRUE(fileBytes(d + "whole.yml.gz") == fileBytes(d + "m2.yml.gz"));

    // A partial file given to matte: exit 2 naming the file, no output.
    const std::string part0 = d + objects[0] + ".yml.gz";
    EXPECT_EQ(runCommand(a + "matte --reconstruction " + d + "r.yml --clones " + part0 +
                         " --out " + d + "mattes", &out), 2);
    EXPECT_NE(out.find(part0 + ": a partial clones file"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(d + "mattes"));
    // A part missing, a part twice, --merge of a complete file, parts of other flags.
    EXPECT_EQ(runCommand(clone + "--out " + d + "bad.yml.gz --merge " + part0, &out), 2);
    EXPECT_NE(out.find("of the masks is in no part"), std::string::npos) << out;
    EXPECT_EQ(runCommand(clone + "--out " + d + "bad.yml.gz --merge" + parts + " " + part0,
                         &out), 2);
    EXPECT_NE(out.find("is in two parts"), std::string::npos) << out;
    EXPECT_EQ(runCommand(clone + "--out " + d + "bad.yml.gz --merge " + d + "whole.yml.gz", &out),
              2);
    EXPECT_NE(out.find("a complete clones file"), std::string::npos) << out;
    EXPECT_EQ(runCommand(clone + "--voxel-pixels 2 --out " + d + "bad.yml.gz --merge" + parts,
                         &out), 2);
    EXPECT_NE(out.find("built with other parameters"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(d + "bad.yml.gz"));
    // Usage errors: --object with --input or --merge, an unknown or repeated object.
    EXPECT_EQ(runCommand(clone + "--object " + objects[0] + " --input " + d + "src/video.mp4 "
                         "--out " + d + "bad.yml.gz", &out), 2);
    EXPECT_NE(out.find("--input"), std::string::npos) << out;
    EXPECT_EQ(runCommand(clone + "--object " + objects[0] + " --out " + d + "bad.yml.gz --merge" +
                         parts, &out), 2);
    EXPECT_NE(out.find("--object, --merge"), std::string::npos) << out;
    EXPECT_EQ(runCommand(clone + "--object nothing --out " + d + "bad.yml.gz", &out), 2);
    EXPECT_NE(out.find("--object nothing: no such object"), std::string::npos) << out;
    EXPECT_EQ(runCommand(clone + "--object " + objects[0] + " --object " + objects[0] +
                         " --out " + d + "bad.yml.gz", &out), 2);
    EXPECT_NE(out.find("given twice"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(d + "bad.yml.gz"));
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test
