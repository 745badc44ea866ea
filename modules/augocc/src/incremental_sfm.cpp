// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Incremental scaled-orthographic reconstruction: the missing-data path of FactorizationSfM for
// long sequences whose tracks are short (a turntable seen over a full turn, a long walk).
//
// Why: the affine missing-data fit (alternation, Buchanan & Fitzgibbon 2005) has 8 free parameters
// per frame; when frames are linked only through chains of short overlaps, the affine cameras may
// drift along the chain ("bending": every overlap is fitted, the whole is not a rigid motion), and
// a metric upgrade of the whole cannot undo it. Measured: a synthetic full turn (72 frames, 3-11
// views per track) came out of the factorization with 4.0 deg mean, 10.4 deg max rotation error
// (0.13 / 0.29 deg on this path); on the Oxford dinosaur (36 views over 360 degrees, 3.3 views per
// track) recoverCameras ended 77 deg mean, 178 deg max from VGG's cameras at an RMS of 1.73 px
// (this path: a consistent turn, RMS 0.36 px). Metric cameras (a rotation, a zoom and an image
// translation: 6 parameters) forbid the bending: each new frame is resected as a scaled-
// orthographic camera from the points already triangulated, so the rigidity of the motion is
// imposed at every step, as in incremental SfM (Snavely, Seitz & Szeliski 2006 "Photo tourism";
// Schoenberger & Frahm 2016 "Structure-from-motion revisited", COLMAP), here specialised to scaled
// orthography:
//   1. start: the metric upgrade (Tomasi-Kanade) of the largest complete block after
//      rejection rounds on it, done by the caller (factorization_sfm.cpp);
//   2. triangulate every track seen by two reconstructed frames whose lines of sight differ by
//      at least kMinTriangulationDeg (COLMAP's min_tri_angle: 1.5 degrees) and whose residual is
//      below the inlier threshold;
//   3. resect the frame that sees the most triangulated points: robust Gauss-Newton on
//      (rotation, zoom, translation) started from the affine resection projected on the
//      scaled-orthographic cameras and from the nearest reconstructed frames' poses;
//   4. local bundle adjustment of the last kLocalWindow frames and their points (the other
//      frames held fixed), a global one whenever the reconstruction grew by kGlobalGrowth, with
//      rejection of the tracks whose residual exceeds the robust threshold;
//   5. at the end, every usable track is re-triangulated from the final cameras (rejected ones
//      may come back) and a last global adjustment is run.

#include "precomp.hpp"
#include "sfm_ceres.hpp"
#include "sfm_detail.hpp"
#include "stats.hpp"

#include <deque>
#include <Eigen/Dense>

namespace cv {
namespace augocc {
namespace detail {

namespace {

// A frame is resected from at least this many inlier points (6 unknowns, 2 equations each;
// margin against near-coplanar sets, as the affine resection of the factorization).
const int kMinResectInliers = 6;
// ... and at least this fraction of the points it sees must agree with the pose.
const double kMinResectInlierFraction = 0.5;
// Robust (Huber) scale of the resection and of the bundle adjustments, pixels: the refiner's
// default lossScale.
const double kHuberPx = OrthoCameraRefiner::Params().lossScale;
// Frames adjusted after each resection: the newest few (their points' other frames fixed).
const int kLocalWindow = 6;
// A global adjustment and a rejection round each time the reconstructed frames grew by this
// factor (the geometric schedule of COLMAP's global BA). Measured: 1.25 and 1.5 give the same
// cameras (within 0.01 deg on the dinosaur and the synthetic tests), 1.5 in 25% less time;
// without the intermediate global adjustments (200 frames, 0.25 deg a frame) the error doubled
// and the final adjustment took longer than all of them.
const double kGlobalGrowth = 1.5;
// Iterations of the Gauss-Newton resection and of the adjustments. The global adjustments
// before the last crawl along flat valleys (Oxford dinosaur: 35-39 iterations at 50, 0.1% lower
// cost); capped at 10 they leave the final cameras the same to 0.01 deg at half the run time
// (the last adjustment and recoverCameras' bundle adjustments finish the descent).
const int kResectIterations = 20;
const int kLocalBaIterations = 10;
const int kGlobalBaIterations = 10;
const int kFinalBaIterations = 50;
// Observations per point up to which the adjustments use sparse Cholesky (see bundleAdjust).
const double kNarrowBandObs = 6.0;

inline Vec2d projectView(const OrthoView& v, const Point2d& pp, const double* X)
{
    const Vec3d Y = v.R * Vec3d(X[0], X[1], X[2]);
    return Vec2d(v.s * (Y[0] + v.t[0]) + pp.x, v.s * (Y[1] + v.t[1]) + pp.y);
}

class IncrementalBuilder
{
public:
    IncrementalBuilder(const ObservationIndex& idx, const std::vector<uchar>& usable,
                       const Point2d& pp, double outlierThreshold, double outlierSigmas,
                       std::vector<OrthoView>& views, Mat& X)
        : idx_(idx), usable_(usable), pp_(pp), floor_(outlierThreshold),
          sigmas_(outlierSigmas), views_(views), X_(X)
    {
        rejected_.assign(idx.points, 0);
        failed_.assign(idx.frames, 0);
        thr_ = floor_;
    }

    void run();

private:
    int triangulateNew(bool all);
    bool triangulate(int p, Vec3d& X) const;
    int bestFrame() const;
    bool resect(int f);
    double resectFrom(const std::vector<Vec3d>& Xs, const std::vector<Vec2d>& obs,
                      OrthoView& v) const;
    void bundleAdjust(const std::vector<uchar>& variable, int iterations);
    int rejectTracks();
    int solvedFrames() const
    {
        int n = 0;
        for (const OrthoView& v : views_)
            n += v.solved ? 1 : 0;
        return n;
    }
    bool solvedPoint(int p) const { return std::isfinite(X_.at<double>(p, 0)); }

    const ObservationIndex& idx_;
    const std::vector<uchar>& usable_;
    Point2d pp_;
    double floor_, sigmas_, thr_;
    std::vector<OrthoView>& views_;
    Mat& X_;
    std::vector<uchar> rejected_, failed_;
    std::vector<int> order_;   // frames in the order they were reconstructed
};

// Least squares point from the reconstructed frames that see track p (pixel-weighted linear
// equations: exact for orthographic cameras), if the lines of sight differ enough and every
// observation is within the inlier threshold.
bool IncrementalBuilder::triangulate(int p, Vec3d& X) const
{
    Matx33d N = Matx33d::zeros();
    Vec3d r(0, 0, 0);
    std::vector<Vec3d> dirs;
    for (int k = idx_.pointStart[p]; k < idx_.pointStart[p + 1]; k++)
    {
        const SfmObservation& o = idx_.byFrame[idx_.byPoint[k]];
        const OrthoView& v = views_[o.frame];
        if (!v.solved)
            continue;
        const Vec3d r1(v.R(0, 0), v.R(0, 1), v.R(0, 2)), r2(v.R(1, 0), v.R(1, 1), v.R(1, 2));
        const double s2 = v.s * v.s;
        N += s2 * (r1 * r1.t() + r2 * r2.t());
        r += s2 * (r1 * ((o.u - pp_.x) / v.s - v.t[0]) + r2 * ((o.v - pp_.y) / v.s - v.t[1]));
        dirs.push_back(Vec3d(v.R(2, 0), v.R(2, 1), v.R(2, 2)));
    }
    if (dirs.size() < 2)
        return false;
    double minCos = 1;
    for (size_t a = 0; a < dirs.size(); a++)
        for (size_t b = a + 1; b < dirs.size(); b++)
            minCos = std::min(minCos, std::abs(dirs[a].dot(dirs[b])));
    if (minCos > std::cos(kMinTriangulationDeg * CV_PI / 180))
        return false;
    if (!cv::solve(N, r, X, DECOMP_CHOLESKY))
        return false;
    for (int k = idx_.pointStart[p]; k < idx_.pointStart[p + 1]; k++)
    {
        const SfmObservation& o = idx_.byFrame[idx_.byPoint[k]];
        const OrthoView& v = views_[o.frame];
        if (!v.solved)
            continue;
        const Vec2d q = projectView(v, pp_, X.val);
        if (std::hypot(q[0] - o.u, q[1] - o.v) > thr_)
            return false;
    }
    return true;
}

int IncrementalBuilder::triangulateNew(bool all)
{
    const int P = idx_.points;
    std::vector<uchar> ok(P, 0);
    std::vector<Vec3d> Xs(P);
    parallel_for_(Range(0, P), [&](const Range& range) {
        for (int p = range.start; p < range.end; p++)
            if (usable_[p] && (all || (!rejected_[p] && !solvedPoint(p))))
                ok[p] = triangulate(p, Xs[p]) ? 1 : 0;
    });
    int added = 0;
    for (int p = 0; p < P; p++)
    {
        if (ok[p])
        {
            added += solvedPoint(p) ? 0 : 1;
            rejected_[p] = 0;
            for (int k = 0; k < 3; k++)
                X_.at<double>(p, k) = Xs[p][k];
        }
        else if (all && solvedPoint(p))
        {
            X_.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
            rejected_[p] = 1;
        }
    }
    return added;
}

// The unreconstructed frame that sees the most triangulated points (-1 if none sees enough).
int IncrementalBuilder::bestFrame() const
{
    int best = -1, bestN = kMinResectInliers - 1;
    for (int f = 0; f < idx_.frames; f++)
    {
        if (views_[f].solved || failed_[f])
            continue;
        int n = 0;
        for (int i = idx_.frameStart[f]; i < idx_.frameStart[f + 1]; i++)
            n += solvedPoint(idx_.byFrame[i].point) ? 1 : 0;
        if (n > bestN)
        {
            bestN = n;
            best = f;
        }
    }
    return best;
}

// Robust Gauss-Newton of one scaled-orthographic pose (rotation updated on the left by a
// rotation vector, zoom, translation) from the start in `v`; returns the Huber cost.
double IncrementalBuilder::resectFrom(const std::vector<Vec3d>& Xs,
                                      const std::vector<Vec2d>& obs, OrthoView& v) const
{
    const int n = (int)Xs.size();
    auto cost = [&](const OrthoView& c) {
        double e = 0;
        for (int k = 0; k < n; k++)
        {
            const Vec2d q = projectView(c, pp_, Xs[k].val);
            const double d = std::hypot(q[0] - obs[k][0], q[1] - obs[k][1]);
            e += d <= kHuberPx ? 0.5 * d * d : kHuberPx * (d - 0.5 * kHuberPx);
        }
        return e;
    };
    double c0 = cost(v);
    double lambda = 1e-3;
    for (int it = 0; it < kResectIterations; it++)
    {
        Matx66d H = Matx66d::zeros();
        Vec6d g(0, 0, 0, 0, 0, 0);
        for (int k = 0; k < n; k++)
        {
            const Vec3d Y = v.R * Xs[k];
            const double ru = v.s * (Y[0] + v.t[0]) + pp_.x - obs[k][0];
            const double rv = v.s * (Y[1] + v.t[1]) + pp_.y - obs[k][1];
            const double d = std::hypot(ru, rv);
            const double w = d <= kHuberPx ? 1.0 : kHuberPx / d;
            // d(u, v) / d(omega, s, tx, ty) for R <- exp([omega]x) R.
            const Vec6d ju(0, v.s * Y[2], -v.s * Y[1], Y[0] + v.t[0], v.s, 0);
            const Vec6d jv(-v.s * Y[2], 0, v.s * Y[0], Y[1] + v.t[1], 0, v.s);
            H += w * (ju * ju.t() + jv * jv.t());
            g += w * (ju * ru + jv * rv);
        }
        bool improved = false;
        for (int tries = 0; tries < 10 && !improved; tries++)
        {
            Matx66d Hd = H;
            for (int k = 0; k < 6; k++)
                Hd(k, k) += lambda * std::max(H(k, k), 1e-12);
            Vec6d dx;
            if (!cv::solve(Hd, -g, dx, DECOMP_CHOLESKY))
            {
                lambda *= 10;
                continue;
            }
            OrthoView c = v;
            Matx33d dR;
            Rodrigues(Vec3d(dx[0], dx[1], dx[2]), dR);
            c.R = nearestRotation(dR * v.R);
            c.s = v.s + dx[3];
            c.t = Vec2d(v.t[0] + dx[4], v.t[1] + dx[5]);
            const double c1 = c.s > 0 ? cost(c) : std::numeric_limits<double>::infinity();
            if (c1 < c0)
            {
                improved = true;
                const bool converged = c0 - c1 < 1e-10 * c0;
                v = c;
                c0 = c1;
                lambda = std::max(1e-7, lambda * 0.1);
                if (converged)
                    return c0;
            }
            else
                lambda *= 10;
        }
        if (!improved)
            break;
    }
    return c0;
}

bool IncrementalBuilder::resect(int f)
{
    std::vector<Vec3d> Xs;
    std::vector<Vec2d> obs;
    for (int i = idx_.frameStart[f]; i < idx_.frameStart[f + 1]; i++)
    {
        const SfmObservation& o = idx_.byFrame[i];
        if (!solvedPoint(o.point))
            continue;
        const double* x = X_.ptr<double>(o.point);
        Xs.push_back(Vec3d(x[0], x[1], x[2]));
        obs.push_back(Vec2d(o.u, o.v));
    }
    const int n = (int)Xs.size();
    if (n < kMinResectInliers)
        return false;
    std::vector<OrthoView> starts;
    // Start 1: the affine camera (least squares) projected on the scaled-orthographic ones: the
    // nearest matrix s [r1; r2] with orthonormal rows to its 2x3 part (SVD: s = mean singular
    // value, rows U V^T).
    {
        Matx44d N = Matx44d::zeros();
        Vec4d ru(0, 0, 0, 0), rv(0, 0, 0, 0);
        for (int k = 0; k < n; k++)
        {
            const Vec4d h(Xs[k][0], Xs[k][1], Xs[k][2], 1.0);
            N += h * h.t();
            ru += h * (obs[k][0] - pp_.x);
            rv += h * (obs[k][1] - pp_.y);
        }
        Vec4d a, b;
        if (cv::solve(N, ru, a, DECOMP_SVD) && cv::solve(N, rv, b, DECOMP_SVD))
        {
            const Matx23d A(a[0], a[1], a[2], b[0], b[1], b[2]);
            SVD svd(Mat(A), SVD::FULL_UV);
            const Mat rows = svd.u * svd.vt.rowRange(0, 2);
            const double s = 0.5 * (svd.w.at<double>(0) + svd.w.at<double>(1));
            if (s > 0)
            {
                const Vec3d r1(rows.at<double>(0, 0), rows.at<double>(0, 1),
                               rows.at<double>(0, 2));
                const Vec3d r2(rows.at<double>(1, 0), rows.at<double>(1, 1),
                               rows.at<double>(1, 2));
                const Vec3d r3 = r1.cross(r2);
                OrthoView v;
                v.R = nearestRotation(Matx33d(r1[0], r1[1], r1[2], r2[0], r2[1], r2[2],
                                              r3[0], r3[1], r3[2]));
                v.s = s;
                v.t = Vec2d(a[3] / s, b[3] / s);
                starts.push_back(v);
            }
        }
    }
    // Starts 2, 3: the poses of the nearest reconstructed frames before and after f (the
    // affine start is poor when the points are nearly coplanar), translation re-fitted.
    for (int dir = -1; dir <= 1; dir += 2)
        for (int g = f + dir; g >= 0 && g < idx_.frames; g += dir)
            if (views_[g].solved)
            {
                OrthoView v = views_[g];
                Vec2d m(0, 0);
                for (int k = 0; k < n; k++)
                {
                    const Vec3d Y = v.R * Xs[k];
                    m += Vec2d((obs[k][0] - pp_.x) / v.s - Y[0], (obs[k][1] - pp_.y) / v.s - Y[1]);
                }
                v.t = m * (1.0 / n);
                starts.push_back(v);
                break;
            }
    double best = std::numeric_limits<double>::infinity();
    OrthoView bestView;
    for (OrthoView v : starts)
    {
        const double c = resectFrom(Xs, obs, v);
        if (c < best)
        {
            best = c;
            bestView = v;
        }
    }
    if (!std::isfinite(best))
        return false;
    int inliers = 0;
    for (int k = 0; k < n; k++)
    {
        const Vec2d q = projectView(bestView, pp_, Xs[k].val);
        inliers += std::hypot(q[0] - obs[k][0], q[1] - obs[k][1]) <= thr_ ? 1 : 0;
    }
    if (inliers < kMinResectInliers || inliers < kMinResectInlierFraction * n)
    {
        CV_LOG_DEBUG(NULL, cv::format("augocc sfm: incremental: frame %d: %d of %d points agree "
                     "with its pose", f, inliers, n));
        return false;
    }
    bestView.solved = true;
    views_[f] = bestView;
    return true;
}

// Scaled-orthographic bundle adjustment of the frames flagged `variable` and of every point they
// see; the other reconstructed frames that see those points are held fixed. Gauge: when no fixed
// frame takes part, the first variable frame's rotation and zoom are held.
void IncrementalBuilder::bundleAdjust(const std::vector<uchar>& variable, int iterations)
{
    const int F = idx_.frames, P = idx_.points;
    std::vector<uchar> pointUsed(P, 0);
    for (int f = 0; f < F; f++)
    {
        if (!variable[f] || !views_[f].solved)
            continue;
        for (int i = idx_.frameStart[f]; i < idx_.frameStart[f + 1]; i++)
            if (solvedPoint(idx_.byFrame[i].point))
                pointUsed[idx_.byFrame[i].point] = 1;
    }
    // Every camera's blocks in one buffer, frame by frame (CameraBlocks: q, tx ty, s), so that
    // the blocks' order, and with it the result to the last bit, is the frames'.
    CameraBlocks cam(F, 2, 1);
    auto q = [&](int f) { return cam.q(f); };
    auto t = [&](int f) { return cam.t(f); };
    auto s = [&](int f) { return cam.extra(f); };
    for (int f = 0; f < F; f++)
        if (views_[f].solved)
        {
            cam.setRotation(f, views_[f].R);
            t(f)[0] = views_[f].t[0];
            t(f)[1] = views_[f].t[1];
            *s(f) = views_[f].s;
        }
    Mat X = X_.clone();
    std::deque<OrthoReprojectionCost> costs;   // declared before the problem: outlives it
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    ceres::EigenQuaternionManifold quatManifold;
    ceres::HuberLoss loss(kHuberPx);
    ceres::ParameterBlockOrdering* ordering = new ceres::ParameterBlockOrdering;
    std::vector<uchar> inProblem(F, 0);
    for (int p = 0; p < P; p++)
    {
        if (!pointUsed[p])
            continue;
        for (int k = idx_.pointStart[p]; k < idx_.pointStart[p + 1]; k++)
        {
            const SfmObservation& o = idx_.byFrame[idx_.byPoint[k]];
            if (!views_[o.frame].solved)
                continue;
            costs.emplace_back(o.u, o.v, pp_.x, pp_.y);
            problem.AddResidualBlock(&costs.back(), &loss, q(o.frame), t(o.frame),
                                     s(o.frame), X.ptr<double>(p));
            inProblem[o.frame] = 1;
        }
        ordering->AddElementToGroup(X.ptr<double>(p), 0);
    }
    if (problem.NumResidualBlocks() == 0)
        return;
    std::vector<Vec3d> fixedDirs;
    int firstVar = -1;
    for (int f = 0; f < F; f++)
    {
        if (!inProblem[f])
            continue;
        problem.SetManifold(q(f), &quatManifold);
        ordering->AddElementToGroup(q(f), 1);
        ordering->AddElementToGroup(t(f), 1);
        ordering->AddElementToGroup(s(f), 1);
        if (variable[f])
        {
            if (firstVar < 0)
                firstVar = f;
            continue;
        }
        problem.SetParameterBlockConstant(q(f));
        problem.SetParameterBlockConstant(t(f));
        problem.SetParameterBlockConstant(s(f));
        fixedDirs.push_back(Vec3d(views_[f].R(2, 0), views_[f].R(2, 1), views_[f].R(2, 2)));
    }
    // Gauge (a similarity: 7 degrees of freedom). A fixed frame holds the rotation, the scale and
    // the translation across its line of sight; two fixed frames with distinct lines of sight
    // hold everything. Else: without a fixed frame, the first variable frame's rotation and zoom
    // and the most observed point (the translation); with one, that point's coordinate most
    // along the fixed line of sight (the shift along it, the one freedom left). Exactly the
    // gauge is removed, so the reduced camera system is regular and Cholesky can solve it.
    bool distinct = false;
    for (size_t k = 1; k < fixedDirs.size() && !distinct; k++)
        distinct = std::abs(fixedDirs[k].dot(fixedDirs[0])) <
                   std::cos(kMinTriangulationDeg * CV_PI / 180);
    std::unique_ptr<ceres::SubsetManifold> holdAlong;   // outlives the problem's solve
    if (!distinct && firstVar >= 0)
    {
        int anchor = -1, anchorObs = 0;
        for (int p = 0; p < P; p++)
        {
            if (!pointUsed[p])
                continue;
            int n = 0;
            for (int k = idx_.pointStart[p]; k < idx_.pointStart[p + 1]; k++)
                n += views_[idx_.byFrame[idx_.byPoint[k]].frame].solved ? 1 : 0;
            if (n > anchorObs)
            {
                anchorObs = n;
                anchor = p;
            }
        }
        if (fixedDirs.empty())
        {
            problem.SetParameterBlockConstant(q(firstVar));
            problem.SetParameterBlockConstant(s(firstVar));
            if (anchor >= 0)
                problem.SetParameterBlockConstant(X.ptr<double>(anchor));
        }
        else if (anchor >= 0)
        {
            const Vec3d& d = fixedDirs[0];
            int axis = 0;
            for (int k = 1; k < 3; k++)
                if (std::abs(d[k]) > std::abs(d[axis]))
                    axis = k;
            holdAlong.reset(new ceres::SubsetManifold(3, {axis}));
            problem.SetManifold(X.ptr<double>(anchor), holdAlong.get());
        }
    }
    ceres::Solver::Options o;
    o.minimizer_type = ceres::TRUST_REGION;
    o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    // Linear solver by the width of the band of the reduced camera system (frames overlap their
    // neighbours only, over about a track's length). Short tracks: the band is narrow, exact
    // sparse Cholesky is cheap, while conjugate gradients crawl along the chain of short
    // overlaps (one neighbour per step). Longer tracks: the band fills in and the implicit Schur
    // complement with CG wins (settings of the refiner's adjustments). Measured with 1.5x growth:
    // Oxford dinosaur (3.3 observations per point) sparse 3.1 s, CG 4.6 s for recoverCameras;
    // 120 frames / 200 frames with 24 / 30 observations per point, sparse 7.6 / 12.9 s, CG
    // 4.6 / 6.0 s; 72 frames with 7, 1.4 against 1.2 s.
    const double obsPerPoint = (double)problem.NumResidualBlocks() /
                               std::max(1, (int)std::count(pointUsed.begin(), pointUsed.end(), 1));
    if (obsPerPoint <= kNarrowBandObs)
        o.linear_solver_type = ceres::SPARSE_SCHUR;
    else
    {
        o.linear_solver_type = ceres::ITERATIVE_SCHUR;
        o.preconditioner_type = ceres::JACOBI;
        o.use_explicit_schur_complement = false;
        o.eta = kBundleForcing;
        o.max_linear_solver_iterations = kBundleMaxCgSteps;
    }
    o.linear_solver_ordering.reset(ordering);
    o.max_num_iterations = iterations;
    o.function_tolerance = 1e-6;
    // One thread: the result must not depend on the thread count (FactorizationSfM's contract;
    // the conjugate-gradient reductions would sum in a thread-dependent order), and the
    // problems here are small (36 frames x 5000 tracks: tens of milliseconds an adjustment).
    o.num_threads = 1;
    o.minimizer_progress_to_stdout = false;
    o.logging_type = ceres::SILENT;
    SolverProgress solverProgress(o, "incremental BA");
    ceres::Solver::Summary summary;
    ceres::Solve(o, &problem, &summary);
    if (!summary.IsSolutionUsable())
    {
        CV_LOG_WARNING(NULL, "augocc sfm: incremental bundle adjustment unusable: " +
                       summary.message);
        return;
    }
    for (int f = 0; f < F; f++)
        if (inProblem[f] && variable[f])
        {
            views_[f].R = fromQuaternion(q(f));
            views_[f].t = Vec2d(t(f)[0], t(f)[1]);
            views_[f].s = *s(f);
        }
    for (int p = 0; p < P; p++)
        if (pointUsed[p])
            X.row(p).copyTo(X_.row(p));
}

// Rejects the tracks whose RMS residual exceeds max(floor, sigmas x median), the rule of the
// factorization's rejection rounds; updates the inlier threshold. Returns the count rejected.
int IncrementalBuilder::rejectTracks()
{
    const int P = idx_.points;
    std::vector<double> rms(P, -1);
    parallel_for_(Range(0, P), [&](const Range& range) {
        for (int p = range.start; p < range.end; p++)
        {
            if (!solvedPoint(p))
                continue;
            const double* x = X_.ptr<double>(p);
            double e = 0;
            int n = 0;
            for (int k = idx_.pointStart[p]; k < idx_.pointStart[p + 1]; k++)
            {
                const SfmObservation& o = idx_.byFrame[idx_.byPoint[k]];
                if (!views_[o.frame].solved)
                    continue;
                const Vec2d q = projectView(views_[o.frame], pp_, x);
                e += (q[0] - o.u) * (q[0] - o.u) + (q[1] - o.v) * (q[1] - o.v);
                n++;
            }
            // Corrected for the 3 fitted coordinates (2n equations), as the factorization.
            rms[p] = std::sqrt(e / std::max(0.5, n - 1.5));
        }
    });
    std::vector<double> r;
    for (int p = 0; p < P; p++)
        if (rms[p] >= 0)
            r.push_back(rms[p]);
    if (r.empty())
        return 0;
    thr_ = std::max(floor_, sigmas_ * detail::median(r));
    int n = 0;
    for (int p = 0; p < P; p++)
        if (rms[p] > thr_)
        {
            X_.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
            rejected_[p] = 1;
            n++;
        }
    return n;
}

void IncrementalBuilder::run()
{
    const int F = idx_.frames;
    for (int f = 0; f < F; f++)
        if (views_[f].solved)
            order_.push_back(f);
    std::vector<uchar> all(F, 1);
    bundleAdjust(all, kFinalBaIterations);   // the start: a few frames, converged in full
    rejectTracks();
    int lastGlobal = solvedFrames();
    for (;;)
    {
        if (triangulateNew(false) > 0)
            std::fill(failed_.begin(), failed_.end(), 0);
        const int f = bestFrame();
        if (f < 0)
            break;
        if (!resect(f))
        {
            failed_[f] = 1;
            continue;
        }
        order_.push_back(f);
        std::vector<uchar> window(F, 0);
        for (int k = std::max(0, (int)order_.size() - kLocalWindow); k < (int)order_.size(); k++)
            window[order_[k]] = 1;
        triangulateNew(false);
        bundleAdjust(window, kLocalBaIterations);
        const int n = solvedFrames();
        if (n >= kGlobalGrowth * lastGlobal)
        {
            bundleAdjust(all, kGlobalBaIterations);
            rejectTracks();
            lastGlobal = n;
        }
    }
    bundleAdjust(all, kGlobalBaIterations);
    rejectTracks();
    triangulateNew(true);
    bundleAdjust(all, kFinalBaIterations);
    rejectTracks();
    CV_LOG_INFO(NULL, cv::format("augocc sfm: incremental reconstruction: %d of %d frames, "
                "inlier threshold %.2f px", solvedFrames(), F, thr_));
}

} // namespace

void growIncremental(const ObservationIndex& idx, const std::vector<uchar>& usable,
                     const Point2d& pp, double outlierThreshold, double outlierSigmas,
                     std::vector<OrthoView>& views, Mat& X)
{
    CV_Assert((int)views.size() == idx.frames && (int)usable.size() == idx.points);
    CV_Assert(X.type() == CV_64F && X.rows == idx.points && X.cols == 3);
    IncrementalBuilder(idx, usable, pp, outlierThreshold, outlierSigmas, views, X).run();
}

} // namespace detail
} // namespace augocc
} // namespace cv
