// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_LENS_HPP
#define OPENCV_AUGOCC_LENS_HPP

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include "opencv2/augocc/camera.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief The ideal pinhole view of a camera with lens distortion, and the two warps between it
and the frame.

Every stage that draws or reads pixels through a pose (carving, patches, free space,
photo-consistency, mattes, the compositor, the synthesizer) works in the ideal view, where the
projection is the pinhole x = K' X / z and lines stay lines, and warps its input from the frame
and its output back to the frame, as Blender's Movie Distortion node does. Files always hold
the frame's own, distorted pixels (@ref augocc_conventions_camera "camera conventions").

The ideal camera has the frame camera's pose, the same principal-point offset from the image
centre and the same aspect, a focal length `f' = scale * f` with `scale >= 1` chosen so that the
ideal view samples the scene at least as densely as the frame everywhere in it (no detail is lost
where pincushion distortion stretches the frame), and a size and principal point such that the
whole frame (pixel edges included) lands inside it, plus a margin of 2 pixels. The warps use the
exact model of Camera::distortNormalized() (forward) and Camera::undistortNormalized() (backward,
evaluated exactly on a grid of 4 pixels and bilinearly between: < 0.005 px off for the lenses
OpenCV calibrates). Thread-safe; get() caches the views of the last few intrinsics.
*/
class CV_EXPORTS LensView
{
public:
    /** @brief The view of `camera`'s intrinsics and lens at frame size `frameSize` (the pose is
    ignored), from a cache of the last 8 asked for.
    Throws StsBadArg when the camera is not PERSPECTIVE, or when its distortion folds over the
    frame (a pixel of the frame's border that no ideal point distorts to: the model has no
    inverse there, as OpenCV's undistortPoints would silently return a wrong point). */
    static Ptr<const LensView> get(const Camera& camera, Size frameSize);

    //! Frame size the view was made for.
    Size frameSize() const { return frameSize_; }
    //! Size of the ideal image.
    Size idealSize() const { return idealSize_; }
    //! Intrinsics K' of the ideal pinhole.
    const Matx33d& idealK() const { return idealK_; }
    //! The ideal pinhole of a frame camera with these intrinsics: its pose, K', no distortion.
    Camera idealCamera(const Camera& frameCamera) const;
    //! A frame pixel to the ideal view's pixel that sees the same ray.
    Point2d frameToIdeal(const Point2d& px) const;
    //! An ideal view's pixel to the frame pixel that sees the same ray.
    Point2d idealToFrame(const Point2d& px) const;

    /** @brief Warps a frame-sized image into the ideal view (cv::remap).
    @param frameImage image of frameSize().
    @param idealImage output of idealSize(); pixels the frame does not see get `border`.
    @param interpolation cv::remap's interpolation (INTER_LINEAR, INTER_NEAREST, ...).
    @param border value outside the frame. */
    void toIdeal(InputArray frameImage, OutputArray idealImage,
                 int interpolation = INTER_LINEAR, const Scalar& border = Scalar()) const;
    /** @brief Warps an image of the ideal view back into the frame (cv::remap).
    @param idealImage image of idealSize().
    @param frameImage output of frameSize().
    @param interpolation cv::remap's interpolation.
    @param border value of frame pixels outside the ideal image (none, by construction). */
    void toFrame(InputArray idealImage, OutputArray frameImage,
                 int interpolation = INTER_LINEAR, const Scalar& border = Scalar()) const;

    //! Per frame pixel, the ideal pixel it sees (frameSize(), CV_32FC2; cv::remap's map).
    const Mat& frameMap() const { return toFrameMap_; }
    //! Per ideal pixel, the frame pixel it sees (idealSize(), CV_32FC2; cv::remap's map).
    const Mat& idealMap() const { return toIdealMap_; }

    //! Internal: use get().
    LensView(const Camera& camera, Size frameSize);

private:
    Camera lens_;          // intrinsics and distortion of the frame (pose unused)
    Size frameSize_, idealSize_;
    Matx33d idealK_;
    Mat toIdealMap_;       // idealSize, CV_32FC2: the frame pixel each ideal pixel sees
    Mat toFrameMap_;       // frameSize, CV_32FC2: the ideal pixel each frame pixel sees
};

//! @}

} // namespace augocc
} // namespace cv

#endif
