// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "sfm_test_utils.hpp"
#include "sfm_ceres.hpp"
#include "stats.hpp"

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// The targets (SceneSynthesizer-like scenes, 0.5 px noise):
const double kFullRotDeg = 0.1;          // full tracks: mean rotation error
const double kFullRmsRatio = 1.05;       // full tracks: RMS <= 1.05 x expected noise RMS
const double kPartialRotDeg = 0.15;      // 40% partial + 5% outliers
const double kPerspRotDeg = 0.3;         // perspective scene at 10x: perspective mode
const double kPerspRmsRatio = 1.1;       // perspective scene: RMS <= 1.1 x noise

TEST(Augocc_OrthoCameraRefiner, can_create_default)
{
    Ptr<OrthoCameraRefiner> r = OrthoCameraRefiner::create();
    ASSERT_FALSE(r.empty());
    EXPECT_EQ((int)OrthoCameraRefiner::POSITION_ZOOM, r->getParams().mode);
}

TEST(Augocc_OrthoCameraRefiner, position_zoom_recovers_perturbed_positions)
{
    // Ground-truth orientations and points, positions and zoom perturbed: the 3F+1 LM must
    // bring the reprojection error back to the noise level.
    SfmProblemParams prm;
    prm.frames = 30;
    prm.points = 200;
    const SfmProblem pb = makeSfmProblem(prm);
    Reconstruction rec = pb.groundTruth;
    RNG rng(3);
    for (Camera& c : rec.cameras)
    {
        c.t += Vec3d(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), 0);
        c.s *= 1.1;
    }
    const double tz0 = rec.cameras[5].t[2];
    ASSERT_TRUE(OrthoCameraRefiner::create()->refine(pb.tracks, rec));
    const ReprojectionStats st = computeReprojectionStats(rec, pb.tracks);
    EXPECT_LT(st.rms, kFullRmsRatio * expectedNoiseRms(prm.noiseSigma));
    EXPECT_NEAR(pb.groundTruth.cameras[0].s, rec.cameras[0].s, 0.01 * rec.cameras[0].s);
    EXPECT_EQ(tz0, rec.cameras[5].t[2]);  // the line-of-sight component is a held gauge
    for (const Camera& c : rec.cameras)
        EXPECT_EQ(rec.cameras[0].s, c.s);  // one zoom, as in the paper
}

TEST(Augocc_OrthoCameraRefiner, accuracy_full_tracks)
{
    SfmProblemParams prm;  // 60 frames, 600 tracks, 0.5 px
    const SfmProblem pb = makeSfmProblem(prm);
    SfmOptions opt;
    opt.model = "scaled_orthographic";
    SfmReport rep;
    const Reconstruction rec = recoverCameras(pb.tracks, opt, &rep);
    const CameraComparison c = compareCameras(rec, pb.groundTruth);
    std::cout << "full tracks: mean rotation error " << c.meanRotationDeg << " deg, RMS "
              << rep.orthographic.rms << " px (factorization " << rep.factorization.rms
              << ", 3F+1 " << rep.positionZoom.rms << "), expected noise RMS "
              << expectedNoiseRms(prm.noiseSigma) << std::endl;
    EXPECT_LT(c.meanRotationDeg, kFullRotDeg);
    EXPECT_LT(rep.orthographic.rms, kFullRmsRatio * expectedNoiseRms(prm.noiseSigma));
    EXPECT_EQ("scaled_orthographic", rep.chosenModel);
}

TEST(Augocc_OrthoCameraRefiner, accuracy_partial_outliers)
{
    SfmProblemParams prm;
    prm.partialFraction = 0.4;
    prm.outlierFraction = 0.05;
    const SfmProblem pb = makeSfmProblem(prm);
    SfmOptions opt;
    opt.model = "scaled_orthographic";
    SfmReport rep;
    const Reconstruction rec = recoverCameras(pb.tracks, opt, &rep);
    const CameraComparison c = compareCameras(rec, pb.groundTruth);
    std::cout << "partial+outliers: mean rotation error " << c.meanRotationDeg << " deg, RMS "
              << rep.orthographic.rms << " px, rejected " << rep.rejectedTracks << std::endl;
    EXPECT_LT(c.meanRotationDeg, kPartialRotDeg);
}

TEST(Augocc_OrthoCameraRefiner, accuracy_perspective)
{
    SfmProblemParams prm;
    prm.model = PERSPECTIVE;
    prm.distanceRatio = 10;
    const SfmProblem pb = makeSfmProblem(prm);
    SfmOptions opt;
    opt.model = "auto";
    SfmReport rep;
    const Reconstruction rec = recoverCameras(pb.tracks, opt, &rep);
    const CameraComparison c = compareCameras(rec, pb.groundTruth, false);
    std::cout << "perspective 10x: mean rotation error " << c.meanRotationDeg << " deg, RMS "
              << rep.perspective.rms << " px (orthographic " << rep.orthographic.rms
              << "), chosen " << rep.chosenModel << std::endl;
    EXPECT_EQ("perspective", rep.chosenModel);
    EXPECT_EQ(PERSPECTIVE, rec.model);
    EXPECT_LT(c.meanRotationDeg, kPerspRotDeg);
    EXPECT_LT(rep.perspective.rms, kPerspRmsRatio * expectedNoiseRms(prm.noiseSigma));
}

TEST(Augocc_OrthoCameraRefiner, auto_keeps_orthographic_when_far)
{
    SfmProblemParams prm;
    prm.frames = 30;
    prm.points = 300;
    const SfmProblem pb = makeSfmProblem(prm);
    SfmReport rep;
    recoverCameras(pb.tracks, SfmOptions(), &rep);
    EXPECT_EQ("scaled_orthographic", rep.chosenModel);
}

TEST(Augocc_OrthoCameraRefiner, bad_arg)
{
    SfmProblemParams prm;
    prm.frames = 10;
    prm.points = 50;
    const SfmProblem pb = makeSfmProblem(prm);
    Reconstruction rec = pb.groundTruth;
    rec.points = Mat::zeros(10, 3, CV_64F);
    EXPECT_THROW(OrthoCameraRefiner::create()->refine(pb.tracks, rec), cv::Exception);
    rec = pb.groundTruth;
    rec.cameras.clear();
    EXPECT_THROW(OrthoCameraRefiner::create()->refine(pb.tracks, rec), cv::Exception);
    rec = pb.groundTruth;
    rec.cameras[3].frame = 99;
    EXPECT_THROW(OrthoCameraRefiner::create()->refine(pb.tracks, rec), cv::Exception);
    OrthoCameraRefiner::Params p;
    p.mode = 7;
    EXPECT_THROW(OrthoCameraRefiner::create(p), cv::Exception);
    SfmOptions opt;
    opt.model = "fisheye";
    EXPECT_THROW(recoverCameras(pb.tracks, opt), cv::Exception);
}

TEST(Augocc_OrthoCameraRefiner, multithread_reproducibility)
{
    SfmProblemParams prm;
    prm.frames = 20;
    prm.points = 200;
    prm.partialFraction = 0.3;
    const SfmProblem pb = makeSfmProblem(prm);
    SfmOptions opt;
    opt.model = "scaled_orthographic";
    setNumThreads(1);
    const Reconstruction a = recoverCameras(pb.tracks, opt);
    setNumThreads(4);
    const Reconstruction b = recoverCameras(pb.tracks, opt);
    ASSERT_EQ(a.cameras.size(), b.cameras.size());
    // Bit for bit: every Ceres solve runs on one thread (its per-thread sums would differ in
    // rounding), whatever OpenCV's thread count.
    for (size_t i = 0; i < a.cameras.size(); i++)
    {
        EXPECT_MAT_NEAR(a.cameras[i].R, b.cameras[i].R, 0);
        EXPECT_MAT_NEAR(a.cameras[i].t, b.cameras[i].t, 0);
    }
    EXPECT_TRUE(identicalWithNan(a.points, b.points));
}

// Evaluates a cost function at `params` and returns its residuals and every block's Jacobian.
void evaluateCost(const ceres::CostFunction& cost, const std::vector<std::vector<double>>& params,
                  std::vector<double>& residuals, std::vector<std::vector<double>>& jac)
{
    std::vector<const double*> p;
    for (const std::vector<double>& b : params)
        p.push_back(b.data());
    residuals.assign(cost.num_residuals(), 0.0);
    jac.assign(params.size(), std::vector<double>());
    std::vector<double*> j;
    for (size_t k = 0; k < params.size(); k++)
    {
        jac[k].assign(cost.num_residuals() * params[k].size(), 0.0);
        j.push_back(jac[k].data());
    }
    ASSERT_TRUE(cost.Evaluate(p.data(), residuals.data(), j.data()));
}

void expectSameCost(const ceres::CostFunction& analytic, const ceres::CostFunction& autodiff,
                    const std::vector<std::vector<double>>& params)
{
    std::vector<double> ra, rb;
    std::vector<std::vector<double>> ja, jb;
    evaluateCost(analytic, params, ra, ja);
    evaluateCost(autodiff, params, rb, jb);
    // Both are the same double-precision formula: agreement to rounding of values ~1e3.
    const double kJacobianTol = 1e-9;
    for (size_t i = 0; i < ra.size(); i++)
        EXPECT_NEAR(ra[i], rb[i], kJacobianTol);
    for (size_t k = 0; k < ja.size(); k++)
        for (size_t i = 0; i < ja[k].size(); i++)
            EXPECT_NEAR(ja[k][i], jb[k][i], kJacobianTol) << "block " << k << " entry " << i;
}

TEST(Augocc_OrthoCameraRefiner, analytic_jacobians_match_autodiff)
{
    RNG rng(7);
    for (int trial = 0; trial < 20; trial++)
    {
        SCOPED_TRACE(trial);
        Eigen::Quaterniond q(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0),
                             rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
        q.normalize();
        const std::vector<double> qv(q.coeffs().data(), q.coeffs().data() + 4);
        const std::vector<double> X = {rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0),
                                       rng.uniform(-5.0, 5.0)};
        const double u = rng.uniform(0.0, 640.0), v = rng.uniform(0.0, 480.0);
        const double s = rng.uniform(10.0, 40.0);
        {
            cv::augocc::detail::OrthoReprojectionCost analytic(u, v, 319.5, 239.5);
            std::unique_ptr<ceres::CostFunction> ad(
                cv::augocc::detail::OrthoReprojectionError::Create(u, v, 319.5, 239.5));
            expectSameCost(analytic, *ad, {qv, {rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)},
                                           {s}, X});
        }
        {
            cv::augocc::detail::PerspectiveStrengthCost analytic(u, v, 319.5, 239.5);
            std::unique_ptr<ceres::CostFunction> ad(
                cv::augocc::detail::PerspectiveStrengthError::Create(u, v, 319.5, 239.5));
            expectSameCost(analytic, *ad, {qv, {rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0),
                                           rng.uniform(-3.0, 3.0)}, {s},
                                           {rng.uniform(-0.02, 0.02)}, X});
        }
    }
}

// ---- The "Done when" figures on SceneSynthesizer data ----

SyntheticScene synthesize(CameraModel model, double partial, double outliers)
{
    SceneSynthesizer::Params sp;  // 60 frames, 640x480, 600 tracks, 0.5 px noise
    sp.model = model;
    sp.partialFraction = partial;
    sp.outlierFraction = outliers;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    return scene;
}

TEST(Augocc_SfmSynth, scaled_orthographic_full_tracks)
{
    const SyntheticScene scene = synthesize(SCALED_ORTHOGRAPHIC, 0, 0);
    SfmOptions opt;
    opt.model = "scaled_orthographic";
    SfmReport rep;
    const Reconstruction rec = recoverCameras(scene.tracks, opt, &rep);
    const CameraComparison c = compareCameras(rec, scene.groundTruth);
    const double noise = expectedNoiseRms(SceneSynthesizer::Params().noiseSigma);
    std::cout << "SceneSynthesizer scaled orthographic, full tracks: mean rotation error "
              << c.meanRotationDeg << " deg (max " << c.maxRotationDeg << "), RMS "
              << rep.orthographic.rms << " px = " << rep.orthographic.rms / noise
              << " x noise RMS (3F+1 only: " << rep.positionZoom.rms / noise << " x)"
              << std::endl;
    EXPECT_EQ(scene.tracks.frames(), c.frames);
    EXPECT_LT(c.meanRotationDeg, kFullRotDeg);
    EXPECT_LT(rep.orthographic.rms, kFullRmsRatio * noise);
}

TEST(Augocc_SfmSynth, depth_reversal_resolved_by_dominant_plane)
{
    // Scaled orthography: the depth-reversed twin projects to the same pixels; recoverCameras
    // picks the one with the scene in front of its dominant plane (the ground). Without the
    // prior the factorization's arbitrary choice gave the twin (23 deg off) for seeds 1 and 5.
    for (int seed : {1, 2, 5})
    {
        SCOPED_TRACE(cv::format("seed %d", seed));
        SceneSynthesizer::Params sp;
        sp.frames = 30;
        sp.seed = (uint64)seed;
        if (seed == 5)
        {
            sp.elevationDegrees = 60;
            sp.orbitDegrees = 70;
        }
        SyntheticScene scene;
        SceneSynthesizer::create(sp)->synthesize(scene);
        const Reconstruction rec = recoverCameras(scene.tracks);
        const CameraComparison c = compareCameras(rec, scene.groundTruth, false);
        EXPECT_LT(c.meanRotationDeg, kFullRotDeg);
    }
}

TEST(Augocc_SfmSynth, partial_and_outlier_tracks)
{
    const SyntheticScene scene = synthesize(SCALED_ORTHOGRAPHIC, 0.4, 0.05);
    SfmOptions opt;
    opt.model = "scaled_orthographic";
    SfmReport rep;
    const Reconstruction rec = recoverCameras(scene.tracks, opt, &rep);
    int nOut = 0, outRejected = 0, nGood = 0, goodKept = 0;
    for (int p = 0; p < scene.tracks.points(); p++)
    {
        const bool kept = rec.hasPoint(p);
        if (scene.outlierTrack[p])
        {
            nOut++;
            outRejected += !kept;
        }
        else
        {
            nGood++;
            goodKept += kept;
        }
    }
    const CameraComparison c = compareCameras(rec, scene.groundTruth);
    std::cout << "SceneSynthesizer 40% partial + 5% outliers: outliers rejected "
              << outRejected << "/" << nOut << ", good kept " << goodKept << "/" << nGood
              << ", mean rotation error " << c.meanRotationDeg << " deg" << std::endl;
    ASSERT_GT(nOut, 0);
    EXPECT_GE(outRejected, 0.95 * nOut);   // the issue: >= 95% of outlier tracks rejected
    EXPECT_GE(goodKept, 0.90 * nGood);     // the issue: >= 90% of good tracks kept
    EXPECT_LT(c.meanRotationDeg, kPartialRotDeg);
}

TEST(Augocc_SfmSynth, perspective_scene)
{
    const SyntheticScene scene = synthesize(PERSPECTIVE, 0, 0);
    SfmOptions opt;
    opt.model = "perspective";
    SfmReport rep;
    const Reconstruction rec = recoverCameras(scene.tracks, opt, &rep);
    const CameraComparison c = compareCameras(rec, scene.groundTruth, false);
    const double noise = expectedNoiseRms(SceneSynthesizer::Params().noiseSigma);
    std::cout << "SceneSynthesizer perspective at 10x: mean rotation error "
              << c.meanRotationDeg << " deg, RMS " << rep.perspective.rms << " px = "
              << rep.perspective.rms / noise << " x noise (scaled orthographic: "
              << rep.orthographic.rms / noise << " x)" << std::endl;
    EXPECT_EQ(PERSPECTIVE, rec.model);
    EXPECT_LT(c.meanRotationDeg, kPerspRotDeg);
    EXPECT_LT(rep.perspective.rms, kPerspRmsRatio * noise);
    // `auto` must pick perspective here.
    SfmReport autoRep;
    recoverCameras(scene.tracks, SfmOptions(), &autoRep);
    EXPECT_EQ("perspective", autoRep.chosenModel);
}

// Tracks the factorization rejects against its affine model but the final perspective cameras
// explain come back (hand-held footage near the buildings: the camera three scene sizes away),
// and no outlier track with them. Measured 2026-12-01 (40% partial tracks, 5% outliers): 41
// rescued, 0 of them outliers; error after alignment (scene units, the scene about 5 across):
// rescued median 0.017, max 0.075; kept median 0.014, 95th percentile 0.070. Bound: the rescued
// median within the kept points' 95th percentile. The 3 of 30 outliers that stay were
// kept by the factorization itself (random walks that barely move look like points near the
// orbit's centre). On the perspective demo's own tracks 41 of 92 rejected tracks came back.
TEST(Augocc_SfmSynth, perspective_rejected_tracks_rescued)
{
    SceneSynthesizer::Params sp;
    sp.model = PERSPECTIVE;
    sp.distanceRatio = 3;
    sp.partialFraction = 0.4;
    sp.outlierFraction = 0.05;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    SfmOptions opt;
    opt.model = "perspective";
    SfmReport rep;
    const Reconstruction rec = recoverCameras(scene.tracks, opt, &rep);
    Reconstruction rec0;
    Mat inliers;
    ASSERT_TRUE(FactorizationSfM::create()->reconstruct(scene.tracks, rec0, inliers));
    const Matx44d M = alignReconstructions(rec, scene.groundTruth);
    int rescued = 0, outRescued = 0;
    std::vector<double> err, errR;
    for (int p = 0; p < scene.tracks.points(); p++)
    {
        if (!rec.hasPoint(p) || scene.outlierTrack[p])
        {
            outRescued += rec.hasPoint(p) && !inliers.at<uchar>(p);
            continue;
        }
        const Vec3d X = rec.point(p);
        const Vec4d Y = M * Vec4d(X[0], X[1], X[2], 1);
        const double* G = scene.groundTruth.points.ptr<double>(p);
        const double e = cv::norm(Vec3d(Y[0], Y[1], Y[2]) - Vec3d(G[0], G[1], G[2]));
        if (inliers.at<uchar>(p))
            err.push_back(e);
        else
        {
            rescued++;
            errR.push_back(e);
        }
    }
    ASSERT_GT(rescued, 0);
    const double rescuedMedian = augocc::detail::median(errR);
    const double keptMedian = augocc::detail::median(err);
    std::sort(err.begin(), err.end());
    std::sort(errR.begin(), errR.end());
    const double keptP95 = err[err.size() * 95 / 100];
    std::cout << "perspective at 3x, 40% partial + 5% outliers: rescued " << rep.rescuedTracks
              << " tracks (" << outRescued << " outliers); error after alignment (units): "
              << "rescued median " << rescuedMedian << " max " << errR.back() << ", kept median "
              << keptMedian << " p95 " << keptP95 << " max " << err.back() << std::endl;
    EXPECT_EQ(rep.rescuedTracks, rescued + outRescued);
    EXPECT_EQ(outRescued, 0);
    EXPECT_LE(rescuedMedian, keptP95);
}

} // namespace
} // namespace opencv_test
