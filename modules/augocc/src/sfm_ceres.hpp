// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Ceres residuals of the camera refiner (private: Ceres and Eigen types stay out of the public
// headers). Units: every residual is a reprojection error in pixels, (u, v) order.
// Quaternions are stored (x, y, z, w), the order of Eigen::Quaternion::coeffs() and of
// ceres::EigenQuaternionManifold.

#ifndef OPENCV_AUGOCC_SFM_CERES_HPP
#define OPENCV_AUGOCC_SFM_CERES_HPP

#include <algorithm>
#include <vector>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/ceres.h>
#include <opencv2/core.hpp>
#include "progress_detail.hpp"

namespace cv {
namespace augocc {
namespace detail {

/** @brief The paper's 3F+1 residuals of one frame (Ong, Teh & Tan 1998, Section 4): all the
observations of frame f in one block, orientation and points fixed.

Parameters: t (3: tx, ty, tz; tz has no effect under orthography and is held by a
SubsetManifold) and the global zoom s (1). Residuals 2n: u_k = s * (xr_k + tx) + cx - u_obs,
v_k = s * (yr_k + ty) + cy - v_obs with (xr, yr) the first two rows of R_f X_k.
Analytic Jacobian (the problem is bilinear, autodiff would only cost time). */
class PositionZoomCost : public ceres::CostFunction
{
public:
    /** @param rotated 2n values (xr_k, yr_k). @param observed 2n values (u_k, v_k).
    @param cx principal point x. @param cy principal point y. */
    PositionZoomCost(std::vector<double> rotated, std::vector<double> observed, double cx,
                     double cy)
        : rotated_(std::move(rotated)), observed_(std::move(observed)), cx_(cx), cy_(cy)
    {
        set_num_residuals((int)observed_.size());
        mutable_parameter_block_sizes()->push_back(3);
        mutable_parameter_block_sizes()->push_back(1);
    }

    bool Evaluate(double const* const* parameters, double* residuals,
                  double** jacobians) const override
    {
        const double* t = parameters[0];
        const double s = parameters[1][0];
        const int n = (int)observed_.size() / 2;
        for (int k = 0; k < n; k++)
        {
            const double x = rotated_[2 * k] + t[0], y = rotated_[2 * k + 1] + t[1];
            residuals[2 * k] = s * x + cx_ - observed_[2 * k];
            residuals[2 * k + 1] = s * y + cy_ - observed_[2 * k + 1];
            if (jacobians && jacobians[0])
            {
                double* J = jacobians[0] + 6 * k;  // 2 rows x 3 cols, row-major
                J[0] = s; J[1] = 0; J[2] = 0;
                J[3] = 0; J[4] = s; J[5] = 0;
            }
            if (jacobians && jacobians[1])
            {
                jacobians[1][2 * k] = x;
                jacobians[1][2 * k + 1] = y;
            }
        }
        return true;
    }

private:
    std::vector<double> rotated_, observed_;
    double cx_, cy_;
};

/** @brief Rotation of X by the unit quaternion q = (x, y, z, w) in the formula Eigen uses
(Xc = X + 2 w (u x X) + 2 u x (u x X), u = (x, y, z)), with its derivatives: dq (3 x 4,
row-major, columns x y z w) and dX (3 x 3, row-major, = R(q) for a unit q), when not null.
The ambient quaternion derivatives are what Ceres multiplies by the manifold's PlusJacobian. */
inline void rotateByQuaternion(const double* q, const double* X, double* Xc, double* dq,
                               double* dX)
{
    const double ux = q[0], uy = q[1], uz = q[2], w = q[3];
    const double a0 = uy * X[2] - uz * X[1];   // a = u x X
    const double a1 = uz * X[0] - ux * X[2];
    const double a2 = ux * X[1] - uy * X[0];
    const double b0 = uy * a2 - uz * a1;       // b = u x a
    const double b1 = uz * a0 - ux * a2;
    const double b2 = ux * a1 - uy * a0;
    Xc[0] = X[0] + 2 * (w * a0 + b0);
    Xc[1] = X[1] + 2 * (w * a1 + b1);
    Xc[2] = X[2] + 2 * (w * a2 + b2);
    if (dq)
    {
        // d/du: 2 (-w [X]x + u X^T + (u . X) I - 2 X u^T); d/dw: 2 a.
        const double u[3] = {ux, uy, uz};
        const double ud = ux * X[0] + uy * X[1] + uz * X[2];
        const double cx[3][3] = {{0, -X[2], X[1]}, {X[2], 0, -X[0]}, {-X[1], X[0], 0}};
        const double a[3] = {a0, a1, a2};
        for (int r = 0; r < 3; r++)
        {
            for (int c = 0; c < 3; c++)
                dq[4 * r + c] = 2 * (-w * cx[r][c] + u[r] * X[c] + (r == c ? ud : 0.0) -
                                     2 * X[r] * u[c]);
            dq[4 * r + 3] = 2 * a[r];
        }
    }
    if (dX)
    {
        // I + 2 w [u]x + 2 (u u^T - (u . u) I).
        const double u[3] = {ux, uy, uz};
        const double uu = ux * ux + uy * uy + uz * uz;
        const double cu[3][3] = {{0, -uz, uy}, {uz, 0, -ux}, {-uy, ux, 0}};
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                dX[3 * r + c] = (r == c ? 1.0 - 2 * uu : 0.0) + 2 * w * cu[r][c] +
                                2 * u[r] * u[c];
    }
}

/** @brief Scaled-orthographic reprojection of one observation (full bundle adjustment).
Blocks: q (4, rotation world->camera), t (2: tx, ty), s (1: zoom), X (3: world point).
Residual (2): s * ((q * X).xy + t) + c - observed, pixels. Analytic Jacobians: with 100k
residual blocks, Ceres' automatic differentiation was a third of the bundle adjustment's time
(OrthoReprojectionError is the same residual in template form, the reference of the tests). */
class OrthoReprojectionCost : public ceres::SizedCostFunction<2, 4, 2, 1, 3>
{
public:
    OrthoReprojectionCost(double u, double v, double cx, double cy)
        : u_(u), v_(v), cx_(cx), cy_(cy) {}

    bool Evaluate(double const* const* parameters, double* residuals,
                  double** jacobians) const override
    {
        const double* t = parameters[1];
        const double s = parameters[2][0];
        const bool jq = jacobians && jacobians[0], jx = jacobians && jacobians[3];
        double Xc[3], dq[12], dX[9];
        rotateByQuaternion(parameters[0], parameters[3], Xc, jq ? dq : nullptr,
                           jx ? dX : nullptr);
        const double x = Xc[0] + t[0], y = Xc[1] + t[1];
        residuals[0] = s * x + cx_ - u_;
        residuals[1] = s * y + cy_ - v_;
        if (!jacobians)
            return true;
        if (jq)
            for (int k = 0; k < 8; k++)
                jacobians[0][k] = s * dq[k];
        if (jacobians[1])
        {
            double* J = jacobians[1];
            J[0] = s; J[1] = 0;
            J[2] = 0; J[3] = s;
        }
        if (jacobians[2])
        {
            jacobians[2][0] = x;
            jacobians[2][1] = y;
        }
        if (jx)
            for (int k = 0; k < 6; k++)
                jacobians[3][k] = s * dX[k];
        return true;
    }

private:
    double u_, v_, cx_, cy_;
};

//! The residual of OrthoReprojectionCost for automatic differentiation (test reference).
struct OrthoReprojectionError
{
    OrthoReprojectionError(double u, double v, double cx, double cy)
        : u_(u), v_(v), cx_(cx), cy_(cy) {}

    template <typename T>
    bool operator()(const T* const q, const T* const t, const T* const s, const T* const X,
                    T* residuals) const
    {
        const Eigen::Map<const Eigen::Quaternion<T>> Q(q);
        const Eigen::Map<const Eigen::Matrix<T, 3, 1>> P(X);
        const Eigen::Matrix<T, 3, 1> Xc = Q * P;
        residuals[0] = s[0] * (Xc(0) + t[0]) + T(cx_) - T(u_);
        residuals[1] = s[0] * (Xc(1) + t[1]) + T(cy_) - T(v_);
        return true;
    }

    static ceres::CostFunction* Create(double u, double v, double cx, double cy)
    {
        return new ceres::AutoDiffCostFunction<OrthoReprojectionError, 2, 4, 2, 1, 3>(
            new OrthoReprojectionError(u, v, cx, cy));
    }

    double u_, v_, cx_, cy_;
};

/** @brief Perspective reprojection in the "perspective strength" form (well conditioned near
orthography, where a plain pinhole's focal length and distance become one parameter).
Blocks: q (4), t (3: Xc = q * X + t, t.z relative to the reference depth), s (1: pixels per
world unit at the reference depth), kappa (1: inverse reference depth), X (3).
Residual (2): s * Xc.xy / (1 + kappa * Xc.z) + c - observed, pixels. kappa = 0 is scaled
orthography; the pinhole equivalent is f = s / kappa, t_pinhole = t + (0, 0, 1 / kappa).
A negative kappa is the depth-reversed (mirror) twin of a positive one. Analytic Jacobians
(PerspectiveStrengthError is the template form, the reference of the tests). */
class PerspectiveStrengthCost : public ceres::SizedCostFunction<2, 4, 3, 1, 1, 3>
{
public:
    PerspectiveStrengthCost(double u, double v, double cx, double cy)
        : u_(u), v_(v), cx_(cx), cy_(cy) {}

    bool Evaluate(double const* const* parameters, double* residuals,
                  double** jacobians) const override
    {
        const double* t = parameters[1];
        const double s = parameters[2][0], kappa = parameters[3][0];
        const bool jq = jacobians && jacobians[0], jx = jacobians && jacobians[4];
        double R[3], dq[12], dX[9];
        rotateByQuaternion(parameters[0], parameters[4], R, jq ? dq : nullptr,
                           jx ? dX : nullptr);
        const double Xc[3] = {R[0] + t[0], R[1] + t[1], R[2] + t[2]};
        const double d = 1.0 + kappa * Xc[2];
        const double w = s / d;
        residuals[0] = w * Xc[0] + cx_ - u_;
        residuals[1] = w * Xc[1] + cy_ - v_;
        if (!jacobians)
            return true;
        // G = d residual / d Xc (2 x 3).
        const double G[2][3] = {{w, 0, -w * Xc[0] * kappa / d},
                                {0, w, -w * Xc[1] * kappa / d}};
        if (jq)
            for (int r = 0; r < 2; r++)
                for (int c = 0; c < 4; c++)
                    jacobians[0][4 * r + c] = G[r][0] * dq[c] + G[r][1] * dq[4 + c] +
                                              G[r][2] * dq[8 + c];
        if (jacobians[1])
            for (int r = 0; r < 2; r++)
                for (int c = 0; c < 3; c++)
                    jacobians[1][3 * r + c] = G[r][c];
        if (jacobians[2])
        {
            jacobians[2][0] = Xc[0] / d;
            jacobians[2][1] = Xc[1] / d;
        }
        if (jacobians[3])
        {
            jacobians[3][0] = -w * Xc[0] * Xc[2] / d;
            jacobians[3][1] = -w * Xc[1] * Xc[2] / d;
        }
        if (jx)
            for (int r = 0; r < 2; r++)
                for (int c = 0; c < 3; c++)
                    jacobians[4][3 * r + c] = G[r][0] * dX[c] + G[r][1] * dX[3 + c] +
                                              G[r][2] * dX[6 + c];
        return true;
    }

private:
    double u_, v_, cx_, cy_;
};

//! The residual of PerspectiveStrengthCost for automatic differentiation (test reference).
struct PerspectiveStrengthError
{
    PerspectiveStrengthError(double u, double v, double cx, double cy)
        : u_(u), v_(v), cx_(cx), cy_(cy) {}

    template <typename T>
    bool operator()(const T* const q, const T* const t, const T* const s, const T* const kappa,
                    const T* const X, T* residuals) const
    {
        const Eigen::Map<const Eigen::Quaternion<T>> Q(q);
        const Eigen::Map<const Eigen::Matrix<T, 3, 1>> P(X);
        const Eigen::Matrix<T, 3, 1> Xc = Q * P + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(t);
        const T w = s[0] / (T(1) + kappa[0] * Xc(2));
        residuals[0] = w * Xc(0) + T(cx_) - T(u_);
        residuals[1] = w * Xc(1) + T(cy_) - T(v_);
        return true;
    }

    static ceres::CostFunction* Create(double u, double v, double cx, double cy)
    {
        return new ceres::AutoDiffCostFunction<PerspectiveStrengthError, 2, 4, 3, 1, 1, 3>(
            new PerspectiveStrengthError(u, v, cx, cy));
    }

    double u_, v_, cx_, cy_;
};

/** @brief Pinhole with OpenCV's lens distortion, exactly as Camera::project (and
cv::projectPoints) apply it: the residual of the lens bundle adjustment (camera_refiner.cpp).
Blocks: q (4, rotation world->camera, (x, y, z, w)), t (3), X (3, world point), intrinsics (3:
f = fx, cx, cy), distortion (12: k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4; zeros for the
terms a camera does not have). Constants: fy / fx and skew / fx (one focal block for the
sequence keeps the calibration's aspect), and the tilt homography of tx, ty (14-coefficient
lenses; identity otherwise), which is never refined. Residual (2): projected - observed, pixels.
Automatic differentiation (a few 10k observations; analytic Jacobians would save time only). */
struct LensReprojectionError
{
    LensReprojectionError(double u, double v, double aspect, double skew, const Matx33d& tilt)
        : u_(u), v_(v), aspect_(aspect), skew_(skew), tilt_(tilt),
          hasTilt_(tilt != Matx33d::eye()) {}

    template <typename T>
    bool operator()(const T* const q, const T* const t, const T* const X, const T* const intr,
                    const T* const k, T* residuals) const
    {
        const Eigen::Map<const Eigen::Quaternion<T>> Q(q);
        const Eigen::Map<const Eigen::Matrix<T, 3, 1>> P(X);
        const Eigen::Matrix<T, 3, 1> Xc = Q * P + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(t);
        const T x = Xc(0) / Xc(2), y = Xc(1) / Xc(2);
        const T r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
        const T radial = (T(1) + k[0] * r2 + k[1] * r4 + k[4] * r6) /
                         (T(1) + k[5] * r2 + k[6] * r4 + k[7] * r6);
        T xd = x * radial + T(2) * k[2] * x * y + k[3] * (r2 + T(2) * x * x) + k[8] * r2 +
               k[9] * r4;
        T yd = y * radial + k[2] * (r2 + T(2) * y * y) + T(2) * k[3] * x * y + k[10] * r2 +
               k[11] * r4;
        if (hasTilt_)
        {
            const T hx = T(tilt_(0, 0)) * xd + T(tilt_(0, 1)) * yd + T(tilt_(0, 2));
            const T hy = T(tilt_(1, 0)) * xd + T(tilt_(1, 1)) * yd + T(tilt_(1, 2));
            const T hw = T(tilt_(2, 0)) * xd + T(tilt_(2, 1)) * yd + T(tilt_(2, 2));
            xd = hx / hw;
            yd = hy / hw;
        }
        residuals[0] = intr[0] * (xd + T(skew_) * yd) + intr[1] - T(u_);
        residuals[1] = intr[0] * T(aspect_) * yd + intr[2] - T(v_);
        return true;
    }

    static ceres::CostFunction* Create(double u, double v, double aspect, double skew,
                                       const Matx33d& tilt)
    {
        return new ceres::AutoDiffCostFunction<LensReprojectionError, 2, 4, 3, 3, 3, 12>(
            new LensReprojectionError(u, v, aspect, skew, tilt));
    }

    double u_, v_, aspect_, skew_;
    Matx33d tilt_;
    bool hasTilt_;
};

/** Relative accuracy of the bundle adjustments' inexact Newton steps (Ceres'
Solver::Options::eta) and the conjugate-gradient steps allowed for one (Ceres' default: 500), for
every iterative adjustment (camera_refiner.cpp, incremental_sfm.cpp). Well-conditioned problems
(100 x 1000 full tracks, CMU hotel) need 2-25 CG steps for 1e-3; on the Oxford dinosaur (91%
missing) 1e-3 took 100-400 a step and tripled the time, while capping them at 50 kept the time
of the 10% default and reached a lower cost. */
const double kBundleForcing = 1e-3;
const int kBundleMaxCgSteps = 50;

/** @brief Every camera's parameter blocks of a bundle adjustment in ONE buffer, camera after
camera: the quaternion (x, y, z, w) at offset 0, then the translation (`tSize` values), then
`extra` values (a per-frame zoom). Ceres orders the blocks of an elimination group by address
(ParameterBlockOrdering keeps a std::set<double*>), and through the ordering the sparse
factorisation and the summation order: blocks in separate heap buffers (one for the rotations,
one for the translations) came in an order that changed with the allocator's state, and with
it the last digits of the solution from call to call. One buffer makes the order the cameras'
and the result reproducible to the bit. */
class CameraBlocks
{
public:
    CameraBlocks(int cameras, int tSize, int extra = 0)
        : stride_(4 + tSize + extra), tSize_(tSize), data_((size_t)cameras * stride_, 0.0) {}
    double* q(int i) { return &data_[(size_t)i * stride_]; }
    double* t(int i) { return &data_[(size_t)i * stride_ + 4]; }
    double* extra(int i) { return &data_[(size_t)i * stride_ + 4 + tSize_]; }
    //! Stores the rotation R of camera i as its unit quaternion.
    void setRotation(int i, const Matx33d& R);
    //! The rotation of camera i (its quaternion normalised).
    Matx33d rotation(int i) const;
private:
    int stride_, tSize_;
    std::vector<double> data_;
};

//! Unit quaternion of a rotation matrix.
inline Eigen::Quaterniond toQuaternion(const Matx33d& R)
{
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m(r, c) = R(r, c);
    Eigen::Quaterniond q(m);
    q.normalize();
    return q;
}

//! Rotation matrix of a quaternion stored (x, y, z, w) (normalised first).
inline Matx33d fromQuaternion(const double* xyzw)
{
    Eigen::Quaterniond q(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
    q.normalize();
    const Eigen::Matrix3d m = q.toRotationMatrix();
    Matx33d R;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            R(r, c) = m(r, c);
    return R;
}

inline void CameraBlocks::setRotation(int i, const Matx33d& R)
{
    const Eigen::Quaterniond qi = toQuaternion(R);
    std::copy(qi.coeffs().data(), qi.coeffs().data() + 4, q(i));
}

inline Matx33d CameraBlocks::rotation(int i) const
{
    return fromQuaternion(&data_[(size_t)i * stride_]);
}

/** @brief Reports a solve's iterations to the stage's progress (ProgressScope::current()) as
step `step`, "iterations" of at most Options::max_num_iterations, and the bound when it goes
(the solve is over). Construct it after the options
are filled, before ceres::Solve, in the same scope; without a scope it does nothing. Returning
SOLVER_CONTINUE always, it does not change the solve. */
class SolverProgress : public ceres::IterationCallback
{
public:
    SolverProgress(ceres::Solver::Options& options, const char* step)
        : scope_(ProgressScope::current()), step_(step), max_(options.max_num_iterations)
    {
        if (scope_)
            options.callbacks.push_back(this);
    }
    //! The solve is over (converged early or not): its step is complete.
    ~SolverProgress() CV_OVERRIDE
    {
        if (scope_)
            scope_->report(step_, max_, max_, "iterations");
    }
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) CV_OVERRIDE
    {
        scope_->report(step_, std::min<int64>(s.iteration, max_), max_, "iterations");
        return ceres::SOLVER_CONTINUE;
    }

private:
    const ProgressScope* scope_;
    String step_;
    int64 max_;
};

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
