// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Camera refinement with Ceres: the paper's 3F+1 Levenberg-Marquardt (Ong, Teh & Tan 1998,
// Section 4), a scaled-orthographic bundle adjustment, and a perspective bundle adjustment
// started from the affine solution; recoverCameras(), the `augocc sfm` pipeline.

#include "precomp.hpp"
#include "ground_plane.hpp"
#include "sfm_ceres.hpp"
#include "sfm_detail.hpp"
#include "stats.hpp"

#include <deque>
#include <Eigen/Geometry>

namespace cv {
namespace augocc {

ReprojectionStats computeReprojectionStats(const Reconstruction& rec, const Tracks& tracks)
{
    ReprojectionStats st;
    if (rec.points.rows != tracks.points())
        CV_Error(Error::StsBadSize, cv::format("reconstruction has %d points, tracks %d",
                 rec.points.rows, tracks.points()));
    std::vector<double> e;
    double s2 = 0;
    for (const Camera& cam : rec.cameras)
    {
        if (cam.frame < 0 || cam.frame >= tracks.frames())
            continue;
        const Range obs = tracks.frame(cam.frame);
        for (int k = obs.start; k < obs.end; k++)
        {
            const int p = tracks.pointOf(tracks.byFrame(k));
            const Point2f o = tracks.uv(tracks.byFrame(k));
            if (!rec.hasPoint(p))
                continue;
            const Point2d q = cam.project(rec.point(p));
            const double d = std::hypot(q.x - o.x, q.y - o.y);
            e.push_back(d);
            s2 += d * d;
        }
    }
    st.observations = (int)e.size();
    if (e.empty())
        return st;
    st.rms = std::sqrt(s2 / e.size());
    st.median = detail::median(e);
    std::sort(e.begin(), e.end());
    st.p95 = e[std::min(e.size() - 1, (size_t)(0.95 * e.size()))];
    return st;
}

namespace {

class OrthoCameraRefinerImpl CV_FINAL : public OrthoCameraRefiner
{
public:
    explicit OrthoCameraRefinerImpl(const Params& p) { setParams(p); }

    Params getParams() const CV_OVERRIDE { return params_; }

    void setParams(const Params& p) CV_OVERRIDE
    {
        if (p.mode < POSITION_ZOOM || p.mode > PERSPECTIVE_BA)
            CV_Error(Error::StsBadArg, cv::format("OrthoCameraRefiner: unknown mode %d", p.mode));
        if (p.loss < LOSS_NONE || p.loss > LOSS_CAUCHY)
            CV_Error(Error::StsBadArg, cv::format("OrthoCameraRefiner: unknown loss %d", p.loss));
        if (!(p.lossScale > 0) || p.maxIterations < 1 || !(p.functionTolerance > 0))
            CV_Error(Error::StsBadArg, "OrthoCameraRefiner: lossScale and functionTolerance "
                     "must be positive, maxIterations >= 1");
        params_ = p;
    }

    bool refine(const Tracks& tracks, Reconstruction& rec) const CV_OVERRIDE;

private:
    void fillOptions(ceres::Solver::Options& o, bool bundle = false) const
    {
        o.minimizer_type = ceres::TRUST_REGION;
        o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
        o.linear_solver_type = ceres::DENSE_SCHUR;
        o.max_num_iterations = params_.maxIterations;
        o.function_tolerance = params_.functionTolerance;
        // One thread: with two, Ceres' sums over the threads' residual blocks made `augocc sfm`
        // on the same tracks differ in the cameras' last digits from run to run; with one the
        // runs match bit for bit, at any OpenCV thread count. On 2 cores the threads gained
        // nothing measurable (perf, 100 frames x 1000 tracks: full BA 131 / 138 ms, perspective
        // BA 376 / 376 ms with two / one).
        o.num_threads = 1;
        o.minimizer_progress_to_stdout = false;
        o.logging_type = ceres::SILENT;
        if (bundle)
        {
            // Bundle adjustment: every camera sees most points, so the reduced camera system
            // is dense and forming it costs points x cameras^2 blocks (seconds at 100 x 1000);
            // the implicit Schur complement with conjugate gradients costs one pass over the
            // observations per CG step.
            o.linear_solver_type = ceres::ITERATIVE_SCHUR;
            // JACOBI measured 4x faster than SCHUR_JACOBI here (100 x 1000, same final cost).
            o.preconditioner_type = ceres::JACOBI;
            o.use_explicit_schur_complement = false;
            // Newton steps solved to 0.1% (Ceres' default forcing term is 10%): started from
            // the factorization, two such steps reach the optimum, where 10% steps crawled for
            // five (100 x 1000: 5 -> 3 Jacobian evaluations for a few more cheap CG steps).
            o.eta = detail::kBundleForcing;
            o.max_linear_solver_iterations = detail::kBundleMaxCgSteps;
        }
    }

    ceres::LossFunction* makeLoss() const
    {
        switch (params_.loss)
        {
        case LOSS_HUBER: return new ceres::HuberLoss(params_.lossScale);
        case LOSS_CAUCHY: return new ceres::CauchyLoss(params_.lossScale);
        default: return nullptr;
        }
    }

    bool refinePositionZoom(const Tracks& tracks, Reconstruction& rec) const;
    bool refineOrthoBA(const Tracks& tracks, Reconstruction& rec) const;
    bool refinePerspective(const Tracks& tracks, Reconstruction& rec, double* cost) const;

    Params params_;
};

void checkInput(const Tracks& tracks, const Reconstruction& rec)
{
    tracks.validate("tracks");
    if (rec.cameras.empty())
        CV_Error(Error::StsBadArg, "reconstruction: no camera to refine");
    if (rec.points.rows != tracks.points() || rec.points.cols != 3 ||
        rec.points.type() != CV_64F)
        CV_Error(Error::StsBadSize, cv::format("reconstruction: points must be %d x 3 CV_64F "
                 "(one row per track), got %d x %d %s", tracks.points(), rec.points.rows,
                 rec.points.cols, typeToString(rec.points.type()).c_str()));
    for (const Camera& c : rec.cameras)
    {
        if (c.frame < 0 || c.frame >= tracks.frames())
            CV_Error(Error::StsBadArg, cv::format("reconstruction: camera of frame %d, tracks "
                     "have %d frames", c.frame, tracks.frames()));
        if (c.model != rec.model)
            CV_Error(Error::StsBadArg, "reconstruction: cameras mix camera models");
    }
}

// Visits every observation of a reconstructed point (rec.hasPoint), point by point: the order in
// which the Schur elimination visits the residual blocks, so that Ceres' blocks and the costs lie
// in memory in the order they are used. fn(i, p, o, pp) gets the camera index, the point, the
// observation and the camera's principal point; used (one flag per row of rec.points) is set for
// every point with an observation.
template <typename Fn>
void forEachObservationPointMajor(const Tracks& tracks, const Reconstruction& rec,
                                  std::vector<uchar>& used, Fn fn)
{
    const int n = (int)rec.cameras.size();
    std::vector<Point2d> pp(n);
    for (int i = 0; i < n; i++)
        pp[i] = rec.cameras[i].principalPoint();
    used.assign(rec.points.rows, 0);
    // Cameras are in increasing frame order, as are a track's observations.
    std::vector<int> cameraOf(tracks.frames(), -1);
    for (int i = 0; i < n; i++)
        cameraOf[rec.cameras[i].frame] = i;
    for (int p = 0; p < rec.points.rows; p++)
    {
        if (!rec.hasPoint(p))
            continue;
        const Range obs = tracks.track(p);
        for (int k = obs.start; k < obs.end; k++)
        {
            const int i = cameraOf[tracks.frameOf(k)];
            if (i < 0)
                continue;
            fn(i, p, tracks.uv(k), pp[i]);
            used[p] = 1;
        }
    }
}

bool solverUsable(const ceres::Solver::Summary& summary, const char* what)
{
    if (!summary.IsSolutionUsable())
    {
        CV_LOG_WARNING(NULL, cv::format("augocc sfm: %s: Ceres solution unusable: %s", what,
                       summary.message.c_str()));
        return false;
    }
    CV_LOG_INFO(NULL, cv::format("augocc sfm: %s: cost %.6g -> %.6g in %d iterations", what,
                summary.initial_cost, summary.final_cost,
                (int)summary.iterations.size()));
    return true;
}

bool OrthoCameraRefinerImpl::refinePositionZoom(const Tracks& tracks, Reconstruction& rec) const
{
    const int n = (int)rec.cameras.size();
    std::vector<Vec3d> t(n);
    double s = 0;
    for (int i = 0; i < n; i++)
    {
        t[i] = rec.cameras[i].t;
        s += rec.cameras[i].s;
    }
    s /= n;
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    // tz does not change the image under orthography: held at its input value (a gauge).
    ceres::SubsetManifold holdZ(3, {2});
    ceres::ParameterBlockOrdering* ordering = new ceres::ParameterBlockOrdering;
    int residualBlocks = 0;
    for (int i = 0; i < n; i++)
    {
        const Camera& cam = rec.cameras[i];
        const Range obs = tracks.frame(cam.frame);
        std::vector<double> rotated, observed;
        for (int k = obs.start; k < obs.end; k++)
        {
            const int p = tracks.pointOf(tracks.byFrame(k));
            const Point2f o = tracks.uv(tracks.byFrame(k));
            if (!rec.hasPoint(p))
                continue;
            const Vec3d Xc = cam.R * rec.point(p);
            rotated.push_back(Xc[0]);
            rotated.push_back(Xc[1]);
            observed.push_back(o.x);
            observed.push_back(o.y);
        }
        if (observed.empty())
            continue;
        const Point2d pp = cam.principalPoint();
        problem.AddResidualBlock(new detail::PositionZoomCost(std::move(rotated),
                                 std::move(observed), pp.x, pp.y), nullptr, t[i].val, &s);
        problem.SetManifold(t[i].val, &holdZ);
        ordering->AddElementToGroup(t[i].val, 0);
        residualBlocks++;
    }
    if (residualBlocks == 0)
        CV_Error(Error::StsBadArg, "reconstruction: no observation of a reconstructed point");
    ordering->AddElementToGroup(&s, 1);
    ceres::Solver::Options options;
    fillOptions(options);
    options.linear_solver_ordering.reset(ordering);
    detail::SolverProgress solverProgress(options, "3F+1 refinement");
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (!solverUsable(summary, "3F+1 refinement") || !(s > 0))
        return false;
    for (int i = 0; i < n; i++)
    {
        rec.cameras[i].t = t[i];
        rec.cameras[i].s = s;
    }
    return true;
}

// Problem options of the bundle adjustments: 100k residual blocks and more, built by this file
// (parameter blocks of consistent sizes, each residual block's blocks distinct), so Ceres' checks
// of every AddResidualBlock are skipped; the cost functions live in a deque owned by the caller
// (Ceres' ownership bookkeeping is a map insertion per residual block).
ceres::Problem::Options bundleProblemOptions()
{
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.disable_all_safety_checks = true;
    return po;
}

bool OrthoCameraRefinerImpl::refineOrthoBA(const Tracks& tracks, Reconstruction& rec) const
{
    const int n = (int)rec.cameras.size(), P = tracks.points();
    detail::CameraBlocks cams(n, 2, 1);  // q, (tx, ty), s
    double sGlobal = 0;
    for (int i = 0; i < n; i++)
    {
        cams.setRotation(i, rec.cameras[i].R);
        cams.t(i)[0] = rec.cameras[i].t[0];
        cams.t(i)[1] = rec.cameras[i].t[1];
        *cams.extra(i) = rec.cameras[i].s;
        sGlobal += rec.cameras[i].s / n;
    }
    Mat X = rec.points.clone();
    std::deque<detail::OrthoReprojectionCost> costs;  // declared before the problem: outlives it
    ceres::Problem problem(bundleProblemOptions());
    ceres::EigenQuaternionManifold quatManifold;
    std::unique_ptr<ceres::LossFunction> loss(makeLoss());
    ceres::ParameterBlockOrdering* ordering = new ceres::ParameterBlockOrdering;
    std::vector<uchar> used;
    forEachObservationPointMajor(tracks, rec, used,
                                 [&](int i, int p, const Point2f& o, const Point2d& pp) {
        costs.emplace_back(o.x, o.y, pp.x, pp.y);
        problem.AddResidualBlock(&costs.back(), loss.get(), cams.q(i), cams.t(i),
                                 params_.perFrameScale ? cams.extra(i) : &sGlobal,
                                 X.ptr<double>(p));
    });
    for (int i = 0; i < n; i++)
    {
        if (problem.HasParameterBlock(cams.q(i)))
        {
            problem.SetManifold(cams.q(i), &quatManifold);
            ordering->AddElementToGroup(cams.q(i), 1);
            ordering->AddElementToGroup(cams.t(i), 1);
            if (params_.perFrameScale)
                ordering->AddElementToGroup(cams.extra(i), 1);
        }
    }
    if (problem.NumResidualBlocks() == 0)
        CV_Error(Error::StsBadArg, "reconstruction: no observation of a reconstructed point");
    // Gauge: the first camera's rotation and the zoom (global, or the first camera's).
    problem.SetParameterBlockConstant(cams.q(0));
    if (params_.perFrameScale)
        problem.SetParameterBlockConstant(cams.extra(0));
    else
    {
        ordering->AddElementToGroup(&sGlobal, 1);
        problem.SetParameterBlockConstant(&sGlobal);
    }
    for (int p = 0; p < P; p++)
        if (used[p])
            ordering->AddElementToGroup(X.ptr<double>(p), 0);
    ceres::Solver::Options options;
    fillOptions(options, true);
    options.linear_solver_ordering.reset(ordering);
    detail::SolverProgress solverProgress(options, "scaled-orthographic BA");
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (!solverUsable(summary, "scaled-orthographic bundle adjustment"))
        return false;
    // Back, with the points re-centred on their centroid (a translation gauge).
    for (int p = 0; p < P; p++)
        if (!used[p])
            X.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
    Vec3d c;
    detail::rmsRadius(X, &c);
    for (int p = 0; p < P; p++)
        if (used[p])
            for (int k = 0; k < 3; k++)
                X.at<double>(p, k) -= c[k];
    for (int i = 0; i < n; i++)
    {
        Camera& cam = rec.cameras[i];
        cam.R = cams.rotation(i);
        const Vec3d Rc = cam.R * c;
        cam.t = Vec3d(cams.t(i)[0] + Rc[0], cams.t(i)[1] + Rc[1], cam.t[2]);
        cam.s = params_.perFrameScale ? *cams.extra(i) : sGlobal;
    }
    rec.points = X;
    return true;
}

// Perspective bundle adjustment in the perspective-strength form (sfm_ceres.hpp): one zoom s
// at the reference depth, one inverse reference depth kappa, per-frame rotation and translation
// (t.z relative to the reference depth), points. Started from kappa = 0 (the orthographic
// solution, or the pinhole input converted), so that the orthographic optimum is the start and
// the perspective effects pull kappa away from it; a negative kappa at the end is the mirror
// twin of the solution and is flipped.
bool OrthoCameraRefinerImpl::refinePerspective(const Tracks& tracks, Reconstruction& rec,
                                               double* finalCost) const
{
    const int n = (int)rec.cameras.size(), P = tracks.points();
    Vec3d c;
    const double radius = detail::rmsRadius(rec.points, &c);
    if (!(radius > 0))
        CV_Error(Error::StsBadArg, "reconstruction: no finite point to refine");
    Mat X = rec.points.clone();
    for (int p = 0; p < P; p++)
        if (rec.hasPoint(p))
            for (int k = 0; k < 3; k++)
                X.at<double>(p, k) -= c[k];
    detail::CameraBlocks cams(n, 3);  // q, t
    double s = 0, kappa = 0;
    double D0 = 0;
    if (rec.model == PERSPECTIVE)
    {
        const Camera& c0 = rec.cameras[0];
        D0 = (c0.R * c + c0.t)[2];
        if (!(D0 > 0))
            CV_Error(Error::StsBadArg, "reconstruction: the points' centroid is behind the "
                     "first camera");
        kappa = 1.0 / D0;
    }
    for (int i = 0; i < n; i++)
    {
        const Camera& cam = rec.cameras[i];
        cams.setRotation(i, cam.R);
        const Vec3d Rc = cam.R * c;
        Vec3d ti;
        if (rec.model == PERSPECTIVE)
        {
            ti = cam.t + Rc - Vec3d(0, 0, D0);
            s += 0.5 * (cam.K(0, 0) + cam.K(1, 1)) * kappa / n;
        }
        else
        {
            ti = Vec3d(cam.t[0] + Rc[0], cam.t[1] + Rc[1], 0.0);
            s += cam.s / n;
        }
        std::copy(ti.val, ti.val + 3, cams.t(i));
    }
    std::deque<detail::PerspectiveStrengthCost> costs;  // declared before the problem
    ceres::Problem problem(bundleProblemOptions());
    ceres::EigenQuaternionManifold quatManifold;
    std::unique_ptr<ceres::LossFunction> loss(makeLoss());
    ceres::ParameterBlockOrdering* ordering = new ceres::ParameterBlockOrdering;
    std::vector<uchar> used;
    forEachObservationPointMajor(tracks, rec, used,
                                 [&](int i, int p, const Point2f& o, const Point2d& pp) {
        costs.emplace_back(o.x, o.y, pp.x, pp.y);
        problem.AddResidualBlock(&costs.back(), loss.get(), cams.q(i), cams.t(i), &s,
                                 &kappa, X.ptr<double>(p));
    });
    for (int i = 0; i < n; i++)
    {
        if (problem.HasParameterBlock(cams.q(i)))
        {
            problem.SetManifold(cams.q(i), &quatManifold);
            ordering->AddElementToGroup(cams.q(i), 1);
            ordering->AddElementToGroup(cams.t(i), 1);
        }
    }
    if (problem.NumResidualBlocks() == 0)
        CV_Error(Error::StsBadArg, "reconstruction: no observation of a reconstructed point");
    ordering->AddElementToGroup(&s, 1);
    ordering->AddElementToGroup(&kappa, 1);
    // Gauge (similarity, 7 dof): the first camera's rotation and translation, and the zoom.
    problem.SetParameterBlockConstant(cams.q(0));
    problem.SetParameterBlockConstant(cams.t(0));
    problem.SetParameterBlockConstant(&s);
    for (int p = 0; p < P; p++)
        if (used[p])
            ordering->AddElementToGroup(X.ptr<double>(p), 0);
    ceres::Solver::Options options;
    fillOptions(options, true);
    options.linear_solver_ordering.reset(ordering);
    detail::SolverProgress solverProgress(options, "perspective BA");
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (!solverUsable(summary, "perspective bundle adjustment") || !std::isfinite(kappa))
        return false;
    if (finalCost)
        *finalCost = summary.final_cost;
    const Matx33d Z(1, 0, 0, 0, 1, 0, 0, 0, -1);
    const bool mirror = kappa < 0;
    if (mirror)
        kappa = -kappa;
    // A camera farther than this many scene radii is orthographic for any practical purpose;
    // kappa is floored there so that the pinhole stays finite.
    const double kMaxDistanceRatio = 1e4;
    if (kappa < 1.0 / (kMaxDistanceRatio * radius))
    {
        CV_LOG_INFO(NULL, "augocc sfm: no measurable perspective: the camera is placed at "
                    "1e4 scene radii");
        kappa = 1.0 / (kMaxDistanceRatio * radius);
    }
    D0 = 1.0 / kappa;
    const double f = s * D0;
    for (int p = 0; p < P; p++)
    {
        if (!used[p])
        {
            X.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
            continue;
        }
        if (mirror)
            X.at<double>(p, 2) = -X.at<double>(p, 2);
    }
    for (int i = 0; i < n; i++)
    {
        Camera& cam = rec.cameras[i];
        const Point2d pp = cam.principalPoint();
        Matx33d R = cams.rotation(i);
        Vec3d ti(cams.t(i)[0], cams.t(i)[1], cams.t(i)[2]);
        if (mirror)
        {
            R = Z * R * Z;
            ti[2] = -ti[2];
        }
        cam = Camera::perspective(R, ti + Vec3d(0, 0, D0),
                                  Matx33d(f, 0, pp.x, 0, f, pp.y, 0, 0, 1), cam.frame);
    }
    rec.model = PERSPECTIVE;
    rec.points = X;
    return true;
}

bool OrthoCameraRefinerImpl::refine(const Tracks& tracks, Reconstruction& rec) const
{
    checkInput(tracks, rec);
    Reconstruction work = rec;
    bool ok = false;
    if (params_.mode == PERSPECTIVE_BA)
    {
        ok = refinePerspective(tracks, work, nullptr);
    }
    else
    {
        if (rec.model != SCALED_ORTHOGRAPHIC)
            CV_Error(Error::StsBadArg, "OrthoCameraRefiner: POSITION_ZOOM and FULL_BA need a "
                     "scaled_orthographic reconstruction");
        ok = params_.mode == POSITION_ZOOM ? refinePositionZoom(tracks, work)
                                           : refineOrthoBA(tracks, work);
    }
    if (!ok)
        return false;
    rec = work;
    return true;
}

} // namespace

Ptr<OrthoCameraRefiner> OrthoCameraRefiner::create(const Params& params)
{
    return makePtr<OrthoCameraRefinerImpl>(params);
}

Ptr<OrthoCameraRefiner> OrthoCameraRefiner::create()
{
    return create(Params());
}

namespace {

// The depth-reversal prior of recoverCameras(). Plane inliers lie within kPlaneBand x the points'
// RMS radius of the plane (the ground of a SceneSynthesizer scene: ~40% of the tracks at 0.5 px
// noise); points beyond 3 bands count as off the plane; the prior needs kMinOffPlane of them.
// RANSAC over kPlaneTrials triples (fixed seed: deterministic) finds the dominant plane.
const double kPlaneBand = 0.02;
const int kPlaneTrials = 300;
const double kMinOffPlane = 0.05;

// Fraction of the points off the dominant plane that lie on the side of the first camera, or
// -1 when there is no dominant plane with enough points off it.
double frontOfDominantPlane(const Reconstruction& rec)
{
    const Matx33d R = rec.cameras.front().R;
    std::vector<Vec3d> P;
    Vec3d m(0, 0, 0);
    for (int i = 0; i < rec.points.rows; i++)
    {
        if (!rec.hasPoint(i))
            continue;
        P.push_back(R * rec.point(i));   // first camera's axes: it looks along +z
        m += P.back();
    }
    const int N = (int)P.size();
    if (N < 10)
        return -1;
    m *= 1.0 / N;
    double r2 = 0;
    for (const Vec3d& p : P)
        r2 += (p - m).dot(p - m);
    const double band = kPlaneBand * std::sqrt(r2 / N);
    const detail::PlaneFit plane = detail::ransacPlane(P, P, band, kPlaneTrials, 0x2545F491);
    if (plane.inliers < 3)
        return -1;
    Vec3d bestN = plane.normal;
    double bestD = plane.offset;
    if (bestN[2] > 0)   // normal towards the camera
    {
        bestN = -bestN;
        bestD = -bestD;
    }
    int off = 0, front = 0;
    for (const Vec3d& p : P)
    {
        const double dist = bestN.dot(p) - bestD;
        if (std::abs(dist) > 3 * band)
        {
            off++;
            front += dist > 0;
        }
    }
    if (off < kMinOffPlane * N)
        return -1;
    return (double)front / off;
}

} // namespace

namespace {

/* The camera of each frame of `tracks` (nullptr where the reconstruction has none). */
std::vector<const Camera*> camerasByFrame(const Tracks& tracks, const Reconstruction& rec)
{
    std::vector<const Camera*> cameraOf(tracks.frames(), nullptr);
    for (const Camera& c : rec.cameras)
        if (c.frame >= 0 && c.frame < tracks.frames())
            cameraOf[c.frame] = &c;
    return cameraOf;
}

/* Largest angle between the lines of sight from perspective cameras to X, radians (0 for
fewer than two): the two-sweep estimate (the direction farthest from the first, then the
farthest from that one), at least half the true largest angle and exact for centres on a line. */
double triangulationAngle(const Vec3d& X, const std::vector<const Camera*>& cams)
{
    std::vector<Vec3d> dirs;
    dirs.reserve(cams.size());
    for (const Camera* c : cams)
    {
        const Vec3d d = X - c->center();
        const double n = cv::norm(d);
        if (n > 0)
            dirs.push_back(d / n);
    }
    if (dirs.size() < 2)
        return 0;
    auto angle = [](const Vec3d& a, const Vec3d& b) {
        return std::atan2(cv::norm(a.cross(b)), a.dot(b));
    };
    size_t far = 0;
    double best = -1;
    for (size_t k = 0; k < dirs.size(); k++)
    {
        const double a = angle(dirs[0], dirs[k]);
        if (a > best)
        {
            best = a;
            far = k;
        }
    }
    double largest = 0;
    for (const Vec3d& d : dirs)
        largest = std::max(largest, angle(dirs[far], d));
    return largest;
}

// Tracks the factorization rejected are triangulated again with the final cameras and kept when
// these explain them: at least kRescueMinViews frames, reprojection RMS within kRescueRmsPx and
// every observation within kRescueMaxPx, in front of every perspective camera and seen under at
// least detail::kMinTriangulationDeg (see dropUnmeasuredDepths). The factorization
// judges tracks against the affine model of its first stage; under perspective (hand-held
// footage near the buildings) some good tracks fit it badly and were dropped, while tracks that
// slide along an occluding contour fit no camera and stay out. Measured on the perspective demo
// (distance 3): 41 of 92 rejected tracks back, on the L-block's inner walls among others, where
// free-space carving needs them; on the orthographic demo none of the 79 (all slide).
const int kRescueMinViews = 3;
const double kRescueRmsPx = 1.0;
const double kRescueMaxPx = 2.0;

int rescueTracks(const Tracks& tracks, Reconstruction& rec)
{
    const int P = rec.points.rows;
    std::vector<uchar> ok(P, 0);
    const std::vector<const Camera*> cameraOf = camerasByFrame(tracks, rec);
    parallel_for_(Range(0, P), [&](const Range& r) {
        for (int p = r.start; p < r.end; p++)
        {
            if (rec.hasPoint(p))
                continue;
            double* X = rec.points.ptr<double>(p);
            std::vector<const Camera*> cams;
            std::vector<Point2d> obs;
            const Range seen = tracks.track(p);  // frames increasing, as the cameras
            for (int k = seen.start; k < seen.end; k++)
                if (const Camera* c = cameraOf[tracks.frameOf(k)])
                {
                    const Point2f o = tracks.uv(k);
                    cams.push_back(c);
                    obs.push_back(Point2d(o.x, o.y));
                }
            if ((int)cams.size() < kRescueMinViews)
                continue;
            Vec3d Y;
            // Triangulated through the pinholes on the undistorted observations (the
            // triangulation's equations are those of the pinhole); judged with the lens below.
            std::vector<Camera> pinholes;
            std::vector<const Camera*> pinholePtrs;
            std::vector<Point2d> ideal;
            if (!cams.empty() && cams.front()->hasDistortion())
            {
                for (size_t k = 0; k < cams.size(); k++)
                {
                    pinholes.push_back(cams[k]->pinhole());
                    ideal.push_back(cams[k]->undistortPixel(obs[k]));
                }
                for (const Camera& c : pinholes)
                    pinholePtrs.push_back(&c);
            }
            if (!(pinholes.empty() ? detail::triangulatePoint(cams, obs, Y)
                                   : detail::triangulatePoint(pinholePtrs, ideal, Y)))
                continue;
            double s2 = 0, worst = 0;
            bool front = true;
            for (size_t k = 0; k < cams.size() && front; k++)
            {
                front = cams[k]->model != PERSPECTIVE || cams[k]->depth(Y) > 0;
                const double e = cv::norm(cams[k]->project(Y) - obs[k]);
                s2 += e * e;
                worst = std::max(worst, e);
            }
            // The angle last: it is the costliest test.
            if (front && std::sqrt(s2 / cams.size()) <= kRescueRmsPx && worst <= kRescueMaxPx &&
                (cams.front()->model != PERSPECTIVE ||
                 triangulationAngle(Y, cams) >= detail::kMinTriangulationDeg * CV_PI / 180))
            {
                for (int k = 0; k < 3; k++)
                    X[k] = Y[k];
                ok[p] = 1;
            }
        }
    });
    const int n = (int)std::count(ok.begin(), ok.end(), (uchar)1);
    if (n > 0)
        CV_LOG_INFO(NULL, cv::format("augocc sfm: %d rejected tracks explained by the final "
                    "cameras kept", n));
    return n;
}

} // namespace

namespace {

// ---------------------------------------------------------------------------------------------
// Lens bundle adjustment: the pinhole with OpenCV's distortion on the frames' own pixels.

//! What the lens bundle adjustment refines besides poses and points.
struct LensFreedom
{
    bool focal = false;             //!< the focal length (fx; fy / fx kept)
    std::vector<int> coefficients;  //!< indices (0..11) into the 12 distortion terms refined
};

// The tilt homography (coefficients tx, ty of a 14-coefficient lens) as a 3x3 matrix, from the
// camera model itself: the distortion with only tx, ty set is that homography of the
// normalised point, so four points determine it exactly.
Matx33d tiltHomography(const std::vector<double>& d)
{
    if (d.size() < 14 || (d[12] == 0 && d[13] == 0))
        return Matx33d::eye();
    Camera c = Camera::perspective(Matx33d::eye(), Vec3d(0, 0, 0), Matx33d::eye());
    c.distortion.assign(14, 0.0);
    c.distortion[12] = d[12];
    c.distortion[13] = d[13];
    std::vector<Point2f> a = {Point2f(-0.5f, -0.5f), Point2f(0.5f, -0.5f), Point2f(0.5f, 0.5f),
                              Point2f(-0.5f, 0.5f)}, b;
    for (const Point2f& p : a)
        b.push_back(Point2f(c.distortNormalized(Point2d(p))));
    Matx33d H = getPerspectiveTransform(a, b);
    return H * (1.0 / H(2, 2));
}

// The pixel (u, v) of every observation of a reconstructed point in every reconstructed frame,
// with its residual under `rec`.
double sumSquaredResiduals(const Tracks& tracks, const Reconstruction& rec,
                           const std::vector<uchar>* inlier, double inlierPx,
                           std::vector<uchar>* inlierOut, int* count)
{
    double rss = 0;
    int n = 0;
    size_t k = 0;
    if (inlierOut)
        inlierOut->clear();
    for (const Camera& cam : rec.cameras)
    {
        const Range obs = tracks.frame(cam.frame);
        for (int j = obs.start; j < obs.end; j++)
        {
            const int p = tracks.pointOf(tracks.byFrame(j));
            const Point2f o = tracks.uv(tracks.byFrame(j));
            if (!rec.hasPoint(p))
                continue;
            const Point2d e = cam.project(rec.point(p)) - Point2d(o.x, o.y);
            const double e2 = e.dot(e);
            const bool in = inlier ? (*inlier)[k] != 0 : e2 <= inlierPx * inlierPx;
            if (inlierOut)
                inlierOut->push_back(in);
            k++;
            if (!in)
                continue;
            rss += e2;
            n += 2;
        }
    }
    if (count)
        *count = n;
    return rss;
}

/** Bundle adjustment of the perspective cameras of `rec` (one K and one distortion for all of
them: the first camera's) on the observations of `tracks`, pixels of the frames. Poses
(quaternion manifold) and points always; the focal and distortion terms of `freedom`. Gauge: the
first camera's pose, and the scale by one coordinate of the camera farthest from it (the one that
scaling about the first camera's centre moves most). `focalRelStd`, when not null, gets the
relative standard deviation of the focal (ceres::Covariance, residuals scaled to the RMS;
-1 when it cannot be computed). Returns false (logged) when Ceres fails. */
bool adjustLens(const Tracks& tracks, Reconstruction& rec, const LensFreedom& freedom,
                const OrthoCameraRefiner::Params& params, double* focalRelStd,
                bool solve = true)
{
    const int n = (int)rec.cameras.size(), P = tracks.points();
    CV_Assert(rec.model == PERSPECTIVE && n >= 2);
    const Camera& c0 = rec.cameras[0];
    double intr[3] = {c0.K(0, 0), c0.K(0, 2), c0.K(1, 2)};
    const double aspect = c0.K(1, 1) / c0.K(0, 0), skew = c0.K(0, 1) / c0.K(0, 0);
    double dist[12] = {0};
    for (size_t k = 0; k < std::min<size_t>(12, c0.distortion.size()); k++)
        dist[k] = c0.distortion[k];
    const Matx33d tilt = tiltHomography(c0.distortion);
    // Every pose in one buffer (detail::CameraBlocks: the blocks' order is the cameras').
    detail::CameraBlocks poses(n, 3);
    auto qd = [&](int i) { return poses.q(i); };
    auto td = [&](int i) { return poses.t(i); };
    for (int i = 0; i < n; i++)
    {
        poses.setRotation(i, rec.cameras[i].R);
        std::copy(rec.cameras[i].t.val, rec.cameras[i].t.val + 3, td(i));
    }
    Mat X = rec.points.clone();
    ceres::Problem::Options po;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    ceres::EigenQuaternionManifold quatManifold;
    std::unique_ptr<ceres::LossFunction> loss;
    if (params.loss == OrthoCameraRefiner::LOSS_HUBER)
        loss.reset(new ceres::HuberLoss(params.lossScale));
    else if (params.loss == OrthoCameraRefiner::LOSS_CAUCHY)
        loss.reset(new ceres::CauchyLoss(params.lossScale));
    ceres::ParameterBlockOrdering* ordering = new ceres::ParameterBlockOrdering;
    std::vector<uchar> used;
    forEachObservationPointMajor(tracks, rec, used,
                                 [&](int i, int p, const Point2f& o, const Point2d&) {
        problem.AddResidualBlock(detail::LensReprojectionError::Create(o.x, o.y, aspect, skew,
                                 tilt), loss.get(), qd(i), td(i),
                                 X.ptr<double>(p), intr, dist);
    });
    if (problem.NumResidualBlocks() == 0)
        CV_Error(Error::StsBadArg, "reconstruction: no observation of a reconstructed point");
    int farthest = -1;
    double best = 0;
    const Vec3d center0 = c0.center();
    for (int i = 0; i < n; i++)
    {
        if (!problem.HasParameterBlock(qd(i)))
            continue;
        problem.SetManifold(qd(i), &quatManifold);
        ordering->AddElementToGroup(qd(i), 1);
        ordering->AddElementToGroup(td(i), 1);
        const double d = cv::norm(rec.cameras[i].center() - center0);
        if (i > 0 && d > best)
        {
            best = d;
            farthest = i;
        }
    }
    for (int p = 0; p < P; p++)
        if (used[p])
            ordering->AddElementToGroup(X.ptr<double>(p), 0);
    ordering->AddElementToGroup(intr, 1);
    ordering->AddElementToGroup(dist, 1);
    // Gauge: the first camera's pose; the scale by the coordinate of the farthest camera's
    // translation that a scaling about the first camera's centre changes most,
    // d t_k / d lambda = -R_k (c_k - c_0). Without camera motion, no scale to fix.
    problem.SetParameterBlockConstant(qd(0));
    problem.SetParameterBlockConstant(td(0));
    std::unique_ptr<ceres::SubsetManifold> scaleGauge, intrManifold, distManifold;
    if (farthest > 0)
    {
        const Camera& ck = rec.cameras[farthest];
        const Vec3d g = ck.R * (ck.center() - center0);
        int j = 0;
        for (int k = 1; k < 3; k++)
            if (std::abs(g[k]) > std::abs(g[j]))
                j = k;
        scaleGauge.reset(new ceres::SubsetManifold(3, {j}));
        problem.SetManifold(td(farthest), scaleGauge.get());
    }
    if (freedom.focal)
    {
        intrManifold.reset(new ceres::SubsetManifold(3, {1, 2}));   // principal point held
        problem.SetManifold(intr, intrManifold.get());
    }
    else
        problem.SetParameterBlockConstant(intr);
    if (freedom.coefficients.empty())
        problem.SetParameterBlockConstant(dist);
    else
    {
        std::vector<int> held;
        for (int k = 0; k < 12; k++)
            if (std::find(freedom.coefficients.begin(), freedom.coefficients.end(), k) ==
                freedom.coefficients.end())
                held.push_back(k);
        distManifold.reset(new ceres::SubsetManifold(12, held));
        problem.SetManifold(dist, distManifold.get());
    }
    ceres::Solver::Options options;
    options.minimizer_type = ceres::TRUST_REGION;
    options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    options.linear_solver_type = ceres::ITERATIVE_SCHUR;
    options.preconditioner_type = ceres::SCHUR_JACOBI;
    options.eta = detail::kBundleForcing;
    options.max_num_iterations = params.maxIterations;
    options.function_tolerance = params.functionTolerance;
    // One thread, as the other bundle adjustments here: Ceres' threaded sums change the last
    // digits with the thread count, and results must not depend on it.
    options.num_threads = 1;
    options.minimizer_progress_to_stdout = false;
    options.logging_type = ceres::SILENT;
    double finalCost = 0;
    if (solve)
    {
        options.linear_solver_ordering.reset(ordering);
        detail::SolverProgress solverProgress(options, "lens BA");
        ceres::Solver::Summary summary;
        ceres::Solve(options, &problem, &summary);
        if (!solverUsable(summary, "lens bundle adjustment"))
            return false;
        finalCost = summary.final_cost;
    }
    else
    {
        delete ordering;
        problem.Evaluate(ceres::Problem::EvaluateOptions(), &finalCost, nullptr, nullptr,
                         nullptr);
    }
    if (focalRelStd)
    {
        *focalRelStd = -1;
        ceres::Covariance::Options co;
        co.algorithm_type = ceres::SPARSE_QR;
        co.num_threads = 1;  // as the solve: no dependence on the thread count
        ceres::Covariance cov(co);
        std::vector<std::pair<const double*, const double*>> blocks = {{intr, intr}};
        double C[9];
        if (freedom.focal && cov.Compute(blocks, &problem) &&
            cov.GetCovarianceBlock(intr, intr, C))
        {
            // Covariance of the unit-weight problem: scaled by the residual variance.
            const double dof = std::max(1, problem.NumResiduals() - problem.NumParameters());
            *focalRelStd = std::sqrt(std::max(0.0, C[0]) * 2 * finalCost / dof) / intr[0];
        }
    }
    // The count of the input lens (a refined term is one it has: the callers give it the
    // count they refine); the tilt terms are never refined.
    std::vector<double> d = c0.distortion;
    for (size_t k = 0; k < std::min<size_t>(12, d.size()); k++)
        d[k] = dist[k];
    const Matx33d K(intr[0], skew * intr[0], intr[1], 0, aspect * intr[0], intr[2], 0, 0, 1);
    for (int i = 0; i < n; i++)
    {
        Camera& cam = rec.cameras[i];
        cam = Camera::perspective(detail::fromQuaternion(qd(i)), Vec3d(td(i)), K,
                                  cam.frame, d);
    }
    for (int p = 0; p < P; p++)
        if (!used[p])
            X.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
    rec.points = X;
    return true;
}

// ---------------------------------------------------------------------------------------------
// Observations the cameras do not explain

/* A track the tracker followed correctly for a while and then lost without noticing: its point
went behind an occluding contour and the window slid along the contour, or the feature is a
T-junction of two contours at different depths (a roof line crossing a tower behind it). The
forward-backward check cannot see either (the drag is the same both ways), per-track rejection
keeps such a track when most of it is good, and the robust loss bounds each bad observation's
weight but not the bias of hundreds of them. Measured on the hand-held demo footage (1280x720,
H.264, 1665 tracks), against the true cameras: median residual 0.27 px, but 5% of the
observations beyond 2.6 px and 1% beyond 9.9 px, mostly on the shed as the front building slides
over it; the known-lens BA on all of them gave 0.08 deg rotation error and 0.85 px slide at the
95th percentile, on those within 1 px of the truth 0.026 deg and 0.17 px.

So observation by observation: for Gaussian pixel noise of sigma per axis the residual length is
Rayleigh, median sigma sqrt(2 ln 2), 99.9th percentile sigma sqrt(2 ln 1000); beyond that
percentile, with the scale taken from the median of all residuals (robust to the outliers
themselves), an observation is not the point's. The floor keeps exact synthetic tracks whole
(float32 coordinates at 4K resolve ~2.4e-4 px). */
const double kUnexplainedOverMedian = std::sqrt(std::log(1000.0) / std::log(2.0));  // 3.16
const double kUnexplainedFloorPx = 0.01;
// A point keeps its observations only while this many are explained (fewer: too weak to place
// it; it is dropped, and may come back through rescueTracks when the final cameras explain it).
const int kMinExplainedViews = 3;

/* `tracks` without the observations of reconstructed points that `rec` does not explain (see
above); points left with fewer than kMinExplainedViews explained observations become NaN in
`rec`. Observations of unreconstructed points and of frames without a camera are kept as they
are. Returns the count of observations dropped; `thresholdPx` gets the threshold used. */
int dropUnexplained(const Tracks& tracks, Reconstruction& rec, Tracks& kept, double& thresholdPx)
{
    const int P = tracks.points(), N = tracks.observations();
    const std::vector<const Camera*> cameraOf = camerasByFrame(tracks, rec);
    // Residual of every observation judged (NaN: not judged), by observation index.
    std::vector<float> e(N, std::numeric_limits<float>::quiet_NaN());
    parallel_for_(Range(0, N), [&](const Range& r) {
        for (int i = r.start; i < r.end; i++)
        {
            const Camera* cam = cameraOf[tracks.frameOf(i)];
            const int p = tracks.pointOf(i);
            if (cam && rec.hasPoint(p))
                e[i] = (float)cv::norm(cam->project(rec.point(p)) - Point2d(tracks.uv(i)));
        }
    });
    std::vector<float> judged;
    for (float x : e)
        if (!std::isnan(x))
            judged.push_back(x);
    thresholdPx = 0;
    if (judged.empty())
    {
        kept = tracks;
        return 0;
    }
    std::nth_element(judged.begin(), judged.begin() + judged.size() / 2, judged.end());
    thresholdPx = std::max(kUnexplainedFloorPx,
                           kUnexplainedOverMedian * judged[judged.size() / 2]);
    std::vector<int> explained(P, 0);
    int dropped = 0;
    for (int i = 0; i < N; i++)
    {
        if (std::isnan(e[i]))
            continue;
        if (e[i] > thresholdPx)
            dropped++;
        else
            explained[tracks.pointOf(i)]++;
    }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const double thr = thresholdPx;
    kept = tracks.mapped([&](int f, int p, const Point2f& uv) {
        const float x = e[tracks.find(f, p)];
        return x > thr ? Point2f(nan, nan) : uv;
    }, tracks.imageSize);
    for (int p = 0; p < P; p++)
        if (rec.hasPoint(p) && explained[p] < kMinExplainedViews)
            rec.points.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
    return dropped;
}

/* Rounds of dropUnexplained() and the lens bundle adjustment with `freedom` on what is kept,
each round judging every original observation again against the new cameras (an observation
dropped against biased cameras may come back), until the count dropped stops changing or after
`rounds`. Returns false when a bundle adjustment fails (`rec` then as after the last good
round). */
bool adjustOnExplained(const Tracks& tracks, Reconstruction& rec, const LensFreedom& freedom,
                       const OrthoCameraRefiner::Params& params, int rounds, SfmReport& rep)
{
    int last = -1;
    for (int r = 0; r < rounds; r++)
    {
        Reconstruction next = rec;
        Tracks kept;
        double thr = 0;
        const int dropped = dropUnexplained(tracks, next, kept, thr);
        if (dropped == last)
            break;
        if (!adjustLens(kept, next, freedom, params, nullptr))
            return false;
        rec = next;
        rep.unexplainedObservations = dropped;
        rep.unexplainedThresholdPx = thr;
        rep.explained = computeReprojectionStats(rec, kept);
        last = dropped;
        CV_LOG_INFO(NULL, cv::format("augocc sfm: round %d: %d observations beyond %.2f px "
                    "(3.16 x the median residual) left out of the lens bundle adjustment",
                    r + 1, dropped, thr));
    }
    return true;
}

// ---------------------------------------------------------------------------------------------
// Known intrinsics

// The lens the options give (calibration, or a focal with the principal point at the image
// centre), or an empty optional (model SCALED_ORTHOGRAPHIC) when none.
bool knownLens(const SfmOptions& o, Size imageSize, Camera& lens)
{
    const bool hasCal = !o.calibration.imageSize.empty();
    if (hasCal && o.focal > 0)
        CV_Error(Error::StsBadArg, "sfm: give the calibration or the focal length, not both");
    if (o.focal != 0 && !(o.focal > 0 && std::isfinite(o.focal)))
        CV_Error(Error::StsBadArg, cv::format("sfm: --focal %g must be a positive number of "
                 "pixels", o.focal));
    if (hasCal)
    {
        if (o.calibration.imageSize != imageSize)
            CV_Error(Error::StsBadSize, cv::format("sfm: the calibration is for %d x %d, the "
                     "tracks' frames are %d x %d (readCalibration scales it)",
                     o.calibration.imageSize.width, o.calibration.imageSize.height,
                     imageSize.width, imageSize.height));
        lens = o.calibration.camera();
        lens.validate("calibration");
        return true;
    }
    if (o.focal > 0)
    {
        lens = Camera::perspective(Matx33d::eye(), Vec3d(0, 0, 0), Matx33d(o.focal, 0,
                                   (imageSize.width - 1) * 0.5, 0, o.focal,
                                   (imageSize.height - 1) * 0.5, 0, 0, 1));
        return true;
    }
    return false;
}

// The tracks as an ideal square-pixel pinhole with focal fx and the principal point at the
// image centre would see them (what the affine and perspective stages assume).
Tracks idealTracks(const Tracks& tracks, const Camera& lens)
{
    const Point2d c((tracks.imageSize.width - 1) * 0.5, (tracks.imageSize.height - 1) * 0.5);
    const Matx33d& K = lens.K;
    return tracks.mapped([&](int, int, const Point2f& q) {
        const Point2d u = lens.undistortPixel(Point2d(q.x, q.y));
        const double y = (u.y - K(1, 2)) / K(1, 1);
        const double x = (u.x - K(0, 2) - K(0, 1) * y) / K(0, 0);
        return Point2f((float)(K(0, 0) * x + c.x), (float)(K(0, 0) * y + c.y));
    }, tracks.imageSize);
}

// The perspective solution of the ideal tracks brought to the known lens: each camera is
// dollied along its axis so that the scene's centroid keeps its image size at the known focal
// (f / z constant), the start of the lens bundle adjustment.
void applyKnownLens(Reconstruction& rec, const Camera& lens)
{
    Vec3d c;
    detail::rmsRadius(rec.points, &c);
    for (Camera& cam : rec.cameras)
    {
        const double ratio = lens.K(0, 0) / cam.K(0, 0);
        const double z = cam.depth(c);
        cam = Camera::perspective(cam.R, cam.t + Vec3d(0, 0, (ratio - 1) * z), lens.K,
                                  cam.frame, lens.distortion);
    }
}

// ---------------------------------------------------------------------------------------------
// Stages of recoverCameras

// Factorization, the paper's 3F+1, the scaled-orthographic BA, the depth-reversal prior and the
// perspective BA with the model choice: the affine and perspective stages.
Reconstruction recoverPinhole(const Tracks& tracks, const SfmOptions& options, SfmReport& rep)
{
    const String model = options.model;
    Reconstruction rec;
    Mat inliers;
    if (!FactorizationSfM::create(options.factorization)->reconstruct(tracks, rec, inliers))
        CV_Error(Error::StsError, "sfm: the factorization could not reconstruct the tracks "
                 "(too few overlapping tracks between frames; see the log)");
    rep.inlierTracks = countNonZero(inliers);
    rep.rejectedTracks = tracks.points() - rep.inlierTracks;
    rep.factorization = computeReprojectionStats(rec, tracks);

    OrthoCameraRefiner::Params rp = options.refiner;
    rp.mode = OrthoCameraRefiner::POSITION_ZOOM;
    if (!OrthoCameraRefiner::create(rp)->refine(tracks, rec))
        CV_Error(Error::StsError, "sfm: the 3F+1 refinement failed (see the log)");
    rep.positionZoom = computeReprojectionStats(rec, tracks);
    rep.orthographic = rep.positionZoom;
    if (options.bundleAdjust)
    {
        rp.mode = OrthoCameraRefiner::FULL_BA;
        rp.perFrameScale = options.perFrameScale;
        if (!OrthoCameraRefiner::create(rp)->refine(tracks, rec))
            CV_Error(Error::StsError, "sfm: the scaled-orthographic bundle adjustment failed "
                     "(see the log)");
        rep.orthographic = computeReprojectionStats(rec, tracks);
    }
    // Scaled orthography cannot tell a reconstruction from its depth-reversed twin (the Necker
    // reversal: both project to the same pixels); which one the factorization returns depends on
    // arbitrary sign choices. Prior: the dominant plane of the scene (the ground, a table, a
    // wall) is opaque background, so the points off it are in front of it, on the camera's side;
    // the twin puts them behind. Measured on SceneSynthesizer scenes (6 seeds and viewpoints)
    // and the demo: 100% or 0% of the off-plane points in front, the true twin always chosen.
    // The perspective BA below may still flip it where perspective effects tell (kappa < 0).
    const double front = frontOfDominantPlane(rec);
    if (front >= 0 && front < 0.5)
    {
        CV_LOG_INFO(NULL, cv::format("augocc sfm: %.0f%% of the points off the dominant plane "
                    "behind it: taking the depth-reversed twin (scaled orthography cannot tell "
                    "them apart)", 100 * (1 - front)));
        rec = detail::mirrorDepth(rec);
    }
    rep.chosenModel = "scaled_orthographic";
    if (model != "scaled_orthographic")
    {
        Reconstruction persp = rec;
        rp.mode = OrthoCameraRefiner::PERSPECTIVE_BA;
        const bool ok = OrthoCameraRefiner::create(rp)->refine(tracks, persp);
        if (!ok && model == "perspective")
            CV_Error(Error::StsError, "sfm: the perspective bundle adjustment failed (see the "
                     "log)");
        if (ok)
        {
            rep.perspective = computeReprojectionStats(persp, tracks);
            if (model == "perspective" ||
                rep.perspective.rms < options.autoRatio * rep.orthographic.rms)
            {
                rec = persp;
                rep.chosenModel = "perspective";
            }
        }
    }
    return rec;
}

/* Points whose depth the cameras do not measure: a skyline, clouds, a mountain far behind the
scene. A point's triangulation angle is the largest angle between its lines of sight from the
frames that see it; under COLMAP's minimum (1.5 degrees, its mapper's filter_min_tri_angle, applied
after each bundle adjustment) the point's place along its line of sight is set less by its
parallax than by the errors: pixel noise, but also what is correlated across frames and does
not average out, the cameras' own rotation errors and, before the lens is known, the distortion.
Measured on a synthetic hand-held shot with points 1e6 m ahead (test
sky_points_not_reconstructed): every such point came out reconstructed, up to 2.9e6 units away;
a rule of 3 noise sigmas of parallax instead of an angle still kept 10 of 60 after the rescue,
at 1-2 px of parallax that the cameras' errors gave them. A hand-held shot's own tracks gave one
at 1.17e9 units, past the writer's limit, and `augocc sfm` wrote no reconstruction. Such points
are not reconstructed (NaN), here after the first solution and after the last adjustment, and
the rescue does not bring them back; the cameras keep what they told them about rotation.
`flagged` (resized to the points) marks every point dropped. */
int dropUnmeasuredDepths(const Tracks& tracks, Reconstruction& rec, std::vector<uchar>& flagged)
{
    if (rec.model != PERSPECTIVE || rec.points.empty())
        return 0;
    const double minAngle = detail::kMinTriangulationDeg * CV_PI / 180;
    const std::vector<const Camera*> cameraOf = camerasByFrame(tracks, rec);
    const int P = rec.points.rows;
    std::vector<uchar> drop(P, 0);
    parallel_for_(Range(0, P), [&](const Range& r) {
        std::vector<const Camera*> cams;
        for (int p = r.start; p < r.end; p++)
        {
            if (!rec.hasPoint(p))
                continue;
            cams.clear();
            const Range seen = tracks.track(p);
            for (int k = seen.start; k < seen.end; k++)
                if (const Camera* c = cameraOf[tracks.frameOf(k)])
                    cams.push_back(c);
            const double* x = rec.points.ptr<double>(p);
            drop[p] = triangulationAngle(Vec3d(x[0], x[1], x[2]), cams) < minAngle ? 1 : 0;
        }
    });
    flagged.resize(P, 0);
    int n = 0;
    for (int p = 0; p < P; p++)
        if (drop[p])
        {
            rec.points.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
            flagged[p] = 1;
            n++;
        }
    if (n > 0)
        CV_LOG_INFO(NULL, cv::format("augocc sfm: %d points seen under less than %.1f degrees "
                    "not reconstructed: the cameras do not measure their depth", n,
                    detail::kMinTriangulationDeg));
    return n;
}

// Self-calibration of the lens after the perspective solution (see SfmOptions::selfCalibrate):
// focal, focal + k1, focal + k1 + k2 by BIC; the prior kept when the focal is not determined.
void selfCalibrate(const Tracks& tracks, const SfmOptions& options, Reconstruction& rec,
                   SfmReport& rep, std::vector<uchar>& unmeasured)
{
    rep.lensModel = "focal";
    // Nested models in order: focal + k1, then focal + k1 + k2 only when k1 beat the focal
    // alone (the BIC of a coefficient that explains nothing already lost).
    LensFreedom free1;
    free1.focal = true;
    free1.coefficients = {0};
    LensFreedom free2 = free1;
    free2.coefficients = {0, 1};
    std::vector<Reconstruction> models = {rec, rec};
    models[1].cameras[0].distortion.assign(4, 0.0);
    if (!adjustLens(tracks, models[1], free1, options.refiner, nullptr))
    {
        rep.lensReason = "the lens bundle adjustment failed: the perspective solution is kept";
        return;
    }
    std::vector<uchar> inl;
    int N = 0;
    rep.lensBic.clear();
    auto bic = [&](const Reconstruction& m, int p) {
        const double rss = sumSquaredResiduals(tracks, m, &inl, 0, nullptr, nullptr);
        return N * std::log(std::max(rss, 1e-300) / N) + p * std::log(N);
    };
    // The inlier set: that of the richest model fitted so far, the same for every model.
    auto scoreAll = [&]() {
        sumSquaredResiduals(tracks, models.back(), nullptr, options.lensInlierPx, &inl, &N);
        rep.lensBic.clear();
        for (size_t k = 0; k < models.size(); k++)
            rep.lensBic.push_back(bic(models[k], (int)k));
    };
    scoreAll();
    if (rep.lensBic[1] < rep.lensBic[0])
    {
        models.push_back(models[1]);
        if (adjustLens(tracks, models[2], free2, options.refiner, nullptr))
            scoreAll();
        else
            models.pop_back();
    }
    const int bestModel = (int)(std::min_element(rep.lensBic.begin(), rep.lensBic.end()) -
                                rep.lensBic.begin());
    const char* names[3] = {"focal", "focal_k1", "focal_k1_k2"};
    String bicText = "BIC";
    for (size_t k = 0; k < rep.lensBic.size(); k++)
        bicText += cv::format(" %s %.1f", names[k], rep.lensBic[k]);
    bicText += cv::format(" over %d residuals", N);
    if (bestModel == 0)
    {
        rep.lensReason = "no evidence of lens distortion (" + bicText + "): the perspective "
                         "solution is kept";
        return;
    }
    // The focal's standard deviation in the kept model (k2 correlates with the focal).
    // Points whose depth the cameras do not measure (dropUnmeasuredDepths) stay in the models
    // above, where as points near infinity they still tell the rotation and the distortion
    // (taking them out there was tried: no better lens). Their free depths make the covariance
    // rank-deficient (60 points of a synthetic skyline: refused), so the focal's deviation is
    // computed without them.
    double relStd = -1;
    Reconstruction best = models[bestModel];
    dropUnmeasuredDepths(tracks, best, unmeasured);
    adjustLens(tracks, best, bestModel == 1 ? free1 : free2, options.refiner, &relStd, false);
    rep.focalRelStd = relStd;
    // ceres::Covariance's SPARSE_QR refuses a Jacobian it finds rank-deficient; with the scale
    // gauge free that decision is borderline and varied between runs of the same footage
    // (2026-12-02: 0.0066 in one run, refused in the next). A refused computation is no evidence
    // that the focal is undetermined: the BIC choice stands and the reason says so. (Far-away
    // footage is caught before, by the orthographic model choice.)
    if (!(relStd >= 0))
    {
        rec = models[bestModel];
        rep.lensModel = names[bestModel];
        rep.lensReason = "self-calibrated; the focal's standard deviation could not be computed "
                         "(rank-deficient Jacobian), the BIC choice is kept; " + bicText;
        return;
    }
    if (relStd > options.maxFocalRelStd)
    {
        rep.lensReason = cv::format("the focal length is not determined (relative standard "
                                    "deviation %.3g > %.3g: too little depth variation or "
                                    "rotation to tell it from the distance): the perspective "
                                    "solution is kept, no distortion; ", relStd,
                                    options.maxFocalRelStd) + bicText;
        return;
    }
    rec = models[bestModel];
    rep.lensModel = names[bestModel];
    rep.lensReason = cv::format("self-calibrated, focal relative standard deviation %.2g; ",
                                relStd) + bicText;
}

} // namespace

Reconstruction recoverCameras(const Tracks& tracks, const SfmOptions& options, SfmReport* report)
{
    // The tracks of a sub-range of a shot (`augocc run --frames a:b`) keep the input's frame
    // numbers, so their first a frames are empty: the stages below see frames 0.. (the
    // factorization would otherwise solve cameras for frames that observe nothing), and the
    // cameras get their input frame numbers back.
    const int firstFrame = tracks.firstObservedFrame();
    if (firstFrame > 0 && firstFrame < tracks.frames())
    {
        Reconstruction rec = recoverCameras(
            tracks.shiftedFrames(-firstFrame, tracks.frames() - firstFrame), options, report);
        for (Camera& c : rec.cameras)
            c.frame += firstFrame;
        return rec;
    }
    const String model = options.model;
    if (model != "auto" && model != "scaled_orthographic" && model != "perspective")
        CV_Error(Error::StsBadArg, "--model " + model + ": expected scaled_orthographic, "
                 "perspective or auto");
    if (!(options.lensInlierPx > 0) || !(options.maxFocalRelStd > 0))
        CV_Error(Error::StsBadArg, "sfm: lensInlierPx and maxFocalRelStd must be positive");
    tracks.validate("tracks");
    const detail::ProgressScope progressScope(options.progress, "sfm");
    SfmReport rep;
    Reconstruction rec;
    Camera lens;
    std::vector<uchar> unmeasured;   // tracks dropped by dropUnmeasuredDepths, at any stage
    if (knownLens(options, tracks.imageSize, lens))
    {
        // Known intrinsics: the affine and perspective stages on the undistorted observations,
        // then the lens bundle adjustment on the frames' own pixels.
        if (model == "scaled_orthographic")
            CV_Error(Error::StsBadArg, "sfm: known intrinsics need the perspective model, not "
                     "scaled_orthographic");
        SfmOptions pinhole = options;
        pinhole.model = "perspective";
        rec = recoverPinhole(idealTracks(tracks, lens), pinhole, rep);
        applyKnownLens(rec, lens);
        dropUnmeasuredDepths(tracks, rec, unmeasured);
        LensFreedom freedom;
        freedom.focal = options.refineIntrinsics;
        if (options.refineIntrinsics)
            for (int k = 0; k < std::min<int>(12, (int)lens.distortion.size()); k++)
                freedom.coefficients.push_back(k);
        if (!adjustLens(tracks, rec, freedom, options.refiner, nullptr) ||
            !adjustOnExplained(tracks, rec, freedom, options.refiner, options.explainedRounds,
                               rep))
            CV_Error(Error::StsError, "sfm: the lens bundle adjustment failed (see the log)");
        rep.lens = computeReprojectionStats(rec, tracks);
        rep.lensModel = options.refineIntrinsics ? "given_refined" : "given";
        rep.lensReason = options.refineIntrinsics ? "known intrinsics, focal and distortion "
                         "refined" : "known intrinsics, held fixed";
    }
    else
    {
        rec = recoverPinhole(tracks, options, rep);
        dropUnmeasuredDepths(tracks, rec, unmeasured);
        if (rec.model != PERSPECTIVE)
        {
            rep.lensModel = "none";
            rep.lensReason = "scaled orthographic model chosen (no measurable perspective): no "
                             "focal length or lens distortion to estimate";
        }
        else if (!options.selfCalibrate)
        {
            rep.lensModel = "focal";
            rep.lensReason = "self-calibration off: the perspective solution's focal";
        }
        else
        {
            const Reconstruction pinhole = rec;
            selfCalibrate(tracks, options, rec, rep, unmeasured);
            // The lens chosen again on the observations that lens explains: the first choice's
            // BIC and covariance carry the bias of the unexplained ones (dropUnexplained).
            // Judged against the chosen lens, not the pinhole, so that the corners' distortion
            // is not taken for outliers.
            Reconstruction judged = rec;
            Tracks kept;
            double thr = 0;
            if (options.explainedRounds > 0 && dropUnexplained(tracks, judged, kept, thr) > 0)
            {
                Reconstruction again = pinhole;
                for (int p = 0; p < again.points.rows; p++)
                    if (!judged.hasPoint(p))
                        again.points.row(p).setTo(std::numeric_limits<double>::quiet_NaN());
                selfCalibrate(kept, options, again, rep, unmeasured);
                rec = again;
            }
        }
        if (rec.model == PERSPECTIVE)
        {
            // The perspective solution's focal stays when no lens was self-calibrated (not
            // determined, or self-calibration off); a self-calibrated lens stays free.
            LensFreedom freedom;
            if (rep.lensModel == "focal_k1")
                freedom.coefficients = {0};
            else if (rep.lensModel == "focal_k1_k2")
                freedom.coefficients = {0, 1};
            freedom.focal = !freedom.coefficients.empty();
            if (!adjustOnExplained(tracks, rec, freedom, options.refiner,
                                   options.explainedRounds, rep))
                CV_Error(Error::StsError, "sfm: the final bundle adjustment failed (see the "
                         "log)");
            if (rep.lensModel != "focal" || options.explainedRounds > 0)
                rep.lens = computeReprojectionStats(rec, tracks);
        }
    }
    CV_LOG_INFO(NULL, "augocc sfm: lens " + rep.lensModel + ": " + rep.lensReason);
    if (rec.model == PERSPECTIVE)
    {
        rep.focal = rec.cameras.front().K(0, 0);
        rep.distortion = rec.cameras.front().distortion;
    }
    rep.rescuedTracks = rescueTracks(tracks, rec);
    dropUnmeasuredDepths(tracks, rec, unmeasured);
    // Counted on the output: every stage above may have dropped points.
    rep.inlierTracks = 0;
    rep.unmeasuredDepthTracks = 0;
    for (int p = 0; p < rec.points.rows; p++)
    {
        const bool kept = rec.hasPoint(p);
        rep.inlierTracks += kept ? 1 : 0;
        rep.unmeasuredDepthTracks += !kept && p < (int)unmeasured.size() && unmeasured[p];
    }
    rep.rejectedTracks = rec.points.rows - rep.inlierTracks;
    if (report)
        *report = rep;
    return rec;
}

} // namespace augocc
} // namespace cv
