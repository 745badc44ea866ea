// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "test_silhouette_scene.hpp"

#include <filesystem>
#include <set>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// Done-when of issue 6: IoU >= 0.98 with at most 12 clicks for a box-shaped building.
const double kMinClickIoU = 0.98;
const int kMaxClicks = 12;
// A human click lands within a few pixels of the corner aimed at: jitter up to this (pixels).
const int kClickJitterPx = 2;

// Vertices of the true silhouette's outline (a box seen from above: a hexagon), as a user would
// aim at the corners.
std::vector<Point> outlineCorners(const Mat& mask)
{
    std::vector<std::vector<Point>> contours;
    findContours(mask.clone(), contours, RETR_EXTERNAL, CHAIN_APPROX_NONE);
    CV_Assert(!contours.empty());
    size_t biggest = 0;
    for (size_t i = 1; i < contours.size(); ++i)
        if (contourArea(contours[i]) > contourArea(contours[biggest]))
            biggest = i;
    std::vector<Point> approx;
    // 2 px: small enough to keep every corner of the box, large enough to drop staircase steps.
    approxPolyDP(contours[biggest], approx, 2.0, true);
    return approx;
}

std::vector<Point> jittered(const std::vector<Point>& pts, uint64 seed)
{
    RNG rng(seed);
    std::vector<Point> out;
    for (const Point& p : pts)
        out.push_back(p + Point(rng.uniform(-kClickJitterPx, kClickJitterPx + 1),
                                rng.uniform(-kClickJitterPx, kClickJitterPx + 1)));
    return out;
}

double traceWithClicks(const SilhouetteScene& scene, const std::vector<Point>& clicks, int mode,
                       int* clickCount = nullptr)
{
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    ed->setSegmentMode(mode);
    int n = 0;
    for (const Point& c : clicks)
    {
        ed->addPoint(c);
        ++n;
    }
    EXPECT_TRUE(ed->closeContour());
    ++n;  // closing is one more click (on the first anchor, in the window)
    if (clickCount)
        *clickCount = n;
    Mat mask;
    ed->getMask(mask);
    return maskIoU(mask, scene.mask);
}

TEST(Augocc_SilhouetteEditor, can_create_default)
{
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ASSERT_FALSE(ed.empty());
    EXPECT_EQ(SilhouetteEditor::LIVE_WIRE, ed->getSegmentMode());
    EXPECT_EQ(0, ed->getContourCount());
    EXPECT_FALSE(ed->canUndo());
    EXPECT_TRUE(ed->getImageSize().empty());
}

TEST(Augocc_SilhouetteEditor, bad_arg)
{
    SilhouetteEditor::Params p;
    p.snapSpacing = 1;
    EXPECT_THROW(SilhouetteEditor::create(p), cv::Exception);
    p = SilhouetteEditor::Params();
    p.clickSnapRadius = -1;
    EXPECT_THROW(SilhouetteEditor::create(p), cv::Exception);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    EXPECT_THROW(ed->addPoint(Point(1, 1)), cv::Exception);            // no image yet
    EXPECT_THROW(ed->setImage(Mat()), cv::Exception);                  // empty
    EXPECT_THROW(ed->setImage(Mat(10, 10, CV_32F)), cv::Exception);    // wrong type
    EXPECT_THROW(ed->setSegmentMode(7), cv::Exception);
    ed->setImage(Mat(40, 50, CV_8UC3, Scalar::all(90)));
    EXPECT_THROW(ed->loadMask(Mat(41, 50, CV_8U, Scalar::all(0))), cv::Exception);  // size
    EXPECT_THROW(ed->loadMask(Mat(40, 50, CV_16U, Scalar::all(0))), cv::Exception); // type
    EXPECT_THROW(ed->moveAnchor(0, 0, Point(3, 3)), cv::Exception);  // no contour
    EXPECT_FALSE(ed->closeContour());
    Mat canvas(10, 10, CV_8UC3);
    EXPECT_THROW(ed->drawOverlay(canvas), cv::Exception);  // canvas size differs
}

TEST(Augocc_SilhouetteEditor, accuracy_scripted_clicks_box_building)
{
    for (uint64 seed : {1, 2, 3})
    {
        SilhouetteScene scene = makeBoxScene(Size(640, 480), seed);
        const std::vector<Point> clicks = jittered(outlineCorners(scene.mask), seed);
        int count = 0;
        const double iouLive = traceWithClicks(scene, clicks, SilhouetteEditor::LIVE_WIRE, &count);
        const double iouStraight = traceWithClicks(scene, clicks, SilhouetteEditor::STRAIGHT);
        SCOPED_TRACE(cv::format("seed %d: %d clicks, live wire IoU %.4f, straight IoU %.4f",
                                int(seed), count, iouLive, iouStraight));
        std::cout << cv::format("[ box seed %d ] %d clicks: live wire IoU %.4f, straight %.4f",
                                int(seed), count, iouLive, iouStraight)
                  << std::endl;
        EXPECT_LE(count, kMaxClicks);
        EXPECT_GE(iouLive, kMinClickIoU);
    }
}

TEST(Augocc_SilhouetteEditor, straight_segments_do_not_snap)
{
    SilhouetteScene scene = makeBoxScene(Size(320, 240), 5);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    ed->setSegmentMode(SilhouetteEditor::STRAIGHT);
    const Point a(20, 30), b(200, 100);
    EXPECT_EQ(a, ed->addPoint(a));  // no click snap in straight mode
    EXPECT_EQ(b, ed->addPoint(b));
    std::vector<Point> poly = ed->getContour(0);
    LineIterator it(a, b, 8);
    ASSERT_EQ(it.count, int(poly.size()));
    for (int i = 0; i < it.count; ++i, ++it)
        EXPECT_EQ(it.pos(), poly[i]);
}

TEST(Augocc_SilhouetteEditor, live_wire_follows_edge_between_clicks)
{
    // A bright square on a dark ground: the wire between two points on its outline must run
    // along the outline, not straight across the corner.
    Mat img(120, 120, CV_8UC3, Scalar::all(40));
    rectangle(img, Rect(30, 30, 60, 60), Scalar::all(200), FILLED);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(img);
    ed->addPoint(Point(60, 30));
    ed->addPoint(Point(89, 60));
    std::vector<Point> poly = ed->getContour(0);
    // The straight chord passes ~20 px inside the corner; the wire stays within 2 px of it.
    const Point corner(89, 30);
    double nearest = 1e9;
    for (const Point& p : poly)
        nearest = std::min(nearest, norm(p - corner));
    EXPECT_LE(nearest, 2.0);
}

TEST(Augocc_SilhouetteEditor, undo_redo)
{
    SilhouetteScene scene = makeBoxScene(Size(320, 240), 4);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    ed->setSegmentMode(SilhouetteEditor::STRAIGHT);
    ed->addPoint(Point(10, 10));
    ed->addPoint(Point(100, 10));
    ed->addPoint(Point(100, 100));
    EXPECT_EQ(3, ed->getAnchorCount());
    ASSERT_TRUE(ed->closeContour());
    Mat closedMask;
    ed->getMask(closedMask);
    EXPECT_GT(countNonZero(closedMask), 4000);
    ASSERT_TRUE(ed->undo());  // reopens
    EXPECT_TRUE(ed->hasOpenContour());
    ASSERT_TRUE(ed->undo());  // drops (100, 100)
    EXPECT_EQ(2, ed->getAnchorCount());
    ASSERT_TRUE(ed->redo());
    ASSERT_TRUE(ed->redo());
    EXPECT_FALSE(ed->canRedo());
    Mat again;
    ed->getMask(again);
    EXPECT_EQ(0, norm(again, closedMask, NORM_INF));
    // A new edit after undo drops the redo branch.
    ASSERT_TRUE(ed->undo());
    ed->addPoint(Point(10, 100));
    EXPECT_FALSE(ed->canRedo());
    ed->clear();
    EXPECT_EQ(0, ed->getContourCount());
    ASSERT_TRUE(ed->undo());
    EXPECT_EQ(4, ed->getAnchorCount());
    // removeLastPoint is an edit too.
    ASSERT_TRUE(ed->removeLastPoint());
    EXPECT_EQ(3, ed->getAnchorCount());
    ASSERT_TRUE(ed->undo());
    EXPECT_EQ(4, ed->getAnchorCount());
}

TEST(Augocc_SilhouetteEditor, edit_existing_mask)
{
    SilhouetteScene scene = makeBoxScene(Size(640, 480), 6);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    ed->loadMask(scene.mask);
    ASSERT_EQ(1, ed->getContourCount());
    EXPECT_FALSE(ed->hasOpenContour());
    Mat back;
    ed->getMask(back);
    // Polygon approximation at 1 px tolerance changes only staircase pixels along the outline.
    const double kRoundTripIoU = 0.99;
    EXPECT_GE(maskIoU(back, scene.mask), kRoundTripIoU);
    EXPECT_LE(ed->getAnchorCount(), 40);  // an editable outline, not every boundary pixel

    // Drag the anchor nearest to the top-left corner 30 px outward: the mask grows there only.
    const std::vector<Point> corners = outlineCorners(scene.mask);
    int c = -1, a = -1;
    ASSERT_TRUE(ed->findAnchor(corners[0], 5.0, c, a));
    const Point moved = ed->getAnchors(c)[a] + Point(0, -30);
    ed->moveAnchor(c, a, moved);
    Mat grown;
    ed->getMask(grown);
    EXPECT_GT(countNonZero(grown), countNonZero(back));
    EXPECT_EQ(255, grown.at<uchar>(moved + Point(0, 2)));
    ASSERT_TRUE(ed->undo());
    Mat undone;
    ed->getMask(undone);
    EXPECT_EQ(0, norm(undone, back, NORM_INF));

    // Remove an anchor, insert one, remove the whole contour.
    const int before = ed->getAnchorCount();
    ed->removeAnchor(0, 0);
    EXPECT_EQ(before - 1, ed->getAnchorCount());
    const std::vector<Point> poly = ed->getContour(0);
    ASSERT_TRUE(ed->insertAnchor(poly[poly.size() / 2], 2.0));
    EXPECT_EQ(before, ed->getAnchorCount());
    EXPECT_FALSE(ed->insertAnchor(Point(0, 0), 1.0));  // far from every segment
    ed->removeContour(0);
    EXPECT_EQ(0, ed->getContourCount());
}

TEST(Augocc_SilhouetteEditor, several_contours_union)
{
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(Mat(100, 100, CV_8UC3, Scalar::all(128)));
    ed->setSegmentMode(SilhouetteEditor::STRAIGHT);
    for (Point o : {Point(10, 10), Point(30, 30)})  // two overlapping squares
    {
        ed->addPoint(o);
        ed->addPoint(o + Point(40, 0));
        ed->addPoint(o + Point(40, 40));
        ed->addPoint(o + Point(0, 40));
        ASSERT_TRUE(ed->closeContour());
    }
    Mat mask, expected = Mat::zeros(100, 100, CV_8U);
    ed->getMask(mask);
    rectangle(expected, Rect(10, 10, 41, 41), Scalar::all(255), FILLED);
    rectangle(expected, Rect(30, 30, 41, 41), Scalar::all(255), FILLED);
    EXPECT_EQ(0, norm(mask, expected, NORM_INF));  // union, the overlap is not a hole
}

// Proposed outlines (item 3): a coarse matte that is too large, too small or shifted by a few
// pixels, as a clone projected into a new frame is, is pulled back to the true edges.
TEST(Augocc_SilhouetteEditor, accuracy_snap_proposed_mask)
{
    // Issue 6 target for proposals: IoU >= 0.97 before correction.
    const double kMinSnappedIoU = 0.97;
    SilhouetteScene scene = makeBoxScene(Size(640, 480), 7);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    const Mat k = getStructuringElement(MORPH_ELLIPSE, Size(7, 7));  // 3 px radius
    Mat dilated, eroded, shifted;
    dilate(scene.mask, dilated, k);
    erode(scene.mask, eroded, k);
    const Matx23d shift(1, 0, 3, 0, 1, -2);
    warpAffine(scene.mask, shifted, shift, scene.mask.size(), INTER_NEAREST);
    struct Case { const char* name; Mat proposal; } cases[] = {
        {"dilated 3 px", dilated}, {"eroded 3 px", eroded}, {"shifted (3,-2) px", shifted}};
    for (const Case& c : cases)
    {
        Mat snapped;
        ed->snapMask(c.proposal, snapped);
        const double before = maskIoU(c.proposal, scene.mask), after = maskIoU(snapped, scene.mask);
        std::cout << cv::format("[ snap %s ] IoU %.4f -> %.4f", c.name, before, after)
                  << std::endl;
        EXPECT_GE(after, kMinSnappedIoU) << c.name;
        EXPECT_GT(after, before) << c.name;
    }
    // snapMask leaves the edited silhouette alone.
    EXPECT_EQ(0, ed->getContourCount());
    // loadMask(..., true) gives the same outline as editable live-wire anchors.
    ed->loadMask(dilated, true);
    Mat loaded, snapped;
    ed->getMask(loaded);
    ed->snapMask(dilated, snapped);
    EXPECT_EQ(0, norm(loaded, snapped, NORM_INF));
    EXPECT_TRUE(ed->canUndo());
}

TEST(Augocc_SilhouetteEditor, multithread_reproducibility)
{
    SilhouetteScene scene = makeBoxScene(Size(640, 480), 9);
    Mat proposal;
    dilate(scene.mask, proposal, getStructuringElement(MORPH_ELLIPSE, Size(7, 7)));
    Mat snapped[2], traced[2];
    const int threads[2] = {1, 4};
    for (int i = 0; i < 2; ++i)
    {
        setNumThreads(threads[i]);
        Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
        ed->setImage(scene.image);
        ed->snapMask(proposal, snapped[i]);
        for (const Point& c : outlineCorners(scene.mask))
            ed->addPoint(c);
        ASSERT_TRUE(ed->closeContour());
        ed->getMask(traced[i]);
    }
    EXPECT_EQ(0, norm(snapped[0], snapped[1], NORM_INF));
    EXPECT_EQ(0, norm(traced[0], traced[1], NORM_INF));
}

TEST(Augocc_SilhouetteEditor, overlay_draws)
{
    SilhouetteScene scene = makeBoxScene(Size(320, 240), 8);
    Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
    ed->setImage(scene.image);
    ed->loadMask(scene.mask);
    ed->addPoint(Point(5, 5));
    Mat canvas = scene.image.clone();
    ed->drawOverlay(canvas, Point(50, 50));
    EXPECT_GT(norm(canvas, scene.image, NORM_L1), 0.0);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

TEST(Augocc_SilhouetteEditor, resolve_visible_silhouettes)
{
    // Object 0 (near, z = 5) covers the left part of object 1 (far, z = 9).
    std::vector<Mat> mattes(2), depths(2), visible;
    for (int i = 0; i < 2; ++i)
    {
        mattes[i] = Mat::zeros(60, 80, CV_8U);
        depths[i] = Mat(60, 80, CV_32F, Scalar::all(std::numeric_limits<float>::infinity()));
    }
    rectangle(mattes[0], Rect(10, 10, 30, 30), Scalar::all(255), FILLED);
    depths[0].setTo(5.f, mattes[0]);
    rectangle(mattes[1], Rect(25, 5, 40, 40), Scalar::all(255), FILLED);
    depths[1].setTo(9.f, mattes[1]);
    resolveVisibleSilhouettes(mattes, depths, visible);
    ASSERT_EQ(2u, visible.size());
    EXPECT_EQ(0, norm(visible[0], mattes[0], NORM_INF));  // nothing in front of it
    Mat expected1 = mattes[1].clone();
    expected1.setTo(0, mattes[0]);
    EXPECT_EQ(0, norm(visible[1], expected1, NORM_INF));
    depths.pop_back();
    EXPECT_THROW(resolveVisibleSilhouettes(mattes, depths, visible), cv::Exception);
}

// `augocc propagate --mattes`: coarse mattes in, snapped masks out, for the frames asked.
TEST(Augocc_PropagateCli, mattes_snapped_and_bad_input)
{
    const std::string dir = tempDir("propagate");
    std::filesystem::create_directories(dir + "/frames");
    std::filesystem::create_directories(dir + "/mattes/building");
    const Size size(640, 480);
    std::vector<SilhouetteScene> scenes;
    const Mat k = getStructuringElement(MORPH_ELLIPSE, Size(5, 5));  // 2 px radius
    for (int f = 0; f < 3; ++f)
    {
        scenes.push_back(drawBoxScene(orbitCamera(30 + 3 * f, 25, size.height / 14.0, size),
                                      size, 31 + f));
        ASSERT_TRUE(imwrite(format("%s/frames/%04d.png", dir.c_str(), f), scenes[f].image));
        Mat coarse;
        dilate(scenes[f].mask, coarse, k);
        ASSERT_TRUE(imwrite(format("%s/mattes/building/%04d.png", dir.c_str(), f), coarse));
    }
    const std::string bin = augoccBinary();
    std::string out;
    const std::string base = bin + " propagate --input " + dir + "/frames";
    ASSERT_EQ(0, runCommand(base + " --mattes " + dir + "/mattes --frames 0,2 --out " + dir +
                            "/proposed", &out)) << out;
    for (int f : {0, 2})
    {
        const Mat m = imread(format("%s/proposed/building/%04d.png", dir.c_str(), f),
                             IMREAD_GRAYSCALE);
        ASSERT_FALSE(m.empty()) << out;
        const double kMinProposalIoU = 0.97;  // issue 6 target for proposed silhouettes
        EXPECT_GE(maskIoU(m, scenes[f].mask), kMinProposalIoU) << "frame " << f;
    }
    EXPECT_FALSE(std::filesystem::exists(dir + "/proposed/building/0001.png"));
    // A range is half-open, as in every sub-command: 1:2 is frame 1 alone.
    ASSERT_EQ(0, runCommand(base + " --mattes " + dir + "/mattes --frames 1:2 --out " + dir +
                            "/proposed_range", &out)) << out;
    EXPECT_TRUE(std::filesystem::exists(dir + "/proposed_range/building/0001.png"));
    EXPECT_FALSE(std::filesystem::exists(dir + "/proposed_range/building/0000.png"));
    EXPECT_FALSE(std::filesystem::exists(dir + "/proposed_range/building/0002.png"));
    // Bad input: exit 2, a message naming the flag, no output.
    const std::string o2 = " --out " + dir + "/bad";
    EXPECT_EQ(2, runCommand(base + " --mattes " + dir + "/mattes --frames 0,7" + o2, &out));
    EXPECT_NE(std::string::npos, out.find("--frames")) << out;
    EXPECT_EQ(2, runCommand(base + " --mattes " + dir + "/mattes --frames 2:1" + o2, &out));
    EXPECT_EQ(2, runCommand(base + " --mattes " + dir + "/mattes --frames x" + o2, &out));
    for (const char* bad : {"1:1", "0:4", "0:2:0", "0,,2"})  // empty, past the end, step, item
    {
        EXPECT_EQ(2, runCommand(base + " --mattes " + dir + "/mattes --frames " + bad + o2, &out))
            << bad;
        EXPECT_NE(std::string::npos, out.find("--frames")) << out;
    }
    EXPECT_EQ(2, runCommand(base + o2, &out));  // neither --clones nor --mattes
    EXPECT_NE(std::string::npos, out.find("--mattes")) << out;
    EXPECT_EQ(2, runCommand(base + " --mattes " + dir + "/nope" + o2, &out));
    EXPECT_EQ(2, runCommand(base + " --clones " + dir + "/c.yml.gz" + o2, &out));
    EXPECT_EQ(2, runCommand(bin + " propagate --input " + dir + "/none --mattes " + dir +
                            "/mattes" + o2, &out));
    EXPECT_FALSE(std::filesystem::exists(dir + "/bad"));
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// A small synthesized sequence shared by the tests below (synthesized once: ~1 s).
const SyntheticScene& synthScene()
{
    static SyntheticScene scene;
    static bool done = false;
    if (!done)
    {
        SceneSynthesizer::Params p;
        p.frames = 12;
        p.numKeyFrames = 3;
        p.numTracks = 200;
        SceneSynthesizer::create(p)->synthesize(scene);
        done = true;
    }
    return scene;
}

std::vector<Point> mainOutlineCorners(const Mat& mask)
{
    std::vector<std::vector<Point>> contours;
    findContours(mask.clone(), contours, RETR_EXTERNAL, CHAIN_APPROX_NONE);
    CV_Assert(!contours.empty());
    size_t biggest = 0;
    for (size_t i = 1; i < contours.size(); ++i)
        if (contourArea(contours[i]) > contourArea(contours[biggest]))
            biggest = i;
    std::vector<Point> approx;
    approxPolyDP(contours[biggest], approx, 2.0, true);  // the corners a user aims at
    return approx;
}

// Done-when 1 on SceneSynthesizer frames: the box building traced in every frame of a short
// sequence with <= 12 clicks (its corners, hit within +-2 px), against its true visible
// silhouette. Where a facade turns edge-on it shows as a 1-3 px sliver of the same darkness as
// the block behind it, and the wire takes the sliver's inner edge: those frames reach ~0.97.
TEST(Augocc_SilhouetteEditor, accuracy_scripted_clicks_synthesized)
{
    const SyntheticScene& s = synthScene();
    const double kMinMeanIoU = 0.98;   // issue 6: IoU >= 0.98 in <= 12 clicks
    const double kMinWorstIoU = 0.95;  // the sliver frames (see above) with margin
    const double kMinFractionAtTarget = 0.6;  // most frames reach the target on their own
    const int kMaxClickCount = 12;
    RNG rng(17);
    double sum = 0, worst = 1;
    int atTarget = 0;
    const int F = int(s.frames.size());
    std::string list;
    for (int f = 0; f < F; ++f)
    {
        const Mat& truth = s.visibleMasks.at("building").at(f);
        const std::vector<Point> corners = mainOutlineCorners(truth);
        Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
        ed->setImage(s.frames[f]);
        int clicks = 0;
        for (const Point& c : corners)
        {
            ed->addPoint(c + Point(rng.uniform(-2, 3), rng.uniform(-2, 3)));
            ++clicks;
        }
        ASSERT_TRUE(ed->closeContour());
        ++clicks;
        EXPECT_LE(clicks, kMaxClickCount) << "frame " << f;
        Mat mask;
        ed->getMask(mask);
        const double iou = maskIoU(mask, truth);
        sum += iou;
        worst = std::min(worst, iou);
        atTarget += iou >= kMinMeanIoU ? 1 : 0;
        list += format(" %d:%.3f(%d)", f, iou, clicks);
    }
    std::cout << "[ synth building, frame:IoU(clicks) ]" << list << std::endl;
    std::cout << format("[ synth building ] mean IoU %.4f, worst %.4f, %d/%d frames >= %.2f",
                        sum / F, worst, atTarget, F, kMinMeanIoU) << std::endl;
    EXPECT_GE(sum / F, kMinMeanIoU);
    EXPECT_GE(worst, kMinWorstIoU);
    EXPECT_GE(atTarget, kMinFractionAtTarget * F);
}

// Done-when 3, measured with ground-truth-derived proposals (a clone's matte stands in: the
// true visible silhouette grown by 2 px, as a carved clone is slightly too large, or shifted by
// (2, -1) px, as a camera error moves it): snapped outlines on the non-key frames.
TEST(Augocc_SilhouetteEditor, accuracy_proposals_synthesized_gt_derived)
{
    const SyntheticScene& s = synthScene();
    const double kMinMeanIoU = 0.97;   // issue 6: proposed silhouettes, before any correction
    const double kMinWorstIoU = 0.95;  // no single frame far off (regression guard)
    const Mat grow = getStructuringElement(MORPH_ELLIPSE, Size(5, 5));
    const Matx23d shift(1, 0, 2, 0, 1, -1);
    std::set<int> keys(s.keyFrames.begin(), s.keyFrames.end());
    for (int variant = 0; variant < 2; ++variant)
    {
        double sumBefore = 0, sumAfter = 0, worst = 1;
        int n = 0;
        for (int f = 0; f < int(s.frames.size()); ++f)
        {
            if (keys.count(f))
                continue;
            Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
            ed->setImage(s.frames[f]);
            for (const String& name : s.objectNames)
            {
                const Mat& truth = s.visibleMasks.at(name).at(f);
                Mat proposal, snapped;
                if (variant == 0)
                    dilate(truth, proposal, grow);
                else
                    warpAffine(truth, proposal, shift, truth.size(), INTER_NEAREST);
                ed->snapMask(proposal, snapped);
                const double after = maskIoU(snapped, truth);
                sumBefore += maskIoU(proposal, truth);
                sumAfter += after;
                worst = std::min(worst, after);
                ++n;
            }
        }
        std::cout << format("[ proposals %s ] %d object-frames: mean IoU %.4f -> %.4f, worst %.4f",
                            variant == 0 ? "grown 2 px" : "shifted (2,-1)", n, sumBefore / n,
                            sumAfter / n, worst)
                  << std::endl;
        EXPECT_GE(sumAfter / n, kMinMeanIoU);
        EXPECT_GT(sumAfter, sumBefore);
        EXPECT_GE(worst, kMinWorstIoU);
    }
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// Done-when 3 with real clones: SceneSynthesizer sequence, clones built by CloneBuilder from the
// key-frame silhouettes and the true cameras, proposed silhouettes (clone matte, depth-resolved,
// snapped) in every non-key frame against the true visible silhouettes, before any correction.
TEST(Augocc_SilhouetteEditor, accuracy_proposals_from_clones)
{
    SceneSynthesizer::Params sp;
    sp.frames = 24;
    sp.numKeyFrames = 4;
    sp.numTracks = 300;
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(s.groundTruth, s.keyFrameMasks);
    const double kMinMeanIoU = 0.97;   // issue 6: proposed silhouettes, non-key frames
    const double kMinWorstIoU = 0.95;  // per object-frame, regression guard
    std::set<int> keys(s.keyFrames.begin(), s.keyFrames.end());
    double sumRaw = 0, sumSnapped = 0, worst = 1;
    int n = 0;
    for (int f = 0; f < sp.frames; ++f)
    {
        if (keys.count(f))
            continue;
        const Camera& cam = s.groundTruth.camera(f);
        std::map<String, Mat> raw, snapped;
        proposeSilhouettes(*clones, f, cam, s.frames[f], raw, false);
        proposeSilhouettes(*clones, f, cam, s.frames[f], snapped, true);
        for (const String& name : s.objectNames)
        {
            const Mat& truth = s.visibleMasks.at(name).at(f);
            const double iou = maskIoU(snapped.at(name), truth);
            sumRaw += maskIoU(raw.at(name), truth);
            sumSnapped += iou;
            worst = std::min(worst, iou);
            ++n;
        }
    }
    std::cout << format("[ proposals from clones ] %d object-frames: mean IoU %.4f projected, "
                        "%.4f snapped, worst snapped %.4f", n, sumRaw / n, sumSnapped / n, worst)
              << std::endl;
    EXPECT_GE(sumSnapped / n, kMinMeanIoU);
    EXPECT_GE(worst, kMinWorstIoU);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// `augocc propagate --clones`: the headless path of item 3, from files as the CLI sees them.
TEST(Augocc_PropagateCli, clones_to_proposed_masks)
{
    SceneSynthesizer::Params sp;
    sp.frames = 8;
    sp.numKeyFrames = 3;
    sp.numTracks = 200;
    SyntheticScene s;
    SceneSynthesizer::create(sp)->synthesize(s);
    const std::string dir = tempDir("propagate_clones");
    std::filesystem::create_directories(dir + "/frames");
    for (int f = 0; f < sp.frames; ++f)
        ASSERT_TRUE(imwrite(format("%s/frames/%04d.png", dir.c_str(), f), s.frames[f]));
    writeReconstruction(dir + "/rec.yml", s.groundTruth);
    CloneBuilder::create()->build(s.groundTruth, s.keyFrameMasks)->save(dir + "/clones.yml.gz");
    const std::string base = augoccBinary() + " propagate --input " + dir + "/frames" +
                             " --reconstruction " + dir + "/rec.yml --clones " + dir +
                             "/clones.yml.gz";
    std::string out;
    ASSERT_EQ(0, runCommand(base + " --frames 1,2:4 --out " + dir + "/proposed", &out)) << out;
    // The CLI's plumbing on a short 8-frame scene with 3 key frames, whose clones of the hidden
    // objects are looser than with the 4-of-24 key frames of accuracy_proposals_from_clones,
    // which asserts the 0.97 target. Measured here: 0.9695 (after the clone builder's
    // patch-clipping change); a broken CLI (wrong frame, camera or object) gives < 0.5.
    const double kMinMeanIoU = 0.95;
    double sum = 0;
    int n = 0;
    for (const String& name : s.objectNames)
        for (int f : {1, 2, 3})
        {
            const Mat m = imread(format("%s/proposed/%s/%04d.png", dir.c_str(), name.c_str(), f),
                                 IMREAD_GRAYSCALE);
            ASSERT_FALSE(m.empty()) << name << " frame " << f << "\n" << out;
            sum += maskIoU(m, s.visibleMasks.at(name).at(f));
            ++n;
        }
    EXPECT_GE(sum / n, kMinMeanIoU);
    EXPECT_FALSE(std::filesystem::exists(dir + "/proposed/building/0000.png"));
    // One object only; an unknown object and a frame without a camera are usage errors.
    ASSERT_EQ(0, runCommand(base + " --frames 4 --object tower --out " + dir + "/one", &out))
        << out;
    EXPECT_TRUE(std::filesystem::exists(dir + "/one/tower/0004.png"));
    EXPECT_FALSE(std::filesystem::exists(dir + "/one/building"));
    EXPECT_EQ(2, runCommand(base + " --frames 4 --object nosuch --out " + dir + "/bad", &out));
    EXPECT_NE(std::string::npos, out.find("nosuch")) << out;
    EXPECT_EQ(2, runCommand(base + " --frames 9 --out " + dir + "/bad", &out));
    EXPECT_FALSE(std::filesystem::exists(dir + "/bad"));
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace opencv_test
