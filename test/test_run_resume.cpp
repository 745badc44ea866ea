// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// `augocc run` as a driver, through the built binary: its progress lines in a log, and the
// resume (per-stage manifests): a re-run reuses what is unchanged, a scene change re-composites
// only, --force redoes everything, a run killed during the clone stage picks up there.

#include "test_precomp.hpp"
#include "sfm_test_utils.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <thread>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace opencv_test
{
namespace
{
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

// A small data set: 12 frames of 240x180 as PNGs, key-frame masks, the demo's scene.
struct RunData
{
    String frames, masks, scene;
    bool ok = false;
};

const RunData& runData()
{
    static RunData d;
    if (d.ok)
        return d;
    const String dir = (fs::temp_directory_path() / "augocc_test" /
                        cv::format("Augocc_RunDriver.%d", (int)getpid())).string();
    fs::remove_all(dir);
    fs::create_directories(dir);
    SceneSynthesizer::Params sp;
    sp.frames = 12;
    sp.imageSize = Size(240, 180);
    sp.numKeyFrames = 3;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    d.frames = dir + "/frames";
    fs::create_directories(d.frames);
    for (size_t f = 0; f < scene.frames.size(); f++)
        imwrite(d.frames + cv::format("/%04d.png", (int)f), scene.frames[f]);
    d.masks = dir + "/masks";
    writeMasks(d.masks, scene.keyFrameMasks);
    d.scene = dir + "/scene.yml";
    writeScene(d.scene, demoVirtualScene(d.scene));
    d.ok = true;
    return d;
}

String q(const String& s)
{
    return "'" + s + "'";
}

String runCmd(const String& out, const String& scene, const String& extra = String())
{
    const RunData& d = runData();
    return augoccBinary() + " run --input " + q(d.frames) + " --masks " + q(d.masks) +
           " --scene " + q(scene) + " --out-dir " + q(out) + " " + extra;
}

// What identifies one version of a file: inode and modification time (an atomic rewrite
// makes a new inode).
std::pair<long long, long long> fileId(const String& path)
{
    struct stat st;
    if (stat(path.c_str(), &st) != 0)
        return {-1, -1};
    return {(long long)st.st_ino,
            (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec};
}

const char* const kOutputs[] = {"tracks.yml", "reconstruction.yml", "clones.yml.gz", "mattes",
                                "composite.mp4"};

std::map<String, std::pair<long long, long long> > outputIds(const String& out)
{
    std::map<String, std::pair<long long, long long> > ids;
    for (const char* o : kOutputs)
        ids[o] = fileId(out + "/" + o);
    return ids;
}

// Every matte PNG of `a` equals `b`'s, and the folders hold the same files.
testing::AssertionResult sameMattes(const String& a, const String& b)
{
    const std::vector<std::string> files = filesUnder(a), inB = filesUnder(b);
    if (files.empty() || files != inB)
        return testing::AssertionFailure() << files.size() << " mattes against " << inB.size();
    for (const String& f : files)
    {
        const Mat ma = imread(a + "/" + f, IMREAD_UNCHANGED), mb = imread(b + "/" + f,
                                                                          IMREAD_UNCHANGED);
        if (ma.empty() || mb.empty() || ma.size() != mb.size() || cv::norm(ma, mb, NORM_INF) != 0)
            return testing::AssertionFailure() << f << " differs";
    }
    return testing::AssertionSuccess();
}

// Per-frame PSNR of a video against the frames it was encoded from.
std::vector<double> psnrAgainst(const String& video, const String& pngDir)
{
    std::vector<double> psnr;
    VideoCapture cap(video);
    for (int f = 0;; f++)
    {
        Mat v;
        if (!cap.read(v))
            break;
        const Mat png = imread(pngDir + cv::format("/%04d.png", f));
        if (png.empty() || png.size() != v.size())
            return std::vector<double>();
        psnr.push_back(cv::PSNR(v, png));
    }
    return psnr;
}

// Two composites are the same frames encoded twice: OpenCV 4.6's x264 writer does not give the
// same bytes for the same frames in a busy process (doc/pitfalls.md), so each video is scored
// against the frames themselves (PNG, bit-reproducible) and the two scores must agree.
// Measured on this data set under the demo's sun: 8 concurrent encodes of the same frames were
// 4 distinct files whose per-frame PSNR against the PNG frames agreed within 0.1 dB (mean
// |difference| <= 0.05 dB); a composite made from clones that differed only in the last bits
// of their reconstruction (the defect 681ca46 fixed) scored 0.1-0.66 dB lower, 0.4 dB mean.
// Bound: mean |difference| <= 0.15 dB and no frame over 0.3 dB.
testing::AssertionResult sameComposite(const String& a, const String& b, const String& pngDir)
{
    const std::vector<double> pa = psnrAgainst(a, pngDir), pb = psnrAgainst(b, pngDir);
    if (pa.empty() || pa.size() != pb.size())
        return testing::AssertionFailure() << a << ": " << pa.size() << " frames, " << b << ": "
                                           << pb.size() << " frames (or unreadable frames in "
                                           << pngDir << ")";
    double sum = 0;
    for (size_t f = 0; f < pa.size(); f++)
    {
        const double d = std::abs(pa[f] - pb[f]);
        sum += d;
        if (d > 0.3)
            return testing::AssertionFailure() << "frame " << f << ": " << pa[f] << " dB against "
                                               << pb[f] << " dB PSNR to the PNG composite";
    }
    if (sum / pa.size() > 0.15)
        return testing::AssertionFailure() << "mean PSNR difference " << sum / pa.size() << " dB";
    return testing::AssertionSuccess();
}

TEST(Augocc_RunDriver, progress_lines_in_a_log)
{
    // stderr to a file: not a terminal, so plain lines. Their presence and order are checked,
    // not their timing (perf/progress_interval.sh measures that).
    ASSERT_TRUE(runData().ok);
    const String out = tempDir("out"), log = out + "/../progress_lines.log";
    String output;
    ASSERT_EQ(0, runCommand("( " + runCmd(out + "/run", runData().scene) + " 2> " + q(log) +
                            " )", &output)) << output;
    std::ifstream in(log);
    const std::regex line(R"(^([a-z]+)(?:: (.*?))? +(\d+)/(\d+) (\S+) \(\s*\d+%\).*$)");
    std::vector<String> stages;                  // in order of first appearance
    std::map<String, std::pair<long long, long long> > last;  // stage/step -> (done, total)
    String s;
    int lines = 0;
    while (std::getline(in, s))
    {
        std::smatch m;
        ASSERT_TRUE(std::regex_match(s, m, line)) << "not a progress line: " << s;
        lines++;
        const String stage = m[1], key = stage + "/" + String(m[2]);
        const long long done = std::stoll(m[3]), total = std::stoll(m[4]);
        EXPECT_LE(done, total) << s;
        if (stages.empty() || stages.back() != stage)
        {
            EXPECT_EQ(std::find(stages.begin(), stages.end(), stage), stages.end())
                << stage << " comes back after another stage: " << s;
            stages.push_back(stage);
        }
        auto it = last.find(key);
        if (it != last.end())
        {
            EXPECT_GE(done, it->second.first) << "progress went back: " << s;
            EXPECT_EQ(total, it->second.second) << "total changed within a step: " << s;
        }
        last[key] = {done, total};
    }
    const std::vector<String> want = {"track", "sfm", "clone", "matte", "composite"};
    EXPECT_EQ(want, stages) << lines << " lines";
    // The stages counting frames end at their total (a stage's last line is always printed).
    for (const char* k : {"track/", "matte/", "composite/"})
    {
        ASSERT_TRUE(last.count(k)) << k;
        EXPECT_EQ(last[k].second, last[k].first) << k;
    }
    EXPECT_EQ(12, last["track/"].second);
    // --quiet: nothing at all on stderr.
    const String quietLog = out + "/../quiet.log";
    ASSERT_EQ(0, runCommand("( " + augoccBinary() + " --quiet " +
                            runCmd(out + "/quiet", runData().scene).substr(
                                augoccBinary().size()) + " --force 2> " + q(quietLog) + " )",
                            &output)) << output;
    EXPECT_EQ(0, (int)fs::file_size(quietLog));
}

TEST(Augocc_RunDriver, resume_rerun_scene_change_force)
{
    ASSERT_TRUE(runData().ok);
    const String out = tempDir("out") + "/run", sceneDir = tempDir("scene");
    const String scene = sceneDir + "/scene.yml";
    fs::copy_file(runData().scene, scene);
    String output;
    ASSERT_EQ(0, runCommand(runCmd(out, scene, "--no-photo-refine"), &output)) << output;
    const auto first = outputIds(out);
    for (const auto& kv : first)
        ASSERT_GE(kv.second.first, 0) << kv.first << " missing";
    for (const char* m : {"tracks", "reconstruction", "clones", "mattes", "composite"})
        EXPECT_TRUE(fs::exists(out + "/" + m + ".manifest.yml")) << m;

    // The same inputs and options: every stage reused, nothing rewritten.
    ASSERT_EQ(0, runCommand(runCmd(out, scene, "--no-photo-refine"), &output)) << output;
    EXPECT_EQ(first, outputIds(out)) << output;
    EXPECT_NE(String::npos, output.find("reused")) << output;

    // Only the scene changes (the dome moves): only the composite is made again.
    VirtualScene vs = demoVirtualScene(scene);
    vs.objects[0].offset[0] += 0.2;
    writeScene(scene, vs);
    ASSERT_EQ(0, runCommand(runCmd(out, scene, "--no-photo-refine"), &output)) << output;
    const auto third = outputIds(out);
    for (const char* o : {"tracks.yml", "reconstruction.yml", "clones.yml.gz", "mattes"})
        EXPECT_EQ(first.at(o), third.at(o)) << o << " was made again\n" << output;
    EXPECT_NE(first.at("composite.mp4"), third.at("composite.mp4"));

    // An option of the clone stage: clone, matte and composite again, track and sfm reused.
    ASSERT_EQ(0, runCommand(runCmd(out, scene, ""), &output)) << output;
    const auto fourth = outputIds(out);
    EXPECT_EQ(first.at("tracks.yml"), fourth.at("tracks.yml"));
    EXPECT_EQ(first.at("reconstruction.yml"), fourth.at("reconstruction.yml"));
    EXPECT_NE(third.at("clones.yml.gz"), fourth.at("clones.yml.gz"));
    EXPECT_NE(third.at("mattes"), fourth.at("mattes"));
    EXPECT_NE(third.at("composite.mp4"), fourth.at("composite.mp4"));

    // --force: everything again.
    ASSERT_EQ(0, runCommand(runCmd(out, scene, "--force"), &output)) << output;
    const auto fifth = outputIds(out);
    for (const char* o : kOutputs)
        EXPECT_NE(fourth.at(o), fifth.at(o)) << o << " was reused under --force";

    // A reused output that changed behind the run's back is not trusted: made again.
    {
        std::ofstream f(out + "/reconstruction.yml", std::ios::app);
        f << "\n";
    }
    ASSERT_EQ(0, runCommand(runCmd(out, scene, ""), &output)) << output;
    const auto sixth = outputIds(out);
    EXPECT_EQ(fifth.at("tracks.yml"), sixth.at("tracks.yml"));
    // (the append kept the inode: a new one is the stage's atomic rewrite)
    EXPECT_NE(fifth.at("reconstruction.yml").first, sixth.at("reconstruction.yml").first);
    EXPECT_NE(fifth.at("clones.yml.gz"), sixth.at("clones.yml.gz"));
}

TEST(Augocc_RunDriver, resume_after_kill_during_clone)
{
    ASSERT_TRUE(runData().ok);
    // Under the demo's sun (the shadows make the composite depend on every bit of the clones).
    const String ref = tempDir("ref") + "/run", out = tempDir("out") + "/run";
    const String log = out + "_progress.log";
    String output;
    ASSERT_EQ(0, runCommand(runCmd(ref, runData().scene), &output)) << output;

    // The same run, killed (SIGKILL) as soon as its log shows the clone stage.
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0)
    {
        const String cmd = "exec " + runCmd(out, runData().scene) + " > /dev/null 2> " + q(log);
        execl("/bin/sh", "sh", "-c", cmd.c_str(), (char*)nullptr);
        _exit(127);
    }
    bool killed = false;
    for (int i = 0; i < 120000 && !killed; i++)  // at most 2 minutes
    {
        std::ifstream in(log);
        String l;
        while (std::getline(in, l))
            if (l.compare(0, 5, "clone") == 0)
            {
                kill(pid, SIGKILL);
                killed = true;
                break;
            }
        int st = 0;
        if (!killed && waitpid(pid, &st, WNOHANG) == pid)
            FAIL() << "the run ended before its clone stage was seen";
        if (!killed)
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_TRUE(killed);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    ASSERT_FALSE(fs::exists(out + "/clones.yml.gz")) << "killed after the clone stage, not in it";
    const auto tracks = fileId(out + "/tracks.yml"), rec = fileId(out + "/reconstruction.yml");
    ASSERT_GE(tracks.first, 0);
    ASSERT_GE(rec.first, 0);

    // Re-run: track and sfm reused (not rewritten), the result the uninterrupted run's.
    ASSERT_EQ(0, runCommand(runCmd(out, runData().scene), &output)) << output;
    EXPECT_EQ(tracks, fileId(out + "/tracks.yml"));
    EXPECT_EQ(rec, fileId(out + "/reconstruction.yml"));
    const Ptr<CloneSet> a = CloneSet::load(out + "/clones.yml.gz"),
                        b = CloneSet::load(ref + "/clones.yml.gz");
    ASSERT_EQ(b->objectNames(), a->objectNames());
    for (const String& name : a->objectNames())
        EXPECT_EQ(b->voxelCount(name), a->voxelCount(name)) << name;
    EXPECT_TRUE(sameMattes(out + "/mattes", ref + "/mattes"));
    // The composite's frames, bit-reproducible as PNG, from the uninterrupted run's files.
    const String png = tempDir("png") + "/composite";
    ASSERT_EQ(0, runCommand(augoccBinary() + " composite --input " + q(runData().frames) +
                            " --reconstruction " + q(ref + "/reconstruction.yml") + " --clones " +
                            q(ref + "/clones.yml.gz") + " --scene " + q(runData().scene) +
                            " --out " + q(png), &output)) << output;
    EXPECT_TRUE(sameComposite(out + "/composite.mp4", ref + "/composite.mp4", png));
    // No temporary of the killed run is left.
    for (const auto& e : fs::directory_iterator(out))
        EXPECT_NE('.', e.path().filename().string()[0]) << e.path();
}

TEST(Augocc_RunDriver, results_do_not_depend_on_progress)
{
    // The same sfm and clones with a callback set as without; the callback hears the stages.
    SceneSynthesizer::Params sp;
    sp.frames = 12;
    sp.imageSize = Size(240, 180);
    sp.numKeyFrames = 3;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    std::map<String, int> heard;
    const ProgressCallback cb = [&](const Progress& p) { heard[p.stage]++; };
    SfmOptions plain, reported;
    reported.progress = cb;
    const Reconstruction a = recoverCameras(scene.tracks, plain);
    const Reconstruction b = recoverCameras(scene.tracks, reported);
    // Bit for bit, for both camera models: the progress callback does not touch the solve, and
    // two calls of recoverCameras on the same tracks give the same cameras (one Ceres thread,
    // every problem's camera blocks in one buffer: detail::CameraBlocks; before, the
    // perspective cameras differed by ~1e-6 from call to call).
    SfmOptions perspPlain, perspReported;
    perspPlain.model = perspReported.model = "perspective";
    perspReported.progress = cb;
    const Reconstruction pa = recoverCameras(scene.tracks, perspPlain);
    const Reconstruction pb = recoverCameras(scene.tracks, perspReported);
    for (const auto& ab : {std::make_pair(&a, &b), std::make_pair(&pa, &pb)})
    {
        ASSERT_EQ(ab.first->cameras.size(), ab.second->cameras.size());
        for (size_t i = 0; i < ab.first->cameras.size(); i++)
        {
            const Camera &ca = ab.first->cameras[i], &cb = ab.second->cameras[i];
            EXPECT_EQ(0, cv::norm(Mat(ca.R), Mat(cb.R), NORM_INF)) << i;
            EXPECT_EQ(0, cv::norm(Mat(ca.t), Mat(cb.t), NORM_INF)) << i;
            EXPECT_EQ(0, cv::norm(Mat(ca.K), Mat(cb.K), NORM_INF)) << i;
            EXPECT_EQ(ca.distortion, cb.distortion) << i;
        }
        EXPECT_TRUE(identicalWithNan(ab.first->points, ab.second->points));
    }
    EXPECT_EQ(PERSPECTIVE, pa.model);
    CloneBuilder::Params cp;
    const Ptr<CloneSet> ca = CloneBuilder::create(cp)->build(a, scene.keyFrameMasks,
                                                             &scene.tracks);
    cp.progress = cb;
    const Ptr<CloneSet> cb2 = CloneBuilder::create(cp)->build(a, scene.keyFrameMasks,
                                                              &scene.tracks);
    ObjectMasks ma, mb;
    renderMattes(*ca, a, ma);
    renderMattes(*cb2, a, mb, nullptr, cb);
    ASSERT_EQ(ma.size(), mb.size());
    for (const auto& o : ma)
    {
        EXPECT_EQ(ca->voxelCount(o.first), cb2->voxelCount(o.first)) << o.first;
        for (const auto& f : o.second)
            EXPECT_EQ(0, cv::norm(f.second, mb[o.first][f.first], NORM_INF))
                << o.first << " frame " << f.first;
    }
    EXPECT_GT(heard["sfm"], 0);
    EXPECT_GT(heard["clone"], 0);
    EXPECT_GT(heard["matte"], 0);
}

// Issue 17: a frame replaced while a stage reads it. Before, the tracks (a mixture of the two
// versions) were kept and their manifest made the next run reuse them; now the stage's end finds
// the input's sizes/times changed, keeps nothing and names the input.
TEST(Augocc_RunDriver, regression_input_replaced_while_read)
{
    const RunData& d = runData();
    ASSERT_TRUE(d.ok);
    const String dir = tempDir("replaced");
    const String frames = dir + "/frames";
    fs::copy(d.frames, frames, fs::copy_options::recursive);
    RunOptions o;
    o.input = frames;
    o.masksDir = d.masks;
    o.outDir = dir + "/run";
    o.photoRefine = false;
    bool replaced = false;
    o.progress = [&](const Progress& p) {
        // Half-way through tracking: a new version of a frame still to be read (atomically,
        // as an editor or a sync tool replaces it), slightly brighter: the second run below
        // tracks it as well as the first.
        if (replaced || p.stage != "track" || p.done < 6)
            return;
        Mat f = imread(frames + "/0010.png");
        f += Scalar::all(2);
        imwrite(frames + "/.new.png", f);
        fs::rename(frames + "/.new.png", frames + "/0010.png");
        replaced = true;
    };
    try
    {
        runPipeline(o);
        ADD_FAILURE() << "a run over replaced frames succeeded";
    }
    catch (const cv::Exception& e)
    {
        // Whichever check fires first: the frame source's (FrameSource::checkUnchanged, naming
        // the file) or the stage manifest's (naming the folder).
        EXPECT_TRUE(e.err.find(frames + "/0010.png was replaced") != String::npos ||
                    e.err.find(frames + ": changed while the run read it") != String::npos)
            << e.err;
    }
    EXPECT_TRUE(replaced) << "the track stage reported no progress to hook";
    EXPECT_FALSE(fs::exists(o.outDir + "/tracks.yml"));
    EXPECT_FALSE(fs::exists(o.outDir + "/tracks.manifest.yml"));
    // Unchanged from here on, the same run goes through (the stages start afresh).
    o.progress = ProgressCallback();
    EXPECT_NO_THROW(runPipeline(o));
    EXPECT_TRUE(fs::exists(o.outDir + "/mattes"));
    std::error_code ec;
    fs::remove_all(dir, ec);
}

} // namespace
} // namespace opencv_test
