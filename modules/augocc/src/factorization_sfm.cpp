// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Tomasi-Kanade factorization under orthography (Tomasi & Kanade 1992; Ong, Teh & Tan 1998,
// Section 3) with missing data (largest complete block, growth by affine triangulation and
// resection, then alternation: the ALS of Buchanan & Fitzgibbon 2005) and rejection of gross
// outlier tracks by their residual to the affine fit.
//
// Over 800 lines in one file: the stages (largest complete block, growth, alternation, metric
// upgrade, outlier rejection, refinement) work on one shared measurement-matrix representation;
// the incremental path for long sequences with short tracks is in incremental_sfm.cpp.

#include "precomp.hpp"
#include "sfm_detail.hpp"
#include "stats.hpp"

#include <numeric>
#include <Eigen/Dense>

namespace cv {
namespace augocc {

namespace detail {

void ObservationIndex::build(const Tracks& tracks, const String& what)
{
    tracks.validate(what);  // every observation finite
    frames = tracks.frames();
    points = tracks.points();
    const int N = tracks.observations();
    frameStart.assign(frames + 1, 0);
    pointStart.assign(points + 1, 0);
    for (int f = 0; f < frames; f++)
        frameStart[f + 1] = frameStart[f] + tracks.frameObservationCount(f);
    for (int p = 0; p < points; p++)
        pointStart[p + 1] = pointStart[p] + tracks.observationCount(p);
    byFrame.resize(N);
    byPoint.resize(N);
    std::vector<int> fill(pointStart.begin(), pointStart.end() - 1);
    int i = 0;
    for (int f = 0; f < frames; f++)
    {
        const Range r = tracks.frame(f);
        for (int k = r.start; k < r.end; k++)
        {
            const int o = tracks.byFrame(k), p = tracks.pointOf(o);
            const Point2f q = tracks.uv(o);
            byFrame[i] = SfmObservation{f, p, (double)q.x, (double)q.y};
            byPoint[fill[p]++] = i++;
        }
    }
}

Matx33d nearestRotation(const Matx33d& M)
{
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m(r, c) = M(r, c);
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0)
        D(2, 2) = -1;
    const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
    Matx33d out;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            out(r, c) = R(r, c);
    return out;
}

namespace {

// Coefficients g with a^T L b = g . l for the symmetric L packed as
// l = (L00, L01, L02, L11, L12, L22).
inline void symCoeffs(const double* a, const double* b, double* g)
{
    g[0] = a[0] * b[0];
    g[1] = a[0] * b[1] + a[1] * b[0];
    g[2] = a[0] * b[2] + a[2] * b[0];
    g[3] = a[1] * b[1];
    g[4] = a[1] * b[2] + a[2] * b[1];
    g[5] = a[2] * b[2];
}

// Relative singular value of the constraint system below which L is not determined: the
// constraints of two distinct views leave a one-parameter family (Ullman: three views are
// needed); with noise-free data that family shows as a singular value at rounding level
// (~1e-16), with real noise the smallest values stay near the noise level (~1e-3 and above).
const double kMinConstraintSingular = 1e-7;
// Nearest positive-definite repair: eigenvalues of L are clipped to this fraction of the
// largest (a condition number of 1e6, far beyond any real camera-motion upgrade).
const double kMinEigenRatio = 1e-6;

} // namespace

void metricUpgrade(const Mat& A, const std::vector<uchar>& solved, Matx33d& Q)
{
    CV_Assert(A.type() == CV_64F && A.cols == 6 && (int)solved.size() == A.rows);
    int n = 0;
    for (uchar s : solved)
        n += s ? 1 : 0;
    CV_Assert(n > 0);
    // Normalise the motion so that the right-hand side 1 matches its magnitude (the affine
    // factorization fixes the overall scale arbitrarily); the scale is restored after.
    double meanNorm2 = 0;
    for (int f = 0; f < A.rows; f++)
    {
        if (!solved[f])
            continue;
        const double* a = A.ptr<double>(f);
        meanNorm2 += 0.5 * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2] +
                            a[3] * a[3] + a[4] * a[4] + a[5] * a[5]);
    }
    meanNorm2 /= n;
    const double k = 1.0 / std::sqrt(meanNorm2);
    Eigen::MatrixXd G(3 * n, 6);
    Eigen::VectorXd rhs(3 * n);
    int row = 0;
    for (int f = 0; f < A.rows; f++)
    {
        if (!solved[f])
            continue;
        const double* a = A.ptr<double>(f);
        const double i[3] = {k * a[0], k * a[1], k * a[2]};
        const double j[3] = {k * a[3], k * a[4], k * a[5]};
        double g[6];
        symCoeffs(i, i, g);
        for (int c = 0; c < 6; c++) G(row, c) = g[c];
        rhs(row++) = 1.0;
        symCoeffs(j, j, g);
        for (int c = 0; c < 6; c++) G(row, c) = g[c];
        rhs(row++) = 1.0;
        symCoeffs(i, j, g);
        for (int c = 0; c < 6; c++) G(row, c) = g[c];
        rhs(row++) = 0.0;
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = svd.singularValues();
    if (n < 2 || sv(5) < kMinConstraintSingular * sv(0))
        CV_Error(Error::StsBadArg, cv::format("tracks: the metric upgrade is not determined "
                 "(constraint singular values %.3g / %.3g): fewer than three distinct views "
                 "(Ullman), e.g. pure translation with a fixed line of sight", sv(5), sv(0)));
    const Eigen::VectorXd l = svd.solve(rhs);
    Eigen::Matrix3d L;
    L << l(0), l(1), l(2),
         l(1), l(3), l(4),
         l(2), l(4), l(5);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(L);
    Eigen::Vector3d d = eig.eigenvalues();
    const double dmax = d.maxCoeff();
    if (!(dmax > 0))
        CV_Error(Error::StsBadArg, "tracks: the metric upgrade has no positive solution: the "
                 "motion is not that of an orthographic camera");
    if (d.minCoeff() < kMinEigenRatio * dmax)
        CV_LOG_INFO(NULL, cv::format("augocc sfm: metric upgrade L indefinite or near singular "
                    "(eigenvalues %.3g %.3g %.3g), repaired to the nearest positive definite",
                    d(0), d(1), d(2)));
    for (int c = 0; c < 3; c++)
        d(c) = std::max(d(c), kMinEigenRatio * dmax);
    const Eigen::Matrix3d Qe = eig.eigenvectors() * d.cwiseSqrt().asDiagonal() * k;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            Q(r, c) = Qe(r, c);
}

double rmsRadius(const Mat& points, Vec3d* centroid)
{
    Vec3d c(0, 0, 0);
    int n = 0;
    for (int i = 0; i < points.rows; i++)
    {
        const double* x = points.ptr<double>(i);
        if (!std::isfinite(x[0]))
            continue;
        c += Vec3d(x[0], x[1], x[2]);
        n++;
    }
    if (n == 0)
    {
        if (centroid)
            *centroid = c;
        return 0;
    }
    c *= 1.0 / n;
    double s = 0;
    for (int i = 0; i < points.rows; i++)
    {
        const double* x = points.ptr<double>(i);
        if (!std::isfinite(x[0]))
            continue;
        const Vec3d d = Vec3d(x[0], x[1], x[2]) - c;
        s += d.dot(d);
    }
    if (centroid)
        *centroid = c;
    return std::sqrt(s / n);
}

Reconstruction mirrorDepth(const Reconstruction& rec)
{
    Reconstruction m = rec;
    const Matx33d Z(1, 0, 0, 0, 1, 0, 0, 0, -1);
    for (Camera& c : m.cameras)
    {
        c.R = Z * c.R * Z;
        // t.z is a gauge under orthography; keep the depth of the mirrored centroid the same.
    }
    m.points = rec.points.clone();
    for (int i = 0; i < m.points.rows; i++)
        m.points.at<double>(i, 2) = -m.points.at<double>(i, 2);
    return m;
}

bool triangulatePoint(const std::vector<const Camera*>& cams, const std::vector<Point2d>& obs,
                      Vec3d& X)
{
    CV_Assert(cams.size() == obs.size());
    if (cams.size() < 2)
        return false;
    // Linear equations: orthographic rows are exact; perspective rows are the DLT rows
    // (u * P3 - P1) . (X, 1) = 0, a good start for the Gauss-Newton steps below.
    Matx33d N = Matx33d::zeros();
    Vec3d r(0, 0, 0);
    bool perspective = false;
    for (size_t k = 0; k < cams.size(); k++)
    {
        const Matx34d P = cams[k]->projectionMatrix();
        perspective = perspective || cams[k]->model == PERSPECTIVE;
        for (int a = 0; a < 2; a++)
        {
            const double m = a == 0 ? obs[k].x : obs[k].y;
            Vec3d g;
            double h;
            if (cams[k]->model == PERSPECTIVE)
            {
                g = Vec3d(m * P(2, 0) - P(a, 0), m * P(2, 1) - P(a, 1), m * P(2, 2) - P(a, 2));
                h = P(a, 3) - m * P(2, 3);
                const double w = 1.0 / std::max(1e-12, cv::norm(g));
                g *= w;
                h *= w;
            }
            else
            {
                g = Vec3d(P(a, 0), P(a, 1), P(a, 2));
                h = m - P(a, 3);
            }
            N += g * g.t();
            r += g * h;
        }
    }
    // Two lines of sight closer than this (sine of the angle between them) do not fix depth.
    const double kMinParallax = 1e-6;
    Matx33d Ninv;
    Mat evals;
    cv::eigen(Mat(N), evals);
    if (!(evals.at<double>(2) > kMinParallax * kMinParallax * evals.at<double>(0)))
        return false;
    X = N.solve(r, DECOMP_CHOLESKY);
    if (!perspective)
        return true;
    for (int it = 0; it < 5; it++)
    {
        Matx33d H = Matx33d::zeros();
        Vec3d g(0, 0, 0);
        for (size_t k = 0; k < cams.size(); k++)
        {
            const Camera& c = *cams[k];
            const Vec3d Xc = c.toCamera(X);
            if (Xc[2] <= 0)
                return false;
            const Point2d p = c.projectCamera(Xc);
            Matx23d J;
            if (c.model == PERSPECTIVE)
            {
                const double iz = 1.0 / Xc[2];
                const Matx23d dProj(c.K(0, 0) * iz, c.K(0, 1) * iz,
                                    -(c.K(0, 0) * Xc[0] + c.K(0, 1) * Xc[1]) * iz * iz,
                                    0, c.K(1, 1) * iz, -c.K(1, 1) * Xc[1] * iz * iz);
                J = dProj * c.R;
            }
            else
            {
                J = Matx23d(c.s * c.R(0, 0), c.s * c.R(0, 1), c.s * c.R(0, 2),
                            c.s * c.R(1, 0), c.s * c.R(1, 1), c.s * c.R(1, 2));
            }
            const Vec2d e(p.x - obs[k].x, p.y - obs[k].y);
            H += J.t() * J;
            g += J.t() * e;
        }
        const Vec3d dx = H.solve(-g, DECOMP_SVD);
        X += dx;
        if (cv::norm(dx) < 1e-9 * (1.0 + cv::norm(X)))
            break;
    }
    return true;
}

} // namespace detail

using detail::AffineModel;
using detail::ObservationIndex;
using detail::SfmObservation;

namespace {

// Moves the reconstructed points of `rec` so that their centroid is the origin; `centre` is that
// centroid before the move. Returns their RMS radius (the scale of the cameras' depth).
double centrePoints(Reconstruction& rec, Vec3d& centre)
{
    const double radius = detail::rmsRadius(rec.points, &centre);
    for (int p = 0; p < rec.points.rows; p++)
        if (rec.hasPoint(p))
            for (int k = 0; k < 3; k++)
                rec.points.at<double>(p, k) -= centre[k];
    return radius;
}

// The inlier flags of reconstruct(): 1 where a track's point was kept (hasPoint), 0 where
// rejected.
void writeInliers(const Reconstruction& rec, OutputArray inliersOut)
{
    if (!inliersOut.needed())
        return;
    Mat inl(rec.points.rows, 1, CV_8U);
    for (int p = 0; p < rec.points.rows; p++)
        inl.at<uchar>(p) = rec.hasPoint(p) ? 1 : 0;
    inl.copyTo(inliersOut);
}

// A frame is resected from at least this many points (an affine camera has 8 unknowns, 2
// equations per point; 6 leaves a margin against near-coplanar sets).
const int kMinResectPoints = 6;
// The complete block that starts the missing-data fit holds at least this many tracks and
// frames (the rank-3 factorization of a 2F x P block needs 2F > 3 and P > 3; margins added).
const int kMinBlockTracks = 8;
const int kMinBlockFrames = 3;
// Windows of more frames than this are not scored for the complete block (memory F x this).
const int kMaxBlockFrames = 400;
// Affine rank test: the third singular value of the registered measurement matrix must exceed
// the fourth (noise) by this factor and the first by this fraction, else the motion is rank
// deficient (pure translation, one view repeated). Measured on noisy rank-3 data: sigma3/sigma4
// >= 10 for any motion the metric upgrade can use; rank-2 data gives ~1.
const double kMinRankGap = 3.0;
const double kMinRankRatio = 1e-9;
// Alternation sweeps run between two growth steps of the missing-data fit.
const int kGrowthSweeps = 3;
// Normal matrices whose smallest/largest eigenvalue ratio is below this are not solved.
const double kMinNormalCondition = 1e-10;

struct SfmData
{
    ObservationIndex idx;
    std::vector<uchar> usable;   // track used at all (enough observations)
    std::vector<uchar> inlier;   // track currently trusted
    Size imageSize;
};

inline bool solve4(const Matx44d& N, const Vec4d& ru, const Vec4d& rv, Vec4d& xu, Vec4d& xv)
{
    const Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> n(N.val);
    const Eigen::LLT<Eigen::Matrix4d> llt(n);
    if (llt.info() != Eigen::Success)
        return false;
    Eigen::Map<Eigen::Vector4d>(xu.val) = llt.solve(Eigen::Map<const Eigen::Vector4d>(ru.val));
    Eigen::Map<Eigen::Vector4d>(xv.val) = llt.solve(Eigen::Map<const Eigen::Vector4d>(rv.val));
    return std::isfinite(xu[0]) && std::isfinite(xv[0]);
}

inline bool solve3(const Matx33d& N, const Vec3d& r, Vec3d& x)
{
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> n(N.val);
    const Eigen::LLT<Eigen::Matrix3d> llt(n);
    if (llt.info() != Eigen::Success)
        return false;
    Eigen::Map<Eigen::Vector3d>(x.val) = llt.solve(Eigen::Map<const Eigen::Vector3d>(r.val));
    return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

// Resects frame f (affine camera) from the solved inlier points it sees.
bool resectFrame(const SfmData& d, int f, AffineModel& m, bool checkCondition)
{
    Matx44d N = Matx44d::zeros();
    Vec4d ru(0, 0, 0, 0), rv(0, 0, 0, 0);
    int n = 0;
    for (int i = d.idx.frameStart[f]; i < d.idx.frameStart[f + 1]; i++)
    {
        const SfmObservation& o = d.idx.byFrame[i];
        if (!d.inlier[o.point] || !m.solvedPoint[o.point])
            continue;
        const double* x = m.X.ptr<double>(o.point);
        const Vec4d h(x[0], x[1], x[2], 1.0);
        N += h * h.t();
        ru += h * o.u;
        rv += h * o.v;
        n++;
    }
    if (n < (checkCondition ? kMinResectPoints : 4))
        return false;
    if (checkCondition)
    {
        // Scale-free check on the centred second moments of the points.
        Matx33d C;
        const Vec3d mean(N(0, 3) / n, N(1, 3) / n, N(2, 3) / n);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                C(r, c) = N(r, c) / n - mean[r] * mean[c];
        Mat ev;
        cv::eigen(Mat(C), ev);
        if (!(ev.at<double>(2) > kMinNormalCondition * 1e4 * ev.at<double>(0)))
            return false;
    }
    Vec4d xu, xv;
    if (!solve4(N, ru, rv, xu, xv))
        return false;
    double* a = m.A.ptr<double>(f);
    a[0] = xu[0]; a[1] = xu[1]; a[2] = xu[2];
    a[3] = xv[0]; a[4] = xv[1]; a[5] = xv[2];
    m.b.at<double>(f, 0) = xu[3];
    m.b.at<double>(f, 1) = xv[3];
    m.solvedFrame[f] = 1;
    return true;
}

// Affine triangulation of track p from the solved frames that see it.
bool triangulateAffine(const SfmData& d, int p, const AffineModel& m, Vec3d& X, bool check,
                       int* nUsed = nullptr)
{
    Matx33d N = Matx33d::zeros();
    Vec3d r(0, 0, 0);
    int n = 0;
    for (int k = d.idx.pointStart[p]; k < d.idx.pointStart[p + 1]; k++)
    {
        const SfmObservation& o = d.idx.byFrame[d.idx.byPoint[k]];
        if (!m.solvedFrame[o.frame])
            continue;
        const double* a = m.A.ptr<double>(o.frame);
        const double* b = m.b.ptr<double>(o.frame);
        const Vec3d i(a[0], a[1], a[2]), j(a[3], a[4], a[5]);
        N += i * i.t() + j * j.t();
        r += i * (o.u - b[0]) + j * (o.v - b[1]);
        n++;
    }
    if (nUsed)
        *nUsed = n;
    if (n < 2)
        return false;
    if (check)
    {
        Mat ev;
        cv::eigen(Mat(N), ev);
        if (!(ev.at<double>(2) > kMinNormalCondition * 1e4 * ev.at<double>(0)))
            return false;
    }
    return solve3(N, r, X);
}

// Sum of squared residuals of track p over the solved frames, and the observation count.
double trackSsr(const SfmData& d, int p, const AffineModel& m, const Vec3d& X, int& n)
{
    double s = 0;
    n = 0;
    for (int k = d.idx.pointStart[p]; k < d.idx.pointStart[p + 1]; k++)
    {
        const SfmObservation& o = d.idx.byFrame[d.idx.byPoint[k]];
        if (!m.solvedFrame[o.frame])
            continue;
        const double* a = m.A.ptr<double>(o.frame);
        const double* b = m.b.ptr<double>(o.frame);
        const double eu = a[0] * X[0] + a[1] * X[1] + a[2] * X[2] + b[0] - o.u;
        const double ev = a[3] * X[0] + a[4] * X[1] + a[5] * X[2] + b[1] - o.v;
        s += eu * eu + ev * ev;
        n++;
    }
    return s;
}

// Largest eigenpairs of the Gram matrix C = W W^T of a registered measurement matrix W (n x m),
// decreasing: the eigenvalues are the squared singular values of W, the eigenvectors its left
// singular vectors. Small n: C is formed and solved exactly. Else the top kSubspace pairs (the
// rank-3 factorization needs 3, the rank test the 4th) by subspace iteration with a
// Rayleigh-Ritz step (a full eigensolver on a 200 x 200 matrix costs 10 ms). The iteration is
// first applied to W itself, C Q = W (W^T Q): 4 n m kSubspace flops a step, where forming C
// costs n^2 m (100 frames x 1000 tracks: 1 ms a step against 7 ms for C), and with a rank-3
// signal well above the noise the top 3 pairs converge in 2-3 steps. When they have not after
// kDirectIterations (a small gap between sigma3 and the noise: near-degenerate motion), C is
// formed and the iteration goes on with it, where a step costs 2 n^2 kSubspace flops. The start
// is a fixed pseudo-random block, so the result does not depend on anything but W.
const int kDenseEigenMax = 48;
const int kSubspace = 8;
const int kDirectIterations = 6;
const int kMaxSubspaceIterations = 300;
const double kSubspaceTol = 1e-13;

// Converged when the top 3 Ritz values stop moving (relative to the largest).
inline bool ritzConverged(const Eigen::VectorXd& ritz, const Eigen::VectorXd& prev)
{
    return (ritz.head(3) - prev.head(3)).cwiseAbs().maxCoeff() <=
           kSubspaceTol * std::max(ritz(0), 1e-300);
}

inline Eigen::MatrixXd orthonormalBasis(const Eigen::MatrixXd& Y)
{
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(Y);
    return qr.householderQ() * Eigen::MatrixXd::Identity(Y.rows(), Y.cols());
}

void topEigenOfGram(const Eigen::MatrixXd& W, Eigen::VectorXd& values, Eigen::MatrixXd& vectors)
{
    const int n = (int)W.rows();
    if (n <= kDenseEigenMax)
    {
        Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
        C.selfadjointView<Eigen::Lower>().rankUpdate(W);
        C = C.selfadjointView<Eigen::Lower>();
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(C);
        values = eig.eigenvalues().reverse();
        vectors = eig.eigenvectors().rowwise().reverse();
        return;
    }
    RNG rng(0x5f3759df);
    Eigen::MatrixXd Q(n, kSubspace);
    for (int r = 0; r < n; r++)
        for (int c = 0; c < kSubspace; c++)
            Q(r, c) = rng.uniform(-1.0, 1.0);
    Q = orthonormalBasis(Q);
    Eigen::VectorXd prev = Eigen::VectorXd::Zero(kSubspace);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> small;
    Eigen::MatrixXd Z;
    for (int it = 0; it < kDirectIterations; it++)
    {
        Z.noalias() = W.transpose() * Q;
        small.compute(Z.transpose() * Z);   // Q^T C Q
        const Eigen::VectorXd ritz = small.eigenvalues().reverse();
        if (it > 0 && ritzConverged(ritz, prev))
        {
            values = ritz;
            vectors = Q * small.eigenvectors().rowwise().reverse();
            return;
        }
        prev = ritz;
        Q = orthonormalBasis(W * Z);
    }
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
    C.selfadjointView<Eigen::Lower>().rankUpdate(W);
    C = C.selfadjointView<Eigen::Lower>();
    for (int it = 0; it < kMaxSubspaceIterations; it++)
    {
        Q = orthonormalBasis(C * Q);
        if (it % 4 != 3)
            continue;
        small.compute(Q.transpose() * C * Q);
        const Eigen::VectorXd ritz = small.eigenvalues().reverse();
        if (ritzConverged(ritz, prev))
            break;
        prev = ritz;
    }
    small.compute(Q.transpose() * C * Q);
    values = small.eigenvalues().reverse();
    vectors = Q * small.eigenvectors().rowwise().reverse();
}

// Rank-3 factorization of the registered 2F' x P' block (frames x tracks, all observed).
// Returns sigma1, sigma3, sigma4 of the registered matrix in `sv`.
void factorBlock(const SfmData& d, const std::vector<int>& frames, const std::vector<int>& tracks,
                 AffineModel& m, Vec3d& sv)
{
    const int nf = (int)frames.size(), np = (int)tracks.size();
    Eigen::MatrixXd W(2 * nf, np);
    std::vector<int> col(d.idx.points, -1);
    for (int c = 0; c < np; c++)
        col[tracks[c]] = c;
    for (int r = 0; r < nf; r++)
    {
        const int f = frames[r];
        for (int i = d.idx.frameStart[f]; i < d.idx.frameStart[f + 1]; i++)
        {
            const SfmObservation& o = d.idx.byFrame[i];
            const int c = col[o.point];
            if (c < 0)
                continue;
            W(2 * r, c) = o.u;
            W(2 * r + 1, c) = o.v;
        }
    }
    // Registration: subtract the centroid of the tracks in every image row (Tomasi-Kanade).
    const Eigen::VectorXd mean = W.rowwise().mean();
    W.colwise() -= mean;
    // The top left singular vectors from the 2F' x 2F' Gram matrix (2F' << P' in practice).
    const int n = 2 * nf;
    Eigen::VectorXd evals;   // the largest eigenvalues, decreasing
    Eigen::MatrixXd evecs;   // their eigenvectors
    topEigenOfGram(W, evals, evecs);
    Eigen::MatrixXd U3(n, 3);
    Eigen::Vector3d s3;
    for (int k = 0; k < 3; k++)
    {
        U3.col(k) = evecs.col(k);
        s3(k) = std::sqrt(std::max(0.0, evals(k)));
    }
    sv = Vec3d(s3(0), s3(2), evals.size() > 3 ? std::sqrt(std::max(0.0, evals(3))) : 0.0);
    // M = U3 Sigma^(1/2), S = Sigma^(-1/2) U3^T W.
    Eigen::Vector3d sq, isq;
    for (int k = 0; k < 3; k++)
    {
        sq(k) = std::sqrt(s3(k));
        isq(k) = s3(k) > 0 ? 1.0 / sq(k) : 0.0;
    }
    const Eigen::MatrixXd M = U3 * sq.asDiagonal();
    const Eigen::MatrixXd S = isq.asDiagonal() * (U3.transpose() * W);
    for (int r = 0; r < nf; r++)
    {
        const int f = frames[r];
        double* a = m.A.ptr<double>(f);
        for (int k = 0; k < 3; k++)
        {
            a[k] = M(2 * r, k);
            a[3 + k] = M(2 * r + 1, k);
        }
        m.b.at<double>(f, 0) = mean(2 * r);
        m.b.at<double>(f, 1) = mean(2 * r + 1);
        m.solvedFrame[f] = 1;
    }
    for (int c = 0; c < np; c++)
    {
        double* x = m.X.ptr<double>(tracks[c]);
        for (int k = 0; k < 3; k++)
            x[k] = S(k, c);
        m.solvedPoint[tracks[c]] = 1;
    }
}

// The largest complete block: a window of consecutive frames and the inlier tracks observed in
// every frame of it, maximising (tracks x frames) with at least kMinBlockTracks tracks.
bool findCompleteBlock(const SfmData& d, std::vector<int>& frames, std::vector<int>& tracks)
{
    const int F = d.idx.frames;
    const int L = std::min(F, kMaxBlockFrames);
    // hist[a * L + k]: inlier tracks whose run of consecutive observations starting at or before
    // a extends exactly min(k, L - 1) frames beyond a.
    std::vector<int> hist((size_t)F * L, 0);
    for (int p = 0; p < d.idx.points; p++)
    {
        if (!d.inlier[p])
            continue;
        int k = d.idx.pointStart[p];
        const int end = d.idx.pointStart[p + 1];
        while (k < end)
        {
            const int s = d.idx.byFrame[d.idx.byPoint[k]].frame;
            int e = s;
            k++;
            while (k < end && d.idx.byFrame[d.idx.byPoint[k]].frame == e + 1)
            {
                e++;
                k++;
            }
            for (int a = s; a <= e; a++)
                hist[(size_t)a * L + std::min(e - a, L - 1)]++;
        }
    }
    long best = -1;
    int bestA = -1, bestLen = 0;
    for (int a = 0; a < F; a++)
    {
        int cnt = 0;
        // cnt for window length len = sum of hist[a][k] for k >= len - 1.
        std::vector<int> suffix(L + 1, 0);
        for (int k = L - 1; k >= 0; k--)
            suffix[k] = suffix[k + 1] + hist[(size_t)a * L + k];
        for (int len = kMinBlockFrames; len <= std::min(L, F - a); len++)
        {
            cnt = suffix[len - 1];
            if (cnt < kMinBlockTracks)
                break;
            const long score = (long)cnt * len;
            if (score > best)
            {
                best = score;
                bestA = a;
                bestLen = len;
            }
        }
    }
    if (bestA < 0)
        return false;
    frames.clear();
    for (int f = bestA; f < bestA + bestLen; f++)
        frames.push_back(f);
    tracks.clear();
    for (int p = 0; p < d.idx.points; p++)
    {
        if (!d.inlier[p])
            continue;
        int n = 0;
        for (int k = d.idx.pointStart[p]; k < d.idx.pointStart[p + 1]; k++)
        {
            const int f = d.idx.byFrame[d.idx.byPoint[k]].frame;
            n += (f >= bestA && f < bestA + bestLen) ? 1 : 0;
        }
        if (n == bestLen)
            tracks.push_back(p);
    }
    return (int)tracks.size() >= kMinBlockTracks;
}

// When the tracks are short relative to the sequence (their mean length below this fraction of
// the frames), the frames are linked only through chains of short overlaps and the affine
// missing-data fit may bend along the chain (incremental_sfm.cpp); the reconstruction is then
// built incrementally with metric cameras. Measured: the Oxford dinosaur 0.09 (3.3 views of
// 36), CMU hotel KLT 1.0, the perf set with 50% missing data 0.5; sequences as short as
// kMinIncrementalFrames are left to the factorization (every window is then a large part of
// the sequence).
const double kShortTrackFraction = 0.25;
const int kMinIncrementalFrames = 12;

bool needsIncrementalPath(const SfmData& d)
{
    const int F = d.idx.frames;
    if (F < kMinIncrementalFrames)
        return false;
    long obs = 0;
    int n = 0;
    for (int p = 0; p < d.idx.points; p++)
        if (d.usable[p])
        {
            obs += d.idx.pointCount(p);
            n++;
        }
    return n > 0 && (double)obs / n < kShortTrackFraction * F;
}

class FactorizationSfMImpl CV_FINAL : public FactorizationSfM
{
public:
    explicit FactorizationSfMImpl(const Params& p) { setParams(p); }

    Params getParams() const CV_OVERRIDE { return params_; }

    void setParams(const Params& p) CV_OVERRIDE
    {
        if (p.minTrackLength < 2)
            CV_Error(Error::StsBadArg, cv::format("FactorizationSfM: minTrackLength = %d must be "
                     ">= 2", p.minTrackLength));
        if (p.maxAlternations < 0 || p.maxRejectionRounds < 1)
            CV_Error(Error::StsBadArg, "FactorizationSfM: maxAlternations must be >= 0 and "
                     "maxRejectionRounds >= 1");
        if (!(p.outlierThreshold > 0) || !(p.outlierSigmas > 0) || !(p.depthRatio > 0) ||
            !(p.alternationTol >= 0))
            CV_Error(Error::StsBadArg, "FactorizationSfM: outlierThreshold, outlierSigmas and "
                     "depthRatio must be positive, alternationTol non-negative");
        params_ = p;
    }

    bool reconstruct(const Tracks& tracks, Reconstruction& out, OutputArray inliers) const
        CV_OVERRIDE;

private:
    bool fitAffine(SfmData& d, bool full, AffineModel& m, bool warm, Vec3d& sv) const;
    void alternate(const SfmData& d, AffineModel& m, int iterations) const;
    bool reconstructIncremental(SfmData& d, Reconstruction& out, OutputArray inliers) const;

    Params params_;
};

// Alternation (ALS): frames from points, then points from frames, each a small linear least
// squares problem solved independently (parallel, deterministic). Stops when the RMS improves
// by less than alternationTol (relative) or after `iterations` sweeps.
void FactorizationSfMImpl::alternate(const SfmData& d, AffineModel& m, int iterations) const
{
    const int F = d.idx.frames, P = d.idx.points;
    double prev = -1;
    std::vector<double> ssr(P, 0.0);
    std::vector<int> cnt(P, 0);
    for (int it = 0; it < iterations; it++)
    {
        parallel_for_(Range(0, F), [&](const Range& r) {
            for (int f = r.start; f < r.end; f++)
                if (m.solvedFrame[f])
                    resectFrame(d, f, m, false);
        });
        parallel_for_(Range(0, P), [&](const Range& r) {
            for (int p = r.start; p < r.end; p++)
            {
                ssr[p] = 0;
                cnt[p] = 0;
                if (!d.inlier[p] || !m.solvedPoint[p])
                    continue;
                Vec3d X;
                if (triangulateAffine(d, p, m, X, false))
                {
                    double* x = m.X.ptr<double>(p);
                    x[0] = X[0]; x[1] = X[1]; x[2] = X[2];
                }
                const double* x = m.X.ptr<double>(p);
                ssr[p] = trackSsr(d, p, m, Vec3d(x[0], x[1], x[2]), cnt[p]);
            }
        });
        double s = 0;
        long n = 0;
        for (int p = 0; p < P; p++)
        {
            s += ssr[p];
            n += cnt[p];
        }
        const double rms = n > 0 ? std::sqrt(s / n) : 0.0;
        if (prev >= 0 && prev - rms <= params_.alternationTol * prev)
            break;
        prev = rms;
    }
}

bool FactorizationSfMImpl::fitAffine(SfmData& d, bool full, AffineModel& m, bool warm,
                                     Vec3d& sv) const
{
    const int F = d.idx.frames, P = d.idx.points;
    if (full)
    {
        m.A = Mat::zeros(F, 6, CV_64F);
        m.b = Mat::zeros(F, 2, CV_64F);
        m.X = Mat::zeros(P, 3, CV_64F);
        m.solvedFrame.assign(F, 0);
        m.solvedPoint.assign(P, 0);
        std::vector<int> frames(F), tr;
        std::iota(frames.begin(), frames.end(), 0);
        for (int p = 0; p < P; p++)
            if (d.inlier[p])
                tr.push_back(p);
        factorBlock(d, frames, tr, m, sv);
        return true;
    }
    if (!warm)
    {
        m.A = Mat::zeros(F, 6, CV_64F);
        m.b = Mat::zeros(F, 2, CV_64F);
        m.X = Mat::zeros(P, 3, CV_64F);
        m.solvedFrame.assign(F, 0);
        m.solvedPoint.assign(P, 0);
        std::vector<int> frames, tr;
        if (!findCompleteBlock(d, frames, tr))
        {
            CV_LOG_WARNING(NULL, cv::format("augocc sfm: no complete block of %d frames x %d "
                           "tracks to start the missing-data factorization", kMinBlockFrames,
                           kMinBlockTracks));
            return false;
        }
        CV_LOG_INFO(NULL, cv::format("augocc sfm: complete block frames %d..%d x %d tracks",
                    frames.front(), frames.back(), (int)tr.size()));
        factorBlock(d, frames, tr, m, sv);
        // Growth: triangulate tracks seen in two solved frames, resect frames that see enough
        // solved points, a few alternation sweeps to spread the error, until nothing is added.
        for (;;)
        {
            int added = 0;
            for (int p = 0; p < P; p++)
            {
                if (!d.inlier[p] || m.solvedPoint[p])
                    continue;
                Vec3d X;
                if (triangulateAffine(d, p, m, X, true))
                {
                    double* x = m.X.ptr<double>(p);
                    x[0] = X[0]; x[1] = X[1]; x[2] = X[2];
                    m.solvedPoint[p] = 1;
                    added++;
                }
            }
            for (int f = 0; f < F; f++)
                if (!m.solvedFrame[f] && resectFrame(d, f, m, true))
                    added++;
            if (added == 0)
                break;
            alternate(d, m, kGrowthSweeps);
        }
    }
    else
    {
        // Warm start after a rejection round: tracks re-admitted need a position.
        for (int p = 0; p < P; p++)
        {
            if (!d.inlier[p] || m.solvedPoint[p])
                continue;
            Vec3d X;
            if (triangulateAffine(d, p, m, X, true))
            {
                double* x = m.X.ptr<double>(p);
                x[0] = X[0]; x[1] = X[1]; x[2] = X[2];
                m.solvedPoint[p] = 1;
            }
        }
    }
    alternate(d, m, params_.maxAlternations);
    return true;
}

// Incremental path (incremental_sfm.cpp): metric upgrade of the largest complete block, then
// growth with scaled-orthographic cameras; output in the conventions of the factorization, except
// that each camera keeps its own zoom (their mean is 1).
bool FactorizationSfMImpl::reconstructIncremental(SfmData& d, Reconstruction& out,
                                                  OutputArray inliersOut) const
{
    const int F = d.idx.frames, P = d.idx.points;
    std::vector<int> frames, tr;
    if (!findCompleteBlock(d, frames, tr))
        return false;
    AffineModel m;
    m.A = Mat::zeros(F, 6, CV_64F);
    m.b = Mat::zeros(F, 2, CV_64F);
    m.X = Mat::zeros(P, 3, CV_64F);
    m.solvedFrame.assign(F, 0);
    m.solvedPoint.assign(P, 0);
    Vec3d sv;
    // Gross outliers in the block (a sliding T-junction adds a rank of its own and can hide the
    // rotation's third singular value): rejection rounds on the block, the rule of the
    // factorization below (RMS residual to the rank-3 fit against max(floor, sigmas x median)).
    for (int round = 0; round < params_.maxRejectionRounds; round++)
    {
        factorBlock(d, frames, tr, m, sv);
        std::vector<double> res(tr.size());
        for (size_t c = 0; c < tr.size(); c++)
        {
            int n = 0;
            const double* x = m.X.ptr<double>(tr[c]);
            const double ssr = trackSsr(d, tr[c], m, Vec3d(x[0], x[1], x[2]), n);
            res[c] = std::sqrt(ssr / std::max(1, n));
        }
        const double thr = std::max(params_.outlierThreshold,
                                    params_.outlierSigmas * detail::median(res));
        std::vector<int> kept;
        for (size_t c = 0; c < tr.size(); c++)
            if (res[c] <= thr)
                kept.push_back(tr[c]);
        if (kept.size() == tr.size())
            break;
        if ((int)kept.size() < kMinBlockTracks)
            return false;
        for (int p : tr)
            m.solvedPoint[p] = 0;
        tr = kept;
    }
    if (sv[1] < kMinRankGap * sv[2] || sv[1] <= kMinRankRatio * sv[0])
    {
        CV_LOG_INFO(NULL, cv::format("augocc sfm: incremental start: the complete block frames "
                    "%d..%d has no rank-3 motion (s3 / s4 = %.2f)", frames.front(), frames.back(),
                    sv[1] / std::max(sv[2], 1e-300)));
        return false;
    }
    Matx33d Q;
    try
    {
        detail::metricUpgrade(m.A, m.solvedFrame, Q);
    }
    catch (const cv::Exception& e)
    {
        CV_LOG_INFO(NULL, "augocc sfm: incremental start: " + e.msg);
        return false;
    }
    CV_LOG_INFO(NULL, cv::format("augocc sfm: incremental reconstruction from the complete block "
                "frames %d..%d x %d tracks", frames.front(), frames.back(), (int)tr.size()));
    const Point2d pp((d.imageSize.width - 1) * 0.5, (d.imageSize.height - 1) * 0.5);
    std::vector<detail::OrthoView> views(F);
    for (int f : frames)
    {
        const double* a = m.A.ptr<double>(f);
        const Vec3d i = Q.t() * Vec3d(a[0], a[1], a[2]);
        const Vec3d j = Q.t() * Vec3d(a[3], a[4], a[5]);
        const double ni = cv::norm(i), nj = cv::norm(j);
        const Vec3d r1 = i / ni, r2 = j / nj, r3 = r1.cross(r2);
        detail::OrthoView& v = views[f];
        v.R = detail::nearestRotation(Matx33d(r1[0], r1[1], r1[2], r2[0], r2[1], r2[2],
                                              r3[0], r3[1], r3[2]));
        v.s = 0.5 * (ni + nj);
        v.t = Vec2d((m.b.at<double>(f, 0) - pp.x) / v.s, (m.b.at<double>(f, 1) - pp.y) / v.s);
        v.solved = true;
    }
    const Matx33d Qinv = Q.inv();
    Mat X(P, 3, CV_64F, Scalar::all(std::numeric_limits<double>::quiet_NaN()));
    for (int p : tr)
    {
        const double* x = m.X.ptr<double>(p);
        const Vec3d Y = Qinv * Vec3d(x[0], x[1], x[2]);
        for (int k = 0; k < 3; k++)
            X.at<double>(p, k) = Y[k];
    }
    detail::growIncremental(d.idx, d.usable, pp, params_.outlierThreshold,
                            params_.outlierSigmas, views, X);
    // Frames need enough points to be trusted (as in the factorization).
    int first = -1, nFrames = 0;
    double sMean = 0;
    for (int f = 0; f < F; f++)
    {
        if (!views[f].solved)
            continue;
        int n = 0;
        for (int i = d.idx.frameStart[f]; i < d.idx.frameStart[f + 1]; i++)
            n += std::isfinite(X.at<double>(d.idx.byFrame[i].point, 0)) ? 1 : 0;
        if (n < 4)
        {
            views[f].solved = false;
            continue;
        }
        if (first < 0)
            first = f;
        sMean += views[f].s;
        nFrames++;
    }
    if (nFrames < 3)
        return false;
    sMean /= nFrames;
    // World: axes of the first reconstructed camera, unit such that the mean zoom is 1, origin
    // at the points' centroid.
    const Matx33d G = views[first].R;
    Reconstruction rec;
    rec.model = SCALED_ORTHOGRAPHIC;
    rec.imageSize = d.imageSize;
    rec.points = Mat(P, 3, CV_64F, Scalar::all(std::numeric_limits<double>::quiet_NaN()));
    for (int p = 0; p < P; p++)
    {
        const double* x = X.ptr<double>(p);
        if (!std::isfinite(x[0]))
            continue;
        const Vec3d Xw = sMean * (G * Vec3d(x[0], x[1], x[2]));
        for (int k = 0; k < 3; k++)
            rec.points.at<double>(p, k) = Xw[k];
    }
    Vec3d c;
    const double depth = params_.depthRatio * std::max(centrePoints(rec, c), 1.0);
    for (int f = 0; f < F; f++)
    {
        if (!views[f].solved)
            continue;
        // u = s_f (R_f X + t_f) + pp with X = G^T (Xw + c) / sMean.
        const Matx33d R = views[f].R * G.t();
        const Vec3d Rc = R * c;
        const Vec3d t(Rc[0] + sMean * views[f].t[0], Rc[1] + sMean * views[f].t[1], depth);
        rec.cameras.push_back(Camera::orthographic(R, t, views[f].s / sMean, pp, f));
    }
    out = rec;
    writeInliers(rec, inliersOut);
    return true;
}

bool FactorizationSfMImpl::reconstruct(const Tracks& tracks, Reconstruction& out,
                                       OutputArray inliersOut) const
{
    tracks.validate("tracks");
    const int F = tracks.frames(), P = tracks.points();
    if (F < 3)
        CV_Error(Error::StsBadArg, cv::format("tracks: %d frames; the factorization needs at "
                 "least three distinct views (Ullman)", F));
    SfmData d;
    d.imageSize = tracks.imageSize;
    d.idx.build(tracks, "tracks");
    d.usable.assign(P, 0);
    int nUsable = 0;
    for (int p = 0; p < P; p++)
    {
        const int n = d.idx.pointCount(p);
        if (n >= params_.minTrackLength)
        {
            d.usable[p] = 1;
            nUsable++;
        }
    }
    if (nUsable < 4)
        CV_Error(Error::StsBadArg, cv::format("tracks: %d usable tracks (seen in at least %d "
                 "frames); the factorization needs at least 4", nUsable,
                 params_.minTrackLength));
    d.inlier = d.usable;
    // Long sequences with short tracks: the metric incremental path (incremental_sfm.cpp).
    if (needsIncrementalPath(d))
    {
        if (reconstructIncremental(d, out, inliersOut))
            return true;
        CV_LOG_INFO(NULL, "augocc sfm: the incremental reconstruction failed; falling back to "
                    "the affine missing-data factorization");
        d.inlier = d.usable;
    }

    AffineModel m;
    Vec3d sv(0, 0, 0);
    std::vector<double> resid(P, 0.0);
    std::vector<uchar> solvedPt(P, 0);
    bool warm = false;
    for (int round = 0; round < params_.maxRejectionRounds; round++)
    {
        int nIn = 0;
        bool fullIn = true;
        for (int p = 0; p < P; p++)
            if (d.inlier[p])
            {
                nIn++;
                fullIn = fullIn && d.idx.pointCount(p) == F;
            }
        if (nIn < 4)
            CV_Error(Error::StsBadArg, cv::format("tracks: only %d tracks agree with a rigid "
                     "scene after outlier rejection; the factorization needs at least 4", nIn));
        if (!fitAffine(d, fullIn, m, warm, sv))
            return false;
        warm = !fullIn;
        // Residual of every usable track (rejected ones too, so that they can come back).
        parallel_for_(Range(0, P), [&](const Range& r) {
            for (int p = r.start; p < r.end; p++)
            {
                resid[p] = std::numeric_limits<double>::infinity();
                solvedPt[p] = 0;
                if (!d.usable[p])
                    continue;
                Vec3d X;
                const double* x = m.X.ptr<double>(p);
                if (d.inlier[p] && m.solvedPoint[p])
                    X = Vec3d(x[0], x[1], x[2]);
                else if (!triangulateAffine(d, p, m, X, true))
                    continue;
                int n = 0;
                const double ssr = trackSsr(d, p, m, X, n);
                if (n < 2)
                    continue;
                solvedPt[p] = 1;
                // RMS per observation, corrected for the 3 fitted coordinates (2n equations).
                resid[p] = std::sqrt(ssr / std::max(0.5, n - 1.5));
            }
        });
        if (!params_.rejectOutliers)
            break;
        std::vector<double> r;
        for (int p = 0; p < P; p++)
            if (d.inlier[p] && std::isfinite(resid[p]))
                r.push_back(resid[p]);
        if (r.empty())
            break;
        const double med = detail::median(r);
        const double thr = std::max(params_.outlierThreshold, params_.outlierSigmas * med);
        std::vector<uchar> next(P, 0);
        int changed = 0, nNext = 0;
        for (int p = 0; p < P; p++)
        {
            next[p] = d.usable[p] && resid[p] <= thr;
            changed += next[p] != d.inlier[p];
            nNext += next[p];
        }
        CV_LOG_INFO(NULL, cv::format("augocc sfm: rejection round %d: median track residual "
                    "%.3f px, threshold %.3f px, %d inliers, %d changed", round, med, thr, nNext,
                    changed));
        if (changed == 0)
            break;
        d.inlier = next;
        if (!warm)
            continue;
        for (int p = 0; p < P; p++)
            if (!d.inlier[p])
                m.solvedPoint[p] = 0;
    }

    // Rank test on the complete block of the final inliers.
    {
        std::vector<int> frames, tr;
        bool ok = true;
        if (warm)
            ok = findCompleteBlock(d, frames, tr);
        Vec3d s = sv;
        if (warm && ok)
        {
            AffineModel tmp;
            tmp.A = Mat::zeros(F, 6, CV_64F);
            tmp.b = Mat::zeros(F, 2, CV_64F);
            tmp.X = Mat::zeros(P, 3, CV_64F);
            tmp.solvedFrame.assign(F, 0);
            tmp.solvedPoint.assign(P, 0);
            factorBlock(d, frames, tr, tmp, s);
        }
        if (ok && (s[1] < kMinRankGap * s[2] || s[1] <= kMinRankRatio * s[0]))
            CV_Error(Error::StsBadArg, cv::format("tracks: the registered measurement matrix "
                     "has rank below 3 (singular values s1 = %.4g, s3 = %.4g, s4 = %.4g): "
                     "fewer than three distinct views, e.g. pure translation with a fixed "
                     "line of sight, or a planar scene seen in one direction", s[0], s[1], s[2]));
    }

    // Frames need enough inlier points to be trusted.
    std::vector<uchar> solvedFrame = m.solvedFrame;
    for (int f = 0; f < F; f++)
    {
        if (!solvedFrame[f])
            continue;
        int n = 0;
        for (int i = d.idx.frameStart[f]; i < d.idx.frameStart[f + 1]; i++)
            n += d.inlier[d.idx.byFrame[i].point] && solvedPt[d.idx.byFrame[i].point];
        if (n < 4)
            solvedFrame[f] = 0;
    }
    int nFrames = 0;
    for (uchar s : solvedFrame)
        nFrames += s;
    if (nFrames < 3)
    {
        CV_LOG_WARNING(NULL, cv::format("augocc sfm: only %d frames could be reconstructed",
                       nFrames));
        return false;
    }

    // Metric upgrade (Tomasi-Kanade Section 3.3 style, scaled orthography).
    Matx33d Q;
    detail::metricUpgrade(m.A, solvedFrame, Q);
    const Matx33d Qinv = Q.inv();
    int first = -1;
    std::vector<Matx33d> R(F);
    std::vector<double> s(F, 0.0);
    double sMean = 0;
    for (int f = 0; f < F; f++)
    {
        if (!solvedFrame[f])
            continue;
        const double* a = m.A.ptr<double>(f);
        const Vec3d i = Q.t() * Vec3d(a[0], a[1], a[2]);
        const Vec3d j = Q.t() * Vec3d(a[3], a[4], a[5]);
        const double ni = cv::norm(i), nj = cv::norm(j);
        s[f] = 0.5 * (ni + nj);
        sMean += s[f];
        const Vec3d r1 = i / ni, r2 = j / nj, r3 = r1.cross(r2);
        R[f] = detail::nearestRotation(Matx33d(r1[0], r1[1], r1[2], r2[0], r2[1], r2[2],
                                               r3[0], r3[1], r3[2]));
        if (first < 0)
            first = f;
    }
    sMean /= nFrames;
    // World aligned to the first reconstructed frame, unit such that the zoom is 1.
    const Matx33d G = R[first];
    const Matx33d Xmap = G * Qinv * sMean;   // affine X -> world X
    Reconstruction rec;
    rec.model = SCALED_ORTHOGRAPHIC;
    rec.imageSize = tracks.imageSize;
    const Point2d pp((tracks.imageSize.width - 1) * 0.5, (tracks.imageSize.height - 1) * 0.5);
    rec.points = Mat(P, 3, CV_64F, Scalar::all(std::numeric_limits<double>::quiet_NaN()));
    for (int p = 0; p < P; p++)
    {
        if (!d.inlier[p] || !solvedPt[p])
            continue;
        const double* x = m.X.ptr<double>(p);
        const Vec3d Xw = Xmap * Vec3d(x[0], x[1], x[2]);
        rec.points.at<double>(p, 0) = Xw[0];
        rec.points.at<double>(p, 1) = Xw[1];
        rec.points.at<double>(p, 2) = Xw[2];
    }
    Vec3d c;
    const double depth = params_.depthRatio * std::max(centrePoints(rec, c), 1.0);
    for (int f = 0; f < F; f++)
    {
        if (!solvedFrame[f])
            continue;
        Camera cam = Camera::orthographic(R[f] * G.t(), Vec3d(0, 0, depth), 1.0, pp, f);
        // Translation: least squares over the frame's inlier observations.
        double su = 0, sv2 = 0;
        int n = 0;
        for (int i = d.idx.frameStart[f]; i < d.idx.frameStart[f + 1]; i++)
        {
            const SfmObservation& o = d.idx.byFrame[i];
            if (!rec.hasPoint(o.point))
                continue;
            const Vec3d Xc = cam.R * rec.point(o.point);
            su += (o.u - pp.x) - Xc[0];
            sv2 += (o.v - pp.y) - Xc[1];
            n++;
        }
        cam.t = Vec3d(su / n, sv2 / n, depth);
        rec.cameras.push_back(cam);
    }
    out = rec;
    writeInliers(rec, inliersOut);
    return true;
}

} // namespace

Ptr<FactorizationSfM> FactorizationSfM::create(const Params& params)
{
    return makePtr<FactorizationSfMImpl>(params);
}

Ptr<FactorizationSfM> FactorizationSfM::create()
{
    return create(Params());
}

} // namespace augocc
} // namespace cv
