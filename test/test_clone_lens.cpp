// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The clone stage and the compositor through a distorted lens (issue 15, item 4): the analytic
// tower-and-L scene filmed by a wide lens close up, silhouettes sampled exactly in the distorted
// frame (a frame pixel is in when its ideal ray falls inside the pinhole silhouette).

#include "test_clone_scenes.hpp"

namespace opencv_test {
namespace {

const Size kLensFrame(1280, 720);
// A phone's main camera at 1280x720 (f about 0.8 of the width) with its barrel distortion:
// the corners move by about 55 px.
const std::vector<double> kBarrel = {-0.12, 0.02, 0.0, 0.0, 0.0};

struct LensScene
{
    AnalyticScene s;          // rec: the distorted cameras; masks in the distorted frames
    Reconstruction pinholeRec; // the same cameras without their lens
};

// Silhouette in the distorted frame: pixel centre p is in when its ray (the ideal view's pixel
// LensView::frameMap() gives, exact to 0.005 px; test_lens.cpp checks it) is inside the pinhole
// silhouette.
Mat distortedSilhouette(const AnalyticObject& o, const Camera& cam, Size size)
{
    Ptr<const LensView> view = LensView::get(cam, size);
    const Camera pin = view->idealCamera(cam);
    const Mat& map = view->frameMap();
    Mat m(size, CV_8U, Scalar(0));
    for (const auto& b : o.boxes)
    {
        const std::vector<Point2f> hull = boxHull(b, pin);
        const Rect r = boundingRect(hull);
        parallel_for_(Range(0, size.height), [&](const Range& rows) {
            for (int y = rows.start; y < rows.end; y++)
                for (int x = 0; x < size.width; x++)
                {
                    const Vec2f q = map.at<Vec2f>(y, x);
                    if (q[0] < r.x - 1 || q[1] < r.y - 1 || q[0] > r.br().x || q[1] > r.br().y)
                        continue;
                    if (pointPolygonTest(hull, Point2f(q[0], q[1]), false) >= 0)
                        m.at<uchar>(y, x) = 255;
                }
        });
    }
    return m;
}

LensScene makeLensScene(int frames, int numKeys)
{
    LensScene ls;
    AnalyticScene& s = ls.s;
    s.objects = towerAndEll();
    s.rec.model = PERSPECTIVE;
    s.rec.imageSize = kLensFrame;
    const Vec3d target(2.2, 1.0, 0.3);
    const double orbitDeg = 40;
    for (int f = 0; f < frames; f++)
    {
        const double az = -orbitDeg / 2 + orbitDeg * f / (frames - 1);
        // 13 units away, f = 1000 px: the scene fills most of the frame, its corners too.
        Camera c = orbitCamera(PERSPECTIVE, az, 20, 13, target, kLensFrame, 1000.0 / 13, f);
        c.distortion = kBarrel;
        s.rec.cameras.push_back(c);
    }
    for (int k = 0; k < numKeys; k++)
        s.keyFrames.push_back(cvRound((double)k * (frames - 1) / (numKeys - 1)));
    for (int f = 0; f < frames; f++)
    {
        Mat covered(kLensFrame, CV_8U, Scalar(0));
        for (const AnalyticObject& o : s.objects)
        {
            const Mat w = distortedSilhouette(o, s.rec.cameras[f], kLensFrame);
            s.whole[o.name][f] = w;
            s.visible[o.name][f] = w & ~covered;
            covered |= w;
        }
    }
    for (int k : s.keyFrames)
        for (const AnalyticObject& o : s.objects)
            s.keyMasks[o.name][k] = s.visible[o.name][k];
    ls.pinholeRec = s.rec;
    for (Camera& c : ls.pinholeRec.cameras)
        c.distortion.clear();
    return ls;
}

// Key frames exact and non-key frames as on the pinhole scene (test_clone_scenes.hpp's
// tolerances), in the distorted frames. (With the true cameras, ignoring the lens gives mattes
// about as good: the carved shape bends to fit the bent silhouettes; what the lens breaks is
// the cameras and the virtual objects' placement, test_sfm_lens.cpp and the compositor test.)
TEST(Augocc_CloneLens, distorted_frames_clone_as_pinhole_ones)
{
    const LensScene ls = makeLensScene(24, 6);
    Ptr<CloneBuilder> builder = CloneBuilder::create();
    Ptr<CloneSet> clones = builder->build(ls.s.rec, ls.s.keyMasks);
    for (const AnalyticObject& o : ls.s.objects)
    {
        const Figures fig = measure(*clones, ls.s, o.name, ls.s.visible);
        std::cout << "  lens " << o.name << ": key min IoU " << fig.keyMin << ", non-key mean "
                  << fig.nonKeyMean << " (min " << fig.nonKeyMin << "), boundary "
                  << fig.boundaryMean << " px" << std::endl;
        EXPECT_GE(fig.keyMin, kKeyFrameMinIoU) << o.name;
        EXPECT_GE(fig.nonKeyMean, kNonKeyMeanIoU) << o.name;
        EXPECT_LE(fig.boundaryMean, kMaxMeanBoundaryPx) << o.name;
    }
    // A key frame added later goes through the same ideal view.
    const int k0 = ls.s.keyFrames.front(), k1 = ls.s.keyFrames.back();
    Ptr<CloneSet> two = builder->build(ls.s.rec, ObjectMasks{
        {"tower", {{k0, ls.s.keyMasks.at("tower").at(k0)}, {k1, ls.s.keyMasks.at("tower").at(k1)}}},
        {"ell", {{k0, ls.s.keyMasks.at("ell").at(k0)}, {k1, ls.s.keyMasks.at("ell").at(k1)}}}});
    const int kf = ls.s.keyFrames[3];
    builder->addKeyFrame(*two, ls.s.rec, "tower", kf, ls.s.keyMasks.at("tower").at(kf));
    Mat matte;
    two->render("tower", kf, ls.s.rec.camera(kf), kLensFrame, matte);
    EXPECT_GE(maskIoU(matte, ls.s.keyMasks.at("tower").at(kf)), kKeyFrameMinIoU);
}

// A virtual point lands on its real pixel through the lens, corners included: a small square
// facing the camera, its coverage centroid against Camera::project of its centre. 0.1 px is the
// issue's figure; the square's own centroid bias (second order in its 8 px size) is < 0.01 px,
// and its coverage is resolved at 8 x 8 samples per pixel (antialiasVirtual), so rasterisation
// moves the centroid by < 1/16 px. The same without the lens is the control.
TEST(Augocc_CloneLens, compositor_places_virtual_points_through_the_lens)
{
    Camera cam = orbitCamera(PERSPECTIVE, 10, 20, 13, Vec3d(2.2, 1.0, 0.3), kLensFrame,
                             1000.0 / 13, 0);
    cam.distortion = kBarrel;
    Compositor::Params cp;
    cp.supersample = 8;
    cp.antialiasVirtual = true;
    Ptr<Compositor> comp = Compositor::create(cp);
    const Mat frame(kLensFrame, CV_8UC3, Scalar(40, 40, 40));
    double worst = 0, worstPinhole = 0;
    const Point2d targets[] = {Point2d(40, 30), Point2d(1240, 30), Point2d(40, 690),
                               Point2d(1240, 690), Point2d(640, 360), Point2d(900, 200)};
    for (const Point2d& px : targets)
        for (int lens = 0; lens < 2; lens++)
    {
        const Camera c = lens ? cam : cam.pinhole();
        const double z = 12.0;
        const Vec3d X = c.unproject(px, z);
        // square of 8 px at depth z, in the camera's x-y plane
        const double half = 4.0 * z / cam.K(0, 0);
        const Vec3d ex(cam.R(0, 0), cam.R(0, 1), cam.R(0, 2)), ey(cam.R(1, 0), cam.R(1, 1), cam.R(1, 2));
        Mesh sq;
        for (int c = 0; c < 4; c++)
        {
            const Vec3d V = X + ((c & 1) ? half : -half) * ex + ((c & 2) ? half : -half) * ey;
            sq.vertices.push_back(Vec3f(V));
        }
        sq.faces = {Vec3i(0, 1, 3), Vec3i(0, 3, 2), Vec3i(0, 3, 1), Vec3i(0, 2, 3)};
        comp->setVirtualObjects({sq});
        {
            Mat result, layer;
            comp->composite(frame, c, Mat(), result, layer);
            Mat alpha;
            extractChannel(layer, alpha, 3);
            const Moments mo = moments(alpha, false);
            ASSERT_GT(mo.m00, 0) << px;
            const Point2d centroid(mo.m10 / mo.m00, mo.m01 / mo.m00);
            const double e = cv::norm(centroid - c.project(X));
            (lens ? worst : worstPinhole) = std::max(lens ? worst : worstPinhole, e);
            EXPECT_LT(e, 0.1) << "target " << px << " centroid " << centroid << " lens " << lens;
        }
    }
    std::cout << "  virtual point through the lens: worst " << worst << " px (pinhole "
              << worstPinhole << " px)" << std::endl;
}

} // namespace
} // namespace opencv_test
