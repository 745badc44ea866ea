// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Lens distortion in the camera recovery: the calibration file reader, known intrinsics,
// self-calibration (focal, k1, k2 by BIC) and its degenerate cases, and the COLMAP export of
// distorted cameras, on synthetic hand-held street-level tracks with known truth.

#include "test_precomp.hpp"
#include "sfm_test_utils.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace opencv_test
{
namespace
{
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// A hand-held street-level problem generator

struct HandheldParams
{
    int frames = 90;
    int points = 300;
    Size imageSize = Size(1280, 720);
    double focal = 1000;                 //!< pixels
    std::vector<double> distortion = {-0.12, 0.01, 0, 0};  //!< barrel, k2 small
    //! Building-sized box, metres: x and z in [-10, 10], y (up) in [0, 12].
    double sceneSize = 20;
    double distanceRatio = 1.5;          //!< camera distance / scene size
    double walkMetres = 16;              //!< sideways walk over the sequence
    double noiseSigma = 0.3;             //!< Gaussian pixel noise per axis
    //! points so far ahead (skyDistance metres) that the walk gives them no measurable
    //! parallax: a skyline, clouds, a mountain, appended after the `points` ones
    int skyPoints = 0;
    double skyDistance = 1e6;
    uint64 seed = 7;
};

struct HandheldProblem
{
    Tracks tracks;
    Reconstruction truth;
};

// Camera looking from C at T, world y up, image y down, rolled by `roll` radians.
Matx33d lookAt(const Vec3d& C, const Vec3d& T, double roll)
{
    const Vec3d z = normalize(T - C);
    const Vec3d down(0, -1, 0);
    const Vec3d x = normalize(down.cross(z));
    const Vec3d y = z.cross(x);
    const Matx33d R(x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]);
    const double c = std::cos(roll), s = std::sin(roll);
    return Matx33d(c, -s, 0, s, c, 0, 0, 0, 1) * R;
}

/* Points uniform in the box (60%) and on the street before it (40%: the ground fills the
lower part of the image, as in street footage); the camera walks sideways at eye height (1.6 m plus a 10 cm
sway), 1.5 scene sizes from the box centre, aimed at it with a wobble of about 2 degrees and a
roll of up to 3 degrees (smooth: sums of slow sines). Each track is visible in one window of
a third to all of the frames (partial tracks) and where it projects inside the image. */
HandheldProblem makeHandheld(const HandheldParams& p)
{
    RNG rng(p.seed);
    const double h = 0.5 * p.sceneSize;
    const int P = p.points + p.skyPoints;
    std::vector<Vec3d> X(P);
    const double D = p.distanceRatio * p.sceneSize;
    for (int i = 0; i < p.points; i++)
    {
        if (i % 5 < 2)   // 40% on the street between the camera and the building
            X[i] = Vec3d(rng.uniform(-1.5 * h, 1.5 * h), 0.0,
                         rng.uniform(-D + 4.0, h));
        else
            X[i] = Vec3d(rng.uniform(-h, h), rng.uniform(0.0, 0.6 * p.sceneSize),
                         rng.uniform(-h, h));
    }
    for (int i = p.points; i < P; i++)   // ahead, within +-0.4 rad, 3 to 11 degrees up
        X[i] = p.skyDistance * normalize(Vec3d(rng.uniform(-0.4, 0.4), rng.uniform(0.05, 0.2),
                                               1.0));
    HandheldProblem out;
    out.truth.model = PERSPECTIVE;
    out.truth.imageSize = p.imageSize;
    const Matx33d K(p.focal, 0, (p.imageSize.width - 1) * 0.5, 0, p.focal,
                    (p.imageSize.height - 1) * 0.5, 0, 0, 1);
    for (int f = 0; f < p.frames; f++)
    {
        const double a = (double)f / (p.frames - 1);
        const Vec3d C(p.walkMetres * (a - 0.5) + 0.3 * std::sin(5.1 * a),
                      1.6 + 0.1 * std::sin(7.3 * a + 0.4), -D + 0.5 * std::sin(3.7 * a));
        const Vec3d aim(0.7 * std::sin(4.3 * a + 1.0), 3.0 + 0.5 * std::sin(6.1 * a),
                        0.7 * std::sin(3.1 * a));
        const double roll = 0.05 * std::sin(2.9 * a + 0.3);
        const Matx33d R = lookAt(C, aim, roll);
        out.truth.cameras.push_back(Camera::perspective(R, -(R * C), K, f, p.distortion));
    }
    out.truth.points = Mat(P, 3, CV_64F);
    for (int i = 0; i < P; i++)
        for (int k = 0; k < 3; k++)
            out.truth.points.at<double>(i, k) = X[i][k];
    Mat m(p.frames, P, CV_32FC2, Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    for (int i = 0; i < P; i++)
    {
        const int len = rng.uniform(std::max(2, p.frames / 3), p.frames + 1);
        const int start = rng.uniform(0, p.frames - len + 1);
        for (int f = start; f < start + len; f++)
        {
            const Camera& cam = out.truth.cameras[f];
            if (cam.depth(X[i]) <= 0)
                continue;
            const Point2d q = cam.project(X[i]);
            if (q.x < 0 || q.y < 0 || q.x > p.imageSize.width - 1 ||
                q.y > p.imageSize.height - 1)
                continue;
            m.at<Point2f>(f, i) = Point2f(
                (float)(q.x + rng.gaussian(p.noiseSigma)),
                (float)(q.y + rng.gaussian(p.noiseSigma)));
        }
    }
    out.tracks = Tracks::fromDense(p.imageSize, m);
    return out;
}

void printFigures(const char* what, const LensFigures& m, const SfmReport& rep)
{
    std::cout << cv::format("[ figures  ] %-22s rotation %.4f deg, focal %.3f%%, corners %.3f px, "
                            "lens %s (%s)", what, m.rotationDeg, m.focalErrorPct, m.cornerPx,
                            rep.lensModel.c_str(), rep.lensReason.c_str()) << std::endl;
}

const HandheldProblem& barrelProblem()
{
    static const HandheldProblem p = makeHandheld(HandheldParams());
    return p;
}

Calibration trueCalibration(const HandheldProblem& p)
{
    Calibration cal;
    cal.K = p.truth.cameras.front().K;
    cal.distortion = p.truth.cameras.front().distortion;
    cal.imageSize = p.truth.imageSize;
    return cal;
}

// Issue 15's targets: calibrated, mean rotation error <= 0.1 deg; uncalibrated, focal within
// 1% and distortion within 0.5 px at the corners.
const double kMaxCalibratedRotationDeg = 0.1;
const double kMaxFocalErrorPct = 1.0;
const double kMaxCornerPx = 0.5;

TEST(Augocc_SfmLens, accuracy_calibrated)
{
    const HandheldProblem& p = barrelProblem();
    SfmOptions opt;
    opt.calibration = trueCalibration(p);
    SfmReport rep;
    const Reconstruction rec = recoverCameras(p.tracks, opt, &rep);
    const LensFigures m = measureLens(rec, p.truth);
    printFigures("calibrated:", m, rep);
    EXPECT_EQ(rep.lensModel, "given");
    ASSERT_EQ(rec.model, PERSPECTIVE);
    EXPECT_EQ(rec.cameras.front().distortion, opt.calibration.distortion);  // held fixed
    EXPECT_EQ(rec.cameras.front().K, opt.calibration.K);
    EXPECT_LE(m.rotationDeg, kMaxCalibratedRotationDeg);
    // 0.3 px noise per axis: RMS sqrt(2) x 0.3 = 0.42 px, + 10% for the fitted parameters.
    EXPECT_LE(rep.lens.rms, 1.1 * expectedNoiseRms(0.3));
}

/* Tracks an occluding contour dragged along after their point went out of sight (the hand-held
demo's own tracker output, against the true cameras: median 0.27 px, but 5% of the observations
beyond 2.6 px and 1% beyond 9.9 px): every 8th track with a long window drifts from the middle
of its window on, at `pxPerFrame` in a direction of its own, as a window sliding along a contour
does. Returns the count of observations moved by more than 1 px. */
int dragTracks(HandheldProblem& p, double pxPerFrame, uint64 seed)
{
    RNG rng(seed);
    // Offset of every observation, by (frame, point); most are zero.
    Mat offset(p.tracks.frames(), p.tracks.points(), CV_32FC2, Scalar::all(0));
    int moved = 0;
    for (int i = 0; i < p.tracks.points(); i += 8)
    {
        const Range seen = p.tracks.track(i);
        const int n = seen.size();
        if (n < 30)
            continue;
        const double a = rng.uniform(0.0, 2 * CV_PI);
        for (int k = n / 2; k < n; k++)
        {
            const double d = pxPerFrame * (double)(k - n / 2 + 1);
            offset.at<Point2f>(p.tracks.frameOf(seen.start + k), i) =
                Point2f((float)(d * std::cos(a)), (float)(d * std::sin(a)));
            moved += d > 1.0 ? 1 : 0;
        }
    }
    p.tracks = p.tracks.mapped([&](int f, int pt, const Point2f& uv) {
        return uv + offset.at<Point2f>(f, pt);
    }, p.tracks.imageSize);
    return moved;
}

TEST(Augocc_SfmLens, dragged_tracks_left_out)
{
    HandheldProblem p = makeHandheld(HandheldParams());
    const int moved = dragTracks(p, 0.2, 11);
    ASSERT_GT(moved, 500);
    SfmOptions opt;
    opt.calibration = trueCalibration(p);
    SfmOptions all = opt;
    all.explainedRounds = 0;
    SfmReport rep, rep0;
    const LensFigures m0 = measureLens(recoverCameras(p.tracks, all, &rep0), p.truth);
    const LensFigures m = measureLens(recoverCameras(p.tracks, opt, &rep), p.truth);
    printFigures("dragged, every obs.:", m0, rep0);
    printFigures("dragged, explained:", m, rep);
    std::cout << cv::format("[ figures  ] %d observations moved by > 1 px, %d left out beyond "
                            "%.2f px", moved, rep.unexplainedObservations,
                            rep.unexplainedThresholdPx) << std::endl;
    EXPECT_LE(m.rotationDeg, kMaxCalibratedRotationDeg);
    // The test's point: the dragged tracks spoil the solution when every observation is used.
    EXPECT_GT(m0.rotationDeg, 2 * m.rotationDeg);
    // Most of what was moved by more than 1 px (over 3 sigma of the 0.3 px noise) is left out;
    // the rest are the first frames of each drag, within the threshold.
    EXPECT_GE(rep.unexplainedObservations, moved / 2);
    // Self-calibration on the same tracks: the lens is chosen on the explained observations.
    SfmReport repSelf;
    const LensFigures ms = measureLens(recoverCameras(p.tracks, SfmOptions(), &repSelf), p.truth);
    printFigures("dragged, self-calib.:", ms, repSelf);
    EXPECT_LE(ms.focalErrorPct, kMaxFocalErrorPct);
    EXPECT_LE(ms.cornerPx, kMaxCornerPx);
}

TEST(Augocc_SfmLens, accuracy_refine_intrinsics)
{
    const HandheldProblem& p = barrelProblem();
    SfmOptions opt;
    opt.calibration = trueCalibration(p);
    opt.calibration.K(0, 0) *= 1.02;   // a calibration 2% off
    opt.calibration.K(1, 1) *= 1.02;
    opt.refineIntrinsics = true;
    SfmReport rep;
    const Reconstruction rec = recoverCameras(p.tracks, opt, &rep);
    const LensFigures m = measureLens(rec, p.truth);
    printFigures("refined from 2% off:", m, rep);
    EXPECT_EQ(rep.lensModel, "given_refined");
    EXPECT_LE(m.focalErrorPct, kMaxFocalErrorPct);
    // k1, k2, p1, p2 all free (the tangential terms too, unlike the self-calibration): the
    // corners are extrapolated further; measured 0.76 px, the bound 1 px.
    const double kMaxRefinedCornerPx = 1.0;
    EXPECT_LE(m.cornerPx, kMaxRefinedCornerPx);
}

TEST(Augocc_SfmLens, accuracy_known_focal)
{
    // Only the focal known on footage without distortion: perspective forced, focal kept.
    HandheldParams hp;
    hp.distortion.clear();
    const HandheldProblem p = makeHandheld(hp);
    SfmOptions opt;
    opt.focal = hp.focal;
    SfmReport rep;
    const Reconstruction rec = recoverCameras(p.tracks, opt, &rep);
    const LensFigures m = measureLens(rec, p.truth);
    printFigures("known focal:", m, rep);
    EXPECT_EQ(rec.cameras.front().K(0, 0), hp.focal);
    EXPECT_TRUE(rec.cameras.front().distortion.empty());
    EXPECT_LE(m.rotationDeg, kMaxCalibratedRotationDeg);
}

TEST(Augocc_SfmLens, accuracy_self_calibration)
{
    const HandheldProblem& p = barrelProblem();
    SfmReport rep;
    const Reconstruction rec = recoverCameras(p.tracks, SfmOptions(), &rep);
    const LensFigures m = measureLens(rec, p.truth);
    printFigures("self-calibrated:", m, rep);
    EXPECT_TRUE(rep.lensModel == "focal_k1" || rep.lensModel == "focal_k1_k2") << rep.lensReason;
    EXPECT_LE(m.focalErrorPct, kMaxFocalErrorPct);
    EXPECT_LE(m.cornerPx, kMaxCornerPx);
    ASSERT_EQ(rep.lensBic.size(), 3u);

    // Today's behaviour, the distortion ignored: the figures for comparison (no target).
    SfmOptions ignored;
    ignored.selfCalibrate = false;
    SfmReport repIgnored;
    const Reconstruction recIgnored = recoverCameras(p.tracks, ignored, &repIgnored);
    const LensFigures mi = measureLens(recIgnored, p.truth);
    printFigures("distortion ignored:", mi, repIgnored);
    EXPECT_TRUE(recIgnored.cameras.front().distortion.empty());
    EXPECT_GT(mi.cornerPx, 10 * kMaxCornerPx);  // the lens it cannot see: ~tens of px
}

TEST(Augocc_SfmLens, no_distortion_keeps_focal_only)
{
    // A pinhole: the criterion must not add k1 / k2, and the result is the perspective
    // solution unchanged (the self-calibration keeps the prior; two runs of the perspective
    // pipeline were seen to differ by 1e-12 relative, hence the 1e-9 tolerance).
    HandheldParams hp;
    hp.distortion.clear();
    const HandheldProblem p = makeHandheld(hp);
    SfmReport rep;
    const Reconstruction rec = recoverCameras(p.tracks, SfmOptions(), &rep);
    printFigures("no distortion:", measureLens(rec, p.truth), rep);
    EXPECT_EQ(rep.lensModel, "focal") << rep.lensReason;
    EXPECT_TRUE(rec.cameras.front().distortion.empty());
    SfmOptions off;
    off.selfCalibrate = false;
    const Reconstruction prior = recoverCameras(p.tracks, off);
    ASSERT_EQ(prior.cameras.size(), rec.cameras.size());
    for (size_t i = 0; i < rec.cameras.size(); i++)
    {
        const double kRel = 1e-9;
        EXPECT_LE(cv::norm(rec.cameras[i].R, prior.cameras[i].R, NORM_INF), kRel);
        EXPECT_LE(cv::norm(rec.cameras[i].t, prior.cameras[i].t, NORM_INF),
                  kRel * cv::norm(prior.cameras[i].t));
        EXPECT_LE(std::abs(rec.cameras[i].K(0, 0) - prior.cameras[i].K(0, 0)),
                  kRel * prior.cameras[i].K(0, 0));
    }
}

TEST(Augocc_SfmLens, far_away_keeps_prior)
{
    // Near orthographic (the camera 15 scene sizes away, the same walk): nothing tells the focal
    // from the distance; the prior is kept and the report says why.
    HandheldParams hp;
    hp.distanceRatio = 15;
    hp.focal = 10000;
    const HandheldProblem p = makeHandheld(hp);
    SfmReport rep;
    const Reconstruction rec = recoverCameras(p.tracks, SfmOptions(), &rep);
    std::cout << "[ figures  ] far away: model " << rep.chosenModel << ", lens " << rep.lensModel
              << ": " << rep.lensReason << std::endl;
    EXPECT_TRUE(rep.lensModel == "none" || rep.lensModel == "focal") << rep.lensModel;
    EXPECT_FALSE(rep.lensReason.empty());
    if (rec.model == PERSPECTIVE)
    {
        EXPECT_TRUE(rec.cameras.front().distortion.empty());
    }
}

/* A skyline ahead: points a million metres away, which the 16 m walk moves by 0.016 px, under
the 0.3 px noise. Their depth is not in the data: the noise alone decides where the bundle
adjustment and the triangulation put them, at any distance, behind the cameras, or beyond the
writer's 1e9 limit (a hand-held shot's own tracks gave a point at 1.17e9, and `augocc sfm` wrote
no reconstruction). They must come out as not reconstructed (NaN), the building's points as
before, and the reconstruction must be writable. */
TEST(Augocc_SfmLens, sky_points_not_reconstructed)
{
    HandheldParams hp;
    hp.skyPoints = 60;
    const HandheldProblem p = makeHandheld(hp);
    const String dir = tempDir("sky");
    for (int calibrated = 1; calibrated >= 0; calibrated--)
    {
        SCOPED_TRACE(calibrated ? "calibrated" : "self-calibrated");
        SfmOptions opt;
        if (calibrated)
            opt.calibration = trueCalibration(p);
        SfmReport rep;
        const Reconstruction rec = recoverCameras(p.tracks, opt, &rep);
        const LensFigures m = measureLens(rec, p.truth);
        printFigures(calibrated ? "sky, calibrated:" : "sky, self-calibrated:", m, rep);
        int sky = 0, building = 0;
        for (int i = 0; i < rec.points.rows; i++)
            (i < hp.points ? building : sky) += rec.hasPoint(i) ? 1 : 0;
        std::cout << cv::format("[ figures  ] %d of %d sky points, %d of %d others "
                                "reconstructed (%d reported as too far)", sky, hp.skyPoints,
                                building, hp.points, rep.unmeasuredDepthTracks) << std::endl;
        EXPECT_EQ(sky, 0);   // before the fix: all of them, up to 2.9e6 units away
        // Reported: most sky points (the factorization or the unexplained-observation rounds
        // may take some first), and no other (every other one kept or rejected otherwise).
        EXPECT_GT(rep.unmeasuredDepthTracks, hp.skyPoints / 2);
        EXPECT_LE(rep.unmeasuredDepthTracks, hp.skyPoints);
        // The others keep their depth (the walk sees them under 10-30 degrees). Measured: 283 of
        // 300 with the sky, 280 without it (the rest are short tracks the factorization
        // rejects); 5 fewer than without it would mean the rule takes points it should not.
        EXPECT_GE(building, 280 - 5);
        if (calibrated)
        {
            EXPECT_LE(m.rotationDeg, kMaxCalibratedRotationDeg);
        }
        else
        {
            EXPECT_LE(m.focalErrorPct, kMaxFocalErrorPct);
            EXPECT_TRUE(rep.focalRelStd > 0) << rep.lensReason;   // before: refused, rank-deficient
            // Not the 0.5 px target: the same shot without the sky gives 0.15 px, with it 0.71
            // (with or without this rule: the sky's tracks in the earlier stages; open in issue
            // 15). The bound is the refined-intrinsics one, 1 px.
            EXPECT_LE(m.cornerPx, 1.0);
        }
        const String path = dir + (calibrated ? "/calibrated.yml" : "/self.yml");
        ASSERT_NO_THROW(writeReconstruction(path, rec));
        EXPECT_EQ(readReconstruction(path).points.rows, rec.points.rows);
    }
}

// ---------------------------------------------------------------------------------------------
// The calibration file

String writeCalibrationFile(const String& dir, const String& name,
                            const std::function<void(FileStorage&)>& fill)
{
    const String path = dir + "/" + name;
    FileStorage fs(path, FileStorage::WRITE);
    fill(fs);
    fs.release();
    return path;
}

const Matx33d kK(1000, 0, 639.5, 0, 1002, 359.5, 0, 0, 1);

void writeGood(FileStorage& fs)
{
    fs << "calibration_time" << "today";    // another tool's key: ignored
    fs << "image_width" << 1280 << "image_height" << 720;
    fs << "camera_matrix" << Mat(kK);
    fs << "distortion_coefficients" << (Mat_<double>(1, 5) << -0.12, 0.01, 0.001, -0.002, 0.0);
    fs << "avg_reprojection_error" << 0.2;
}

TEST(Augocc_Calibration, accuracy)
{
    const String dir = tempDir("calib");
    const String path = writeCalibrationFile(dir, "calibration.yml", writeGood);
    const Calibration c = readCalibration(path, Size(1280, 720));
    EXPECT_EQ(c.K, kK);
    ASSERT_EQ(c.distortion.size(), 5u);
    EXPECT_EQ(c.distortion[0], -0.12);
    EXPECT_EQ(c.imageSize, Size(1280, 720));
    // Nx1 coefficients, no size keys: taken as the frames'.
    const String col = writeCalibrationFile(dir, "col.yml", [](FileStorage& fs) {
        fs << "camera_matrix" << Mat(kK);
        fs << "distortion_coefficients" << Mat(Mat_<double>(8, 1, 0.0));
    });
    const Calibration c2 = readCalibration(col, Size(1280, 720));
    EXPECT_EQ(c2.distortion.size(), 8u);
    EXPECT_EQ(c2.imageSize, Size(1280, 720));
    fs::remove_all(dir);
}

TEST(Augocc_Calibration, scaled_to_frames)
{
    // Calibrated at 1920 x 1080, frames 1280 x 720: r = 2/3, c' = r (c + 0.5) - 0.5 (origin at
    // the centre of the top-left pixel), f' = r f, distortion unchanged.
    const String dir = tempDir("calib");
    const Matx33d K(1500, 0, 959.5, 0, 1500, 539.5, 0, 0, 1);
    const String path = writeCalibrationFile(dir, "c.yml", [&](FileStorage& fs) {
        fs << "image_width" << 1920 << "image_height" << 1080;
        fs << "camera_matrix" << Mat(K);
        fs << "distortion_coefficients" << (Mat_<double>(1, 4) << -0.1, 0.02, 0, 0);
    });
    const Calibration c = readCalibration(path, Size(1280, 720));
    const double r = 2.0 / 3.0;
    EXPECT_NEAR(c.K(0, 0), 1000, 1e-9);
    EXPECT_NEAR(c.K(1, 1), 1000, 1e-9);
    EXPECT_NEAR(c.K(0, 2), r * (959.5 + 0.5) - 0.5, 1e-9);   // 639.5: still the centre
    EXPECT_NEAR(c.K(1, 2), 359.5, 1e-9);
    EXPECT_EQ(c.distortion, std::vector<double>({-0.1, 0.02, 0, 0}));
    EXPECT_EQ(c.imageSize, Size(1280, 720));
    // Another aspect: an error naming both sizes.
    try
    {
        readCalibration(path, Size(1280, 960));
        ADD_FAILURE() << "no error for another aspect";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_NE(e.err.find("1920 x 1080"), std::string::npos) << e.err;
        EXPECT_NE(e.err.find("1280 x 960"), std::string::npos) << e.err;
        EXPECT_NE(e.err.find(path), std::string::npos) << e.err;
    }
    fs::remove_all(dir);
}

// Expects readCalibration(path) to throw a message naming the file and `key`.
void expectBadCalibration(const String& path, const String& key)
{
    try
    {
        readCalibration(path, Size(1280, 720));
        ADD_FAILURE() << path << ": no error (" << key << ")";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_NE(e.err.find(path), std::string::npos) << e.err;
        EXPECT_NE(e.err.find(key), std::string::npos) << e.err;
    }
}

TEST(Augocc_Calibration, bad_arg)
{
    const String dir = tempDir("calib");
    const Mat D = (Mat_<double>(1, 5) << -0.12, 0.01, 0, 0, 0);
    expectBadCalibration(writeCalibrationFile(dir, "no_k.yml", [&](FileStorage& fs) {
        fs << "distortion_coefficients" << D;
    }), "camera_matrix");
    expectBadCalibration(writeCalibrationFile(dir, "no_d.yml", [&](FileStorage& fs) {
        fs << "camera_matrix" << Mat(kK);
    }), "distortion_coefficients");
    expectBadCalibration(writeCalibrationFile(dir, "shape.yml", [&](FileStorage& fs) {
        fs << "camera_matrix" << Mat(Mat_<double>(3, 4, 0.0));
        fs << "distortion_coefficients" << D;
    }), "camera_matrix");
    expectBadCalibration(writeCalibrationFile(dir, "nan.yml", [&](FileStorage& fs) {
        Matx33d K = kK;
        K(0, 2) = std::numeric_limits<double>::quiet_NaN();
        fs << "camera_matrix" << Mat(K);
        fs << "distortion_coefficients" << D;
    }), "camera_matrix");
    expectBadCalibration(writeCalibrationFile(dir, "neg.yml", [&](FileStorage& fs) {
        Matx33d K = kK;
        K(0, 0) = -1000;
        fs << "camera_matrix" << Mat(K);
        fs << "distortion_coefficients" << D;
    }), "camera_matrix");
    expectBadCalibration(writeCalibrationFile(dir, "zero.yml", [&](FileStorage& fs) {
        Matx33d K = kK;
        K(1, 1) = 0;
        fs << "camera_matrix" << Mat(K);
        fs << "distortion_coefficients" << D;
    }), "camera_matrix");
    expectBadCalibration(writeCalibrationFile(dir, "count.yml", [&](FileStorage& fs) {
        fs << "camera_matrix" << Mat(kK);
        fs << "distortion_coefficients" << Mat(Mat_<double>(1, 6, 0.0));
    }), "distortion_coefficients");
    expectBadCalibration(writeCalibrationFile(dir, "dnan.yml", [&](FileStorage& fs) {
        fs << "camera_matrix" << Mat(kK);
        Mat d = D.clone();
        d.at<double>(1) = std::numeric_limits<double>::infinity();
        fs << "distortion_coefficients" << d;
    }), "distortion_coefficients");
    expectBadCalibration(writeCalibrationFile(dir, "half.yml", [&](FileStorage& fs) {
        fs << "image_width" << 1280;
        fs << "camera_matrix" << Mat(kK);
        fs << "distortion_coefficients" << D;
    }), "image_height");
    expectBadCalibration(writeCalibrationFile(dir, "aspect.yml", [&](FileStorage& fs) {
        fs << "image_width" << 640 << "image_height" << 480;
        fs << "camera_matrix" << Mat(kK);
        fs << "distortion_coefficients" << D;
    }), "image_width");
    EXPECT_THROW(readCalibration(dir + "/absent.yml", Size(1280, 720)), cv::Exception);
    fs::remove_all(dir);
}

TEST(Augocc_Calibration, cli_bad_file_exit_status)
{
    // A bad calibration is exit status 2 with a message naming the file and the key, before
    // any stage runs.
    const String dir = tempDir("calib_cli");
    const String bad = writeCalibrationFile(dir, "bad.yml", [](FileStorage& fs) {
        fs << "camera_matrix" << Mat(kK);
    });
    HandheldParams hp;
    hp.frames = 10;
    hp.points = 40;
    writeTracks(dir + "/tracks.yml", makeHandheld(hp).tracks);
    std::string out;
    const int rc = runCommand(augoccBinary() + " sfm --tracks '" + dir + "/tracks.yml' --out '" +
                              dir + "/rec.yml' --calibration '" + bad + "'", &out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find(bad), std::string::npos) << out;
    EXPECT_NE(out.find("distortion_coefficients"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(dir + "/rec.yml"));
    fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// COLMAP export of distorted cameras

// The numbers after "1 <MODEL> " on the first camera line of cameras.txt, or empty.
std::vector<double> colmapCamera(const String& path, const std::string& model)
{
    std::ifstream in(path);
    std::string line;
    std::vector<double> v;
    while (std::getline(in, line))
    {
        if (line.rfind("1 " + model + " ", 0) != 0)
            continue;
        std::istringstream ss(line.substr(3 + model.size()));
        double x;
        while (ss >> x)
            v.push_back(x);
        break;
    }
    return v;
}

void expectNear(const std::vector<double>& a, const std::vector<double>& b)
{
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); i++)
        EXPECT_NEAR(a[i], b[i], 1e-12) << i;  // printed with 17 digits
}

TEST(Augocc_SfmExport, colmap_opencv_model)
{
    HandheldParams hp;
    hp.frames = 6;
    hp.points = 30;
    HandheldProblem p = makeHandheld(hp);
    const String dir = tempDir("colmap");
    // OPENCV: fx fy cx cy k1 k2 p1 p2, principal point +0.5 (COLMAP's origin is the corner).
    writeColmapModel(dir + "/opencv", p.truth, p.tracks);
    expectNear(colmapCamera(dir + "/opencv/cameras.txt", "OPENCV"),
               {1280, 720, 1000, 1000, 640, 360, -0.12, 0.01, 0, 0});
    // k3..k6: FULL_OPENCV.
    for (Camera& c : p.truth.cameras)
        c.distortion = {-0.12, 0.01, 0, 0, 0.001, 0.1, 0, 0};
    writeColmapModel(dir + "/full", p.truth, p.tracks);
    expectNear(colmapCamera(dir + "/full/cameras.txt", "FULL_OPENCV"),
               {1280, 720, 1000, 1000, 640, 360, -0.12, 0.01, 0, 0, 0.001, 0.1, 0, 0});
    // Thin prism / tilt terms: not expressible, nothing written.
    for (Camera& c : p.truth.cameras)
    {
        c.distortion.assign(12, 0.0);
        c.distortion[8] = 0.001;
    }
    EXPECT_THROW(writeColmapModel(dir + "/prism", p.truth, p.tracks), cv::Exception);
    EXPECT_FALSE(fs::exists(dir + "/prism/cameras.txt"));
    // A pinhole stays PINHOLE.
    for (Camera& c : p.truth.cameras)
        c.distortion.clear();
    writeColmapModel(dir + "/pinhole", p.truth, p.tracks);
    expectNear(colmapCamera(dir + "/pinhole/cameras.txt", "PINHOLE"),
               {1280, 720, 1000, 1000, 640, 360});
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test
