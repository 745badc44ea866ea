// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The command line's writers on a full disk and in folders they cannot write, and --input
// patterns that are not frame patterns, through the built binary: exit 2, one message naming the
// output (or the pattern) and the OS reason, nothing left under any name. The full disk is a
// small tmpfs mounted by the test (root only: skipped with a message otherwise); read-only
// folders are a tmpfs remounted read-only (root ignores permission bits); "Permission denied"
// runs the binary as nobody.

#include "test_precomp.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>

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
const uintmax_t kPage = 4096;  // tmpfs counts file data in pages

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

String readAll(const String& path)
{
    std::ifstream in(path, std::ios::binary);
    return String((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Whether a file `run` left reads back whole: through its reader (the numbers of run's
// reconstruction may differ in their last digits from run to run), PNGs equal to the
// reference's, anything else byte for byte.
bool readsBack(const String& file, const String& reference)
{
    const String name = fs::path(file).filename().string();
    try
    {
        if (name == "tracks.yml")
            readTracks(file);
        else if (name == "reconstruction.yml")
            readReconstruction(file);
        else if (name == "clones.yml.gz")
            CloneSet::load(file);
        else if (name.size() > 13 && name.compare(name.size() - 13, 13, ".manifest.yml") == 0)
        {
            // run's resume manifests: they record modification times, so they differ from the
            // roomy run's; complete means a stage and the output's signature are there.
            FileStorage m(file, FileStorage::READ);
            return m.isOpened() && !((String)m["stage"]).empty() &&
                   !((String)m["output"]).empty();
        }
        else if (fs::path(file).extension() == ".png")
        {
            const Mat a = imread(file, IMREAD_UNCHANGED), b = imread(reference, IMREAD_UNCHANGED);
            return !a.empty() && a.size() == b.size() && a.type() == b.type() &&
                   cv::norm(a, b, NORM_INF) == 0;
        }
        else
            return readAll(file) == readAll(reference);
    }
    catch (const cv::Exception&)
    {
        return false;
    }
    return true;
}

// Bytes a tmpfs needs to hold everything under `path`: whole pages per file.
uintmax_t pagesBytes(const String& path)
{
    if (fs::is_regular_file(path))
        return (fs::file_size(path) + kPage - 1) / kPage * kPage;
    uintmax_t n = 0;
    for (const auto& e : fs::recursive_directory_iterator(path))
        if (e.is_regular_file())
            n += (e.file_size() + kPage - 1) / kPage * kPage;
    return n;
}

// A tmpfs mounted on a fresh folder for the test's lifetime; unmounted by the destructor, so
// on every way out of the test.
class Tmpfs
{
public:
    Tmpfs(const String& tag, uintmax_t bytes)
    {
        unmountStale();
        dir_ = (fs::temp_directory_path() / "augocc_test" /
                cv::format("Augocc_CliIo.%d.%s", (int)getpid(), tag.c_str())).string();
        fs::create_directories(dir_);
        const uintmax_t kib = std::max<uintmax_t>(4, (bytes + 1023) / 1024);
        mounted_ = runCommand(cv::format("mount -t tmpfs -o size=%dk tmpfs ", (int)kib) + q(dir_),
                              &why_) == 0;
    }
    ~Tmpfs()
    {
        if (mounted_ && runCommand("umount " + q(dir_)) != 0)
            runCommand("umount -l " + q(dir_));
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    bool mounted() const { return mounted_; }
    const String& why() const { return why_; }
    const String& dir() const { return dir_; }
    bool remountReadOnly() { return runCommand("mount -o remount,ro " + q(dir_), &why_) == 0; }

private:
    // Mounts of a test process killed before its destructor ran (augocc_test/Augocc_CliIo.PID.*).
    static void unmountStale()
    {
        std::ifstream mounts("/proc/self/mounts");
        const String head = (fs::temp_directory_path() / "augocc_test" / "Augocc_CliIo.").string();
        String dev, point, rest;
        while (mounts >> dev >> point && std::getline(mounts, rest))
        {
            int pid = 0;
            if (point.compare(0, head.size(), head) != 0 ||
                std::sscanf(point.c_str() + head.size(), "%d.", &pid) != 1 || pid <= 0 ||
                kill(pid, 0) == 0 || errno == EPERM)
                continue;
            runCommand("umount -l " + q(point));
            std::error_code ec;
            fs::remove_all(point, ec);
        }
    }

    String dir_, why_;
    bool mounted_ = false;
};

#define AUGOCC_REQUIRE_TMPFS(m)                                                            \
    if ((m).mounted())                                                                     \
    {                                                                                      \
    }                                                                                      \
    else                                                                                   \
        GTEST_SKIP() << "cannot mount a tmpfs (needs root, CAP_SYS_ADMIN): " << (m).why()

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

// Each writer of the command line: its arguments given the output folder, and its output.
struct Writer
{
    const char* name;
    String (*args)(const IoData& d, const String& outDir);
    const char* output;  // under outDir
};

String sfmArgs(const IoData& d, const String& out)
{
    return "sfm --tracks " + q(d.tracks) + " --out " + q(out + "/reconstruction.yml");
}
String trackArgs(const IoData& d, const String& out)
{
    return "track --input " + q(d.frames) + " --out " + q(out + "/tracks.yml");
}
String cloneArgs(const IoData& d, const String& out)
{
    return "clone --reconstruction " + q(d.rec) + " --masks " + q(d.masks) + " --out " +
           q(out + "/clones.yml.gz");
}
String matteArgs(const IoData& d, const String& out)
{
    return "matte --reconstruction " + q(d.rec) + " --clones " + q(d.clones) + " --out " +
           q(out + "/mattes");
}
String compositeArgs(const IoData& d, const String& out)
{
    return "composite --input " + q(d.video) + " --reconstruction " + q(d.rec) + " --clones " +
           q(d.clones) + " --scene " + q(d.scene) + " --out " + q(out + "/composite.mp4");
}
String runArgs(const IoData& d, const String& out)
{
    return "run --input " + q(d.frames) + " --masks " + q(d.masks) + " --scene " + q(d.scene) +
           " --no-photo-refine --out-dir " + q(out + "/run");
}

String synthArgs(const IoData&, const String& out)
{
    return "synth --frames 12 --size 320x240 --tracks 100 --out " + q(out + "/synth");
}
String propagateArgs(const IoData& d, const String& out)
{
    return "propagate --input " + q(d.frames) + " --reconstruction " + q(d.rec) + " --clones " +
           q(d.clones) + " --out " + q(out + "/masks");
}
String joinFramesArgs(const IoData& d, const String& out)
{
    return "join --kind frames --out " + q(out + "/joined.mp4") + " " + q(d.frames);
}
String joinMasksArgs(const IoData& d, const String& out)
{
    return "join --kind masks --out " + q(out + "/joined") + " " + q(d.masks);
}
String farmArgs(const IoData& d, const String& out)
{
    // --dry-run: the workflow's scripts are written, nothing is submitted.
    return "farm --dry-run --input " + q(d.frames) + " --masks " + q(d.masks) + " --scene " +
           q(d.scene) + " --out-dir " + q(out + "/farm");
}
String exportBlenderArgs(const IoData& d, const String& out)
{
    return "export-blender --input " + q(d.frames) + " --reconstruction " + q(d.rec) +
           " --clones " + q(d.clones) + " --scene " + q(d.scene) + " --out " +
           q(out + "/shot.py");
}

const Writer kWriters[] = {{"sfm", sfmArgs, "reconstruction.yml"},
                           {"track", trackArgs, "tracks.yml"},
                           {"clone", cloneArgs, "clones.yml.gz"},
                           {"matte", matteArgs, "mattes"},
                           {"composite", compositeArgs, "composite.mp4"},
                           {"run", runArgs, "run"},
                           {"synth", synthArgs, "synth"},
                           {"propagate", propagateArgs, "masks"},
                           {"join_frames", joinFramesArgs, "joined.mp4"},
                           {"join_masks", joinMasksArgs, "joined"},
                           {"farm", farmArgs, "farm"},
                           {"export_blender", exportBlenderArgs, "shot.py"}};
const int kNumWriters = (int)(sizeof(kWriters) / sizeof(kWriters[0]));

typedef testing::TestWithParam<int> Augocc_CliFullDisk;

TEST_P(Augocc_CliFullDisk, regression_nothing_partial)
{
    const Writer& w = kWriters[GetParam()];
    const IoData& d = ioData();
    ASSERT_TRUE(d.ok);
    // The same command on a roomy disk: what a complete output is, and how big.
    const String ref = tempDir(w.name);
    String output;
    ASSERT_EQ(0, runCommand(augoccBinary() + " --quiet " + w.args(d, ref), &output)) << output;
    const String refOut = ref + "/" + w.output;
    // Room for half of the output; for run, for every intermediate but half the mattes: the
    // disk fills while the pipeline is well under way.
    uintmax_t room = pagesBytes(refOut) / 2;
    if (String(w.name) == "run")
        room = pagesBytes(refOut + "/tracks.yml") + pagesBytes(refOut + "/reconstruction.yml") +
               pagesBytes(refOut + "/clones.yml.gz") + pagesBytes(refOut + "/mattes") / 2;
    // export-blender: room for its assets folder and half the script, which it writes after
    // the assets (the assets were left behind, orphaned, when the script could not be written).
    if (String(w.name) == "export_blender")
        room = pagesBytes(ref + "/shot_assets") + pagesBytes(refOut) / 2;
    Tmpfs disk(w.name, room);
    AUGOCC_REQUIRE_TMPFS(disk);
    EXPECT_TRUE(rejected(w.args(d, disk.dir()), {disk.dir() + "/" + w.output,
                                                 "No space left on device"}));
    // Nothing partial under any name: single outputs are absent, run keeps only the
    // intermediates it completed (each equal to the roomy run's), no temporary anywhere.
    const std::vector<String> left = listAll(disk.dir());
    if (String(w.name) != "run")
    {
        EXPECT_TRUE(left.empty()) << "left behind: " << joined(left);
    }
    else
        for (const String& f : left)
        {
            EXPECT_NE('.', fs::path(f).filename().string()[0]) << "temporary left: " << f;
            const String mine = disk.dir() + "/" + f, theirs = ref + "/" + f;
            if (fs::is_regular_file(mine))
            {
                EXPECT_TRUE(readsBack(mine, theirs)) << f << " is not a complete output";
            }
            else if (f != "run")
            {
                EXPECT_EQ(listAll(theirs), listAll(mine)) << f << " is incomplete";
            }
        }
    std::error_code ec;
    fs::remove_all(ref, ec);
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_CliFullDisk, testing::Range(0, kNumWriters),
                         [](const testing::TestParamInfo<int>& info) {
                             return String(kWriters[info.param].name);
                         });

TEST(Augocc_CliIo, regression_read_only_folder)
{
    const IoData& d = ioData();
    ASSERT_TRUE(d.ok);
    Tmpfs ro("ro", 64 * 1024);
    AUGOCC_REQUIRE_TMPFS(ro);
    fs::create_directories(ro.dir() + "/existing");
    if (!ro.remountReadOnly())
        GTEST_SKIP() << "cannot remount the tmpfs read-only: " << ro.why();
    const String kReason = "Read-only file system";
    // Into the folder itself, into an existing sub-folder, and into folders to be made in it.
    for (const String& out : {ro.dir(), ro.dir() + "/existing"})
        for (const Writer& w : kWriters)
            EXPECT_TRUE(rejected(w.args(d, out), {out + "/" + w.output, kReason})) << w.name;
    // Folder outputs (and composite, run) make the folders they need; sfm, track and clone
    // write into an existing folder.
    const String made = ro.dir() + "/new";
    for (const Writer& w : kWriters)
    {
        const bool makesFolders = String("matte composite run synth propagate join_masks farm "
                                         "export_blender").find(w.name) != String::npos;
        EXPECT_TRUE(rejected(w.args(d, made + "/sub"),
                             {made, makesFolders ? kReason : "No such file or directory"}))
            << w.name;
    }
    // composite's image-folder output and its optional outputs.
    const String base = "composite --input " + q(d.video) + " --reconstruction " + q(d.rec) +
                        " --clones " + q(d.clones) + " --scene " + q(d.scene);
    EXPECT_TRUE(rejected(base + " --out " + q(ro.dir() + "/pngs"), {ro.dir() + "/pngs", kReason}));
    const String okOut = tempDir("out");
    EXPECT_TRUE(rejected(base + " --out " + q(okOut + "/c.mp4") + " --mattes " +
                             q(ro.dir() + "/mattes"),
                         {ro.dir() + "/mattes", kReason}));
    EXPECT_TRUE(listAll(okOut).empty()) << joined(listAll(okOut));
}

TEST(Augocc_CliIo, regression_permission_denied)
{
    // Root writes through permission bits: the binary runs as nobody.
    const IoData& d = ioData();
    ASSERT_TRUE(d.ok);
    const String runAs = "setpriv --reuid=65534 --regid=65534 --clear-groups -- ";
    String why;
    if (getuid() != 0 || runCommand(runAs + augoccBinary() + " --help", &why) != 0)
        GTEST_SKIP() << "cannot run augocc as nobody (needs root and setpriv): " << why;
    const String locked = tempDir("locked");
    fs::permissions(locked, fs::perms::owner_all | fs::perms::group_read |
                                fs::perms::group_exec | fs::perms::others_read |
                                fs::perms::others_exec);
    for (const Writer& w : kWriters)
        EXPECT_TRUE(rejected(w.args(d, locked), {locked + "/" + w.output, "Permission denied"},
                             runAs))
            << w.name;
    EXPECT_TRUE(listAll(locked).empty()) << joined(listAll(locked));
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

TEST(Augocc_CliIo, regression_stale_temporaries_swept)
{
    // Temporaries a killed run left (both namings: tick count, and PID-counter of a process
    // that is gone) go with the next write of the same output; others stay.
    const IoData& d = ioData();
    ASSERT_TRUE(d.ok);
    const String out = tempDir("out");
    int dead = 4000000;
    while (kill(dead, 0) == 0 || errno == EPERM)
        dead--;
    auto touch = [&](const String& name) { std::ofstream(out + "/" + name) << "partial"; };
    const std::vector<String> stale = {".reconstruction.tmp123.yml",
                                       cv::format(".reconstruction.tmp%d-3.yml", dead),
                                       ".clones.tmp9.yml.gz", ".composite.tmp77.mp4"};
    for (const String& s : stale)
        touch(s);
    fs::create_directories(out + "/.mattes.tmp4137/tower");
    touch(".mattes.tmp4137/tower/0000.png");
    const std::vector<String> kept = {
        cv::format(".reconstruction.tmp%d-1.yml", (int)getpid()),  // a live writer's
        ".reconstruction.tmpx.yml", "reconstruction.tmp1.yml", ".reconstruction.tmp1.yml.bak",
        ".other.tmp1.yml"};
    for (const String& k : kept)
        touch(k);
    String output;
    for (const auto& args : {sfmArgs(d, out), cloneArgs(d, out), matteArgs(d, out),
                             compositeArgs(d, out)})
        ASSERT_EQ(0, runCommand(augoccBinary() + " --quiet " + args, &output)) << output;
    std::vector<String> expected = kept;
    for (const char* o : {"reconstruction.yml", "clones.yml.gz", "composite.mp4", "mattes"})
        expected.push_back(o);
    std::vector<String> left;
    for (const auto& e : fs::directory_iterator(out))
        left.push_back(e.path().filename().string());
    std::sort(left.begin(), left.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(expected, left);
}

} // namespace
} // namespace opencv_test
