// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CAMERA_REFINER_HPP
#define OPENCV_AUGOCC_CAMERA_REFINER_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/factorization_sfm.hpp"
#include "opencv2/augocc/progress.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

//! Reprojection statistics over every observation of the kept tracks (pixels).
struct CV_EXPORTS ReprojectionStats
{
    int observations = 0;   //!< observations counted
    double rms = 0;         //!< sqrt(mean |e|^2), e the 2D reprojection error
    double median = 0;      //!< median |e|
    double p95 = 0;         //!< 95th percentile of |e|
};

/** @brief Reprojection error of a reconstruction against the tracks it came from, over every
observation whose track has a finite point and whose frame has a camera. */
CV_EXPORTS ReprojectionStats computeReprojectionStats(const Reconstruction& rec,
                                                      const Tracks& tracks);

/** @brief Camera refinement with Ceres (Ong, Teh & Tan @cite Ong1998, Section 4, and beyond).

Modes (Params::mode):
- POSITION_ZOOM (default): exactly the paper's 3F+1 Levenberg-Marquardt. Orientations R_f and
  the 3D points from the factorization are held fixed; the unknowns are the camera position of
  every frame (3 per frame) and one zoom s for the whole sequence, minimising the sum of squared
  reprojection errors. Parameterisation: camera f's position is its translation
  t_f = (tx, ty, tz) (world to camera, so the centre is -R_f^T t_f); under scaled orthography the
  image is u = s * (r1 . X + tx) + cx, v = s * (r2 . X + ty) + cy, so tz (the position along the
  line of sight) does not change the image: it is kept as a parameter of the block but held at
  its input value (a gauge, set by the factorization to a depth in front of the scene) with a
  subset manifold. One global s, as in the paper.
- FULL_BA: scaled-orthographic bundle adjustment: rotations on the quaternion manifold,
  translations (tx, ty), the zoom (global, or per frame with `perFrameScale`), and the points,
  under a robust loss. Gauge: the first camera's rotation and the first camera's zoom are held.
- PERSPECTIVE_BA: the perspective upgrade of an affine solution, a bundle adjustment of the
  pinhole model written in the "perspective strength" form u = s * Xc.x / (1 + kappa * Xc.z) + cx
  (Xc relative to a reference depth 1/kappa; f = s / kappa, after Szeliski & Kang
  @cite Szeliski1994), which is well conditioned near orthography. It starts at kappa = 0,
  i.e. exactly at the scaled-orthographic solution, and refines rotations, translations, points
  and kappa (one focal length, fx = fy, principal point at the image centre) under a robust
  loss. A negative kappa is the depth-reversed twin and is
  flipped, which resolves the orthographic depth-reversal ambiguity. The output model is
  PERSPECTIVE; with no measurable perspective the camera ends 1e4 scene radii away.

Ceres runs with num_threads = cv::getNumThreads().
*/
class CV_EXPORTS OrthoCameraRefiner : public Algorithm
{
public:
    //! What is refined (see the class description).
    enum Mode
    {
        POSITION_ZOOM = 0,  //!< the paper's 3F+1 LM: positions and one zoom
        FULL_BA = 1,        //!< scaled-orthographic bundle adjustment
        PERSPECTIVE_BA = 2  //!< perspective bundle adjustment from the affine solution
    };
    //! Robust loss of the bundle adjustments.
    enum Loss
    {
        LOSS_NONE = 0,      //!< plain least squares
        LOSS_HUBER = 1,     //!< ceres::HuberLoss(lossScale)
        LOSS_CAUCHY = 2     //!< ceres::CauchyLoss(lossScale)
    };

    //! Refinement parameters; the defaults are the initializers.
    struct CV_EXPORTS Params
    {
        //! Mode; the default is the paper's.
        int mode = POSITION_ZOOM;
        //! Loss of FULL_BA and PERSPECTIVE_BA (POSITION_ZOOM is plain least squares).
        int loss = LOSS_HUBER;
        //! Residual at which the robust loss bends, pixels, > 0 (lower down-weights more
        //! observations).
        double lossScale = 2.0;
        //! FULL_BA: one zoom per frame (weak perspective) instead of one for the sequence.
        bool perFrameScale = false;
        //! Levenberg-Marquardt iterations at most, >= 1.
        int maxIterations = 50;
        //! Ceres function_tolerance: stop when the cost changes by less than this fraction,
        //! > 0 (lower iterates longer).
        double functionTolerance = 1e-6;
    };

    /** @brief Creates an instance.
    @param params refinement parameters; throws as setParams() does when they are invalid.
    */
    static Ptr<OrthoCameraRefiner> create(const Params& params);
    //! Creates an instance with default Params (the paper's 3F+1).
    static Ptr<OrthoCameraRefiner> create();
    //! The current parameters.
    virtual Params getParams() const = 0;
    /** @brief Sets the parameters.
    @param params the parameters; StsBadArg on an unknown mode or loss, or a value outside the
    range its field states.
    */
    virtual void setParams(const Params& params) = 0;

    /** @brief Refines a reconstruction in place.
    @param tracks the tracks the reconstruction came from (points rows = track columns).
    @param rec in: a scaled-orthographic reconstruction (any mode) or a perspective one
    (PERSPECTIVE_BA mode); out: refined. Points rows that are NaN stay NaN and are not used.
    @return false (reason logged, `rec` unchanged) when Ceres reports an unusable solution;
    throws StsBadArg on inconsistent input (sizes, model, no usable observation).
    */
    virtual bool refine(const Tracks& tracks, Reconstruction& rec) const = 0;
};

//! Options of recoverCameras() (the `augocc sfm` pipeline).
struct CV_EXPORTS SfmOptions
{
    /** Output model: "scaled_orthographic", "perspective" or "auto". `auto` fits both and keeps
    the perspective one only when its reprojection RMS is below autoRatio times the
    scaled-orthographic one (the two models have about the same number of parameters, so a
    clear drop of the error is what tells that perspective effects are present). */
    String model = "auto";
    bool bundleAdjust = true;      //!< run the full scaled-orthographic BA after the 3F+1
    /** The scaled-orthographic BA estimates one zoom per frame (weak perspective: the scale of
    the image changes as the camera moves closer or farther); false keeps the paper's single
    zoom. Overrides refiner.perFrameScale. */
    bool perFrameScale = true;
    //! `auto`: the RMS ratio below which perspective is kept (higher keeps it more often)
    double autoRatio = 0.9;
    FactorizationSfM::Params factorization;  //!< settings of the factorization stage
    OrthoCameraRefiner::Params refiner;  //!< loss and iteration settings shared by the stages
    /** Known intrinsics (`--calibration`, readCalibration() for the tracks' image size): the
    observations are undistorted with them for the affine and perspective stages, the model is
    perspective, and a last bundle adjustment of the pinhole with this lens on the original
    (distorted) observations gives the cameras, which carry `calibration.K` and its
    distortion. Empty `calibration.imageSize`: unknown (see `focal`). */
    Calibration calibration;
    /** Known focal length only (`--focal`), pixels, fx = fy, principal point at the image
    centre, no distortion; 0: unknown. Exclusive with `calibration`. */
    double focal = 0;
    /** With known intrinsics: also refine the focal length (one, the calibration's fy / fx and
    skew kept) and the distortion coefficients the calibration has (all but the tilt tx, ty);
    the principal point stays. false: the given intrinsics stay fixed. */
    bool refineIntrinsics = false;
    /** Without known intrinsics and when the perspective model is kept: self-calibration, a
    lens bundle adjustment of the focal (fx = fy, principal point at the image centre) and the
    radial k1, k2 (COLMAP's RADIAL). The lens kept is the one of {focal only, focal + k1,
    focal + k1 + k2} with the lowest BIC, N log(RSS / N) + p log N over the N residual
    coordinates of the observations within `lensInlierPx` of the richest model's reprojection
    (the same set for all; p counts the lens parameters beyond the focal; focal + k1 + k2 is fitted
only when focal + k1 beat the focal alone), so that a
    coefficient is kept only when it explains more than noise does (a chance drop of the RSS by
    one parameter is chi-square(1) sigma^2, the penalty log N sigma^2). "focal only" keeps the
    perspective solution unchanged. The kept lens is dropped again (the prior, the perspective
    solution, stays) when the focal's relative standard deviation from the Gauss-Newton
    covariance (ceres::Covariance, residuals scaled to their RMS) exceeds `maxFocalRelStd`:
    too little depth variation or rotation to tell the focal from the distance. false: no
    self-calibration (the perspective solution as before). */
    bool selfCalibrate = true;
    //! Self-calibration: inlier threshold of the BIC, pixels (> 0).
    double lensInlierPx = 3.0;
    //! Self-calibration: largest relative standard deviation of the focal that is trusted.
    double maxFocalRelStd = 0.01;
    /** Perspective cameras: rounds of the final bundle adjustment on the observations the
    cameras explain. Each round leaves out every observation whose reprojection error exceeds
    3.16 times the median one (the 99.9th percentile of the residual length under Gaussian
    noise, its scale from the median): tracks an occluding contour dragged along after their
    point went out of sight, T-junctions of contours at different depths, which the tracker's
    forward-backward check cannot see and per-track rejection keeps when most of the track is
    good. A point left with fewer than 3 explained observations is dropped. Rounds stop when
    the count left out stops changing. With self-calibration the lens is chosen again on the
    observations the first choice explains. 0: every observation is used (before issue 15). */
    int explainedRounds = 3;
    //! Progress (stage "sfm"): each bundle adjustment is a step counting its iterations.
    ProgressCallback progress;
};

//! What recoverCameras() did.
struct CV_EXPORTS SfmReport
{
    int inlierTracks = 0;             //!< tracks kept (finite points)
    int rejectedTracks = 0;           //!< tracks rejected as outliers or unusable
    //! of the tracks the factorization rejected, those the final cameras explain (counted in
    //! inlierTracks)
    int rescuedTracks = 0;
    //! tracks whose point has a parallax under 3 noise sigmas: the cameras do not measure its
    //! depth (a skyline, a far mountain), so it is not reconstructed (counted in rejectedTracks)
    int unmeasuredDepthTracks = 0;
    ReprojectionStats factorization;  //!< after the factorization
    ReprojectionStats positionZoom;   //!< after the paper's 3F+1
    ReprojectionStats orthographic;   //!< after the scaled-orthographic BA (if run)
    ReprojectionStats perspective;    //!< after the perspective BA (if run)
    String chosenModel;               //!< "scaled_orthographic" or "perspective"
    /** Lens of the output cameras: "none" (scaled orthographic), "focal" (the perspective
    solution's focal, no distortion), "focal_k1", "focal_k1_k2" (self-calibrated), "given"
    (known intrinsics, fixed) or "given_refined" (`refineIntrinsics`). */
    String lensModel;
    double focal = 0;                 //!< focal length fx of the output cameras, pixels (0: none)
    std::vector<double> distortion;   //!< distortion coefficients of the output cameras
    //! why this lens (the BIC figures, or why the prior was kept), one sentence for the log
    String lensReason;
    //! relative standard deviation of the self-calibrated focal (0: not computed)
    double focalRelStd = 0;
    //! BIC of the models tried, in the order focal, focal_k1, focal_k1_k2 (self-calibration
    //! only; empty otherwise)
    std::vector<double> lensBic;
    //! after the lens bundle adjustment (if run), against the original observations
    ReprojectionStats lens;
    //! observations the final cameras do not explain, left out (SfmOptions::explainedRounds)
    int unexplainedObservations = 0;
    //! the reprojection error beyond which they were left out, pixels (0: none judged)
    double unexplainedThresholdPx = 0;
    //! the final cameras against the observations they explain
    ReprojectionStats explained;
};

/** @brief Factorization, the paper's 3F+1 refinement, optional full bundle adjustment, model
selection and the lens: what `augocc sfm` and `augocc run` call.

Steps:
1. Known intrinsics (SfmOptions::calibration or SfmOptions::focal): the observations are
   undistorted (Camera::undistortPixel) and brought to a square-pixel pinhole with the principal
   point at the image centre, for the stages below (their ReprojectionStats are against these).
2. Factorization, 3F+1, scaled-orthographic BA, depth-reversal prior, perspective BA and the
   `auto` model choice (forced perspective with known intrinsics).
3. Known intrinsics: a pinhole + distortion bundle adjustment (poses on the quaternion manifold,
   points, the refiner's robust loss) on the original, distorted observations, the intrinsics
   held (or refined with SfmOptions::refineIntrinsics). Unknown: the self-calibration of
   SfmOptions::selfCalibrate when the perspective model was kept.
4. Perspective cameras: the final bundle adjustment again on the observations the cameras
   explain (SfmOptions::explainedRounds; with self-calibration the lens is chosen again on them).
5. The rejected tracks the final cameras explain are kept (through the lens).
@param tracks the tracks.
@param options see SfmOptions.
@param report optional: what was done and the error after each stage.
@return the reconstruction (points rows aligned with the track columns).
Throws cv::Exception on degenerate or bad input, and StsError naming the stage when a stage fails.
*/
CV_EXPORTS Reconstruction recoverCameras(const Tracks& tracks,
                                         const SfmOptions& options = SfmOptions(),
                                         SfmReport* report = nullptr);

//! @}

} // namespace augocc
} // namespace cv

#endif
