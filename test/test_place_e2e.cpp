// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// End-to-end test of `augocc place`: the real window under a private Xvfb display, a drag with
// xdotool, checked by the scene file it saves. Skips when Xvfb or xdotool is missing.
// With AUGOCC_PLACE_SHOTS=<dir> it also grabs screenshots of the window (ffmpeg x11grab) for the
// documentation.

#include "test_precomp.hpp"
#include "test_placement_scene.hpp"
#include "test_x11.hpp"

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;
using namespace x11;
namespace fs = std::filesystem;

// The bound (as in Augocc_PlacementEditor.accuracy_scripted_drag_on_ground).
const double kDragTolFraction = 0.01;
// Generous limits: the window appears in ~1 s on an idle machine; 2 cores shared with builds.
const double kStartTimeoutS = 60.0;
const double kExitTimeoutS = 30.0;

struct PlaceFiles
{
    std::string dir, frames, rec, clones, scene;
};

PlaceFiles writePlaceFiles(const PlacementShot& shot, const std::string& tag)
{
    PlaceFiles p;
    p.dir = tempDir(tag);
    p.frames = p.dir + "/frames";
    fs::create_directories(p.frames);
    for (size_t f = 0; f < shot.scene.frames.size(); f++)
        EXPECT_TRUE(imwrite(format("%s/%04d.png", p.frames.c_str(), (int)f),
                            shot.scene.frames[f]));
    p.rec = p.dir + "/rec.yml";
    writeReconstruction(p.rec, shot.scene.groundTruth);
    p.clones = p.dir + "/clones.yml.gz";
    shot.clones->save(p.clones);
    p.scene = p.dir + "/scene.yml";
    writeScene(p.scene, shot.virtualScene);
    return p;
}

TEST(Augocc_PlaceE2e, xvfb_xdotool_drags_and_saves_scene)
{
    const std::string bin = augoccBinary();
    const char* shotsEnv = std::getenv("AUGOCC_PLACE_SHOTS");
    const std::string shots = shotsEnv ? shotsEnv : "";
    const std::string skip = windowTestSkipReason(bin, shots, "AUGOCC_PLACE_SHOTS");
    if (!skip.empty())
        GTEST_SKIP() << skip;

    const PlacementShot& shot = placementShot();
    const PlaceFiles files = writePlaceFiles(shot, "place_e2e");
    const int frame = 2;
    std::string why;
    Child xvfb;
    const std::string display = startXvfb(xvfb, files.dir, why);
    ASSERT_FALSE(display.empty()) << why;
    Child tool;
    const std::string log = files.dir + "/place.log";
    const std::string out = files.dir + "/placed.yml";
    tool.pid = spawn({bin, "place", "--input", files.frames, "--reconstruction", files.rec,
                      "--clones", files.clones, "--scene", files.scene, "--out", out, "--frame",
                      std::to_string(frame), "--screenshot-dir", files.dir},
                     {"DISPLAY=" + display, "QT_QPA_PLATFORM=xcb"}, log);
    ASSERT_GT(tool.pid, 0);
    Rect rect;
    ASSERT_TRUE(waitForWindowRect(tool, log, kStartTimeoutS, rect, why)) << why;
    const Size size = shot.scene.frames[0].size();
    ASSERT_EQ(size.width, rect.width) << readFile(log);
    ASSERT_GE(rect.height, size.height);
    sleepMs(300);

    // The same drag headless: from the crate's base point to a ground point in front of it.
    Ptr<PlacementEditor> ed = PlacementEditor::create(shot.scene.groundTruth, shot.clones,
                                                      shot.virtualScene);
    ed->setFrame(frame, shot.scene.frames[frame]);
    const Camera& cam = shot.scene.groundTruth.camera(frame);
    const Point start = Point(cam.project(ed->getBasePoint(0)));
    const Point target = Point(cam.project(Vec3d(2.0, 0, 5.5)));
    ASSERT_TRUE(ed->beginDrag(start));
    ASSERT_TRUE(ed->dragTo(target));
    ASSERT_TRUE(ed->endDrag());

    Xdo xdo(display);
    const Point origin = rect.tl();
    if (!shots.empty())
    {
        xdo.moveTo(origin + Point(size.width - 5, size.height - 5));
        sleepMs(500);
        grab(display, rect, shots + "/place_start.png");
    }
    xdo.moveTo(origin + start);
    xdo.run("mousedown 1");
    sleepMs(200);
    for (int i = 1; i <= 5; i++)
        xdo.moveTo(origin + start + (target - start) * i / 5);
    xdo.run("mouseup 1");
    sleepMs(400);
    if (!shots.empty())
    {
        grab(display, rect, shots + "/place_dragged.png");
        xdo.key("h");
        sleepMs(300);
        grab(display, rect, shots + "/place_help.png");
        xdo.key("h");
        xdo.key("o");      // select the dome
        xdo.key("b");      // snap it behind the nearest clone
        sleepMs(500);
        grab(display, rect, shots + "/place_snapped.png");
        xdo.key("u");      // and undo that: the saved file has the drag only
    }
    // The sun keys: on (azimuth 135, elevation 45, the default sky share), turned twice by +5
    // degrees, raised by 5, the sky share up by 0.05.
    for (const char* k : {"g", "2", "2", "4", "6"})
        xdo.key(k);
    sleepMs(500);
    if (!shots.empty())
        grab(display, rect, shots + "/place_sun.png");
    xdo.key("w");          // the tool's own screenshot of its canvas
    xdo.key("q");          // save and quit
    const int rc = tool.wait(kExitTimeoutS);
    const std::string text = readFile(log);
    ASSERT_EQ(0, rc) << "augocc place did not exit cleanly:\n" << text;
    xvfb.stop();

    ASSERT_TRUE(fs::exists(out)) << text;
    const VirtualScene placed = readScene(out);
    EXPECT_EQ(SceneSun::SUN_AZIMUTH_ELEVATION, placed.sun.form) << text;
    EXPECT_NEAR(145.0, placed.sun.azimuthDeg, 1e-9);
    EXPECT_NEAR(50.0, placed.sun.elevationDeg, 1e-9);
    EXPECT_NEAR(Sun().sky + 0.05, placed.sun.sky, 1e-12);
    Ptr<PlacementEditor> saved = PlacementEditor::create(shot.scene.groundTruth, shot.clones,
                                                         placed);
    ASSERT_EQ(2, saved->getObjectCount());
    const Vec3d base = saved->getBasePoint(0);
    const double fromHeadless = norm(base - ed->getBasePoint(0));
    const double fromTruth = norm(base - trueGroundPoint(cam, target));
    std::cout << format("[ place e2e ] dragged crate: %.2e from the headless drag, %.4f (%.3f%% "
                        "of the scene size) from the true ground point under the cursor",
                        fromHeadless, fromTruth, 100 * fromTruth / shot.sceneSize)
              << std::endl;
    // The window gives what the library gives for the same pixels: the file holds 17 digits
    // and the base point is computed in double (1e-9: rounding over the drag's steps).
    EXPECT_LT(fromHeadless, 1e-9 * shot.sceneSize);
    EXPECT_LT(fromTruth, kDragTolFraction * shot.sceneSize);
    // The dome was not touched: it keeps its place.
    EXPECT_LT(norm(saved->getBasePoint(1) - ed->getBasePoint(1)), 1e-9 * shot.sceneSize);
    bool shotFound = false;
    for (const auto& e : fs::directory_iterator(files.dir))
        shotFound = shotFound || e.path().filename().string().rfind("place_0002", 0) == 0;
    EXPECT_TRUE(shotFound) << "the w key saved no screenshot:\n" << text;
    fs::remove_all(files.dir);
}

// Bad input is reported before any window opens (exit 2, the file or flag named).
TEST(Augocc_PlaceE2e, bad_input)
{
    const PlacementShot& shot = placementShot();
    const PlaceFiles p = writePlaceFiles(shot, "place_bad");
    const std::string bin = augoccBinary() + " place";
    const std::string ok = " --input " + p.frames + " --reconstruction " + p.rec + " --clones " +
                           p.clones;
    std::string out;
    EXPECT_EQ(2, runCommand(bin + ok + " --scene " + p.dir + "/none.yml", &out));
    EXPECT_NE(std::string::npos, out.find("none.yml")) << out;
    std::ofstream(p.dir + "/broken.yml") << "%YAML:1.0\n---\nobjects:\n  - { shape: pyramid }\n";
    EXPECT_EQ(2, runCommand(bin + ok + " --scene " + p.dir + "/broken.yml", &out));
    EXPECT_NE(std::string::npos, out.find("broken.yml")) << out;
    std::ofstream(p.dir + "/bad.obj") << "this is not a mesh\n";
    EXPECT_EQ(2, runCommand(bin + ok + " --scene " + p.scene + " --add " + p.dir + "/bad.obj",
                            &out));
    EXPECT_NE(std::string::npos, out.find("bad.obj")) << out;
    EXPECT_EQ(2, runCommand(bin + ok + " --scene " + p.scene + " --frame 99", &out));
    EXPECT_NE(std::string::npos, out.find("--frame")) << out;
    std::ofstream(p.dir + "/c.yml.gz") << "not a clone file";
    EXPECT_EQ(2, runCommand(bin + " --input " + p.frames + " --reconstruction " + p.rec +
                            " --clones " + p.dir + "/c.yml.gz --scene " + p.scene, &out));
    EXPECT_NE(std::string::npos, out.find("c.yml.gz")) << out;
    // A reconstruction of another size than the frames.
    Reconstruction other = shot.scene.groundTruth;
    other.imageSize = Size(640, 480);
    writeReconstruction(p.dir + "/other.yml", other);
    EXPECT_EQ(2, runCommand(bin + " --input " + p.frames + " --reconstruction " + p.dir +
                            "/other.yml --clones " + p.clones + " --scene " + p.scene, &out));
    EXPECT_NE(std::string::npos, out.find("other.yml")) << out;
    EXPECT_EQ(2, runCommand("env -u DISPLAY -u WAYLAND_DISPLAY " + bin + ok + " --scene " +
                            p.scene, &out));
    EXPECT_NE(std::string::npos, out.find("DISPLAY")) << out;
    fs::remove_all(p.dir);
}

} // namespace
} // namespace opencv_test
