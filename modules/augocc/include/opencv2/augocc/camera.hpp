// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CAMERA_HPP
#define OPENCV_AUGOCC_CAMERA_HPP

#include <vector>
#include <opencv2/core.hpp>

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

//! Camera models (@ref augocc_conventions_camera "conventions").
enum CameraModel
{
    SCALED_ORTHOGRAPHIC = 0, //!< the paper's model: u = s * Xc.x + cx, v = s * Xc.y + cy
    PERSPECTIVE = 1          //!< pinhole: u = fx * Xc.x / Xc.z + cx, v = fy * Xc.y / Xc.z + cy
};

//! @brief Contract name of a camera model ("scaled_orthographic", "perspective").
CV_EXPORTS String cameraModelName(CameraModel model);
//! @brief Parses a contract name; throws StsBadArg on an unknown name.
CV_EXPORTS CameraModel parseCameraModel(const String& name);

//! A ray in world coordinates: origin + lambda * direction, direction of unit length.
struct CV_EXPORTS Ray
{
    Vec3d origin;     //!< world point at lambda = 0
    Vec3d direction;  //!< unit direction, world coordinates
    //! Point at parameter lambda.
    Vec3d at(double lambda) const { return origin + lambda * direction; }
};

/** @brief One camera of a reconstruction: pose, model and intrinsics.

The single place where projection, back-projection and depth are defined; every algorithm of
the module uses it instead of re-deriving a projection.
@sa @ref augocc_conventions_camera "Camera conventions"
*/
struct CV_EXPORTS Camera
{
    CameraModel model = SCALED_ORTHOGRAPHIC;  //!< projection model
    int frame = 0;                 //!< 0-based frame index in the input sequence
    Matx33d R = Matx33d::eye();    //!< rotation, world to camera: Xc = R * Xw + t
    Vec3d t = Vec3d(0, 0, 0);      //!< translation, world to camera: Xc = R * Xw + t
    double s = 1.0;                //!< SCALED_ORTHOGRAPHIC: zoom, pixels per world unit
    Matx33d K = Matx33d::eye();    //!< PERSPECTIVE: intrinsics (fx, skew, cx; 0, fy, cy; 0, 0, 1)
    //! SCALED_ORTHOGRAPHIC: principal point (cx, cy), pixels (PERSPECTIVE: in K)
    Point2d pp = Point2d(0, 0);
    /** PERSPECTIVE: OpenCV's lens distortion coefficients (k1, k2, p1, p2[, k3[, k4, k5, k6[,
    s1, s2, s3, s4[, tx, ty]]]]), applied exactly as cv::projectPoints applies them, to the
    normalised point (Xc.x / Xc.z, Xc.y / Xc.z) before K; 0, 4, 5, 8, 12 or 14 values. Empty
    (or all zero): an ideal pinhole. */
    std::vector<double> distortion;

    //! Makes a scaled-orthographic camera.
    static Camera orthographic(const Matx33d& R, const Vec3d& t, double s, const Point2d& pp,
                               int frame = 0);
    //! Makes a perspective camera (distortion: see Camera::distortion).
    static Camera perspective(const Matx33d& R, const Vec3d& t, const Matx33d& K, int frame = 0,
                              const std::vector<double>& distortion = std::vector<double>());

    //! True when the camera is PERSPECTIVE with a non-zero distortion coefficient.
    bool hasDistortion() const;
    /** @brief Lens distortion of a normalised point (x, y) = (Xc.x / Xc.z, Xc.y / Xc.z): the
    distorted normalised point, before K (identity without distortion). */
    Point2d distortNormalized(const Point2d& xy) const;
    /** @brief Inverse of distortNormalized(): the ideal normalised point whose distortion is `xd`,
    by Newton iterations to 1e-12 (cv::undistortPoints with a tight criterion). */
    Point2d undistortNormalized(const Point2d& xd) const;
    /** @brief A frame pixel to the pixel an ideal pinhole with the same K would see (identity
    without distortion or for SCALED_ORTHOGRAPHIC). */
    Point2d undistortPixel(const Point2d& px) const;
    /** @brief Inverse of undistortPixel(): an ideal pinhole pixel to the frame's pixel. */
    Point2d distortPixel(const Point2d& px) const;
    //! The same camera without its lens distortion (an ideal pinhole with the same K).
    Camera pinhole() const;

    //! Principal point (cx, cy) in pixels, whatever the model.
    Point2d principalPoint() const;
    //! World point to camera coordinates.
    Vec3d toCamera(const Vec3d& Xw) const { return R * Xw + t; }
    //! Camera-space depth Xc.z of a world point.
    double depth(const Vec3d& Xw) const
    {
        return R(2, 0) * Xw[0] + R(2, 1) * Xw[1] + R(2, 2) * Xw[2] + t[2];
    }
    //! Projects a camera-space point to pixels.
    Point2d projectCamera(const Vec3d& Xc) const;
    //! Projects a world point to pixels.
    Point2d project(const Vec3d& Xw) const { return projectCamera(toCamera(Xw)); }
    /** @brief Back-projects a pixel to a world ray through it, direction pointing away from the
    camera (increasing depth). For SCALED_ORTHOGRAPHIC the origin lies on the plane Xc.z = 0;
    for PERSPECTIVE it is the camera centre. */
    Ray backproject(const Point2d& px) const;
    //! World point seen at pixel px at camera-space depth z.
    Vec3d unproject(const Point2d& px, double z) const;
    //! Optical axis (camera +z) in world coordinates.
    Vec3d viewDirection() const { return Vec3d(R(2, 0), R(2, 1), R(2, 2)); }
    //! Camera centre in world coordinates (PERSPECTIVE); for SCALED_ORTHOGRAPHIC the world point
    //! with camera coordinates (0, 0, 0).
    Vec3d center() const { return -(R.t() * t); }
    /** @brief Pixels per world unit at camera-space depth z: s for SCALED_ORTHOGRAPHIC,
    sqrt(fx * fy) / z for PERSPECTIVE. Used to size voxels and tolerances. */
    double pixelsPerUnit(double z) const;
    /** @brief The 3x4 matrix P with (u, v, w)^T = P * (X, 1)^T; pixel = (u/w, v/w). For
    SCALED_ORTHOGRAPHIC the last row is (0, 0, 0, 1), i.e. the projection is affine. With lens
    distortion it is the pinhole part only (the camera of undistortPixel()). */
    Matx34d projectionMatrix() const;
    //! Throws StsBadArg when R is not a rotation, s or the focal lengths are not positive, a
    //! value is not finite, or the distortion has another count than 0, 4, 5, 8, 12 or 14 (or is
    //! set on a SCALED_ORTHOGRAPHIC camera). @param what names the source (file, key) in the
    //! message.
    void validate(const String& what = String()) const;
};

/** @brief Projects world points through a camera.
@param camera the camera.
@param objectPoints Nx3 / 1xN CV_64FC3 or CV_32FC3 points, or a vector of Point3d.
@param imagePoints output, N points CV_64FC2.
*/
CV_EXPORTS void projectPoints(const Camera& camera, InputArray objectPoints,
                              OutputArray imagePoints);

//! @brief Rotation matrix from a Rodrigues vector (radians).
CV_EXPORTS Matx33d rotationFromRodrigues(const Vec3d& rvec);
//! @brief Angle in degrees of the rotation Ra^T * Rb.
CV_EXPORTS double rotationAngleDeg(const Matx33d& Ra, const Matx33d& Rb);

//! @}

} // namespace augocc
} // namespace cv

#endif
