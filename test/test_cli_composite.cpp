// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Bad inputs of `augocc composite` and `augocc run`, through the built binary: each must exit 2
// with one message naming the file or flag and the problem, and leave no output behind (not even
// a partial video or PNG under a temporary name).

#include "test_precomp.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace opencv_test
{
namespace
{
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

// A small valid data set: a 6-frame 160x120 synthetic sequence as an MJPG AVI and as PNGs, its
// true reconstruction, clones built from it, key-frame masks and the demo's scene file.
struct CliData
{
    String dir, video, frames, rec, clones, scene, masks;
    int frameCount = 0;
    Size size;
    bool ok = false;
};

const int kFrames = 6;

void writeAvi(const String& path, const std::vector<Mat>& frames, int count)
{
    VideoWriter w(path, CAP_FFMPEG, VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, frames[0].size(),
                  true);
    ASSERT_TRUE(w.isOpened()) << path;
    for (int i = 0; i < count; i++)
        w.write(frames[i]);
}

void writeText(const String& path, const String& text)
{
    std::ofstream f(path, std::ios::binary);
    f << text;
}

const CliData& cliData()
{
    static CliData d;
    if (d.ok)
        return d;
    // One folder per process: CTest runs each test in its own process, two at a time.
    d.dir = (fs::temp_directory_path() / "augocc_test" /
             cv::format("Augocc_CliComposite.%d", (int)getpid()))
                .string();
    fs::remove_all(d.dir);
    fs::create_directories(d.dir);
    SceneSynthesizer::Params sp;
    sp.frames = kFrames;
    sp.imageSize = Size(160, 120);
    sp.numKeyFrames = 2;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    d.size = sp.imageSize;
    d.frameCount = kFrames;
    const fs::path dir(d.dir);
    d.video = (dir / "video.avi").string();
    writeAvi(d.video, scene.frames, kFrames);
    d.frames = (dir / "frames").string();
    fs::create_directories(d.frames);
    for (int f = 0; f < kFrames; f++)
        imwrite((fs::path(d.frames) / cv::format("%04d.png", f)).string(), scene.frames[f]);
    d.rec = (dir / "reconstruction.yml").string();
    writeReconstruction(d.rec, scene.groundTruth);
    d.masks = (dir / "masks").string();
    writeMasks(d.masks, scene.keyFrameMasks);
    d.clones = (dir / "clones.yml.gz").string();
    CloneBuilder::create()->build(scene.groundTruth, scene.keyFrameMasks)->save(d.clones);
    d.scene = (dir / "scene.yml").string();
    writeScene(d.scene, demoVirtualScene(d.scene));
    d.ok = true;
    return d;
}

String q(const String& s)
{
    return "'" + s + "'";
}

// Every entry of a folder, recursively (hidden temporaries included).
std::vector<String> listAll(const String& dir)
{
    std::vector<String> out;
    if (!fs::exists(dir))
        return out;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        out.push_back(e.path().string());
    return out;
}

String joined(const std::vector<String>& v)
{
    String s;
    for (const String& x : v)
        s += x + " ";
    return s;
}

// Runs the command; success when it exits 2 with one message that contains every `needles`
// entry and leaves the output folder empty.
testing::AssertionResult badInputRejected(const String& args, const std::vector<String>& needles,
                                          const String& outDir)
{
    String output;
    const int status = runCommand(augoccBinary() + " " + args, &output);
    if (status != 2)
        return testing::AssertionFailure()
               << "exit status " << status << ", expected 2: " << args << "\n"
               << output;
    for (const String& n : needles)
        if (output.find(n) == String::npos)
            return testing::AssertionFailure() << "message should name '" << n << "': " << output;
    const std::vector<String> left = listAll(outDir);
    if (!left.empty())
        return testing::AssertionFailure() << "output left behind: " << joined(left);
    return testing::AssertionSuccess();
}

class Augocc_CliComposite : public testing::Test
{
protected:
    void SetUp() override
    {
        const CliData& d = cliData();
        ASSERT_TRUE(d.ok);
        out_ = tempDir("out");
    }

    // `augocc composite` with the valid data set, some of it replaced.
    String compositeArgs(const String& input, const String& rec, const String& scene,
                         const String& out, const String& extra = "") const
    {
        const CliData& d = cliData();
        return "--quiet composite --input " + q(input) + " --reconstruction " + q(rec) +
               " --clones " + q(d.clones) + " --scene " + q(scene) + " --out " + q(out) + " " +
               extra;
    }

    String out_;
};

TEST_F(Augocc_CliComposite, valid_inputs_write_the_outputs)
{
    // The data set itself is good: the bad cases below fail for their own reason.
    const CliData& d = cliData();
    const String mp4 = (fs::path(out_) / "out.mp4").string();
    String output;
    ASSERT_EQ(
        0, runCommand(augoccBinary() + " " +
                          compositeArgs(d.video, d.rec, d.scene, mp4, "--frames 1:4 --hard-edges"),
                      &output))
        << output;
    VideoCapture cap(mp4);
    ASSERT_TRUE(cap.isOpened());
    EXPECT_EQ(3, (int)cap.get(CAP_PROP_FRAME_COUNT));
    const String pngs = (fs::path(out_) / "pngs").string();
    ASSERT_EQ(0, runCommand(augoccBinary() + " " +
                                compositeArgs(d.frames, d.rec, d.scene, pngs, "--frames 4:"),
                            &output))
        << output;
    EXPECT_TRUE(fs::exists(fs::path(pngs) / "0004.png"));
    EXPECT_TRUE(fs::exists(fs::path(pngs) / "0005.png"));
    EXPECT_EQ(4u, listAll(out_).size()) << joined(listAll(out_)); // out.mp4, pngs, 2 PNGs
}

TEST_F(Augocc_CliComposite, bad_input_missing_video)
{
    const CliData& d = cliData();
    const String missing = (fs::path(out_).parent_path() / "no_such_video.mp4").string();
    EXPECT_TRUE(badInputRejected(compositeArgs(missing, d.rec, d.scene, out_ + "/out.mp4"),
                                 {"no_such_video.mp4"}, out_));
}

TEST_F(Augocc_CliComposite, bad_input_corrupt_video)
{
    const CliData& d = cliData();
    const String bad = tempDir("in") + "/corrupt.mp4";
    writeText(bad, String(4096, '\x5a'));
    EXPECT_TRUE(badInputRejected(compositeArgs(bad, d.rec, d.scene, out_ + "/out.mp4"),
                                 {"corrupt.mp4"}, out_));
    EXPECT_TRUE(badInputRejected(compositeArgs(bad, d.rec, d.scene, out_ + "/pngs"),
                                 {"corrupt.mp4"}, out_));
}

TEST_F(Augocc_CliComposite, bad_input_video_cut_short)
{
    // The last frames are cut off the file: the first frames decode, composited frames are
    // already written (under a temporary name) when the input fails.
    const CliData& d = cliData();
    const String cut = tempDir("in") + "/cut.avi";
    {
        std::ifstream in(d.video, std::ios::binary);
        const String all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        writeText(cut, all.substr(0, all.size() * 2 / 3));
    }
    // Folders made for the output go too.
    for (const char* name : {"out.mp4", "pngs", "new/sub/out.mp4", "new/pngs"})
        EXPECT_TRUE(badInputRejected(compositeArgs(cut, d.rec, d.scene, out_ + "/" + name),
                                     {"cut.avi"}, out_));
}

TEST_F(Augocc_CliComposite, bad_input_mesh_does_not_parse)
{
    const CliData& d = cliData();
    const String in = tempDir("in");
    writeText(in + "/broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7 9\nthis is not an OBJ file\n");
    writeText(in + "/scene.yml", "%YAML:1.0\n---\nobjects:\n  - { name: statue, mesh: "
                                 "broken.obj, position: [0, 0, 0] }\n");
    EXPECT_TRUE(badInputRejected(
        compositeArgs(d.video, d.rec, in + "/scene.yml", out_ + "/out.mp4"), {"broken.obj"}, out_));
}

TEST_F(Augocc_CliComposite, bad_input_scene_unknown_key)
{
    const CliData& d = cliData();
    const String in = tempDir("in");
    writeText(in + "/scene.yml", "%YAML:1.0\n---\nobjects:\n  - { name: dome, shape: dome, "
                                 "positon: [0, 0, 0] }\n");
    EXPECT_TRUE(
        badInputRejected(compositeArgs(d.video, d.rec, in + "/scene.yml", out_ + "/out.mp4"),
                         {"scene.yml", "positon"}, out_));
}

TEST_F(Augocc_CliComposite, bad_input_frames_out_of_range)
{
    const CliData& d = cliData();
    // Out of the 6 frames, empty, not numbers, negative; a step or a list (composite takes one
    // range of consecutive frames).
    for (const char* range : {"4:99", "6:", "3:2", "a:b", "-1:3", "2:2", "1:4:2", "1,3"})
        EXPECT_TRUE(badInputRejected(
            compositeArgs(d.video, d.rec, d.scene, out_ + "/out.mp4", String("--frames ") + range),
            {"frame"}, out_));
}

TEST_F(Augocc_CliComposite, bad_input_output_is_a_pattern)
{
    // The inputs take printf patterns; --out is a video or a folder: a pattern made a folder
    // named "%04d.png".
    const CliData& d = cliData();
    EXPECT_TRUE(badInputRejected(compositeArgs(d.video, d.rec, d.scene, out_ + "/%04d.png"),
                                 {"%04d.png", "pattern", "folder"}, out_));
}

TEST_F(Augocc_CliComposite, bad_input_reconstruction_does_not_match_video)
{
    const CliData& d = cliData();
    const String in = tempDir("in");
    const Reconstruction rec = readReconstruction(d.rec);
    // Fewer frames in the video than cameras in the reconstruction.
    {
        std::vector<Mat> frames;
        Ptr<FrameSource> src = FrameSource::open(d.frames);
        Mat f;
        while (src->read(f))
            frames.push_back(f.clone());
        const String shortVideo = in + "/short.avi";
        writeAvi(shortVideo, frames, kFrames - 2);
        EXPECT_TRUE(badInputRejected(compositeArgs(shortVideo, d.rec, d.scene, out_ + "/out.mp4"),
                                     {"short.avi", "reconstruction"}, out_));
    }
    // Another image size.
    {
        Reconstruction big = rec;
        big.imageSize = Size(2 * rec.imageSize.width, 2 * rec.imageSize.height);
        const String p = in + "/big.yml";
        writeReconstruction(p, big);
        EXPECT_TRUE(badInputRejected(compositeArgs(d.video, p, d.scene, out_ + "/out.mp4"),
                                     {"big.yml"}, out_));
    }
    // A frame without a camera.
    {
        Reconstruction gap = rec;
        gap.cameras.erase(gap.cameras.begin() + 2);
        const String p = in + "/gap.yml";
        writeReconstruction(p, gap);
        EXPECT_TRUE(badInputRejected(compositeArgs(d.video, p, d.scene, out_ + "/out.mp4"),
                                     {"gap.yml", "frame 2"}, out_));
    }
}

TEST_F(Augocc_CliComposite, bad_input_optional_outputs_left_clean)
{
    // The failure comes after the first frames: mattes, depth and layer folders must go too.
    const CliData& d = cliData();
    const String cut = tempDir("in") + "/cut.avi";
    {
        std::ifstream in(d.video, std::ios::binary);
        const String all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        writeText(cut, all.substr(0, all.size() * 2 / 3));
    }
    EXPECT_TRUE(badInputRejected(compositeArgs(cut, d.rec, d.scene, out_ + "/out.mp4",
                                               "--mattes " + q(out_ + "/mattes") + " --depth " +
                                                   q(out_ + "/depth") + " --virtual-layer " +
                                                   q(out_ + "/layer")),
                                 {"cut.avi"}, out_));
}

// `augocc run`: the bad inputs are found before any work, and --out-dir stays empty.
class Augocc_CliRun : public Augocc_CliComposite
{
protected:
    String runArgs(const String& input, const String& masks, const String& scene) const
    {
        return "--quiet run --input " + q(input) + " --masks " + q(masks) +
               (scene.empty() ? String() : " --scene " + q(scene)) + " --out-dir " +
               q(out_ + "/run");
    }
};

TEST_F(Augocc_CliRun, bad_input_missing_or_corrupt_video)
{
    const CliData& d = cliData();
    const String in = tempDir("in");
    EXPECT_TRUE(badInputRejected(runArgs(in + "/no_such_video.mp4", d.masks, d.scene),
                                 {"no_such_video.mp4"}, out_));
    writeText(in + "/corrupt.mp4", String(4096, '\x5a'));
    EXPECT_TRUE(
        badInputRejected(runArgs(in + "/corrupt.mp4", d.masks, d.scene), {"corrupt.mp4"}, out_));
}

TEST_F(Augocc_CliRun, bad_input_video_cut_short)
{
    // Found only while tracking: the output folder made for the run goes again.
    const CliData& d = cliData();
    const String cut = tempDir("in") + "/cut.avi";
    {
        std::ifstream in(d.video, std::ios::binary);
        const String all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        writeText(cut, all.substr(0, all.size() * 2 / 3));
    }
    EXPECT_TRUE(badInputRejected(runArgs(cut, d.masks, d.scene), {"cut.avi"}, out_));
}

TEST_F(Augocc_CliRun, bad_input_mesh_and_scene)
{
    const CliData& d = cliData();
    const String in = tempDir("in");
    writeText(in + "/broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7 9\nthis is not an OBJ file\n");
    writeText(in + "/mesh.yml", "%YAML:1.0\n---\nobjects:\n  - { name: statue, mesh: "
                                "broken.obj, position: [0, 0, 0] }\n");
    EXPECT_TRUE(
        badInputRejected(runArgs(d.video, d.masks, in + "/mesh.yml"), {"broken.obj"}, out_));
    writeText(in + "/key.yml", "%YAML:1.0\n---\nobjects:\n  - { name: dome, shape: dome, "
                               "behind: building, colour: red }\n");
    EXPECT_TRUE(
        badInputRejected(runArgs(d.video, d.masks, in + "/key.yml"), {"key.yml", "colour"}, out_));
}

TEST_F(Augocc_CliRun, bad_input_masks_do_not_match_video)
{
    // Masks of another size than the frames: the masks belong to another video.
    const CliData& d = cliData();
    const String masks = tempDir("masks");
    const ObjectMasks m = readMasks(d.masks, d.size);
    ObjectMasks big;
    for (const auto& o : m)
        for (const auto& f : o.second)
        {
            Mat up;
            cv::resize(f.second, up, Size(), 2, 2, INTER_NEAREST);
            big[o.first][f.first] = up;
        }
    writeMasks(masks, big);
    EXPECT_TRUE(badInputRejected(runArgs(d.video, masks, d.scene), {"masks"}, out_));
    // Masks for frames the video does not have.
    const String late = tempDir("late");
    ObjectMasks shifted;
    for (const auto& o : m)
        for (const auto& f : o.second)
            shifted[o.first][f.first + kFrames] = f.second;
    writeMasks(late, shifted);
    EXPECT_TRUE(badInputRejected(runArgs(d.video, late, d.scene), {"late", "video.avi"}, out_));
}

TEST_F(Augocc_CliRun, bad_input_empty_mask_before_tracking)
{
    // An all-black key-frame mask: once found by the clone stage only, after track and sfm,
    // with tracks.yml and reconstruction.yml left behind. Now before any stage.
    const CliData& d = cliData();
    ObjectMasks m = readMasks(d.masks, d.size);
    ASSERT_FALSE(m.empty());
    auto& firstObject = *m.begin();
    ASSERT_FALSE(firstObject.second.empty());
    const int frame = firstObject.second.begin()->first;
    firstObject.second.begin()->second.setTo(Scalar(0));
    const String masks = tempDir("empty_masks");
    writeMasks(masks, m);
    EXPECT_TRUE(badInputRejected(runArgs(d.frames, masks, d.scene),
                                 {firstObject.first, cv::format("%04d.png", frame), "empty"},
                                 out_));
    // All white: the same, before any stage.
    firstObject.second.begin()->second.setTo(Scalar(255));
    const String full = tempDir("full_masks");
    writeMasks(full, m);
    EXPECT_TRUE(badInputRejected(runArgs(d.frames, full, d.scene),
                                 {cv::format("%04d.png", frame), "whole frame"}, out_));
}

TEST_F(Augocc_CliRun, bad_input_scene_anchor_without_masks)
{
    // The scene places an object against a clone the masks do not make.
    const CliData& d = cliData();
    const String in = tempDir("in");
    writeText(in + "/anchor.yml", "%YAML:1.0\n---\nobjects:\n  - { name: dome, shape: dome, "
                                  "behind: no_such_object }\n");
    EXPECT_TRUE(badInputRejected(runArgs(d.frames, d.masks, in + "/anchor.yml"),
                                 {"anchor.yml", "no_such_object"}, out_));
}

TEST_F(Augocc_CliRun, bad_input_options_before_tracking)
{
    const CliData& d = cliData();
    EXPECT_TRUE(badInputRejected(runArgs(d.frames, d.masks, d.scene) + " --model weird",
                                 {"--model", "weird"}, out_));
    EXPECT_TRUE(badInputRejected(runArgs(d.frames, d.masks, d.scene) + " --voxel-pixels 0",
                                 {"--voxel-pixels"}, out_));
    EXPECT_TRUE(badInputRejected(runArgs(d.frames, d.masks, d.scene) + " --threads -1",
                                 {"--threads"}, out_));
}

// `augocc export-blender`: the script and its assets from the valid data set; bad inputs exit 2
// naming the file or flag, and leave neither a script nor an assets folder behind.
String exportArgs(const String& input, const String& rec, const String& scene, const String& out,
                  const String& extra = "")
{
    const CliData& d = cliData();
    return "--quiet export-blender --input " + q(input) + " --reconstruction " + q(rec) +
           " --clones " + q(d.clones) + " --scene " + q(scene) + " --out " + q(out) + " " + extra;
}

TEST_F(Augocc_CliComposite, export_blender_writes_script_and_assets)
{
    const CliData& d = cliData();
    const String script = (fs::path(out_) / "shot.py").string();
    String output;
    ASSERT_EQ(0, runCommand(augoccBinary() + " " +
                                exportArgs(d.frames, d.rec, d.scene, script, "--frames 1:4"),
                            &output))
        << output;
    std::ifstream f(script);
    const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    // One keyframe entry per frame of 1:4, the footage's first image, the clones as holdouts.
    EXPECT_EQ(3, [&] {
        int n = 0;
        for (size_t p = text.find("\"frame\": "); p != std::string::npos;
             p = text.find("\"frame\": ", p + 1))
            n++;
        return n;
    }());
    EXPECT_NE(std::string::npos, text.find("frames/0000.png"));
    EXPECT_NE(std::string::npos, text.find("is_holdout = True"));
    for (const String& o : CloneSet::load(d.clones)->objectNames())
        EXPECT_TRUE(fs::exists(fs::path(out_) / "shot_assets" / "clones" / (o + "_clone.ply")))
            << o;
    EXPECT_TRUE(fs::exists(fs::path(out_) / "shot_assets" / "objects" / "tree_0.ply"));
}

TEST_F(Augocc_CliComposite, export_blender_bad_input)
{
    const CliData& d = cliData();
    const String script = out_ + "/shot.py";
    EXPECT_TRUE(badInputRejected(exportArgs(d.frames, d.rec, d.scene, script, "--frames 4:9"),
                                 {"frames 4:9", "out of range"}, out_));
    EXPECT_TRUE(badInputRejected(exportArgs(d.frames, d.rec, d.scene, out_ + "/shot.txt"),
                                 {"--out", "shot.txt"}, out_));
    EXPECT_TRUE(badInputRejected(exportArgs(d.frames, d.rec, d.scene, script, "--save x.png"),
                                 {"--save", "x.png"}, out_));
    EXPECT_TRUE(badInputRejected(exportArgs(d.frames, d.rec, out_ + "/../none.yml", script),
                                 {"--scene", "none.yml"}, out_));
    const String in = tempDir("in");
    Reconstruction big = readReconstruction(d.rec);
    big.imageSize = Size(2 * big.imageSize.width, 2 * big.imageSize.height);
    writeReconstruction(in + "/big.yml", big);
    EXPECT_TRUE(badInputRejected(exportArgs(d.frames, in + "/big.yml", d.scene, script),
                                 {"big.yml"}, out_));
    // Lens distortion Blender has no model of (a rational term, k4).
    Reconstruction persp = readReconstruction(d.rec);
    persp.model = PERSPECTIVE;
    for (Camera& c : persp.cameras)
        c = Camera::perspective(c.R, c.t + Vec3d(0, 0, 1e3),
                                Matx33d(1e3 * c.s, 0, c.pp.x, 0, 1e3 * c.s, c.pp.y, 0, 0, 1),
                                c.frame, {-0.1, 0, 0, 0, 0, 0.01, 0, 0});
    writeReconstruction(in + "/rational.yml", persp);
    EXPECT_TRUE(badInputRejected(exportArgs(d.frames, in + "/rational.yml", d.scene, script),
                                 {"rational.yml", "frame 0", "coefficient k4"}, out_));
}

} // namespace
} // namespace opencv_test
