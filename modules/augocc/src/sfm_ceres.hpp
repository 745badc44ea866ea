// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Ceres residuals of the camera refiner (private: Ceres and Eigen types stay out of the public
// headers). Units: every residual is a reprojection error in pixels, (u, v) order.
// Quaternions are stored (x, y, z, w), the order of Eigen::Quaternion::coeffs() and of
// ceres::EigenQuaternionManifold.

#ifndef OPENCV_AUGOCC_SFM_CERES_HPP
#define OPENCV_AUGOCC_SFM_CERES_HPP

#include <vector>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/ceres.h>

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

/** @brief Scaled-orthographic reprojection of one observation (full bundle adjustment).
Blocks: q (4, rotation world->camera), t (2: tx, ty), s (1: zoom), X (3: world point).
Residual (2): s * ((q * X).xy + t) + c - observed, pixels. */
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
A negative kappa is the depth-reversed (mirror) twin of a positive one. */
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

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
