// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "gl_context.hpp"

#include <GL/gl.h>

#include <filesystem>
#include <unistd.h>
#include <opencv2/videoio.hpp>

namespace fs = std::filesystem;

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// Clones that are the true geometry: each real object's mesh rendered (depth) through OSMesa at
// any camera and size. The "perfect clone" of the edge-quality measurement.
class MeshClones CV_FINAL : public CloneSet
{
public:
    MeshClones(const std::vector<String>& names, const std::vector<Mesh>& meshes)
        : names_(names), meshes_(meshes)
    {
    }
    std::vector<String> objectNames() const CV_OVERRIDE { return names_; }
    void render(const String& object, int, const Camera& cam, Size size, OutputArray matte,
                OutputArray depth) const CV_OVERRIDE
    {
        const size_t i = std::find(names_.begin(), names_.end(), object) - names_.begin();
        CV_Assert(i < names_.size());
        if (!gl_)
            gl_.reset(new augocc::detail::GlContext(size));
        else if (gl_->size() != size)
            gl_->resize(size);
        else
            gl_->makeCurrent();
        // Depth range from the mesh bounds in this camera.
        Vec3f lo, hi;
        meshes_[i].bounds(lo, hi);
        double zmin = 1e30, zmax = -1e30;
        for (int c = 0; c < 8; c++)
        {
            const double z = cam.depth(Vec3d(c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1],
                                             c & 4 ? hi[2] : lo[2]));
            zmin = std::min(zmin, z);
            zmax = std::max(zmax, z);
        }
        const double zNear = cam.model == PERSPECTIVE ? std::max(1e-3, zmin - 1) : zmin - 1;
        const double zFar = zmax + 1;
        const Matx44d P = augocc::detail::glProjection(cam, size, zNear, zFar);
        const Matx44d MV = augocc::detail::glModelView(cam);
        glClearDepth(1.0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glMatrixMode(GL_PROJECTION);
        glLoadTransposeMatrixd(P.val);
        glMatrixMode(GL_MODELVIEW);
        glLoadTransposeMatrixd(MV.val);
        glBegin(GL_TRIANGLES);
        for (const Vec3i& f : meshes_[i].faces)
            for (int k = 0; k < 3; k++)
            {
                const Vec3f& v = meshes_[i].vertices[f[k]];
                glVertex3f(v[0], v[1], v[2]);
            }
        glEnd();
        Mat d01, z;
        gl_->readDepth(d01);
        augocc::detail::windowDepthToCameraZ(cam, d01, zNear, zFar, z);
        Mat m = z < std::numeric_limits<float>::infinity();
        m.copyTo(matte);
        if (depth.needed())
            z.copyTo(depth);
    }
    void save(const String&) const CV_OVERRIDE {}
    std::vector<int> keyFrames(const String&) const CV_OVERRIDE { return {}; }
    std::vector<int> patchFrames(const String&, int) const CV_OVERRIDE { return {}; }
    int voxelCount(const String&) const CV_OVERRIDE { return 0; }
    int patchVoxelCount(const String&, int) const CV_OVERRIDE { return 0; }
    Vec3i gridSize(const String&) const CV_OVERRIDE { return Vec3i(0, 0, 0); }
    double voxelSize(const String&) const CV_OVERRIDE { return 0; }
    void gridPose(const String&, Matx33d& R, Vec3d& o) const CV_OVERRIDE
    {
        R = Matx33d::eye();
        o = Vec3d(0, 0, 0);
    }
    void exportPly(const String&) const CV_OVERRIDE {}

private:
    std::vector<String> names_;
    std::vector<Mesh> meshes_;
    mutable std::unique_ptr<augocc::detail::GlContext> gl_;
};

// Depth of the real objects only (the ground does not hide objects standing on it).
Mat realDepth(const SyntheticScene& scene, int f)
{
    Mat d = scene.depth[f].clone();
    d.setTo(std::numeric_limits<float>::infinity(), scene.labels[f] == 0);
    return d;
}

struct Scores
{
    double within = 0, boundary = 0, band = 0;
    int frames = 0;
};

// Scores a composite of frame f (`result`, `layer` from the compositor under test) against
// `truth`: the occlusion boundary and band come from `ref` (hard edges) composited over `bg` with
// the true real-object depth, and without any occluder (the virtual silhouette).
CompositeScore scoreFrame(const SyntheticScene& scene, int f, const Mat& bg, Compositor& ref,
                          const Mat& result, const Mat& layer, const Mat& truth)
{
    const Camera& cam = scene.groundTruth.camera(f);
    Mat refImg, refLayer, silImg, silLayer;
    ref.composite(bg, cam, realDepth(scene, f), refImg, refLayer);
    ref.composite(bg, cam, noArray(), silImg, silLayer);
    std::vector<Mat> ch, rch, sch;
    split(layer, ch);
    split(refLayer, rch);
    split(silLayer, sch);
    return scoreComposite(result, truth, ch[3], rch[3] > 0, sch[3] > 0);
}

// The 30-frame synthesized scene of the compositing tests (6 key frames, GT cameras) and its
// clones, built from the key-frame masks and the tracks, photo-refined when `refine`.
struct CompositingScene
{
    Ptr<SceneSynthesizer> synth;
    SyntheticScene scene;
};

CompositingScene makeCompositingScene()
{
    SceneSynthesizer::Params sp;
    sp.frames = 30;
    sp.numKeyFrames = 6;
    CompositingScene c;
    c.synth = SceneSynthesizer::create(sp);
    c.synth->synthesize(c.scene);
    return c;
}

Ptr<CloneSet> buildClones(const SyntheticScene& scene, bool refine,
                          const CloneBuilder::Params& params = CloneBuilder::Params())
{
    Ptr<CloneBuilder> builder = CloneBuilder::create(params);
    Ptr<CloneSet> clones = builder->build(scene.groundTruth, scene.keyFrameMasks, &scene.tracks);
    if (refine)
        builder->refine(*clones, scene.groundTruth, scene.frames);
    return clones;
}

// Issue 5 with GT cameras: clones built from the key-frame masks and the tracks (free space),
// refined by photo-consistency, the default compositor (soft edges, k = 3), the demo's dome and
// tree; every third of 30 frames against the synthesizer's ground truth (1x render).
// Measured 2026-12-01: 99.95% of pixels within 8 grey levels, occlusion boundary 0.21 px over the
// 8 of 10 frames that have one (2.84 px before free-space carving, averaged over all frames: the
// dome stands in the L-block's inner corner, which the visual hull fills).
const double kGtMinWithin = 0.995;     // issue 5
const double kGtMaxBoundaryPx = 1.0;   // issue 5

TEST(Augocc_Pipeline, accuracy_gt_cameras_built_clones)
{
    const CompositingScene cs = makeCompositingScene();
    const Ptr<SceneSynthesizer>& synth = cs.synth;
    const SyntheticScene& scene = cs.scene;
    const int frames = (int)scene.frames.size();
    Ptr<CloneSet> clones = buildClones(scene, true);
    const std::vector<Mesh> meshes = placeScene(demoVirtualScene("demo"), scene.groundTruth,
                                                clones.get());
    Ptr<Compositor> comp = Compositor::create();
    comp->setVirtualObjects(meshes);
    Compositor::Params hp;
    hp.supersample = 1;
    Ptr<Compositor> ref = Compositor::create(hp);
    ref->setVirtualObjects(meshes);
    Scores acc;
    int withBoundary = 0;
    for (int f = 0; f < frames; f += 3)
    {
        Mat result, layer, truth;
        comp->composite(scene.frames[f], f, scene.groundTruth.camera(f), *clones, result, layer);
        synth->renderWithVirtual(f, meshes, truth, 1);
        const CompositeScore s = scoreFrame(scene, f, scene.frames[f], *ref, result, layer, truth);
        acc.within += s.fractionWithin;
        acc.frames++;
        if (s.boundaryPixels > 0)  // frames where the dome is hidden in part
        {
            acc.boundary += s.boundaryDistance;
            withBoundary++;
        }
    }
    std::cout << "GT cameras, built clones: " << 100 * acc.within / acc.frames
              << "% within 8 grey levels, occlusion boundary " << acc.boundary / withBoundary
              << " px over the " << withBoundary << " of " << acc.frames
              << " frames that have one" << std::endl;
    ASSERT_GE(2 * withBoundary, acc.frames);
    EXPECT_GE(acc.within / acc.frames, kGtMinWithin);
    EXPECT_LE(acc.boundary / withBoundary, kGtMaxBoundaryPx);
}

// Issue 5 from the video alone: `augocc demo` (track -> sfm -> clone -> matte -> composite on the
// synthesized 60-frame video) scored against the ground truth. Measured 2026-12-01: 99.95%,
// boundary 1.16 px over the frames that have one, rotation error 0.061 deg (before free-space
// carving: 1.62 px averaged over all frames). Since issue 19 the demo is filmed and composited
// under its scene's sun (demoSun()): 99.86%, 0.42 px over the 60 frames, 0.079 deg (2026-12-03;
// a lower sun, elevation 40 and sky 0.4, gave 5.47 px: the L-block's inner corner in deep
// shadow carves worse). The dome, placed relative to the building's clone,
// stands by the L-block's inner corner, whose clone keeps a sliver in front of it in frames 0-10;
// a one-pixel shift of the dome moves the figure by 0.2-0.4 px (0.99, 1.23, 1.61 px seen as the
// clones changed).
const double kDemoMinWithin = 0.99;      // issue 5
const double kDemoMaxBoundaryPx = 1.5;   // issue 5
const double kDemoMaxRotationDeg = 0.3;  // issue 3 (track + sfm on a synthesized video)

TEST(Augocc_Pipeline, accuracy_demo)
{
    DemoOptions o;
    o.outDir = (fs::temp_directory_path() / cv::format("augocc_demo_test_%d", (int)getpid()))
                   .string();
    const DemoResult r = runDemo(o);
    std::cout << "demo: " << 100 * r.fractionWithin << "% within 8 grey levels, occlusion boundary "
              << r.boundaryDistance << " px, rotation error " << r.rotationErrorDeg << " deg"
              << std::endl;
    EXPECT_TRUE(fs::exists(r.compositePath));
    EXPECT_TRUE(fs::exists(r.contactSheetPath));
    EXPECT_GE(r.fractionWithin, kDemoMinWithin);
    EXPECT_LE(r.boundaryDistance, kDemoMaxBoundaryPx);
    EXPECT_LE(r.rotationErrorDeg, kDemoMaxRotationDeg);
    fs::remove_all(o.outDir);
}

// The same from strongly perspective footage (`augocc demo --model perspective --distance-ratio
// 3`: the camera three scene sizes away, as hand-held footage near the buildings). Measured
// 2026-12-01: 99.86% within 8 grey levels, rotation error 0.109 deg, focal length 0.6% off;
// occlusion boundary 2.80 px over the 50 frames with one (2.52 / 2.47 / 2.84 as the clones
// changed; 2.80 or 2.86 from run to run until the bundle adjustments ran on one thread;
// 4-5 px in frames 0-10, where a sliver of the L-block's clone stays in front of the dome's left;
// under 1 px after frame 38). The 1.5 px is for the default demo; here a regression bound above the measurement.
// Under the demo's sun (issue 19, 2026-12-03): 99.69%, 3.497 px, 0.110 deg: at the bound.
// 2026-12-07, points seen under less than 1.5 degrees dropped (2 of 1160 here): 99.72%, 3.529 px,
// 0.110 deg. The figure moves by a few hundredths of a pixel with any change to the point set
// (the sliver of frames 0-10); the bound is 2% above the measurement.
const double kPerspectiveDemoMaxBoundaryPx = 3.6;

TEST(Augocc_Pipeline, accuracy_demo_perspective)
{
    DemoOptions o;
    o.model = PERSPECTIVE;
    o.distanceRatio = 3;
    o.outDir = (fs::temp_directory_path() / cv::format("augocc_demo_p_test_%d", (int)getpid()))
                   .string();
    const DemoResult r = runDemo(o);
    std::cout << "perspective demo: " << 100 * r.fractionWithin << "% within 8 grey levels, "
              << "occlusion boundary " << r.boundaryDistance << " px, rotation error "
              << r.rotationErrorDeg << " deg, model " << r.run.reconstruction.model << std::endl;
    EXPECT_EQ(r.run.reconstruction.model, PERSPECTIVE);
    EXPECT_GE(r.fractionWithin, kDemoMinWithin);
    EXPECT_LE(r.boundaryDistance, kPerspectiveDemoMaxBoundaryPx);
    EXPECT_LE(r.rotationErrorDeg, kDemoMaxRotationDeg);
    fs::remove_all(o.outDir);
}

// Issue 5, edge quality: band error (2 px around the occlusion boundary) against the 4x
// supersampled truth, soft edges (default compositor, k = 3) against the hard depth test, with
// the real objects' exact geometry as occluders (MeshClones), so that the figure is the
// compositor's edge and not the clones' outline (issue 4 measures that). Measured 2026-12-01:
// 7.56 -> 3.29 (-56%); with built + photo-refined voxel clones 13.91 -> 13.25 (-5%), printed, not
// asserted (doc/compositor.md).
const double kMaxSoftOverHardBand = 0.7;  // issue 5: >= 30% lower

TEST(Augocc_Pipeline, accuracy_soft_edges)
{
    const CompositingScene cs = makeCompositingScene();
    const Ptr<SceneSynthesizer>& synth = cs.synth;
    const SyntheticScene& scene = cs.scene;
    const int frames = (int)scene.frames.size();
    Ptr<CloneSet> built = buildClones(scene, true);
    MeshClones exact(scene.objectNames, scene.objectMeshes);
    const std::vector<Mesh> meshes = placeScene(demoVirtualScene("demo"), scene.groundTruth,
                                                built.get());
    Compositor::Params hp;
    hp.supersample = 1;
    Ptr<Compositor> hard = Compositor::create(hp);
    hard->setVirtualObjects(meshes);
    Ptr<Compositor> soft = Compositor::create();
    soft->setVirtualObjects(meshes);
    double band[2][2] = {{0, 0}, {0, 0}};  // [exact, built][hard, soft]
    int n = 0;
    for (int f = 0; f < frames; f += 7)
    {
        Mat bg, truth4;
        synth->renderWithVirtual(f, {}, bg, 4);
        synth->renderWithVirtual(f, meshes, truth4, 4);
        for (int c = 0; c < 2; c++)
            for (int e = 0; e < 2; e++)
            {
                Mat result, layer;
                (e ? soft : hard)->composite(bg, f, scene.groundTruth.camera(f),
                                             c ? (const CloneSet&)*built : exact, result, layer);
                band[c][e] += scoreFrame(scene, f, bg, *hard, result, layer, truth4).bandError;
            }
        n++;
    }
    std::cout << "band error vs 4x truth, hard -> soft: exact clones " << band[0][0] / n << " -> "
              << band[0][1] / n << ", built clones " << band[1][0] / n << " -> "
              << band[1][1] / n << std::endl;
    EXPECT_LE(band[0][1], kMaxSoftOverHardBand * band[0][0]);
    // Soft edges never make the built clones' edges worse.
    EXPECT_LE(band[1][1], band[1][0]);
}

TEST(Augocc_Pipeline, DISABLED_edge_quality_experiment)
{
    const CompositingScene cs = makeCompositingScene();
    const Ptr<SceneSynthesizer>& synth = cs.synth;
    const SyntheticScene& scene = cs.scene;
    const int frames = (int)scene.frames.size();
    CloneBuilder::Params bp;
    if (getenv("AUGOCC_VOXEL_PIXELS"))  // voxel edge of the built clones, in pixels
        bp.voxelPixels = atof(getenv("AUGOCC_VOXEL_PIXELS"));
    Ptr<CloneSet> built = buildClones(scene, false, bp);
    Ptr<CloneSet> refined = buildClones(scene, true, bp);
    MeshClones exact(scene.objectNames, scene.objectMeshes);
    const std::vector<Mesh> meshes = placeScene(demoVirtualScene("demo"), scene.groundTruth, built.get());
    Compositor::Params hp;
    hp.supersample = 1;
    Ptr<Compositor> ref = Compositor::create(hp);
    ref->setVirtualObjects(meshes);
    struct V { int exact, k, r; double eps; };
    const V variants[] = {{0, 1, 0, 1e-3}, {0, 3, 0, 1e-3}, {0, 1, 2, 1e-3}, {0, 3, 2, 1e-3},
                          {0, 3, 3, 1e-3}, {0, 3, 2, 1e-2}, {0, 3, 2, 1e-4}, {1, 1, 0, 1e-3},
                          {1, 3, 0, 1e-3}, {1, 3, 2, 1e-3}, {2, 1, 0, 1e-3}, {2, 3, 0, 1e-3}};
    std::vector<double> bandOf;
    for (const V& v : variants)
        {
            const int useExact = v.exact, k = v.k;
            Compositor::Params cp;
            cp.supersample = k;
            cp.edgeRadius = v.r;
            cp.edgeEps = v.eps;
            cp.antialiasVirtual = getenv("AUGOCC_ANTIALIAS_VIRTUAL") != nullptr;
            Ptr<Compositor> comp = Compositor::create(cp);
            comp->setVirtualObjects(meshes);
            double band = 0, bnd = 0;
            int n = 0;
            for (int f = 0; f < frames; f += 7)
            {
                Mat bg, truth4, result, layer;
                synth->renderWithVirtual(f, {}, bg, 4);
                synth->renderWithVirtual(f, meshes, truth4, 4);
                const CloneSet& clones = useExact == 1 ? (const CloneSet&)exact
                                         : useExact == 2 ? *refined : *built;
                comp->composite(bg, f, scene.groundTruth.camera(f), clones, result, layer);
                const CompositeScore s = scoreFrame(scene, f, bg, *ref, result, layer, truth4);
                band += s.bandError;
                bnd += s.boundaryDistance;
                n++;
            }
            std::cout << (useExact == 1 ? "exact" : useExact == 2 ? "built+photo" : "built")
                      << " k=" << k << " r=" << v.r << " eps="
                      << v.eps << " band(vs ss4) "
                      << band / n << " boundary " << bnd / n << std::endl;
            bandOf.push_back(band / n);
        }
    // Issue 5: soft edges cut the band error by >= 30% against the hard depth test. Met with
    // exact clones (variants 7 vs 8: measured -49%); with built clones the clones' ~1 px outline
    // error dominates (variants 0 vs 1: -9%; photo-refined, variants 10 vs 11: 13.98 -> 13.80,
    // -1%, though hard edges alone drop 19.95 -> 13.98), which is reported, not asserted.
    const double kMaxSoftOverHard = 0.7;
    ASSERT_EQ(bandOf.size(), sizeof(variants) / sizeof(variants[0]));
    EXPECT_LE(bandOf[8], kMaxSoftOverHard * bandOf[7]);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {

// Issue 15, the quick pass of perf/handheld_figures.sh: the hand-held demo at 640x360, 30
// frames, 5 key frames, H.264 at 3 Mbit/s, the lens self-calibrated and ignored. The full-size
// figures are in the README; here the path from the distorted video to the composite must hold
// and knowing the lens must beat ignoring it. Measured 2026-12-02: self-calibrated rotation
// 0.16 deg, focal 1.5% off, slide 0.11 / 0.32 px (median / p95), mattes 0.9997 / 0.977, 99.8%
// within 8 grey levels; ignored: 1.6 deg, 29% off, slide 1.1 / 6.1 px. Bounds: 2.5-3 times the
// measurement (H.264 and the tracker vary with the machine's libraries).
TEST(Augocc_Pipeline, handheld_lens_quick)
{
    double slide[2] = {0, 0};
    for (int ignored = 0; ignored < 2; ignored++)
    {
        DemoOptions o = handheldDemoOptions();
        o.imageSize = Size(640, 360);
        o.frames = 30;
        o.numKeyFrames = 5;
        o.videoBitrateMbps = 3;
        o.lens = ignored ? DEMO_LENS_IGNORED : DEMO_LENS_SELF_CALIBRATE;
        o.outDir = (fs::temp_directory_path() /
                    cv::format("augocc_demo_handheld_%d_%d", ignored, (int)getpid())).string();
        const DemoResult r = runDemo(o);
        std::cout << "hand-held 640x360, lens " << (ignored ? "ignored" : "self-calibrated")
                  << ": " << 100 * r.fractionWithin << "% within 8 grey levels, rotation "
                  << r.rotationErrorDeg << " deg, focal " << r.focalErrorPercent << "% off, slide "
                  << r.slide.median << " / " << r.slide.p95 << " px, mattes " << r.keyFrameIoU
                  << " / " << r.nonKeyIoU << "; " << r.run.sfm.lensReason << std::endl;
        slide[ignored] = r.slide.p95;
        if (!ignored)
        {
            EXPECT_LE(r.rotationErrorDeg, 0.4);
            EXPECT_LE(r.slide.p95, 1.0);
            EXPECT_GE(r.keyFrameIoU, 0.995);
            EXPECT_GE(r.fractionWithin, 0.98);
        }
        fs::remove_all(o.outDir);
    }
    EXPECT_LT(slide[0], 0.5 * slide[1]) << "the lens model must halve the slide at least";
}

} // namespace
} // namespace opencv_test
