// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// PlacementEditor (`augocc place`'s logic), headless: scripted drags against the synthesizer's
// true ground, the other edits, undo, the saved scene against the preview, bad arguments.

#include "test_precomp.hpp"
#include "test_placement_scene.hpp"

#include <filesystem>

namespace opencv_test {

const PlacementShot& placementShot()
{
    static const PlacementShot shot = [] {
        using namespace cv::augocc;
        PlacementShot s;
        SceneSynthesizer::Params sp;
        sp.frames = 6;
        sp.numKeyFrames = 3;
        sp.imageSize = cv::Size(320, 240);
        SceneSynthesizer::create(sp)->synthesize(s.scene);
        s.clones = CloneBuilder::create()->build(s.scene.groundTruth, s.scene.keyFrameMasks);
        double lo0 = DBL_MAX, lo2 = DBL_MAX, hi0 = -DBL_MAX, hi2 = -DBL_MAX;
        for (const Mesh& m : s.scene.objectMeshes)
        {
            cv::Vec3f lo, hi;
            m.bounds(lo, hi);
            lo0 = std::min(lo0, (double)lo[0]);
            lo2 = std::min(lo2, (double)lo[2]);
            hi0 = std::max(hi0, (double)hi[0]);
            hi2 = std::max(hi2, (double)hi[2]);
        }
        s.sceneSize = std::hypot(hi0 - lo0, hi2 - lo2);
        SceneObject box;
        box.name = "crate";
        box.shape = "box";
        box.meshes = proceduralShape("box");
        box.placement = SceneObject::PLACE_BESIDE;
        box.anchor = "building";
        box.size = 0.3;
        SceneObject dome;
        dome.name = "dome";
        dome.shape = "dome";
        dome.meshes = proceduralShape("dome");
        dome.position = cv::Vec3d(-3, 0, 6);
        dome.scale = cv::Vec3d::all(0.8);
        s.virtualScene.objects = {box, dome};
        return s;
    }();
    return shot;
}

cv::Vec3d trueGroundPoint(const cv::augocc::Camera& camera, const cv::Point2d& px)
{
    const cv::augocc::Ray r = camera.backproject(px);
    return r.at(-r.origin[1] / r.direction[1]);
}

namespace {
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

// The bound: the object lands at the ground point under the cursor within 1% of the
// scene's size. The editor's ground is estimated (a RANSAC plane through the reconstructed
// points); a height error h moves the ground point by h / tan(elevation) along the view, which
// is what this bound allows for.
const double kDragTolFraction = 0.01;

Ptr<PlacementEditor> makeEditor(const PlacementShot& shot)
{
    return PlacementEditor::create(shot.scene.groundTruth, shot.clones, shot.virtualScene);
}

// A mouse's drag: press on the object's base point, move through `steps` integer pixels, release.
bool scriptedDrag(PlacementEditor& ed, int object, Point target, int steps)
{
    const Point start = Point(ed.getCamera().project(ed.getBasePoint(object)));
    if (!ed.beginDrag(start))
        return false;
    for (int i = 1; i <= steps; i++)
        ed.dragTo(start + (target - start) * i / steps);
    ed.dragTo(target);
    return ed.endDrag();
}

TEST(Augocc_PlacementEditor, accuracy_scripted_drag_on_ground)
{
    const PlacementShot& shot = placementShot();
    Ptr<PlacementEditor> ed = makeEditor(shot);
    const double tol = kDragTolFraction * shot.sceneSize;
    const GroundFrame g = ed->getGround();
    RNG rng(7);
    double worst = 0;
    for (int f = 0; f < (int)shot.scene.frames.size(); f++)
    {
        ed->setFrame(f, shot.scene.frames[f]);
        const Camera& cam = shot.scene.groundTruth.camera(f);
        // A ground point in front of the real objects, seen in this frame, as a mouse pixel.
        const Vec3d want(rng.uniform(-3.0, 3.0), 0, rng.uniform(4.0, 7.0));
        const Point target = Point(cam.project(want));
        ASSERT_TRUE(Rect(Point(), shot.scene.frames[f].size()).contains(target));
        ASSERT_TRUE(scriptedDrag(*ed, 0, target, 6)) << "frame " << f;
        EXPECT_EQ(0, ed->getSelected());
        const Vec3d base = ed->getBasePoint(0);
        const Vec3d truth = trueGroundPoint(cam, target);
        const double err = norm(base - truth);
        worst = std::max(worst, err);
        EXPECT_LE(err, tol) << "frame " << f;
        // It stays on the (estimated) ground: its lowest point on the plane, to rounding.
        EXPECT_NEAR(g.toGround(base)[1], 0.0, 1e-9 * shot.sceneSize) << "frame " << f;
        EXPECT_EQ(SceneObject::PLACE_ABSOLUTE, ed->getObject(0).placement);
    }
    std::cout << cv::format("[ place drag ] worst distance to the true ground point under the "
                            "cursor over %d frames: %.4f (%.3f%% of the scene's size %.2f)",
                            (int)shot.scene.frames.size(), worst, 100 * worst / shot.sceneSize,
                            shot.sceneSize)
              << std::endl;
    // Each drag is one undo step; the first undo puts the object back where frame 4 left it.
    const Vec3d last = ed->getBasePoint(0);
    ASSERT_TRUE(ed->undo());
    EXPECT_GT(norm(ed->getBasePoint(0) - last), tol);
    ASSERT_TRUE(ed->redo());
    EXPECT_LT(norm(ed->getBasePoint(0) - last), 1e-12 * shot.sceneSize);
}

// Turning, scaling and raising keep the base point where it is (to rounding); the snap puts the
// object against the clone's face with the gap asked for.
TEST(Augocc_PlacementEditor, accuracy_edits_and_snap)
{
    const PlacementShot& shot = placementShot();
    Ptr<PlacementEditor> ed = makeEditor(shot);
    ed->setFrame(0, shot.scene.frames[0]);
    const double kRound = 1e-9 * shot.sceneSize;  // double rounding over a few products
    ed->selectObject(1);
    const Vec3d b0 = ed->getBasePoint(1);
    const Matx44d P0 = ed->getPose(1);
    ASSERT_TRUE(ed->rotate(37));
    EXPECT_LT(norm(ed->getBasePoint(1) - b0), kRound);
    // The linear part turned by 37 degrees about the ground's up (the dome's scale is 0.8).
    const Matx44d P1 = ed->getPose(1);
    Matx33d R0, R1;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
        {
            R0(r, c) = P0(r, c) / 0.8;
            R1(r, c) = P1(r, c) / 0.8;
        }
    EXPECT_NEAR(37.0, rotationAngleDeg(R0, R1), 1e-6);
    const Vec3d up = ed->getGround().up;
    EXPECT_LT(norm(R1 * R0.t() * up - up), 1e-9);
    ASSERT_TRUE(ed->scale(1.5));
    EXPECT_LT(norm(ed->getBasePoint(1) - b0), kRound);
    EXPECT_NEAR(0.8 * 1.5, ed->getObject(1).scale[0], 1e-12);
    ASSERT_TRUE(ed->raise(0.5));
    EXPECT_NEAR(0.5, ed->getGround().toGround(ed->getBasePoint(1))[1] -
                         ed->getGround().toGround(b0)[1], kRound);
    // Snap behind the building, 0.75 units back: the object's nearest face to the viewer
    // (largest back coordinate) 0.75 beyond the clone box's far face, centred on it.
    const double gap = 0.75;
    ASSERT_TRUE(ed->snapToClone("building", PlacementEditor::SNAP_BEHIND, gap));
    Vec3d clo, chi, olo, ohi;
    ed->getCloneBounds("building", clo, chi);
    ed->getObjectBounds(1, olo, ohi);
    const double kSnapTol = 1e-4 * shot.sceneSize;  // float vertices of the placed mesh
    EXPECT_NEAR(clo[2] - gap, ohi[2], kSnapTol);
    EXPECT_NEAR(0.5 * (clo[0] + chi[0]), 0.5 * (olo[0] + ohi[0]), kSnapTol);
    EXPECT_NEAR(0.0, olo[1], kSnapTol);  // on the ground again
    const SceneObject o = ed->getObject(1);
    EXPECT_EQ(SceneObject::PLACE_BEHIND, o.placement);
    EXPECT_EQ("building", o.anchor);
    // The turn and scale survive the snap: same linear part of the pose.
    Matx33d A;
    const Matx44d P = ed->getPose(1);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            A(r, c) = P(r, c);
    ed->undo();
    const Matx44d Q = ed->getPose(1);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            EXPECT_NEAR(Q(r, c), A(r, c), 1e-9);
    ed->redo();
    // Nearest clone: the crate stands beside the building, so the building is the nearest.
    ed->selectObject(0);
    EXPECT_EQ("building", ed->snapToNearestClone(PlacementEditor::SNAP_RIGHT, 0));
    EXPECT_EQ(SceneObject::PLACE_BESIDE, ed->getObject(0).placement);
    EXPECT_EQ(1, ed->getObject(0).side);
    ed->getObjectBounds(0, olo, ohi);
    EXPECT_NEAR(chi[0], olo[0], kSnapTol);  // against the clone's right face, no gap
    // Undo all: back to the scene as given, not modified.
    while (ed->undo())
        ;
    EXPECT_FALSE(ed->isModified());
    EXPECT_EQ(SceneObject::PLACE_BESIDE, ed->getObject(0).placement);
}

// The saved scene.yml composites (augocc composite's compositeSequence) to the preview's pixels.
TEST(Augocc_PlacementEditor, regression_saved_scene_composites_to_preview)
{
    const PlacementShot& shot = placementShot();
    const std::string dir = tempDir("place_save");
    fs::create_directories(dir + "/frames");
    for (size_t f = 0; f < shot.scene.frames.size(); f++)
        ASSERT_TRUE(imwrite(cv::format("%s/frames/%04d.png", dir.c_str(), (int)f),
                            shot.scene.frames[f]));
    Ptr<PlacementEditor> ed = makeEditor(shot);
    const int frame = 3;
    ed->setFrame(frame, shot.scene.frames[frame]);
    const Camera& cam = shot.scene.groundTruth.camera(frame);
    ASSERT_TRUE(scriptedDrag(*ed, 0, Point(cam.project(Vec3d(1.5, 0, 5))), 4));
    ed->rotate(30);
    ed->scale(1.25);
    ed->selectObject(1);
    ed->snapToClone("building", PlacementEditor::SNAP_IN_FRONT, 0.4);
    const std::string data = std::string(AUGOCC_SOURCE_DIR) + "/test/data/";
    const int added = ed->addObject(data + "tetra.ply", Point(cam.project(Vec3d(-1, 0, 6))));
    EXPECT_EQ(2, added);
    EXPECT_EQ(ed->getSelected(), added);
    ed->raise(0.2);
    Mat preview;
    ed->render(preview);
    ASSERT_TRUE(ed->isModified());
    const std::string path = dir + "/scene.yml";
    ed->save(path);
    EXPECT_FALSE(ed->isModified());

    const VirtualScene saved = readScene(path);
    ASSERT_EQ(3u, saved.objects.size());
    EXPECT_EQ(SceneObject::PLACE_ABSOLUTE, saved.objects[0].placement);  // dragged
    EXPECT_EQ(SceneObject::PLACE_IN_FRONT, saved.objects[1].placement);  // the snap's helper
    EXPECT_EQ("tetra", saved.objects[2].name);
    const std::vector<Mesh> meshes = placeScene(saved, shot.scene.groundTruth, shot.clones.get());
    CompositeOptions opt;
    opt.firstFrame = frame;
    opt.endFrame = frame + 1;
    compositeSequence(dir + "/frames", shot.scene.groundTruth, *shot.clones, meshes, dir + "/out",
                      opt);
    const Mat composited = imread(cv::format("%s/out/%04d.png", dir.c_str(), frame));
    ASSERT_EQ(preview.size(), composited.size());
    // Bit-equal: the same poses (the file holds every double to 17 digits) and the same
    // Compositor parameters.
    EXPECT_EQ(0, norm(preview, composited, NORM_INF));
    // ...and the preview did change the frame (a test that can fail).
    EXPECT_GT(norm(preview, shot.scene.frames[frame], NORM_L1), 1000.0);
    fs::remove_all(dir);
}

// Under the scene's sun the preview shows the shadows composite draws (issue 19: "see the
// composite with occlusion and shadows update live"): still bit-equal to the saved scene's
// composite, and the sun did change the preview (shadows on the ground and the clones).
TEST(Augocc_PlacementEditor, regression_preview_under_the_sun)
{
    const PlacementShot& shot = placementShot();
    const std::string dir = tempDir("place_sun");
    fs::create_directories(dir + "/frames");
    const int frame = 2;
    for (size_t f = 0; f < shot.scene.frames.size(); f++)
        ASSERT_TRUE(imwrite(cv::format("%s/frames/%04d.png", dir.c_str(), (int)f),
                            shot.scene.frames[f]));
    VirtualScene sunny = shot.virtualScene;
    sunny.sun.form = SceneSun::SUN_AZIMUTH_ELEVATION;
    sunny.sun.azimuthDeg = 150;
    sunny.sun.elevationDeg = 40;
    Ptr<PlacementEditor> lit = PlacementEditor::create(shot.scene.groundTruth, shot.clones, sunny);
    Ptr<PlacementEditor> unlit = makeEditor(shot);
    Mat withSun, withoutSun;
    lit->setFrame(frame, shot.scene.frames[frame]);
    unlit->setFrame(frame, shot.scene.frames[frame]);
    lit->render(withSun);
    unlit->render(withoutSun);
    // A shadow darkens many pixels by tens of grey levels; 3000 is far above the float noise of
    // one render (0) and far below the shadows' sum.
    EXPECT_GT(norm(withSun, withoutSun, NORM_L1), 3000.0);
    const std::string path = dir + "/scene.yml";
    lit->save(path);
    const VirtualScene saved = readScene(path);
    EXPECT_EQ(SceneSun::SUN_AZIMUTH_ELEVATION, saved.sun.form);
    CompositeOptions opt;
    opt.firstFrame = frame;
    opt.endFrame = frame + 1;
    opt.sun = resolveSun(saved, shot.scene.groundTruth);
    const std::vector<Mesh> meshes = placeScene(saved, shot.scene.groundTruth, shot.clones.get());
    compositeSequence(dir + "/frames", shot.scene.groundTruth, *shot.clones, meshes,
                      dir + "/out", opt);
    const Mat composited = imread(cv::format("%s/out/%04d.png", dir.c_str(), frame));
    ASSERT_EQ(withSun.size(), composited.size());
    EXPECT_EQ(0, norm(withSun, composited, NORM_INF));
    fs::remove_all(dir);
}

// The sun in the editor (issue 19 item 3, "place shows it and lets the user adjust"): estimated
// from the footage under a known sun, turned and its sky changed by the keys' edits, undone,
// saved; the saved scene composites to the preview's pixels.
TEST(Augocc_PlacementEditor, accuracy_sun_estimate_and_turn)
{
    const PlacementShot& shot = placementShot();
    const Reconstruction& rec = shot.scene.groundTruth;
    // The footage under a known sun (the synthesizer's truth), azimuth 120, elevation 35 in the
    // true ground (y up, north -z: GroundFrame()).
    SceneSynthesizer::Params sp;
    sp.frames = 6;
    sp.numKeyFrames = 3;
    sp.imageSize = Size(320, 240);
    sp.sun.direction = sunDirection(GroundFrame(), 120, 35);
    sp.sun.sky = 0.4;
    Ptr<SceneSynthesizer> synth = SceneSynthesizer::create(sp);
    const std::vector<int> frames = sunEstimationFrames(rec, 4);
    std::vector<Mat> images;
    for (int f : frames)
    {
        Mat img;
        synth->renderFrame(f, img);
        images.push_back(img);
    }
    Ptr<PlacementEditor> ed = makeEditor(shot);  // a scene without a sun
    ASSERT_EQ(SceneSun::SUN_NONE, ed->getSun().form);
    double az = 0, el = 0;
    EXPECT_FALSE(ed->getSunAngles(az, el));
    EXPECT_FALSE(ed->turnSun(5, 0));
    EXPECT_FALSE(ed->changeSky(0.1));
    EXPECT_FALSE(ed->canUndo());
    SunEstimationParams quick;
    quick.jackknifeGroups = 3;  // the fewest that give a 1-sigma (faster than the default 8)
    const SunEstimate e = ed->estimateSunFromFrames(images, frames, quick);
    // The editor's estimate is estimateSun()'s on the same inputs, and becomes the scene's sun.
    const SunEstimate direct = estimateSun(images, frames, rec, *shot.clones,
                                           estimateGround(rec), quick);
    EXPECT_EQ(direct.direction, e.direction);
    EXPECT_EQ(e.frames, ed->getSunEstimate().frames);
    ASSERT_TRUE(ed->getSunAngles(az, el));
    EXPECT_EQ(SceneSun::SUN_AZIMUTH_ELEVATION, ed->getSun().form);
    // Its angles are the estimate's (the same ground and north, computed two ways: 1e-9 deg).
    EXPECT_NEAR(e.azimuthDeg, az, 1e-9);
    EXPECT_NEAR(e.elevationDeg, el, 1e-9);
    EXPECT_NEAR(std::min(0.95, e.sky), ed->getSun().sky, 1e-12);
    // The estimator's own accuracy bound on synthesized footage (issue 19: worst 10 degrees).
    const Vec3d truth = sp.sun.direction;
    const Vec3d got = resolveSun(ed->getScene(), rec).direction;
    const double errDeg = std::acos(std::min(1.0, got.dot(truth))) * 180 / CV_PI;
    std::cout << cv::format("[ place sun ] estimate az %.2f el %.2f (1-sigma %.2f), sky %.3f; "
                            "%.2f deg from the true sun (az 120, el 35, sky 0.4)", e.azimuthDeg,
                            e.elevationDeg, e.angularSigmaDeg, e.sky, errDeg)
              << std::endl;
    EXPECT_LE(errDeg, 10.0);
    // Turns add to the angles; the elevation is held in [1, 89] degrees.
    ASSERT_TRUE(ed->turnSun(10, -5));
    double az2 = 0, el2 = 0;
    ASSERT_TRUE(ed->getSunAngles(az2, el2));
    EXPECT_NEAR(std::fmod(az + 10, 360.0), az2, 1e-9);
    EXPECT_NEAR(el - 5, el2, 1e-9);
    ASSERT_TRUE(ed->turnSun(0, 200));
    ASSERT_TRUE(ed->getSunAngles(az2, el2));
    EXPECT_EQ(89.0, el2);
    ASSERT_TRUE(ed->undo());
    ASSERT_TRUE(ed->getSunAngles(az2, el2));
    EXPECT_NEAR(el - 5, el2, 1e-9);
    ASSERT_TRUE(ed->changeSky(-1.0));
    EXPECT_EQ(0.0, ed->getSun().sky);
    ASSERT_TRUE(ed->undo());
    // A direction form reads back as the angles sunDirection() maps to it.
    SceneSun d;
    d.form = SceneSun::SUN_DIRECTION;
    d.direction = sunDirection(ed->getGround(), 200, 30);
    ed->setSun(d);
    ASSERT_TRUE(ed->getSunAngles(az2, el2));
    EXPECT_NEAR(200, az2, 1e-9);
    EXPECT_NEAR(30, el2, 1e-9);
    ASSERT_TRUE(ed->undo());
    // A bad sun is refused and changes nothing.
    SceneSun bad = ed->getSun();
    bad.sky = 1.5;
    const int before = ed->getSun().form;
    EXPECT_THROW(ed->setSun(bad), cv::Exception);
    EXPECT_EQ(before, ed->getSun().form);
    // Saved, the scene composites to the preview under the adjusted sun.
    const int frame = 2;
    const std::string dir = tempDir("place_sun_turn");
    fs::create_directories(dir + "/frames");
    for (size_t f = 0; f < shot.scene.frames.size(); f++)
        ASSERT_TRUE(imwrite(cv::format("%s/frames/%04d.png", dir.c_str(), (int)f),
                            shot.scene.frames[f]));
    ed->setFrame(frame, shot.scene.frames[frame]);
    Mat first, preview;
    ed->render(first);
    ASSERT_TRUE(ed->turnSun(-30, 0));  // the compositor is re-lit, not rebuilt
    ed->render(preview);
    EXPECT_GT(norm(first, preview, NORM_L1), 1000.0);  // the shadows moved
    ed->save(dir + "/scene.yml");
    const VirtualScene saved = readScene(dir + "/scene.yml");
    EXPECT_EQ(SceneSun::SUN_AZIMUTH_ELEVATION, saved.sun.form);
    ASSERT_TRUE(ed->getSunAngles(az2, el2));
    EXPECT_NEAR(az2, saved.sun.azimuthDeg, 1e-9);
    CompositeOptions opt;
    opt.firstFrame = frame;
    opt.endFrame = frame + 1;
    opt.sun = resolveSun(saved, rec);
    compositeSequence(dir + "/frames", rec, *shot.clones,
                      placeScene(saved, rec, shot.clones.get()), dir + "/out", opt);
    const Mat composited = imread(cv::format("%s/out/%04d.png", dir.c_str(), frame));
    ASSERT_EQ(preview.size(), composited.size());
    EXPECT_EQ(0, norm(preview, composited, NORM_INF));
    fs::remove_all(dir);
}

// The preview and the poses do not depend on the thread count (the Compositor's CPU stages and
// the editor's bounds).
TEST(Augocc_PlacementEditor, multithread_reproducibility)
{
    const PlacementShot& shot = placementShot();
    Mat previews[2];
    Vec3d bases[2];
    for (int run = 0; run < 2; run++)
    {
        cv::setNumThreads(run == 0 ? 1 : 2);
        Ptr<PlacementEditor> ed = makeEditor(shot);
        ed->setFrame(1, shot.scene.frames[1]);
        const Camera& cam = shot.scene.groundTruth.camera(1);
        ASSERT_TRUE(scriptedDrag(*ed, 0, Point(cam.project(Vec3d(-1, 0, 5))), 3));
        ed->rotate(20);
        ed->render(previews[run]);
        bases[run] = ed->getBasePoint(0);
    }
    EXPECT_EQ(0, norm(previews[0], previews[1], NORM_INF));
    EXPECT_EQ(bases[0], bases[1]);
}

TEST(Augocc_PlacementEditor, bad_arg)
{
    const PlacementShot& shot = placementShot();
    EXPECT_THROW(PlacementEditor::create(shot.scene.groundTruth, Ptr<CloneSet>(),
                                         shot.virtualScene),
                 cv::Exception);
    PlacementEditor::Params p;
    p.supersample = 0;
    EXPECT_THROW(PlacementEditor::create(shot.scene.groundTruth, shot.clones, shot.virtualScene,
                                         p),
                 cv::Exception);
    VirtualScene unknown = shot.virtualScene;
    unknown.objects[0].anchor = "castle";
    EXPECT_THROW(PlacementEditor::create(shot.scene.groundTruth, shot.clones, unknown),
                 cv::Exception);
    Ptr<PlacementEditor> ed = makeEditor(shot);
    Vec3d w;
    EXPECT_THROW(ed->groundPoint(Point2d(1, 1), w), cv::Exception);  // no frame yet
    EXPECT_THROW(ed->setFrame(99, shot.scene.frames[0]), cv::Exception);
    EXPECT_THROW(ed->setFrame(0, Mat(10, 10, CV_8UC3)), cv::Exception);
    ed->setFrame(0, shot.scene.frames[0]);
    EXPECT_THROW(ed->selectObject(2), cv::Exception);
    EXPECT_FALSE(ed->rotate(10));  // nothing selected
    ed->selectObject(0);
    EXPECT_THROW(ed->scale(0), cv::Exception);
    EXPECT_THROW(ed->snapToClone("castle", PlacementEditor::SNAP_BEHIND, 1), cv::Exception);
    EXPECT_THROW(ed->snapToClone("building", 7, 1), cv::Exception);
    EXPECT_THROW(ed->snapToClone("building", PlacementEditor::SNAP_BEHIND, -1), cv::Exception);
    const std::string data = std::string(AUGOCC_SOURCE_DIR) + "/test/data/";
    try
    {
        ed->addObject(data + "corrupt.ply", Point2d(10, 10));
        ADD_FAILURE() << "a corrupt mesh was added";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_NE(std::string::npos, e.err.find("corrupt.ply")) << e.err;
    }
    EXPECT_EQ(2, ed->getObjectCount());
    EXPECT_FALSE(ed->canUndo());  // the failed edits left no undo step
    ed->removeObject(1);
    ed->removeObject(0);
    const std::string dir = tempDir("place_bad");
    EXPECT_THROW(ed->save(dir + "/empty.yml"), cv::Exception);
    EXPECT_FALSE(fs::exists(dir + "/empty.yml"));
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test
