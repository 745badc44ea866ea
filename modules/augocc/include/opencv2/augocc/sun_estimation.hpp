// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SUN_ESTIMATION_HPP
#define OPENCV_AUGOCC_SUN_ESTIMATION_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/clone_builder.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/lighting.hpp"
#include "opencv2/augocc/scene.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Parameters of estimateSun(); the defaults are the initializers.

Valid ranges (estimateSun() throws StsBadArg otherwise): maxSamplesPerFrame >= 100,
edgeMarginPx >= 0, normalStep >= 1, sideBins >= 1, coarseStepDeg in [1, 45],
finalStepDeg in (0, coarseStepDeg], 0 <= minElevationDeg < maxElevationDeg <= 90, both penumbra
fractions > 0, skyInlierSigmas >= 0, jackknifeGroups 0 (no uncertainty) or >= 3. */
struct CV_EXPORTS SunEstimationParams
{
    //! Samples (pixels) per frame at most, on a regular pixel lattice.
    int maxSamplesPerFrame = 6000;
    //! Pixels this close to a change of surface (clone / other clone / ground / nothing) are
    //! not used: their normals and colours mix two surfaces.
    double edgeMarginPx = 3;
    //! surfaceFromDepth()'s baseline for the clones' normals (their depth is a voxel staircase).
    int normalStep = 2;
    /** A clone's pixels are grouped by their normal into an up-facing group (normal within 37
    degrees of up) and `sideBins` groups by the normal's azimuth; each group has its own albedo.
    1: every side of an object shares one albedo (more sun information, biased when the sides'
    materials differ). */
    int sideBins = 12;
    //! Coarse grid over the sky: elevation step, degrees (azimuth: the same arc on the sky).
    double coarseStepDeg = 8;
    //! The refinement stops at this step, degrees.
    double finalStepDeg = 0.25;
    //! Elevation range searched, degrees above the ground.
    double minElevationDeg = 3;
    //! Elevation range searched (upper end).
    double maxElevationDeg = 87;
    //! Penumbra of the shadows predicted during the coarse search, as a fraction of the
    //! clones' extent (a smoother objective).
    double coarsePenumbraFraction = 0.04;
    //! Penumbra of the shadows predicted in the final refinement, fraction of the extent.
    double finePenumbraFraction = 0.01;
    /** The sky share is fitted again, at the estimated direction, over the samples whose log
    residual lies within this many RMS of their group's mean (the pixels a clone's visual hull
    shadows wrongly, being larger than its object, left out); 0: no second fit (the default:
    at 2 it measured 3.4 / -4.7 / +18.2 / +5.2 / +4.3% on the 5 test suns against +4.5 / -0.0 /
    +17.0 / +9.0 / +8.8% without, a smaller mean and a larger worst error). */
    double skyInlierSigmas = 0;
    //! Delete-one-group jackknife over this many sectors of the ground around the clones (the
    //! uncertainty); 0: no uncertainty (faster).
    int jackknifeGroups = 8;
};

/** @brief The sun estimated from the footage (estimateSun()). */
struct CV_EXPORTS SunEstimate
{
    //! Unit vector towards the sun, the reconstruction's world frame.
    Vec3d direction = Vec3d(0, 0, 0);
    //! Sky share (Sun::sky, lighting.hpp).
    double sky = 0;
    //! Azimuth (degrees clockwise from north = -ground.back, seen from above) and elevation
    //! above the ground of `direction` (sunDirection()'s convention).
    double azimuthDeg = 0;
    //! Elevation above the ground, degrees.
    double elevationDeg = 0;
    /** 1-sigma angular uncertainty of `direction`, degrees: the delete-one-sector jackknife's
    spread and the search's resolution (finalStepDeg / sqrt(6)) in quadrature; -1: not computed.
    On the synthesized test scenes it is of the order of the error, not a calibrated bound. */
    double angularSigmaDeg = -1;
    //! 1-sigma uncertainty of `sky` (jackknife; -1: not computed).
    double skySigma = -1;
    //! RMS of the fit's residuals, natural-log brightness units.
    double rmsLog = 0;
    //! RMS of the residuals of the same fit with the sun's share forced to zero (sky only): the
    //! larger rmsLog is relative to it, the less the footage says about the sun.
    double rmsLogNoSun = 0;
    //! Samples used (ground, clones).
    int groundSamples = 0;
    //! Samples on the clones' surfaces.
    int cloneSamples = 0;
    //! Frames used.
    int frames = 0;
    //! Objective evaluations (shadow-map sets rendered).
    int evaluations = 0;
};

/** @brief Frames for estimateSun(): at most `maxFrames` frames with a camera, evenly spaced over
the reconstruction's cameras (first and last included). */
CV_EXPORTS std::vector<int> sunEstimationFrames(const Reconstruction& rec, int maxFrames);

/** @brief Estimates the sun's direction and sky share from frames of the footage, the clones of
the real objects and the ground.

Model (lighting.hpp, exactly the synthesizer's and the compositor's): a real pixel is
I = rho * (s + (1 - s) * V * max(0, n . L)), V the fraction of the sun the point sees. Samples:
pixels of the ground (ray and ground plane, normal `ground.up`, where no clone is nearer) and of
the clones (CloneSet::render depth, normals by surfaceFromDepth()), away from surface changes,
neither black nor saturated. Unknowns: L (2 degrees of freedom), s, and one albedo per surface
group (the ground; per clone its top and its sides by normal, SunEstimationParams::sideBins).
V comes from shadow maps of the clones from L (shadow.hpp's ShadowMap, the compositor's). For a
given L and s the log-albedos are the groups' means of log I - log(s + (1 - s) V c): the
objective is the sum of squared log residuals, minimised over s by golden-section search, over L
by a coarse grid on the sky above the ground (smooth shadows) and a compass search refined to
SunEstimationParams::finalStepDeg (sharper shadows). The direction is identified by where the
shadows fall (the ground's dark regions must be the clones' shadows) and by the brightness of
differently turned surfaces of one group; s by the contrast between shadow and sun in a group.
Uncertainty: delete-one-group jackknife over sectors of the ground around the clones.

Deterministic and independent of the thread count (samples are gathered and summed in order).
@param frames BGR (or grey) CV_8U images of the frames `frameNumbers` (same order).
@param frameNumbers frame numbers (each must have a camera in `rec`).
@param rec the reconstruction (cameras, image size).
@param clones the clones of the real objects.
@param ground the ground frame (estimateGround(rec)).
@param params parameters.
Throws StsBadArg on bad parameters, a frame without a camera, a frame of the wrong size or type,
and when too few samples remain (no ground or clone seen).
*/
CV_EXPORTS SunEstimate estimateSun(const std::vector<Mat>& frames,
                                   const std::vector<int>& frameNumbers,
                                   const Reconstruction& rec, const CloneSet& clones,
                                   const GroundFrame& ground,
                                   const SunEstimationParams& params = SunEstimationParams());

//! The estimate as a Sun (direction, sky; penumbra `penumbra` world units).
CV_EXPORTS Sun toSun(const SunEstimate& estimate, double penumbra = Sun().penumbra);

//! @}

} // namespace augocc
} // namespace cv

#endif
