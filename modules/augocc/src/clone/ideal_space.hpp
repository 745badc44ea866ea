// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CLONE_IDEAL_SPACE_HPP
#define OPENCV_AUGOCC_CLONE_IDEAL_SPACE_HPP

#include "clone/clone_set.hpp"
#include "opencv2/augocc/lens.hpp"

namespace cv {
namespace augocc {
namespace detail {

/** @brief Where the clone passes run when the cameras have lens distortion: the ideal pinhole
view of LensView, in which a voxel's footprint is the affine row walk of the pinhole model.

The key-frame silhouettes, the tracks and the frames are warped into it once; the passes run
unchanged on the ideal cameras; the user's silhouettes stay in the set as drawn (frame pixels),
so the clone file means what it meant. Pixels of the ideal image that no frame pixel sees
(outside `inFrame`) are unknown, as pixels off the image are for a pinhole: carving and
patches keep them (keepMask), Step 1 takes no evidence from them, photo-consistency treats the
voxels that project there as unseen in that view. Without distortion the space is the frame and
nothing is warped (the old code path to the last digit). One lens per reconstruction: cameras
with different intrinsics or coefficients are an error. */
struct IdealSpace
{
    Ptr<const LensView> view;  //!< null: no distortion, the frame is the ideal view
    Reconstruction rec;        //!< the cameras as ideal pinholes, imageSize the ideal view's
    Mat inFrame;               //!< CV_8U ideal size, 255 where the frame sees (empty: all)

    bool active() const { return !view.empty(); }
    //! A frame-sized binary mask (0 / 255) warped into the ideal view (0 outside the frame).
    Mat mask(const Mat& frameMask) const;
    //! A frame image warped into the ideal view (bilinear, black outside the frame).
    Mat image(const Mat& frame) const;
    //! The tracks with every observation moved to the ideal view's pixel of the same ray.
    Tracks tracks(const Tracks& frameTracks) const;
};

//! The ideal space of `rec` (inactive when no camera has distortion). @param who names the caller.
CV_EXPORTS IdealSpace makeIdealSpace(const Reconstruction& rec, const char* who);

/** @brief For the lifetime of the guard, every object's key-frame silhouettes in `set` are the
ideal view's (restored to the frame's on destruction, exception or not). Nothing when the space
is inactive. */
class IdealMasks
{
public:
    IdealMasks(CloneSetImpl& set, const IdealSpace& space);
    ~IdealMasks();

private:
    CloneSetImpl& set_;
    std::map<String, std::map<int, Mat> > frameMasks_;
};

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
