// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Camera recovery on real tracks from ../shared/data (skipped when absent).

#include "test_precomp.hpp"
#include "sfm_test_utils.hpp"
#include "sfm_detail.hpp"
#include "stats.hpp"

#include <fstream>
#include <opencv2/calib3d.hpp>

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// cmu_hotel/SOURCE.txt: an unconstrained affine rank-3 fit reaches a median of 0.55 px on the
// KLT set; plain Tomasi-Kanade 2.12 px. The target for augocc: median <= 0.6 px.
const double kHotelMedianPx = 0.6;

TEST(Augocc_SfmRealData, cmu_hotel_klt)
{
    AUGOCC_REQUIRE_SHARED_DATA(path, "cmu_hotel/tracks_klt_51frames.yml");
    const Tracks tracks = readTracks(path);
    SfmReport rep;
    const Reconstruction rec = recoverCameras(tracks, SfmOptions(), &rep);
    EXPECT_NO_THROW(rec.validate());
    // Over every observation of every track, rejected tracks included (their points are
    // re-triangulated from the final cameras): the figure SOURCE.txt's references use.
    Reconstruction all = rec;
    std::vector<const Camera*> cams;
    for (int p = 0; p < tracks.points(); p++)
    {
        if (all.hasPoint(p))
            continue;
        std::vector<const Camera*> cs;
        std::vector<Point2d> obs;
        for (const Camera& c : rec.cameras)
            if (tracks.observed(c.frame, p))
            {
                cs.push_back(&c);
                obs.push_back(Point2d(tracks.at(c.frame, p)));
            }
        Vec3d X;
        if (cv::augocc::detail::triangulatePoint(cs, obs, X))
            for (int k = 0; k < 3; k++)
                all.points.at<double>(p, k) = X[k];
    }
    const ReprojectionStats everything = computeReprojectionStats(all, tracks);
    std::cout << "cmu_hotel KLT (" << tracks.frames() << " frames, " << tracks.points()
              << " tracks): model " << rep.chosenModel << ", kept " << rep.inlierTracks
              << ", rejected " << rep.rejectedTracks << "\n  factorization median "
              << rep.factorization.median << " px, RMS " << rep.factorization.rms
              << "\n  3F+1 median " << rep.positionZoom.median << " px, RMS "
              << rep.positionZoom.rms << "\n  orthographic BA median "
              << rep.orthographic.median << " px, RMS " << rep.orthographic.rms
              << "\n  perspective BA median " << rep.perspective.median << " px, RMS "
              << rep.perspective.rms << "\n  all observations (rejected tracks too): median "
              << everything.median << " px, RMS " << everything.rms << std::endl;
    EXPECT_LE(everything.median, kHotelMedianPx);
    EXPECT_EQ(tracks.frames(), (int)rec.cameras.size());
}

TEST(Augocc_SfmRealData, cmu_hotel_landmarks)
{
    AUGOCC_REQUIRE_SHARED_DATA(path, "cmu_hotel/tracks_landmarks_101frames.yml");
    const Tracks tracks = readTracks(path);
    SfmReport rep;
    const Reconstruction rec = recoverCameras(tracks, SfmOptions(), &rep);
    std::cout << "cmu_hotel landmarks (101 frames, 30 hand-labelled): model "
              << rep.chosenModel << ", median " << (rep.chosenModel == "perspective"
              ? rep.perspective.median : rep.orthographic.median) << " px, RMS "
              << (rep.chosenModel == "perspective" ? rep.perspective.rms : rep.orthographic.rms)
              << " (SOURCE.txt: plain TK median 2.43 px, affine fit 1.50 px)" << std::endl;
    // Integer-pixel hand labels: the affine fit's 1.50 px median is the reference; the
    // refined cameras must not be worse.
    const double kLandmarkMedianPx = 1.5;
    EXPECT_LE(rep.chosenModel == "perspective" ? rep.perspective.median
                                               : rep.orthographic.median, kLandmarkMedianPx);
    EXPECT_EQ(101, (int)rec.cameras.size());
}

// Real footage end to end: augocc's own tracker on the 101 hotel frames, then recoverCameras()
// (what `augocc track` + `augocc sfm` do), and the cameras checked against tracks nobody on this
// project made: the 30 hand-labelled landmarks, triangulated with our cameras (linear, over every
// frame that sees them) and reprojected. Measured 2026-12-01: 1199 tracks, scaled orthographic,
// own tracks 0.62 px median; landmarks 1.66 px median over 3030 observations (their own best
// affine fit leaves 1.50 px, SOURCE.txt: integer-pixel labels).
const double kHotelOwnTracksMedianPx = 1.0;  // the tracker's own tracks (measured 0.63 px)
const double kHotelLandmarkMedianPx = 2.0;   // landmarks through our cameras (best fit: 1.50)

TEST(Augocc_SfmRealData, cmu_hotel_frames_track_sfm_landmarks)
{
    AUGOCC_REQUIRE_SHARED_DATA(frames, "cmu_hotel/frames");
    AUGOCC_REQUIRE_SHARED_DATA(landmarkPath, "cmu_hotel/tracks_landmarks_101frames.yml");
    Tracks tracks;
    FeatureTracker::create()->track(FrameSource::open(frames + "/%04d.png"), tracks);
    ASSERT_EQ(101, tracks.frames());
    SfmReport rep;
    const Reconstruction rec = recoverCameras(tracks, SfmOptions(), &rep);
    ASSERT_EQ(101, (int)rec.cameras.size());
    const ReprojectionStats& own = rep.chosenModel == "perspective" ? rep.perspective : rep.orthographic;
    // Triangulate each landmark (DLT over the frames that see it) and reproject.
    const Tracks marks = readTracks(landmarkPath);
    std::vector<double> err;
    for (int p = 0; p < marks.points(); p++)
    {
        std::vector<int> seen;
        for (int f = 0; f < marks.frames(); f++)
            if (marks.observed(f, p))
                seen.push_back(f);
        if (seen.size() < 2)
            continue;
        Mat A((int)seen.size() * 2, 4, CV_64F);
        for (size_t q = 0; q < seen.size(); q++)
        {
            const Matx34d P = rec.camera(seen[q]).projectionMatrix();
            const Point2f o = marks.at(seen[q], p);
            for (int c = 0; c < 4; c++)
            {
                A.at<double>(2 * (int)q, c) = o.x * P(2, c) - P(0, c);
                A.at<double>(2 * (int)q + 1, c) = o.y * P(2, c) - P(1, c);
            }
        }
        Mat w, u, vt;
        SVD::compute(A, w, u, vt, SVD::FULL_UV);
        const Mat X = vt.row(3).t();
        for (int f : seen)
        {
            const Matx34d P = rec.camera(f).projectionMatrix();
            const Vec3d x = P * Vec4d(X.at<double>(0), X.at<double>(1), X.at<double>(2),
                                      X.at<double>(3));
            const Point2f o = marks.at(f, p);
            err.push_back(std::hypot(x[0] / x[2] - o.x, x[1] / x[2] - o.y));
        }
    }
    ASSERT_GT(err.size(), 1000u);
    const double median = augocc::detail::median(err);
    std::cout << "cmu_hotel frames, augocc tracker + recoverCameras: " << tracks.points()
              << " tracks, model " << rep.chosenModel << ", own tracks median " << own.median
              << " px; 30 hand-labelled landmarks triangulated with these cameras: median "
              << median << " px over " << err.size() << " observations" << std::endl;
    EXPECT_LE(own.median, kHotelOwnTracksMedianPx);
    EXPECT_LE(median, kHotelLandmarkMedianPx);
}

// Reads dino_Ps.txt: 36 blocks of 3 lines; P maps X to (row, col, w). Rows 0 and 1 are
// swapped to get the contract's (x = col, y = row), then P is decomposed to K [R | t].
bool readDinoCameras(const std::string& path, Reconstruction& gt)
{
    std::ifstream in(path);
    if (!in)
        return false;
    std::string line;
    std::vector<double> vals;
    while (std::getline(in, line))
    {
        if (line.empty() || line[0] == '#')
            continue;
        std::istringstream ss(line);
        double v;
        while (ss >> v)
            vals.push_back(v);
    }
    if (vals.size() != 36 * 12)
        return false;
    gt.model = PERSPECTIVE;
    gt.imageSize = Size(720, 576);
    for (int i = 0; i < 36; i++)
    {
        Matx34d P;
        for (int k = 0; k < 12; k++)
            P.val[k] = vals[i * 12 + k];
        for (int c = 0; c < 4; c++)
            std::swap(P(0, c), P(1, c));
        gt.cameras.push_back(cameraFromProjection(P, i));
    }
    return true;
}

// The rotation of view i relative to view 0, as an unsigned angle (degrees).
double angleFromFirst(const Reconstruction& rec, int i)
{
    const Matx33d D = rec.cameras[i].R * rec.cameras[0].R.t();
    return std::acos(std::max(-1.0, std::min(1.0, 0.5 * (trace(D) - 1)))) * 180 / CV_PI;
}

// dino_Ps.txt with the principal point moved to the image centre, the convention of augocc's
// cameras: each camera turned (minimal rotation) so that its optical axis is its ray through the
// image centre. dino_Ps' intrinsics are far from a centred square-pixel camera (RQ: fx 3217,
// fy 2292, principal point (290, -1071) px, 31 degrees from the image centre), and for a
// turntable (single-axis motion) the camera's tilt against the axis trades with them.
Reconstruction centredPrincipalPoint(const Reconstruction& gt)
{
    Reconstruction c = gt;
    for (Camera& cam : c.cameras)
    {
        const Point2d centre((gt.imageSize.width - 1) * 0.5, (gt.imageSize.height - 1) * 0.5);
        Vec3d ray = cam.K.inv() * Vec3d(centre.x, centre.y, 1.0);
        ray /= cv::norm(ray);
        const Vec3d axis = ray.cross(Vec3d(0, 0, 1));
        const double sn = cv::norm(axis);
        Matx33d Ra = Matx33d::eye();
        if (sn > 0)
            Rodrigues(axis * (std::atan2(sn, ray[2]) / sn), Ra);
        cam.R = Ra * cam.R;
    }
    return c;
}

// The cameras over the whole turn. Before the incremental path (factorization_sfm.cpp), the affine
// path ended in a local minimum spread over the turn: 76.9 deg mean, 178 deg max rotation error
// against dino_Ps.txt, RMS 1.73 px. Now 24.3 deg mean, 24.6 max: a constant offset, the same for
// every view, which we attribute to dino_Ps' calibration rather than to the method. It is all
// elevation of the cameras above the turntable plane (26.9 deg here, 2.7 in dino_Ps, 33.3 once its
// principal point is centred), which single-axis motion does not tell from intrinsics that augocc's
// cameras do not have (dino_Ps: principal point 31 degrees off the image centre, aspect ratio 1.4).
// Measured: the relative rotation angles match (10.0 deg a step); the scaled-orthographic bundle
// adjustment started from dino_Ps' own rotations drifts to the same 23-25 deg offset; the
// dinosaur's points rendered through dino_Ps itself (noise-free) give the same offset at a 0.003 px
// median; imaged by square-pixel cameras with a centred principal point they are recovered to 0.08
// deg (oxford_dinosaur_geometry_square_pixels below). Checked here: the turn angle of every view
// (invariant to the elevation), the offset staying constant, and the error against dino_Ps with its
// principal point moved to the image centre.
TEST(Augocc_SfmRealData, oxford_dinosaur)
{
    AUGOCC_REQUIRE_SHARED_DATA(path, "oxford_dinosaur/tracks.yml");
    AUGOCC_REQUIRE_SHARED_DATA(psPath, "oxford_dinosaur/dino_Ps.txt");
    const Tracks tracks = readTracks(path);
    Reconstruction gt;
    ASSERT_TRUE(readDinoCameras(psPath, gt));
    int observed = 0;
    for (int p = 0; p < tracks.points(); p++)
        observed += tracks.observationCount(p);
    const double missing = 1.0 - (double)observed / (tracks.frames() * tracks.points());
    SfmReport rep;
    const int64 t0 = getTickCount();
    const Reconstruction rec = recoverCameras(tracks, SfmOptions(), &rep);
    const double seconds = (getTickCount() - t0) / getTickFrequency();
    const bool ortho = rec.model == SCALED_ORTHOGRAPHIC;
    const CameraComparison cmp = compareCameras(rec, gt, ortho);
    const CameraComparison centred = compareCameras(rec, centredPrincipalPoint(gt), ortho);
    const ReprojectionStats& st = rep.chosenModel == "perspective" ? rep.perspective
                                                                   : rep.orthographic;
    ASSERT_EQ(36, (int)rec.cameras.size());
    double turnMean = 0, turnMax = 0;
    for (int i = 1; i < 36; i++)
    {
        ASSERT_EQ(i, rec.cameras[i].frame);
        const double e = std::abs(angleFromFirst(rec, i) - angleFromFirst(gt, i));
        turnMean += e / 35;
        turnMax = std::max(turnMax, e);
    }
    std::cout << "oxford_dinosaur (" << tracks.frames() << " views, " << tracks.points()
              << " tracks, " << cvRound(100 * missing) << "% missing): " << rec.cameras.size()
              << " cameras in " << seconds << " s, model " << rep.chosenModel << ", kept "
              << rep.inlierTracks << " tracks; reprojection median " << st.median << " px, RMS "
              << st.rms << "\n  rotation vs dino_Ps.txt: mean " << cmp.meanRotationDeg
              << " deg, max " << cmp.maxRotationDeg << " deg; vs dino_Ps.txt with a centred "
              << "principal point: mean " << centred.meanRotationDeg << " deg, max "
              << centred.maxRotationDeg << " deg\n  turn angle from view 0 vs dino_Ps.txt: "
              << "error mean " << turnMean << " deg, max " << turnMax << " deg" << std::endl;
    // The sequence must be reconstructed as a whole with a low reprojection error.
    const double kMaxDinoMedianPx = 0.3;   // measured 0.20; VGG's own cameras: 0.22 (SOURCE.txt)
    const double kMaxDinoRmsPx = 0.5;      // measured 0.36 (before the incremental path: 1.73)
    EXPECT_LE(st.median, kMaxDinoMedianPx);
    EXPECT_LE(st.rms, kMaxDinoRmsPx);
    // The cameras (see above).
    const double kMaxTurnMeanDeg = 1.0;    // measured 0.41 (10 degrees between views)
    const double kMaxTurnDeg = 2.0;        // measured 0.60
    const double kMaxRawMeanDeg = 26.0;    // measured 24.3, the tilt offset above
    const double kMaxCentredMeanDeg = 8.0; // measured 6.5
    EXPECT_LE(turnMean, kMaxTurnMeanDeg);
    EXPECT_LE(turnMax, kMaxTurnDeg);
    EXPECT_LE(cmp.meanRotationDeg, kMaxRawMeanDeg);
    EXPECT_LE(centred.meanRotationDeg, kMaxCentredMeanDeg);
    // A constant offset: the per-view errors spread less than the step between views.
    const double kMaxOffsetSpreadDeg = 2.0;   // measured 0.3 (24.3 mean, 24.6 max)
    EXPECT_LE(cmp.maxRotationDeg - cmp.meanRotationDeg, kMaxOffsetSpreadDeg);
}

// Linear (DLT) points of the dinosaur tracks through dino_Ps (the sign of P does not matter);
// NaN rows where fewer than two views see the track.
Mat triangulateDlt(const Tracks& tracks, const Reconstruction& gt)
{
    Mat X(tracks.points(), 3, CV_64F, Scalar::all(std::numeric_limits<double>::quiet_NaN()));
    for (int p = 0; p < tracks.points(); p++)
    {
        Mat A;
        for (const Camera& cam : gt.cameras)
        {
            if (!tracks.observed(cam.frame, p))
                continue;
            const Matx34d P = cam.projectionMatrix();
            const Point2f q = tracks.at(cam.frame, p);
            for (int a = 0; a < 2; a++)
            {
                const double m = a == 0 ? q.x : q.y;
                Mat row(1, 4, CV_64F);
                for (int c = 0; c < 4; c++)
                    row.at<double>(c) = m * P(2, c) - P(a, c);
                A.push_back(Mat(row / cv::norm(row)));
            }
        }
        if (A.rows < 4)
            continue;
        Mat w, u, vt;
        SVD::compute(A, w, u, vt, SVD::FULL_UV);
        const double h = vt.at<double>(3, 3);
        if (std::abs(h) < 1e-12)
            continue;
        for (int k = 0; k < 3; k++)
            X.at<double>(p, k) = vt.at<double>(3, k) / h;
    }
    return X;
}

// The dinosaur's geometry (its points, dino_Ps' camera centres, the tracks' visibility: 36 views
// over a full turn, 3.3 views per track) imaged by cameras with square pixels and a centred
// principal point, each aimed along dino_Ps' ray through the image centre (f = sqrt(fx fy)),
// 0.2 px noise (the real tracks' median residual). Where the intrinsics are those augocc
// assumes, the turntable is recovered: this separates the method from dino_Ps' calibration
// (measured: noise-free, 2e-5 deg; the same tracks rendered through dino_Ps' own intrinsics
// give the 24 deg elevation offset of the real tracks at a 0.003 px median). The affine path
// followed by the bundle adjustments passes this clean case too (0.08 deg); it is the real
// tracks on which it failed (RMS 1.73 px, 77 deg).
TEST(Augocc_SfmRealData, oxford_dinosaur_geometry_square_pixels)
{
    AUGOCC_REQUIRE_SHARED_DATA(path, "oxford_dinosaur/tracks.yml");
    AUGOCC_REQUIRE_SHARED_DATA(psPath, "oxford_dinosaur/dino_Ps.txt");
    const Tracks tracks = readTracks(path);
    Reconstruction gt;
    ASSERT_TRUE(readDinoCameras(psPath, gt));
    Mat X = triangulateDlt(tracks, gt);
    Vec3d c;
    cv::augocc::detail::rmsRadius(X, &c);
    // Points in front of every camera (P's sign), and a right-handed world (mirror z if the
    // left 3x3 of P then has a negative determinant), then P = K [R | t] by RQ.
    std::vector<Matx34d> P(36);
    for (int f = 0; f < 36; f++)
    {
        P[f] = gt.cameras[f].projectionMatrix();
        if ((P[f] * Vec4d(c[0], c[1], c[2], 1))[2] < 0)
            P[f] = P[f] * -1.0;
    }
    const bool mirror = determinant(P[0].get_minor<3, 3>(0, 0)) < 0;
    const Matx33d Z(1, 0, 0, 0, 1, 0, 0, 0, -1);
    if (mirror)
        for (int p = 0; p < X.rows; p++)
            X.at<double>(p, 2) = -X.at<double>(p, 2);
    const Point2d centre(359.5, 287.5);
    Reconstruction sq;
    sq.model = PERSPECTIVE;
    sq.imageSize = gt.imageSize;
    for (int f = 0; f < 36; f++)
    {
        const Matx33d M = mirror ? P[f].get_minor<3, 3>(0, 0) * Z : P[f].get_minor<3, 3>(0, 0);
        Matx33d K, R;
        decomposeKR(M, K, R);
        ASSERT_GT(determinant(R), 0);
        const Vec3d t = K.inv() * Vec3d(P[f](0, 3), P[f](1, 3), P[f](2, 3));
        K *= 1.0 / K(2, 2);
        Vec3d ray = K.inv() * Vec3d(centre.x, centre.y, 1.0);
        ray /= cv::norm(ray);
        const Vec3d axis = ray.cross(Vec3d(0, 0, 1));
        const double sn = cv::norm(axis);
        Matx33d Ra = Matx33d::eye();
        if (sn > 0)
            Rodrigues(axis * (std::atan2(sn, ray[2]) / sn), Ra);
        const double fl = std::sqrt(K(0, 0) * K(1, 1));
        sq.cameras.push_back(Camera::perspective(Ra * R, Ra * t,
                             Matx33d(fl, 0, centre.x, 0, fl, centre.y, 0, 0, 1), f));
    }
    Mat rendered(tracks.frames(), tracks.points(), CV_32FC2,
                 Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    RNG rng(36);
    const double kNoisePx = 0.2;
    for (int f = 0; f < 36; f++)
        for (int p = 0; p < tracks.points(); p++)
        {
            const double* x = X.ptr<double>(p);
            if (!tracks.observed(f, p) || !std::isfinite(x[0]))
                continue;
            const Vec3d Xw(x[0], x[1], x[2]);
            ASSERT_GT(sq.cameras[f].toCamera(Xw)[2], 0);
            const Point2d q = sq.cameras[f].project(Xw);
            rendered.at<Point2f>(f, p) = Point2f((float)(q.x + rng.gaussian(kNoisePx)),
                                                 (float)(q.y + rng.gaussian(kNoisePx)));
        }
    SfmReport rep;
    const Reconstruction rec = recoverCameras(Tracks::fromDense(tracks.imageSize, rendered),
                                              SfmOptions(), &rep);
    ASSERT_EQ(36, (int)rec.cameras.size());
    const CameraComparison cmp = compareCameras(rec, sq, rec.model == SCALED_ORTHOGRAPHIC);
    std::cout << "oxford_dinosaur geometry, square-pixel cameras, " << kNoisePx << " px noise: "
              << "model " << rep.chosenModel << ", rotation error mean " << cmp.meanRotationDeg
              << " deg, max " << cmp.maxRotationDeg << " deg" << std::endl;
    const double kMaxMeanDeg = 0.5;   // measured 0.084 (seed 36); the noise-free fit: 2e-5
    const double kMaxDeg = 1.0;       // measured 0.28
    EXPECT_LE(cmp.meanRotationDeg, kMaxMeanDeg);
    EXPECT_LE(cmp.maxRotationDeg, kMaxDeg);
}

} // namespace
} // namespace opencv_test
