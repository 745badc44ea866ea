// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// No gtest here: the perf suite links this file too.
#include "sfm_test_utils.hpp"

#include <cstring>
#include <opencv2/core.hpp>

namespace opencv_test {

using namespace cv;
using namespace cv::augocc;

SfmProblem makeSfmProblem(const SfmProblemParams& prm)
{
    RNG rng(prm.seed);
    const int F = prm.frames, P = prm.points;
    const double sceneSize = 10.0;
    SfmProblem out;
    Mat X(P, 3, CV_64F);
    for (int p = 0; p < P; p++)
    {
        X.at<double>(p, 0) = rng.uniform(-5.0, 5.0);
        X.at<double>(p, 1) = rng.uniform(-3.0, 3.0);
        X.at<double>(p, 2) = rng.uniform(-5.0, 5.0);
    }
    const Point2d pp((prm.imageSize.width - 1) * 0.5, (prm.imageSize.height - 1) * 0.5);
    const double D = prm.distanceRatio * sceneSize;
    Reconstruction gt;
    gt.model = prm.model;
    gt.imageSize = prm.imageSize;
    for (int f = 0; f < F; f++)
    {
        const double az = (-0.5 + (F > 1 ? (double)f / (F - 1) : 0.0)) * prm.orbitDegrees *
                          CV_PI / 180;
        const double el = prm.elevationDegrees * CV_PI / 180;
        // Camera centre on a sphere; optical axis towards the origin; image y down, world y up.
        const Vec3d C(D * std::cos(el) * std::sin(az), D * std::sin(el),
                      -D * std::cos(el) * std::cos(az));
        const Vec3d z = -C / cv::norm(C);
        Vec3d x = Vec3d(0, 1, 0).cross(z);
        x /= cv::norm(x);
        const Vec3d y = z.cross(x);
        const Matx33d R(x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]);
        const Vec3d t = -(R * C);
        if (prm.model == SCALED_ORTHOGRAPHIC)
            gt.cameras.push_back(Camera::orthographic(R, t, prm.pixelsPerUnit, pp, f));
        else
        {
            const double fl = prm.pixelsPerUnit * D;
            gt.cameras.push_back(Camera::perspective(R, t,
                                 Matx33d(fl, 0, pp.x, 0, fl, pp.y, 0, 0, 1), f));
        }
    }
    gt.points = X.clone();

    // Observation windows.
    std::vector<int> start(P, 0), end(P, F);  // [start, end)
    const int nPartial = cvRound(prm.partialFraction * P);
    const double meanMissing = prm.missingFraction > 0 && nPartial > 0
                                   ? std::min(0.9, prm.missingFraction * P / nPartial) : 0.5;
    for (int p = 0; p < nPartial; p++)
    {
        // Length uniform around (1 - meanMissing) F (or trackFrames), at least 3 frames.
        int len;
        if (prm.trackFrames > 0)
            len = std::max(3, std::min(F, cvRound(rng.uniform(0.5, 1.5) * prm.trackFrames)));
        else
        {
            const double frac = std::min(1.0, std::max(0.05, rng.uniform(0.5, 1.5) *
                                                                 (1.0 - meanMissing)));
            len = std::max(3, std::min(F, cvRound(frac * F)));
        }
        start[p] = rng.uniform(0, F - len + 1);
        end[p] = start[p] + len;
    }
    // Shuffle which tracks are partial so that partial and outlier sets are independent.
    std::vector<int> perm(P);
    for (int p = 0; p < P; p++)
        perm[p] = p;
    for (int p = P - 1; p > 0; p--)
        std::swap(perm[p], perm[rng.uniform(0, p + 1)]);
    std::vector<int> s2(P), e2(P);
    for (int p = 0; p < P; p++)
    {
        s2[perm[p]] = start[p];
        e2[perm[p]] = end[p];
    }
    out.outlier.assign(P, 0);
    const int nOut = cvRound(prm.outlierFraction * P);
    for (int k = 0; k < nOut; k++)
        out.outlier[rng.uniform(0, P)] = 1;

    const float nan = std::numeric_limits<float>::quiet_NaN();
    Mat clean(F, P, CV_32FC2, Scalar::all(nan)), noisy(F, P, CV_32FC2, Scalar::all(nan));
    for (int p = 0; p < P; p++)
    {
        const Vec3d Xp(X.at<double>(p, 0), X.at<double>(p, 1), X.at<double>(p, 2));
        // Outliers: a feature that slides across the image (a T-junction, a reflection): start
        // at the projection of the point, drift with a random velocity of 0.5..3 px per frame
        // plus per-frame jumps.
        Point2d vel(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
        if (std::hypot(vel.x, vel.y) < 0.5)
            vel = Point2d(1.5, -1.0);
        for (int f = s2[p]; f < e2[p]; f++)
        {
            const Point2d q = gt.cameras[f].project(Xp);
            Point2d m = q;
            if (out.outlier[p])
            {
                const Point2d q0 = gt.cameras[s2[p]].project(Xp);
                m = q0 + vel * (f - s2[p]) + Point2d(rng.gaussian(4.0), rng.gaussian(4.0));
            }
            else
            {
                clean.at<Point2f>(f, p) = Point2f((float)q.x, (float)q.y);
                m += Point2d(rng.gaussian(prm.noiseSigma), rng.gaussian(prm.noiseSigma));
            }
            noisy.at<Point2f>(f, p) = Point2f((float)m.x, (float)m.y);
        }
    }
    for (int p = 0; p < P; p++)
        if (out.outlier[p])
            gt.points.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
    out.groundTruth = gt;
    out.tracks = Tracks::fromDense(prm.imageSize, noisy);
    out.cleanTracks = Tracks::fromDense(prm.imageSize, clean);
    return out;
}

namespace {

CameraComparison compareOnce(const Reconstruction& est, const Reconstruction& gt)
{
    CameraComparison c;
    std::vector<std::pair<Matx33d, Matx33d>> pairs;
    for (const Camera& ce : est.cameras)
    {
        const int i = gt.findCamera(ce.frame);
        if (i >= 0)
            pairs.emplace_back(gt.cameras[i].R, ce.R);
    }
    c.frames = (int)pairs.size();
    if (pairs.empty())
        return c;
    // R_est = R_gt * G: G = mean of R_gt^T R_est projected on SO(3).
    Matx33d M = Matx33d::zeros();
    for (const auto& pr : pairs)
        M += pr.first.t() * pr.second;
    Mat w, u, vt;
    SVD::compute(Mat(M), w, u, vt);
    Mat Gm = u * vt;
    if (determinant(Gm) < 0)
    {
        Mat D = Mat::eye(3, 3, CV_64F);
        D.at<double>(2, 2) = -1;
        Gm = u * D * vt;
    }
    const Matx33d G = Matx33d(Gm);
    for (const auto& pr : pairs)
    {
        const double e = rotationAngleDeg(pr.first * G, pr.second);
        c.meanRotationDeg += e / pairs.size();
        c.maxRotationDeg = std::max(c.maxRotationDeg, e);
    }
    return c;
}

} // namespace

CameraComparison compareCameras(const Reconstruction& est, const Reconstruction& gt,
                                bool allowMirror)
{
    CameraComparison a = compareOnce(est, gt);
    if (!allowMirror)
        return a;
    Reconstruction m = est;
    const Matx33d Z(1, 0, 0, 0, 1, 0, 0, 0, -1);
    for (Camera& c : m.cameras)
        c.R = Z * c.R * Z;
    CameraComparison b = compareOnce(m, gt);
    b.mirrored = true;
    return b.meanRotationDeg < a.meanRotationDeg ? b : a;
}

bool identicalWithNan(const Mat& a, const Mat& b)
{
    if (a.size() != b.size() || a.type() != b.type())
        return false;
    const size_t row = a.cols * a.elemSize();
    for (int r = 0; r < a.rows; r++)
        if (std::memcmp(a.ptr(r), b.ptr(r), row) != 0)
            return false;
    return true;
}

LensFigures measureLens(const Reconstruction& est, const Reconstruction& truth)
{
    LensFigures m;
    m.rotationDeg = compareCameras(est, truth, false).meanRotationDeg;
    const Camera& ce = est.cameras.front();
    const Camera& ct = truth.camera(ce.frame);
    if (ce.model == PERSPECTIVE)
        m.focalErrorPct = 100 * std::abs(ce.K(0, 0) / ct.K(0, 0) - 1);
    const Size s = truth.imageSize;
    const Point2d corners[4] = {Point2d(0, 0), Point2d(s.width - 1, 0), Point2d(0, s.height - 1),
                                Point2d(s.width - 1, s.height - 1)};
    for (const Point2d& c : corners)
        m.cornerPx = std::max(m.cornerPx, cv::norm(ce.undistortPixel(c) - ct.undistortPixel(c)));
    return m;
}

} // namespace opencv_test
