// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// End-to-end test of `augocc annotate`: the real window under a private Xvfb display, driven by
// xdotool, checked by the mask it writes. Skips when Xvfb or xdotool is missing.
// With AUGOCC_ANNOTATE_SHOTS=<dir> it also grabs screenshots of the window (ffmpeg x11grab) for
// the documentation.

#include "test_precomp.hpp"
#include "test_silhouette_scene.hpp"
#include "test_x11.hpp"

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

// The window must give exactly what the library gives for the same clicks (the e2e test checks
// the plumbing: click mapping, closing, saving); against the truth, this near-frontal view has
// the thin-sliver facade of accuracy_scripted_clicks_synthesized, which reaches ~0.97.
const double kMinE2eIoU = 0.965;
// Frame 1 proposed from the clone (key g; a clone of only two key frames 4 degrees apart, so
// coarse in depth), snapped to this frame's edges.
const double kMinProposedIoU = 0.95;
// Generous limits: the window appears in ~1 s on an idle machine; 2 cores shared with builds.
const double kStartTimeoutS = 40.0;
const double kExitTimeoutS = 30.0;

using namespace x11;

TEST(Augocc_AnnotateE2e, xvfb_xdotool_traces_and_saves_mask)
{
    const std::string bin = augoccBinary();
    const char* shotsEnv = std::getenv("AUGOCC_ANNOTATE_SHOTS");
    const std::string shots = shotsEnv ? shotsEnv : "";
    const std::string skip = windowTestSkipReason(bin, shots, "AUGOCC_ANNOTATE_SHOTS");
    if (!skip.empty())
        GTEST_SKIP() << skip;

    // Three frames of the synthesized scene from a slowly turning camera (2 degrees a frame).
    const std::string dir = tempDir("annotate");
    fs::create_directories(dir + "/frames");
    SceneSynthesizer::Params sp;
    sp.frames = 3;
    sp.numKeyFrames = 2;
    sp.orbitDegrees = 4;
    sp.numTracks = 50;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    const Size size = scene.frames[0].size();
    for (int f = 0; f < 3; ++f)
        ASSERT_TRUE(imwrite(format("%s/frames/%04d.png", dir.c_str(), f), scene.frames[f]));
    // Clones from the two default key frames (0 and 2): the g key on frame 1 proposes from them.
    writeReconstruction(dir + "/rec.yml", scene.groundTruth);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(scene.groundTruth, scene.keyFrameMasks);
    clones->save(dir + "/clones.yml.gz");
    const Mat truth0 = scene.visibleMasks.at("building").at(0);
    const Mat truth1 = scene.visibleMasks.at("building").at(1);
    const std::string masks = dir + "/masks";

    Child xvfb;
    std::string why;
    const std::string display = startXvfb(xvfb, dir, why);
    ASSERT_FALSE(display.empty()) << why;

    Child tool;
    const std::string log = dir + "/annotate.log";
    tool.pid = spawn({bin, "annotate", "--input", dir + "/frames", "--masks", masks, "--object",
                      "building", "--screenshot-dir", dir, "--reconstruction", dir + "/rec.yml",
                      "--clones", dir + "/clones.yml.gz"},
                     {"DISPLAY=" + display, "QT_QPA_PLATFORM=xcb"}, log);
    ASSERT_GT(tool.pid, 0);
    Rect rect;
    ASSERT_TRUE(waitForWindowRect(tool, log, kStartTimeoutS, rect, why)) << why;
    // The window shows the frame 1:1 at the top of its image area, status lines below it.
    ASSERT_EQ(size.width, rect.width) << readFile(log);
    ASSERT_GE(rect.height, size.height);
    sleepMs(300);

    // Trace: the building's corners, a couple of pixels off as a hand would be.
    std::vector<std::vector<Point>> contours;
    findContours(truth0.clone(), contours, RETR_EXTERNAL, CHAIN_APPROX_NONE);
    ASSERT_FALSE(contours.empty());
    std::vector<Point> corners;
    approxPolyDP(contours[0], corners, 2.0, true);
    RNG rng(5);
    std::vector<Point> clicks;
    for (const Point& c : corners)
        clicks.push_back(c + Point(rng.uniform(-2, 3), rng.uniform(-2, 3)));
    Xdo xdo(display);
    const Point origin = rect.tl();
    for (size_t i = 0; i < clicks.size(); ++i)
    {
        if (!shots.empty() && i + 1 == clicks.size())
        {
            // Before the last click: hover there so that the live-wire preview shows.
            xdo.moveTo(origin + clicks[i]);
            sleepMs(600);
            grab(display, rect, shots + "/annotate_tracing.png");
        }
        xdo.click(origin + clicks[i]);
    }
    xdo.click(origin + clicks[0]);  // on the first anchor: closes the contour
    int clickCount = int(clicks.size()) + 1;
    EXPECT_LE(clickCount, 12);
    if (!shots.empty())
    {
        xdo.moveTo(origin + Point(20, size.height - 20));
        sleepMs(400);
        grab(display, rect, shots + "/annotate_closed.png");
        xdo.key("h");
        sleepMs(300);
        grab(display, rect, shots + "/annotate_help.png");
        xdo.key("h");
    }
    xdo.key("w");       // the tool's own screenshot of its canvas
    xdo.key("n");       // next frame: the traced frame is committed
    xdo.key("g");       // propose frame 1's outline from the clone, snapped to edges
    sleepMs(500);
    if (!shots.empty())
        grab(display, rect, shots + "/annotate_proposed.png");
    xdo.key("q");       // save and quit
    const int rc = tool.wait(kExitTimeoutS);
    const std::string text = readFile(log);
    ASSERT_EQ(0, rc) << "augocc annotate did not exit cleanly:\n" << text;
    xvfb.stop();

    const Mat written = imread(masks + "/building/0000.png", IMREAD_GRAYSCALE);
    ASSERT_FALSE(written.empty()) << "no mask written:\n" << text;
    EXPECT_EQ(size, written.size());
    const double iou = maskIoU(written, truth0);
    const Mat proposed = imread(masks + "/building/0001.png", IMREAD_GRAYSCALE);
    ASSERT_FALSE(proposed.empty()) << "the proposal of frame 1 was not saved:\n" << text;
    const double iouProposed = maskIoU(proposed, truth1);
    std::cout << format("[ annotate e2e ] %d clicks, IoU %.4f; frame 1 proposed from the clone "
                        "(g), IoU %.4f",
                        clickCount, iou, iouProposed)
              << std::endl;
    EXPECT_GE(iou, kMinE2eIoU);
    EXPECT_GE(iouProposed, kMinProposedIoU);
    // The same clicks and the same proposal through the library, headless: identical masks.
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.frames[0]);
    for (const Point& c : clicks)
        ed->addPoint(c);
    ASSERT_TRUE(ed->closeContour());
    Mat headless0, headless1;
    ed->getMask(headless0);
    EXPECT_EQ(0, norm(written, headless0, NORM_INF)) << "window and library disagree";
    std::map<String, Mat> visible;
    proposeSilhouettes(*clones, 1, scene.groundTruth.camera(1), scene.frames[1], visible, false);
    ed->setImage(scene.frames[1]);
    ed->loadMask(visible.at("building"), true);
    ed->getMask(headless1);
    EXPECT_EQ(0, norm(proposed, headless1, NORM_INF)) << "window and library disagree (g)";
    EXPECT_FALSE(fs::exists(masks + "/building/0002.png")) << "frame 2 was not traced";
    bool shot = false;
    for (const auto& e : fs::directory_iterator(dir))
        shot = shot || e.path().filename().string().rfind("annotate_building_0000", 0) == 0;
    EXPECT_TRUE(shot) << "the w key saved no screenshot:\n" << text;
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;

// Bad input is reported before any window opens (exit 2, the flag named), display or not.
TEST(Augocc_AnnotateE2e, bad_input)
{
    const std::string dir = tempDir("annotate_bad");
    fs::create_directories(dir + "/frames");
    ASSERT_TRUE(imwrite(dir + "/frames/0000.png", Mat(60, 80, CV_8UC3, Scalar::all(100))));
    const std::string bin = augoccBinary() + " annotate";
    std::string out;
    EXPECT_EQ(2, runCommand(bin + " --input " + dir + "/none --masks " + dir + "/m", &out));
    EXPECT_NE(std::string::npos, out.find("--input")) << out;
    EXPECT_EQ(2, runCommand(bin + " --input " + dir + "/frames --masks " + dir +
                            "/m --suggest 3", &out));
    EXPECT_NE(std::string::npos, out.find("--suggest")) << out;
    EXPECT_EQ(2, runCommand(bin + " --input " + dir + "/frames --masks " + dir +
                            "/m --object a/b", &out));
    EXPECT_EQ(2, runCommand(bin + " --input " + dir + "/frames --masks " + dir +
                            "/m --frame 3", &out));
    EXPECT_NE(std::string::npos, out.find("--frame")) << out;
    for (const char* bad : {"100x50", "1600", "0x900"})
    {
        EXPECT_EQ(2, runCommand(bin + " --input " + dir + "/frames --masks " + dir +
                                "/m --max-window " + bad, &out)) << bad;
        EXPECT_NE(std::string::npos, out.find("--max-window")) << bad << ": " << out;
    }
    std::ofstream(dir + "/c.yml.gz") << "not a clone file";
    EXPECT_EQ(2, runCommand(bin + " --input " + dir + "/frames --masks " + dir +
                            "/m --clones " + dir + "/c.yml.gz", &out));
    EXPECT_NE(std::string::npos, out.find("--reconstruction")) << out;
    EXPECT_EQ(2, runCommand("env -u DISPLAY -u WAYLAND_DISPLAY " + bin + " --input " + dir +
                            "/frames --masks " + dir + "/m", &out));
    EXPECT_NE(std::string::npos, out.find("DISPLAY")) << out;
    EXPECT_FALSE(fs::exists(dir + "/m"));
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// --suggest marks (and prints) key frames before the window opens; without a display the tool
// then stops with exit 2, which lets this test run anywhere.
TEST(Augocc_AnnotateE2e, suggest_prints_key_frames)
{
    SceneSynthesizer::Params sp;
    sp.frames = 6;
    sp.numKeyFrames = 2;
    sp.numTracks = 100;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    const std::string dir = tempDir("annotate_suggest");
    fs::create_directories(dir + "/frames");
    for (int f = 0; f < sp.frames; ++f)
        ASSERT_TRUE(imwrite(format("%s/frames/%04d.png", dir.c_str(), f), scene.frames[f]));
    writeTracks(dir + "/tracks.yml", scene.tracks);
    writeReconstruction(dir + "/rec.yml", scene.groundTruth);
    std::string out;
    EXPECT_EQ(2, runCommand("env -u DISPLAY -u WAYLAND_DISPLAY " + augoccBinary() +
                                " annotate --input " + dir + "/frames --masks " + dir + "/m" +
                                " --tracks " + dir + "/tracks.yml --reconstruction " + dir +
                                "/rec.yml --suggest 3 --object building",
                            &out));
    const size_t at = out.find("suggested key frames for building:");
    ASSERT_NE(std::string::npos, at) << out;
    std::istringstream is(out.substr(at + std::string("suggested key frames for building:").size()));
    std::vector<int> keys(3);
    is >> keys[0] >> keys[1] >> keys[2];
    EXPECT_EQ(suggestKeyFrames(scene.tracks, scene.groundTruth, 3), keys) << out;
    EXPECT_EQ(0, keys.front());
    EXPECT_EQ(sp.frames - 1, keys.back());
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;
using namespace x11;

// The last "view scale S offset X Y" line of annotate's log (window pixel w shows frame point
// (w - offset) / scale) and how many there are.
int lastView(const std::string& log, double& scale, Point2d& offset)
{
    const std::string tag = "annotate: view scale ";
    int n = 0;
    for (size_t at = log.find(tag); at != std::string::npos; at = log.find(tag, at + 1))
    {
        if (log.find('\n', at) == std::string::npos)
            break;
        std::istringstream is(log.substr(at + tag.size()));
        std::string word;
        is >> scale >> word >> offset.x >> offset.y;
        n++;
    }
    return n;
}

bool waitForViews(const std::string& log, int count, double timeoutS)
{
    double s;
    Point2d o;
    for (int i = 0; i < timeoutS * 10; ++i)
    {
        if (lastView(readFile(log), s, o) >= count)
            return true;
        sleepMs(100);
    }
    return false;
}

// 1080p frames in the default window (--max-window 1600x900: the frame scaled to fit), zoomed
// about the cursor with the + key (three presses), panned with a middle-button drag: the
// clicks xdotool makes land on the intended frame pixels. Straight segments (no click snap), so
// the saved mask must equal, pixel for pixel, the library's mask of those frame pixels.
TEST(Augocc_AnnotateE2e, xvfb_zoomed_1080p_clicks_land_on_frame_pixels)
{
    const std::string bin = augoccBinary();
    const char* shotsEnv = std::getenv("AUGOCC_ANNOTATE_SHOTS");
    const std::string shots = shotsEnv ? shotsEnv : "";
    const std::string skip = windowTestSkipReason(bin, shots, "AUGOCC_ANNOTATE_SHOTS");
    if (!skip.empty())
        GTEST_SKIP() << skip;

    const std::string dir = tempDir("annotate_zoom");
    fs::create_directories(dir + "/frames");
    SceneSynthesizer::Params sp;
    sp.frames = 2;
    sp.numKeyFrames = 2;
    sp.numTracks = 50;
    sp.imageSize = Size(1920, 1080);
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    for (int f = 0; f < sp.frames; ++f)
        ASSERT_TRUE(imwrite(format("%s/frames/%04d.png", dir.c_str(), f), scene.frames[f]));
    const std::string masks = dir + "/masks";

    Child xvfb;
    std::string why;
    const std::string display = startXvfb(xvfb, dir, why, "1920x1080x24");
    ASSERT_FALSE(display.empty()) << why;
    Child tool;
    const std::string log = dir + "/annotate.log";
    tool.pid = spawn({bin, "annotate", "--input", dir + "/frames", "--masks", masks, "--object",
                      "building", "--screenshot-dir", dir},
                     {"DISPLAY=" + display, "QT_QPA_PLATFORM=xcb"}, log);
    ASSERT_GT(tool.pid, 0);
    Rect rect;
    ASSERT_TRUE(waitForWindowRect(tool, log, kStartTimeoutS, rect, why)) << why;
    // The frame scaled to fit 1600 x (900 - the status lines), ImageViewport::fitViewSize.
    const Size view = ImageViewport::fitViewSize(sp.imageSize, Size(1600, 900 - 56));
    ASSERT_EQ(view.width, rect.width) << readFile(log);
    ASSERT_GE(rect.height, view.height);
    ASSERT_TRUE(waitForViews(log, 1, 5)) << readFile(log);
    sleepMs(300);

    Xdo xdo(display);
    const Point origin = rect.tl();
    // Zoom about a point left of the building's centre: + three times.
    const Rect bbox = boundingRect(scene.visibleMasks.at("building").at(0));
    double scale0;
    Point2d offset0;
    lastView(readFile(log), scale0, offset0);
    const Point2d c = scale0 * Point2d(bbox.x + 0.3 * bbox.width, bbox.y + 0.5 * bbox.height) +
                      offset0;
    const Point cursor(cvRound(c.x), cvRound(c.y));
    xdo.moveTo(origin + cursor);
    xdo.key("plus");
    xdo.key("plus");
    xdo.key("plus");
    ASSERT_TRUE(waitForViews(log, 4, 10)) << "no zoom from +:\n" << readFile(log);
    // Pan: drag with the middle button 80 px left and 50 px up.
    xdo.run("mousedown 2");
    sleepMs(100);
    xdo.moveTo(origin + cursor + Point(-80, -50));
    xdo.run("mouseup 2");
    sleepMs(300);
    double scale;
    Point2d offset;
    const int views = lastView(readFile(log), scale, offset);
    ASSERT_GE(views, 5) << "no pan:\n" << readFile(log);
    // 1.25^3 over the fit (0.78): 1.53 window pixels per frame pixel.
    const double kZoomed = scale0 * 1.25 * 1.25 * 1.25;
    EXPECT_NEAR(kZoomed, scale, 1e-6 * kZoomed);
    // The frame point under the cursor stayed there while zooming; the drag moved it by the drag.
    const Point2d under = (Point2d(cursor) - offset0) * (1.0 / scale0);
    EXPECT_LE(norm(scale * under + offset - Point2d(cursor + Point(-80, -50))), 1e-3);

    // Five frame pixels spread over what the view shows now; the window pixel that shows each.
    const Point2d lo = (Point2d(0, 0) - offset) * (1.0 / scale);
    const Point2d hi = (Point2d(view.width - 1, view.height - 1) - offset) * (1.0 / scale);
    const double fx[] = {0.2, 0.7, 0.85, 0.5, 0.15}, fy[] = {0.2, 0.15, 0.6, 0.85, 0.7};
    std::vector<Point> pixels, clicks;
    for (int i = 0; i < 5; ++i)
    {
        const Point q(cvRound(lo.x + fx[i] * (hi.x - lo.x)), cvRound(lo.y + fy[i] * (hi.y - lo.y)));
        const Point2d v = scale * Point2d(q) + offset;
        const Point w(cvRound(v.x), cvRound(v.y));
        // That window pixel shows q: its centre lies within q's area (scale > 1).
        ASSERT_EQ(q.x, (int)std::floor((w.x - offset.x) / scale + 0.5));
        ASSERT_EQ(q.y, (int)std::floor((w.y - offset.y) / scale + 0.5));
        pixels.push_back(q);
        clicks.push_back(w);
    }
    xdo.key("l");  // straight segments: clicks are not snapped to edges
    for (size_t i = 0; i < clicks.size(); ++i)
        xdo.click(origin + clicks[i]);
    if (!shots.empty())
    {
        xdo.moveTo(origin + (clicks[0] + clicks[4]) / 2);
        sleepMs(400);
        grab(display, rect, shots + "/annotate_zoom.png");
        xdo.key("h");
        sleepMs(300);
        grab(display, rect, shots + "/annotate_zoom_help.png");
        xdo.key("h");
    }
    xdo.key("c");  // close
    xdo.key("q");  // save and quit
    const int rc = tool.wait(kExitTimeoutS);
    const std::string text = readFile(log);
    ASSERT_EQ(0, rc) << "augocc annotate did not exit cleanly:\n" << text;
    xvfb.stop();

    const Mat written = imread(masks + "/building/0000.png", IMREAD_GRAYSCALE);
    ASSERT_FALSE(written.empty()) << "no mask written:\n" << text;
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.frames[0]);
    ed->setSegmentMode(SilhouetteEditor::STRAIGHT);
    for (const Point& q : pixels)
        EXPECT_EQ(q, ed->addPoint(q));
    ASSERT_TRUE(ed->closeContour());
    Mat headless;
    ed->getMask(headless);
    std::cout << format("[ annotate zoom ] 1920x1080 in a %dx%d view, scale %.4f (fit %.4f); "
                        "mask %d px, differing from the library's: %d px",
                        view.width, view.height, scale, scale0, countNonZero(headless),
                        countNonZero(written != headless))
              << std::endl;
    EXPECT_GT(countNonZero(headless), 1000);
    EXPECT_EQ(0, norm(written, headless, NORM_INF)) << "clicks did not land on the frame pixels";
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test
