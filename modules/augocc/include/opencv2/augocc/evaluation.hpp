// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_EVALUATION_HPP
#define OPENCV_AUGOCC_EVALUATION_HPP

#include <opencv2/core.hpp>
#include "opencv2/augocc/io.hpp"

/*
Scores against a ground truth, for `augocc demo`, the tests and the perf suite: a composite
against the truth rendered with the virtual objects, and the similarity that brings a
reconstruction into the world of a reference one (the synthesizer's ground truth) so that the two
can be compared.
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

//! Scores of a composite against the ground truth (see scoreComposite()).
struct CV_EXPORTS CompositeScore
{
    double fractionWithin = 0;     //!< fraction of pixels whose grey level is within tolerance
    double boundaryDistance = 0;   //!< mean distance (px) between occlusion boundaries, symmetric
    double bandError = 0;          //!< mean |colour error| (0-255, per channel) in the band
    int boundaryPixels = 0;        //!< occlusion-boundary pixels of the ground truth
    int bandPixels = 0;            //!< pixels of the band
};

/** @brief Compares one composite with the ground truth.

@param composite the composite, BGR CV_8UC3.
@param truth the ground truth (e.g. SceneSynthesizer::renderWithVirtual()), BGR CV_8UC3.
@param visible CV_8U, > 127 where the composite shows the virtual objects (coverage >= 1/2).
@param visibleTruth CV_8U, > 127 where the virtual objects are visible in the truth.
@param silhouette CV_8U, > 127 where the virtual objects project (visible or hidden).
@param greyTolerance grey-level tolerance of fractionWithin (the 8).
@param bandRadius half-width in pixels of the band around the true occlusion boundary.

The occlusion boundary is the boundary of the visible region that is not the boundary of the
silhouette: where a real object cuts the virtual one. boundaryDistance averages, over the
boundary pixels of each side, the distance to the other side's visible boundary (0 when the
truth has no occlusion boundary and neither has the composite). bandError is measured in the
pixels within bandRadius of the true occlusion boundary.
*/
CV_EXPORTS CompositeScore scoreComposite(InputArray composite, InputArray truth, InputArray visible,
                                         InputArray visibleTruth, InputArray silhouette,
                                         int greyTolerance = 8, int bandRadius = 2);

//! What scoreShadows() found, on one kind of surface (real or virtual).
struct CV_EXPORTS ShadowScore
{
    double fractionWithin = 1;    //!< band pixels whose grey levels agree within tolerance
    int bandPixels = 0;           //!< pixels where the composite or the truth has a shadow
    double boundaryDistance = 0;  //!< mean distance (px) between shadow boundaries, symmetric
    int boundaryPixels = 0;       //!< shadow-boundary pixels of the truth and the composite
};

/** @brief Compares the shadows of a composite with the ground truth's, on the pixels `mask`
selects (e.g. the real surfaces: no virtual object in either; or the virtual objects: covered in
both).

A pixel has a shadow in an image when its grey level differs from the unshadowed reference by
more than the tolerance; the band is where the composite or the truth has one, and
fractionWithin the fraction of the band where the two agree within the tolerance. The shadow
region of an image is where its grey level is below (1 - kShadowDepth) times the reference's;
boundaryDistance averages, over the boundary pixels of both regions (those more than 2 px from
the pixels `mask` leaves out), the distance to the other region's boundary (to the other
image's band pixels where its region has no boundary: a fainter shadow).
@param reference the unshadowed image (the input frame; for virtual objects, their colour
without the shadows being scored), BGR CV_8UC3.
@param composite the composite, BGR CV_8UC3.
@param truth the ground truth, BGR CV_8UC3.
@param mask CV_8U, > 0 where scored.
@param greyTolerance the 8 grey levels. */
CV_EXPORTS ShadowScore scoreShadows(InputArray reference, InputArray composite, InputArray truth,
                                    InputArray mask, int greyTolerance = 8);
//! scoreShadows(): the darkening (fraction of the reference) that marks the shadow region.
const double kShadowDepth = 0.12;

/** @brief Similarity that maps the world of `rec` onto the world of `reference` (X_ref =
M * X_rec), estimated from the cameras of the frames both have: rotation from the camera
rotations, scale from the zooms (or a joint least-squares with the translation for PERSPECTIVE),
translation by least squares on the camera translations. Used to compare a reconstruction with
the synthetic ground truth. Throws StsBadArg without three common frames. */
CV_EXPORTS Matx44d alignReconstructions(const Reconstruction& rec, const Reconstruction& reference);

//! What measureSlide() found: pixels, over every (grid point, frame) pair counted.
struct CV_EXPORTS SlideStats
{
    int points = 0;        //!< grid points seen in at least two frames
    int observations = 0;  //!< (point, frame) pairs
    double median = 0;     //!< median slide
    double p95 = 0;        //!< 95th percentile
    double max = 0;        //!< worst
};

/** @brief How far a virtual object placed with a recovered reconstruction slides against the
real scene: the figure a user sees.

For a grid of `gridSteps`^3 points spanning the box of the recovered points (their 2nd to 98th
percentiles per axis, grown by `margin` of its size), each point is projected through the
recovered cameras (with their lens); the real point that best explains those pixels through the
true cameras (with their lens) is triangulated (linear start on undistorted rays, then
Gauss-Newton on the pixel error); the slide is the pixel residual in every frame that sees the
point inside the image. Invariant to the similarity ambiguity of the reconstruction: no
alignment is needed. Frames need a camera in both reconstructions; `truth.imageSize` bounds
the images.
Throws StsBadArg when `recovered` has no valid point or the two share fewer than two frames. */
CV_EXPORTS SlideStats measureSlide(const Reconstruction& recovered, const Reconstruction& truth,
                                   int gridSteps = 6, double margin = 0.0);

//! @}

} // namespace augocc
} // namespace cv

#endif
