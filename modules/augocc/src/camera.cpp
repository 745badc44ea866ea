// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "input_limits.hpp"
#include "pinhole.hpp"

namespace cv {
namespace augocc {

String cameraModelName(CameraModel model)
{
    switch (model)
    {
    case SCALED_ORTHOGRAPHIC: return "scaled_orthographic";
    case PERSPECTIVE: return "perspective";
    }
    CV_Error(Error::StsBadArg, cv::format("unknown camera model %d", (int)model));
}

CameraModel parseCameraModel(const String& name)
{
    if (name == "scaled_orthographic")
        return SCALED_ORTHOGRAPHIC;
    if (name == "perspective")
        return PERSPECTIVE;
    CV_Error(Error::StsBadArg, "unknown camera model '" + name +
             "' (expected scaled_orthographic or perspective)");
}

Camera Camera::orthographic(const Matx33d& R, const Vec3d& t, double s, const Point2d& pp, int frame)
{
    Camera c;
    c.model = SCALED_ORTHOGRAPHIC;
    c.frame = frame;
    c.R = R;
    c.t = t;
    c.s = s;
    c.pp = pp;
    return c;
}

Camera Camera::perspective(const Matx33d& R, const Vec3d& t, const Matx33d& K, int frame,
                           const std::vector<double>& distortion)
{
    Camera c;
    c.model = PERSPECTIVE;
    c.frame = frame;
    c.R = R;
    c.t = t;
    c.K = K;
    c.pp = Point2d(K(0, 2), K(1, 2));
    c.distortion = distortion;
    return c;
}

namespace {

// OpenCV's tilted-sensor matrix (computeTiltProjectionMatrix in calib3d's distortion_model.hpp):
// the projection onto the image plane tilted by tauX about x, then tauY about y.
Matx33d tiltMatrix(double tauX, double tauY)
{
    const double cX = std::cos(tauX), sX = std::sin(tauX);
    const double cY = std::cos(tauY), sY = std::sin(tauY);
    const Matx33d rotX(1, 0, 0, 0, cX, sX, 0, -sX, cX);
    const Matx33d rotY(cY, 0, -sY, 0, 1, 0, sY, 0, cY);
    const Matx33d rotXY = rotY * rotX;
    const Matx33d projZ(rotXY(2, 2), 0, -rotXY(0, 2), 0, rotXY(2, 2), -rotXY(1, 2), 0, 0, 1);
    return projZ * rotXY;
}

// The coefficients padded to 14 (zeros).
struct Coeffs
{
    double k[14];
    bool tilt;
    explicit Coeffs(const std::vector<double>& d)
    {
        for (int i = 0; i < 14; i++)
            k[i] = i < (int)d.size() ? d[i] : 0.0;
        tilt = k[12] != 0 || k[13] != 0;
    }
};

// Radial, tangential and thin-prism part (cv::projectPoints before the tilt).
inline Point2d distortNoTilt(const Coeffs& c, double x, double y)
{
    const double* k = c.k;
    const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
    const double a1 = 2 * x * y, a2 = r2 + 2 * x * x, a3 = r2 + 2 * y * y;
    const double cdist = 1 + k[0] * r2 + k[1] * r4 + k[4] * r6;
    const double icdist2 = 1. / (1 + k[5] * r2 + k[6] * r4 + k[7] * r6);
    return Point2d(x * cdist * icdist2 + k[2] * a1 + k[3] * a2 + k[8] * r2 + k[9] * r4,
                   y * cdist * icdist2 + k[2] * a3 + k[3] * a1 + k[10] * r2 + k[11] * r4);
}

Point2d applyTilt(const Matx33d& T, const Point2d& p)
{
    const Vec3d v = T * Vec3d(p.x, p.y, 1.0);
    const double inv = v[2] != 0 ? 1.0 / v[2] : 1.0;
    return Point2d(v[0] * inv, v[1] * inv);
}

} // namespace

bool Camera::hasDistortion() const
{
    if (model != PERSPECTIVE)
        return false;
    for (double d : distortion)
        if (d != 0)
            return true;
    return false;
}

Point2d Camera::distortNormalized(const Point2d& xy) const
{
    if (!hasDistortion())
        return xy;
    const Coeffs c(distortion);
    const Point2d d = distortNoTilt(c, xy.x, xy.y);
    return c.tilt ? applyTilt(tiltMatrix(c.k[12], c.k[13]), d) : d;
}

Point2d Camera::undistortNormalized(const Point2d& xd) const
{
    if (!hasDistortion())
        return xd;
    const Coeffs c(distortion);
    Point2d target = xd;
    if (c.tilt)
        target = applyTilt(tiltMatrix(c.k[12], c.k[13]).inv(), xd);
    // OpenCV's fixed-point start (undistortPoints), then Newton steps on the 2x2 system with a
    // central-difference Jacobian, to a residual of 1e-12 (1e-9 px at a focal of 1000 px).
    const double* k = c.k;
    double x = target.x, y = target.y;
    for (int it = 0; it < 5; it++)
    {
        const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
        const double icdist = (1 + k[5] * r2 + k[6] * r4 + k[7] * r6) /
                              (1 + k[0] * r2 + k[1] * r4 + k[4] * r6);
        if (!(icdist > 0) || !std::isfinite(icdist))
        {
            x = target.x;
            y = target.y;
            break;
        }
        const double dx = k[2] * 2 * x * y + k[3] * (r2 + 2 * x * x) + k[8] * r2 + k[9] * r4;
        const double dy = k[2] * (r2 + 2 * y * y) + k[3] * 2 * x * y + k[10] * r2 + k[11] * r4;
        x = (target.x - dx) * icdist;
        y = (target.y - dy) * icdist;
    }
    const double h = 1e-7;
    for (int it = 0; it < 20; it++)
    {
        const Point2d f = distortNoTilt(c, x, y) - target;
        if (std::abs(f.x) < 1e-13 && std::abs(f.y) < 1e-13)
            break;
        const Point2d fx = (distortNoTilt(c, x + h, y) - distortNoTilt(c, x - h, y)) * (0.5 / h);
        const Point2d fy = (distortNoTilt(c, x, y + h) - distortNoTilt(c, x, y - h)) * (0.5 / h);
        const double det = fx.x * fy.y - fy.x * fx.y;
        if (!(std::abs(det) > 1e-300))
            break;
        x -= (fy.y * f.x - fy.x * f.y) / det;
        y -= (-fx.y * f.x + fx.x * f.y) / det;
    }
    return Point2d(x, y);
}

Point2d Camera::undistortPixel(const Point2d& px) const
{
    if (!hasDistortion())
        return px;
    return detail::pixelOf(K, undistortNormalized(detail::normalizedOf(K, px)));
}

Point2d Camera::distortPixel(const Point2d& px) const
{
    if (!hasDistortion())
        return px;
    return detail::pixelOf(K, distortNormalized(detail::normalizedOf(K, px)));
}

Camera Camera::pinhole() const
{
    Camera c = *this;
    c.distortion.clear();
    return c;
}

Point2d Camera::principalPoint() const
{
    return model == PERSPECTIVE ? Point2d(K(0, 2), K(1, 2)) : pp;
}

Point2d Camera::projectCamera(const Vec3d& Xc) const
{
    if (model == SCALED_ORTHOGRAPHIC)
        return Point2d(s * Xc[0] + pp.x, s * Xc[1] + pp.y);
    const double iz = 1.0 / Xc[2];
    double x = Xc[0] * iz, y = Xc[1] * iz;
    if (!distortion.empty())
    {
        const Point2d d = distortNormalized(Point2d(x, y));
        x = d.x;
        y = d.y;
    }
    return Point2d(K(0, 0) * x + K(0, 1) * y + K(0, 2), K(1, 1) * y + K(1, 2));
}

Vec3d Camera::unproject(const Point2d& px, double z) const
{
    Vec3d Xc;
    if (model == SCALED_ORTHOGRAPHIC)
    {
        Xc = Vec3d((px.x - pp.x) / s, (px.y - pp.y) / s, z);
    }
    else
    {
        double y = (px.y - K(1, 2)) / K(1, 1);
        double x = (px.x - K(0, 2) - K(0, 1) * y) / K(0, 0);
        if (!distortion.empty())
        {
            const Point2d n = undistortNormalized(Point2d(x, y));
            x = n.x;
            y = n.y;
        }
        Xc = Vec3d(x * z, y * z, z);
    }
    return R.t() * (Xc - t);
}

Ray Camera::backproject(const Point2d& px) const
{
    Ray ray;
    if (model == SCALED_ORTHOGRAPHIC)
    {
        ray.origin = unproject(px, 0.0);
        ray.direction = viewDirection();
    }
    else
    {
        ray.origin = center();
        Vec3d d = unproject(px, 1.0) - ray.origin;
        ray.direction = d / cv::norm(d);
    }
    return ray;
}

double Camera::pixelsPerUnit(double z) const
{
    if (model == SCALED_ORTHOGRAPHIC)
        return s;
    return std::sqrt(K(0, 0) * K(1, 1)) / z;
}

Matx34d Camera::projectionMatrix() const
{
    Matx34d Rt(R(0, 0), R(0, 1), R(0, 2), t[0],
               R(1, 0), R(1, 1), R(1, 2), t[1],
               R(2, 0), R(2, 1), R(2, 2), t[2]);
    if (model == PERSPECTIVE)
        return K * Rt;
    Matx33d A(s, 0, pp.x,
              0, s, pp.y,
              0, 0, 1);
    Matx34d P = A * Matx34d(R(0, 0), R(0, 1), R(0, 2), t[0],
                            R(1, 0), R(1, 1), R(1, 2), t[1],
                            0, 0, 0, 1);
    return P;
}

void Camera::validate(const String& what) const
{
    const String where = what.empty() ? String("camera") : what;
    auto finite = [](const double* p, int n) {
        for (int i = 0; i < n; i++)
            if (!std::isfinite(p[i]))
                return false;
        return true;
    };
    if (!finite(R.val, 9) || !finite(t.val, 3))
        CV_Error(Error::StsBadArg, where + ": R or t holds a non-finite value");
    for (int k = 0; k < 3; k++)
        detail::checkMagnitude(t[k], detail::kMaxSceneCoordinate, where + cv::format(": t[%d]", k));
    const Matx33d RtR = R.t() * R;
    const double orthoErr = cv::norm(RtR - Matx33d::eye(), NORM_INF);
    const double det = cv::determinant(R);
    if (orthoErr > 1e-6 || std::abs(det - 1.0) > 1e-6)
        CV_Error(Error::StsBadArg, where + cv::format(": R is not a rotation "
                 "(|R^T R - I|_inf = %.3g, det = %.6f)", orthoErr, det));
    if (model == SCALED_ORTHOGRAPHIC)
    {
        if (!std::isfinite(s) || s <= 0)
            CV_Error(Error::StsBadArg, where + cv::format(": scale s = %g must be positive", s));
        if (!std::isfinite(pp.x) || !std::isfinite(pp.y))
            CV_Error(Error::StsBadArg, where + ": principal point is not finite");
        detail::checkMagnitude(s, detail::kMaxPixelCoordinate, where + ": scale s");
        detail::checkMagnitude(pp.x, detail::kMaxPixelCoordinate, where + ": principal point x");
        detail::checkMagnitude(pp.y, detail::kMaxPixelCoordinate, where + ": principal point y");
    }
    else
    {
        if (!finite(K.val, 9))
            CV_Error(Error::StsBadArg, where + ": K holds a non-finite value");
        if (K(0, 0) <= 0 || K(1, 1) <= 0)
            CV_Error(Error::StsBadArg, where + cv::format(": focal lengths fx = %g, fy = %g must "
                     "be positive", K(0, 0), K(1, 1)));
        if (K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1)
            CV_Error(Error::StsBadArg, where + ": K must be upper triangular with K(2,2) = 1");
        for (int k = 0; k < 6; k++)
            detail::checkMagnitude(K.val[k], detail::kMaxPixelCoordinate,
                                   where + cv::format(": K(%d, %d)", k / 3, k % 3));
    }
    const size_t n = distortion.size();
    if (n != 0)
    {
        if (model != PERSPECTIVE)
            CV_Error(Error::StsBadArg, where + ": distortion_coefficients are for perspective "
                     "cameras only");
        if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
            CV_Error(Error::StsBadArg, where + cv::format(": distortion_coefficients has %d "
                     "values (expected 4, 5, 8, 12 or 14, as OpenCV)", (int)n));
        if (!finite(distortion.data(), (int)n))
            CV_Error(Error::StsBadArg, where + ": distortion_coefficients holds a non-finite "
                     "value");
    }
}

void projectPoints(const Camera& camera, InputArray objectPoints, OutputArray imagePoints)
{
    Mat X = objectPoints.getMat();
    if (X.empty())
    {
        imagePoints.release();
        return;
    }
    Mat X64;
    if (X.channels() == 1 && X.cols == 3)
        X.convertTo(X64, CV_64F);
    else
    {
        CV_CheckEQ(X.channels(), 3, "objectPoints must be Nx3 or N 3-channel points");
        X.reshape(1, (int)X.total()).convertTo(X64, CV_64F);
    }
    const int n = X64.rows;
    imagePoints.create(n, 1, CV_64FC2);
    Mat dst = imagePoints.getMat();
    for (int i = 0; i < n; i++)
    {
        const double* p = X64.ptr<double>(i);
        const Point2d q = camera.project(Vec3d(p[0], p[1], p[2]));
        dst.at<Vec2d>(i) = Vec2d(q.x, q.y);
    }
}

Matx33d rotationFromRodrigues(const Vec3d& rvec)
{
    Matx33d R;
    cv::Rodrigues(rvec, R);
    return R;
}

double rotationAngleDeg(const Matx33d& Ra, const Matx33d& Rb)
{
    const Matx33d D = Ra.t() * Rb;
    const double c = std::max(-1.0, std::min(1.0, (cv::trace(D) - 1.0) * 0.5));
    return std::acos(c) * 180.0 / CV_PI;
}

} // namespace augocc
} // namespace cv
