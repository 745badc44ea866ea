// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"

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

Camera Camera::perspective(const Matx33d& R, const Vec3d& t, const Matx33d& K, int frame)
{
    Camera c;
    c.model = PERSPECTIVE;
    c.frame = frame;
    c.R = R;
    c.t = t;
    c.K = K;
    c.pp = Point2d(K(0, 2), K(1, 2));
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
    const double x = Xc[0] * iz, y = Xc[1] * iz;
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
        const double y = (px.y - K(1, 2)) / K(1, 1);
        const double x = (px.x - K(0, 2) - K(0, 1) * y) / K(0, 0);
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
