// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "gl_context.hpp"
#include "shading.hpp"

#include <opencv2/highgui.hpp>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// Hand-made set-up: a 160x120 frame, a camera looking along world +z (R = I), 10 px per unit at
// z = 10 in both models, and a quad at z = 10 whose edges project between pixel centres
// (u in [49.7, 110.3], v in [39.7, 80.3]): it covers exactly columns 50..110, rows 40..80.
const Size kSize(160, 120);
const double kQuadZ = 10.0;
const Rect kQuadPixels(50, 40, 61, 41);
// GL quantises the lit colour to 8 bits: one grey level.
const double kColorTol = 1.0;

Camera makeCamera(CameraModel model)
{
    if (model == SCALED_ORTHOGRAPHIC)
        return Camera::orthographic(Matx33d::eye(), Vec3d(0, 0, 0), 10.0, Point2d(80, 60));
    return Camera::perspective(Matx33d::eye(), Vec3d(0, 0, 0),
                               Matx33d(100, 0, 80, 0, 100, 60, 0, 0, 1));
}

// Light direction of the shading convention (src/shading.hpp).
Vec3f lightDirection()
{
    return augocc::detail::kLightDirection;
}

// Flat quad at z = kQuadZ, normals along the light direction.
Mesh makeQuad(const Vec3f& diffuse, const Vec3f& ambient)
{
    Mesh m;
    const float x0 = (49.7f - 80) / 10, x1 = (110.3f - 80) / 10;
    const float y0 = (39.7f - 60) / 10, y1 = (80.3f - 60) / 10;
    const float z = (float)kQuadZ;
    m.vertices = {Vec3f(x0, y0, z), Vec3f(x1, y0, z), Vec3f(x1, y1, z), Vec3f(x0, y1, z)};
    m.faces = {Vec3i(0, 1, 2), Vec3i(0, 2, 3)};
    m.normals.assign(4, lightDirection());
    // v up: the image's top rows (small y, i.e. v near the top) get v = 1.
    m.texcoords = {Vec2f(0, 1), Vec2f(1, 1), Vec2f(1, 0), Vec2f(0, 0)};
    m.material.diffuse = diffuse;
    m.material.ambient = ambient;
    return m;
}

Mat makeFrame()
{
    Mat frame(kSize, CV_8UC3);
    RNG rng(7);
    rng.fill(frame, RNG::UNIFORM, 0, 256);
    return frame;
}

// The lit colour of the quad per the shading convention, BGR 8-bit.
Vec3b expectedBgr(const Vec3f& diffuse, const Vec3f& ambient)
{
    // base * (ambient + diffuse * max(0, n.L)) with n = L, base white.
    const float ndotl = lightDirection().dot(lightDirection());
    Vec3f rgb;
    for (int k = 0; k < 3; k++)
        rgb[k] = std::min(1.f, ambient[k] + diffuse[k] * ndotl);
    Vec3b c;
    for (int k = 0; k < 3; k++)
        c[2 - k] = saturate_cast<uchar>(255 * rgb[k]);
    return c;
}

double maxDiff(const Mat& a, const Mat& b)
{
    return cv::norm(a, b, NORM_INF);
}

class Augocc_Compositor_P : public testing::TestWithParam<int> {};

// The known colour rendered through OSMesa in this binary (which also links highgui, PITFALLS.md):
// inside the quad the lit colour, outside the frame untouched.
TEST_P(Augocc_Compositor_P, accuracy_known_colour)
{
    (void)cv::getBuildInformation();  // highgui linked into this binary too
    const Camera cam = makeCamera((CameraModel)GetParam());
    Compositor::Params p;
    p.supersample = 1;
    Ptr<Compositor> comp = Compositor::create(p);
    const Vec3f diffuse(0.5f, 0.3f, 0.2f), ambient(0.1f, 0.1f, 0.1f);
    comp->setVirtualObjects({makeQuad(diffuse, ambient)});
    const Mat frame = makeFrame();
    Mat result, layer, depth;
    comp->composite(frame, cam, noArray(), result, layer, depth);
    ASSERT_EQ(result.size(), kSize);
    ASSERT_EQ(result.type(), CV_8UC3);
    const Mat expectedInside(kQuadPixels.size(), CV_8UC3, Scalar(expectedBgr(diffuse, ambient)));
    EXPECT_LE(maxDiff(result(kQuadPixels), expectedInside), kColorTol);
    Mat outside = Mat::ones(kSize, CV_8U);
    outside(kQuadPixels) = 0;
    Mat diff;
    cv::absdiff(result, frame, diff);
    cv::cvtColor(diff, diff, COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(diff & outside), 0);
    // Layer alpha: 255 inside, 0 outside.
    std::vector<Mat> ch;
    cv::split(layer, ch);
    EXPECT_EQ(cv::countNonZero(ch[3]), kQuadPixels.area());
    EXPECT_EQ(cv::countNonZero(ch[3](kQuadPixels) == 255), kQuadPixels.area());
    // Depth: the quad's camera z inside (24-bit depth buffer over a range of ~0.1 units).
    const double kDepthTol = 1e-3;
    double lo, hi;
    cv::minMaxLoc(depth(kQuadPixels), &lo, &hi);
    EXPECT_NEAR(lo, kQuadZ, kDepthTol);
    EXPECT_NEAR(hi, kQuadZ, kDepthTol);
    EXPECT_TRUE(std::isinf(depth.at<float>(0, 0)));
}

// Real objects hide virtual ones by camera-space depth: an occluder at z = 5 over columns < 80
// hides the quad (z = 10) there; one at z = 20 over columns >= 80 does not.
TEST_P(Augocc_Compositor_P, accuracy_occlusion)
{
    const Camera cam = makeCamera((CameraModel)GetParam());
    Compositor::Params p;
    p.supersample = 1;
    p.edgeRadius = 0;  // the bare depth test
    Ptr<Compositor> comp = Compositor::create(p);
    const Vec3f diffuse(0.2f, 0.6f, 0.3f), ambient(0.2f, 0.2f, 0.2f);
    comp->setVirtualObjects({makeQuad(diffuse, ambient)});
    const Mat frame = makeFrame();
    Mat occ(kSize, CV_32F, Scalar(20.0));
    occ.colRange(0, 80).setTo(5.0);
    Mat result, depth;
    comp->composite(frame, cam, occ, result, noArray(), depth);
    const Rect hidden(50, 40, 30, 41), seen(80, 40, 31, 41);
    EXPECT_EQ(maxDiff(result(hidden), frame(hidden)), 0);
    const Mat expected(seen.size(), CV_8UC3, Scalar(expectedBgr(diffuse, ambient)));
    EXPECT_LE(maxDiff(result(seen), expected), kColorTol);
    // Depth output: the nearest of occluder and virtual object.
    const double kDepthTol = 1e-3;
    EXPECT_NEAR(depth.at<float>(60, 60), 5.0, kDepthTol);
    EXPECT_NEAR(depth.at<float>(60, 100), kQuadZ, kDepthTol);
    EXPECT_NEAR(depth.at<float>(5, 120), 20.0, kDepthTol);
}

// Soft edges: with 4x supersampling an occluder edge that splits pixel column 95 in half gives
// that column alpha 1/2, columns left of it 0 (hidden) and right of it 1, whether the virtual
// objects are drawn at 4x too (antialiasVirtual) or at the frame grid.
TEST_P(Augocc_Compositor_P, accuracy_soft_edge_coverage)
{
    const Camera cam = makeCamera((CameraModel)GetParam());
    for (bool aa : {false, true})
    {
        Compositor::Params p;
        p.supersample = 4;
        p.antialiasVirtual = aa;
        p.edgeRadius = 0;  // the supersampled depth test alone
        Ptr<Compositor> comp = Compositor::create(p);
        comp->setVirtualObjects({makeQuad(Vec3f(0.5f, 0.5f, 0.5f), Vec3f(0.2f, 0.2f, 0.2f))});
        const Size rsz = comp->renderSize(kSize);
        ASSERT_EQ(rsz, Size(640, 480));
        Mat occ(rsz, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
        occ.colRange(0, 4 * 95 + 2).setTo(5.0);
        Mat result, layer, depth;
        comp->composite(makeFrame(), cam, occ, result, layer, depth);
        std::vector<Mat> ch;
        cv::split(layer, ch);
        const Mat& a = ch[3];
        // Box average of 4x4 samples, 8-bit rounding: 128 +- 1.
        EXPECT_NEAR(a.at<uchar>(60, 95), 128, 1) << aa;
        EXPECT_EQ(a.at<uchar>(60, 94), 0) << aa;
        EXPECT_EQ(a.at<uchar>(60, 96), 255) << aa;
        // Depth output: the nearest of each pixel's samples, the occluder's in column 95.
        EXPECT_FLOAT_EQ(depth.at<float>(60, 95), 5.f) << aa;
        if (aa)
        {
            // The quad's own outline is anti-aliased too (its edge at u = 110.3 covers part of
            // pixel 111's samples)...
            EXPECT_GT(a.at<uchar>(60, 110), 0);
            EXPECT_LT(a.at<uchar>(60, 111), 255);
        }
        else
        {
            // ... or drawn at the frame grid, as with hard edges: every pixel of the quad is
            // whole (0 or 255) away from the occluder.
            Mat partial = (a > 0) & (a < 255);
            partial.colRange(94, 97).setTo(0);
            EXPECT_EQ(countNonZero(partial), 0);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_Compositor_P,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

// Texture coordinates have v up: the texture image's top row maps to v = 1, the quad's top.
TEST(Augocc_Compositor, accuracy_texture_orientation)
{
    const Camera cam = makeCamera(SCALED_ORTHOGRAPHIC);
    Compositor::Params p;
    p.supersample = 1;
    Ptr<Compositor> comp = Compositor::create(p);
    Mesh quad = makeQuad(Vec3f(0.8f, 0.8f, 0.8f), Vec3f(0.2f, 0.2f, 0.2f));
    Mat tex(64, 64, CV_8UC3, Scalar(255, 0, 0));           // blue bottom half (BGR)
    tex.rowRange(0, 32).setTo(Scalar(0, 0, 255));          // red top half
    quad.material.texture = tex;
    comp->setVirtualObjects({quad});
    Mat result;
    comp->composite(makeFrame(), cam, noArray(), result);
    const Vec3b top = result.at<Vec3b>(45, 80), bottom = result.at<Vec3b>(75, 80);
    EXPECT_GT(top[2], 200);
    EXPECT_LT(top[0], 10);
    EXPECT_GT(bottom[0], 200);
    EXPECT_LT(bottom[2], 10);
}

// A clone set made by hand: a wall at z = 5 over world x < 0 (any camera, any size).
class WallClones CV_FINAL : public CloneSet
{
public:
    std::vector<String> objectNames() const CV_OVERRIDE { return {"wall"}; }
    void render(const String& object, int, const Camera& camera, Size size, OutputArray matte,
                OutputArray depth) const CV_OVERRIDE
    {
        CV_Assert(object == "wall");
        Mat m(size, CV_8U, Scalar(0));
        Mat d(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
        for (int y = 0; y < size.height; y++)
            for (int x = 0; x < size.width; x++)
            {
                const Ray r = camera.backproject(Point2d(x, y));
                const double lambda = (5.0 - r.origin[2]) / r.direction[2];
                if (r.at(lambda)[0] < 0)
                {
                    m.at<uchar>(y, x) = 255;
                    d.at<float>(y, x) = 5.f;
                }
            }
        m.copyTo(matte);
        if (depth.needed())
            d.copyTo(depth);
    }
    void save(const String&) const CV_OVERRIDE {}
    std::vector<int> keyFrames(const String&) const CV_OVERRIDE { return {}; }
    std::vector<int> patchFrames(const String&, int) const CV_OVERRIDE { return {}; }
    int voxelCount(const String&) const CV_OVERRIDE { return 0; }
    int patchVoxelCount(const String&, int) const CV_OVERRIDE { return 0; }
    Vec3i gridSize(const String&) const CV_OVERRIDE { return Vec3i(0, 0, 0); }
    double voxelSize(const String&) const CV_OVERRIDE { return 1.0; }
    void gridPose(const String&, Matx33d& R, Vec3d& origin) const CV_OVERRIDE
    {
        R = Matx33d::eye();
        origin = Vec3d(0, 0, 0);
    }
    void exportPly(const String&) const CV_OVERRIDE {}
};

// The CloneSet overload renders the clones at the supersampled grid: the same result as the
// occluder-depth overload fed with that depth.
TEST(Augocc_Compositor, accuracy_clone_set)
{
    const Camera cam = makeCamera(PERSPECTIVE);
    Compositor::Params p;
    p.edgeRadius = 0;  // exact comparison of the hidden region
    Ptr<Compositor> comp = Compositor::create(p);
    comp->setVirtualObjects({makeQuad(Vec3f(0.5f, 0.4f, 0.3f), Vec3f(0.2f, 0.2f, 0.2f))});
    const Mat frame = makeFrame();
    WallClones clones;
    Mat viaClones, direct, occ, matte;
    comp->composite(frame, 0, cam, clones, viaClones);
    const int k = comp->getParams().supersample;
    clones.render("wall", 0, supersampledCamera(cam, k), comp->renderSize(kSize), matte, occ);
    comp->composite(frame, cam, occ, direct);
    EXPECT_EQ(maxDiff(viaClones, direct), 0);
    // Left of x = 0 (u < 80) the quad is hidden.
    EXPECT_EQ(maxDiff(viaClones(Rect(50, 40, 29, 41)), frame(Rect(50, 40, 29, 41))), 0);
    EXPECT_GT(maxDiff(viaClones(Rect(81, 40, 29, 41)), frame(Rect(81, 40, 29, 41))), 0);
}

// The supersampled camera renders the same view on a finer grid: a world point projects to
// k * (u + 0.5) - 0.5.
TEST(Augocc_Compositor, accuracy_supersampled_camera)
{
    const Vec3d X(0.3, -0.7, 12.0);
    for (CameraModel model : {SCALED_ORTHOGRAPHIC, PERSPECTIVE})
    {
        const Camera cam = makeCamera(model);
        for (int k : {1, 2, 3})
        {
            const Point2d u = cam.project(X), uk = supersampledCamera(cam, k).project(X);
            const double kTol = 1e-9;  // exact up to rounding
            EXPECT_NEAR(uk.x, k * (u.x + 0.5) - 0.5, kTol);
            EXPECT_NEAR(uk.y, k * (u.y + 0.5) - 0.5, kTol);
        }
    }
}

TEST(Augocc_Compositor, can_create_default)
{
    Ptr<Compositor> comp = Compositor::create();
    ASSERT_TRUE(comp);
    EXPECT_EQ(comp->getParams().supersample, 3);
    // Nothing to insert: the frame comes back unchanged.
    const Mat frame = makeFrame();
    Mat result;
    comp->composite(frame, makeCamera(PERSPECTIVE), noArray(), result);
    EXPECT_EQ(maxDiff(result, frame), 0);
}

TEST(Augocc_Compositor, bad_arg)
{
    Compositor::Params p;
    p.supersample = 0;
    EXPECT_THROW(Compositor::create(p), cv::Exception);
    Ptr<Compositor> comp = Compositor::create();
    const Camera cam = makeCamera(PERSPECTIVE);
    Mat result;
    EXPECT_THROW(comp->composite(Mat(), cam, noArray(), result), cv::Exception);
    EXPECT_THROW(comp->composite(Mat(kSize, CV_8UC1, Scalar(0)), cam, noArray(), result),
                 cv::Exception);
    EXPECT_THROW(comp->composite(makeFrame(), cam, Mat(10, 10, CV_32F, Scalar(1)), result),
                 cv::Exception);
    EXPECT_THROW(comp->composite(makeFrame(), cam, Mat(kSize, CV_64F, Scalar(1)), result),
                 cv::Exception);
    Mesh broken = makeQuad(Vec3f(1, 1, 1), Vec3f(0, 0, 0));
    broken.faces.push_back(Vec3i(0, 1, 7));
    EXPECT_THROW(comp->setVirtualObjects({broken}), cv::Exception);
}

// CPU stages run in parallel_for_: results do not depend on the thread count.
TEST(Augocc_Compositor, multithread_reproducibility)
{
    const Camera cam = makeCamera(PERSPECTIVE);
    Ptr<Compositor> comp = Compositor::create();
    comp->setVirtualObjects({makeQuad(Vec3f(0.5f, 0.4f, 0.3f), Vec3f(0.2f, 0.2f, 0.2f))});
    const Mat frame = makeFrame();
    WallClones clones;
    Mat r1, r2, l1, l2, d1, d2;
    cv::setNumThreads(1);
    comp->composite(frame, 0, cam, clones, r1, l1, d1);
    cv::setNumThreads(4);
    comp->composite(frame, 0, cam, clones, r2, l2, d2);
    EXPECT_EQ(maxDiff(r1, r2), 0);
    EXPECT_EQ(maxDiff(l1, l2), 0);
    EXPECT_MAT_NEAR(d1, d2, 0);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {

// Culling the back faces of closed, outward meshes changes no pixel (and a wrong front-face
// convention would show the inside of the sphere instead).
TEST(Augocc_Compositor, accuracy_back_face_culling)
{
    for (CameraModel model : {SCALED_ORTHOGRAPHIC, PERSPECTIVE})
    {
        const Camera cam = makeCamera(model);
        Mesh sphere = Mesh::sphere(2.f, 24, 12);
        sphere.transform(Matx44d(1, 0, 0, 0.5, 0, 1, 0, -0.3, 0, 0, 1, kQuadZ, 0, 0, 0, 1));
        sphere.material.diffuse = Vec3f(0.6f, 0.5f, 0.4f);
        Mesh box = Mesh::box(Vec3f(-3.5f, -1.f, 9.f), Vec3f(-2.f, 1.5f, 11.f));
        Mat withCull, without;
        for (bool cull : {true, false})
        {
            Compositor::Params p;
            p.supersample = 2;
            p.cullBackFaces = cull;
            Ptr<Compositor> comp = Compositor::create(p);
            comp->setVirtualObjects({sphere, box});
            comp->composite(makeFrame(), cam, noArray(), cull ? withCull : without);
        }
        EXPECT_EQ(maxDiff(withCull, without), 0) << cameraModelName(model);
    }
}

} // namespace
} // namespace opencv_test
