// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// --input patterns that are not frame patterns, through the built binary: exit 2, one message
// naming the pattern, nothing written.

#include "test_precomp.hpp"

#include <unistd.h>


#include <filesystem>
#include <fstream>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace opencv_test
{
namespace
{
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

const int kFrames = 12;

String q(const String& s)
{
    return "'" + s + "'";
}

// A 12-frame synthetic sequence (frames as PNGs and an MJPG AVI), its true tracks and
// reconstruction, clones built from it, key-frame masks and the demo's scene file.
struct IoData
{
    String dir, frames, video, tracks, rec, clones, masks, scene;
    bool ok = false;
    ~IoData()
    {
        std::error_code ec;
        if (!dir.empty())
            fs::remove_all(dir, ec);
    }
};

const IoData& ioData()
{
    static IoData d;
    if (d.ok)
        return d;
    // One folder per process: CTest runs tests in parallel (and other worktrees run theirs).
    d.dir = (fs::temp_directory_path() / "augocc_test" /
             cv::format("Augocc_CliIo.%d", (int)getpid())).string();
    fs::remove_all(d.dir);
    fs::create_directories(d.dir);
    SceneSynthesizer::Params sp;
    sp.frames = kFrames;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    const fs::path dir(d.dir);
    d.frames = (dir / "frames").string();
    fs::create_directories(d.frames);
    for (int f = 0; f < kFrames; f++)
        imwrite((fs::path(d.frames) / cv::format("%04d.png", f)).string(), scene.frames[f]);
    d.video = (dir / "video.avi").string();
    {
        VideoWriter w(d.video, CAP_FFMPEG, VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                      scene.frames[0].size(), true);
        for (const Mat& f : scene.frames)
            w.write(f);
    }
    d.tracks = (dir / "tracks.yml").string();
    writeTracks(d.tracks, scene.tracks);
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

// Every entry under a folder, recursively (hidden temporaries included), relative to it.
std::vector<String> listAll(const String& dir)
{
    std::vector<String> out;
    std::error_code ec;
    if (!fs::exists(dir, ec))
        return out;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        out.push_back(fs::relative(e.path(), dir).string());
    std::sort(out.begin(), out.end());
    return out;
}

String joined(const std::vector<String>& v)
{
    String s;
    for (const String& x : v)
        s += x + " ";
    return s;
}

// Lines of the output that are not empty.
int lineCount(const String& s)
{
    int n = 0;
    std::istringstream in(s);
    String line;
    while (std::getline(in, line))
        n += line.empty() ? 0 : 1;
    return n;
}

// Runs `augocc --quiet ARGS`; success when it exits 2 with one message holding every needle.
testing::AssertionResult rejected(const String& args, const std::vector<String>& needles,
                                  const String& runAs = "")
{
    String output;
    const int status = runCommand(runAs + augoccBinary() + " --quiet " + args, &output);
    if (status != 2)
        return testing::AssertionFailure() << "exit status " << status << ", expected 2: "
                                           << args << "\n" << output;
    for (const String& n : needles)
        if (output.find(n) == String::npos)
            return testing::AssertionFailure() << "message should name '" << n << "': "
                                               << output;
    if (lineCount(output) != 1)
        return testing::AssertionFailure() << "one message expected: " << output;
    return testing::AssertionSuccess();
}

TEST(Augocc_CliIo, bad_input_pattern_is_not_a_format)
{
    // Each crashed (SEGV, "%n in writable segment" abort) or read garbage: the pattern went to
    // printf as its format.
    const IoData& d = ioData();
    ASSERT_TRUE(d.ok);
    const String out = tempDir("out");
    for (const char* bad : {"%s.png", "%n", "%d%d", "%5s", "%n%n%n%n%n%n%n%n.png"})
    {
        const String input = d.dir + "/" + bad;
        const std::vector<String> needles = {input, "not a frame pattern"};
        EXPECT_TRUE(rejected("track --input " + q(input) + " --out " + q(out + "/t.yml"),
                             needles));
        EXPECT_TRUE(rejected("run --input " + q(input) + " --masks " + q(d.masks) +
                                 " --out-dir " + q(out + "/run"),
                             needles));
        EXPECT_TRUE(rejected("composite --input " + q(input) + " --reconstruction " + q(d.rec) +
                                 " --clones " + q(d.clones) + " --scene " + q(d.scene) +
                                 " --out " + q(out + "/c.mp4"),
                             needles));
        EXPECT_TRUE(rejected("clone --input " + q(input) + " --reconstruction " + q(d.rec) +
                                 " --masks " + q(d.masks) + " --out " + q(out + "/c.yml.gz"),
                             needles));
    }
    EXPECT_TRUE(listAll(out).empty()) << joined(listAll(out));
    // A good pattern still reads the frames.
    String output;
    EXPECT_EQ(0, runCommand(augoccBinary() + " --quiet track --input " +
                                q(d.frames + "/%04d.png") + " --out " + q(out + "/t.yml"),
                            &output))
        << output;
}

} // namespace
} // namespace opencv_test
