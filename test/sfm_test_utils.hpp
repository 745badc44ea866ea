// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Camera-recovery test helpers, reusable by any test that needs SfM data or SfM accuracy:
// a pure-math problem generator (points in a box seen by an orbiting camera, with noise,
// partial and outlier tracks) and the comparison of a reconstruction with ground truth up to
// the gauge of the model (a similarity, and for orthography the depth-reversal ambiguity).

#ifndef OPENCV_AUGOCC_TEST_SFM_TEST_UTILS_HPP
#define OPENCV_AUGOCC_TEST_SFM_TEST_UTILS_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc.hpp"

namespace opencv_test {

//! What makeSfmProblem() generates. Scene: points uniform in a box 10 x 6 x 10 world units
//! centred on the origin (y up), camera orbiting about the y axis, looking at the origin.
struct SfmProblemParams
{
    int frames = 60;
    int points = 600;
    cv::Size imageSize = cv::Size(640, 480);
    cv::augocc::CameraModel model = cv::augocc::SCALED_ORTHOGRAPHIC;
    double distanceRatio = 10;       //!< PERSPECTIVE: camera distance / scene size (10 units)
    double orbitDegrees = 50;        //!< azimuth swept over the sequence
    double elevationDegrees = 25;    //!< elevation of the camera above the ground plane
    double pixelsPerUnit = 30;       //!< image scale at the scene centre
    double noiseSigma = 0.5;         //!< Gaussian noise per axis, pixels
    double partialFraction = 0;      //!< tracks that start and end mid-sequence
    double outlierFraction = 0;      //!< tracks that are not a 3D point (gross outliers)
    double missingFraction = 0;      //!< if > 0, partial tracks are sized so that about this
                                     //!< fraction of the whole matrix is missing
    int trackFrames = 0;             //!< if > 0, partial tracks last this many frames on
                                     //!< average (uniform in 0.5-1.5 times it, at least 3),
                                     //!< whatever the length of the shot; missingFraction unused
    uint64 seed = 1;
};

struct SfmProblem
{
    cv::augocc::Tracks tracks;           //!< noisy, partial, with outliers
    cv::augocc::Tracks cleanTracks;      //!< noise-free projections (NaN where unobserved)
    cv::augocc::Reconstruction groundTruth;
    std::vector<uchar> outlier;          //!< 1 where the track is a gross outlier
};

//! Generates a problem (deterministic for params.seed).
SfmProblem makeSfmProblem(const SfmProblemParams& params);

//! Rotation errors of a reconstruction against ground truth, after the best global rotation,
//! over the frames both have.
struct CameraComparison
{
    int frames = 0;
    double meanRotationDeg = 0;
    double maxRotationDeg = 0;
    bool mirrored = false;  //!< the depth-reversed twin of the estimate matched better
};

/** @brief Compares camera orientations with ground truth up to a global rotation (the world
frames differ) and, when `allowMirror`, the orthographic depth reversal (R -> Z R Z,
Z = diag(1, 1, -1)). The global rotation is the chordal L2 mean of R_gt^T R_est. */
CameraComparison compareCameras(const cv::augocc::Reconstruction& est,
                                const cv::augocc::Reconstruction& gt, bool allowMirror = true);

//! Lens figures of a recovered reconstruction against the truth (issue 15).
struct LensFigures
{
    double rotationDeg = 0;      //!< mean rotation error after the best global rotation
    double focalErrorPct = 0;    //!< |f_est - f_true| / f_true, percent
    /** Distortion error at the image corners, pixels: the largest over the four corner pixels
    p of |undistort_est(p) - undistort_true(p)|, each lens undistorting the frame pixel to the
    ideal pinhole pixel with its own K (Camera::undistortPixel): how differently the two lenses
    displace the corners, whatever the focal. */
    double cornerPx = 0;
};
LensFigures measureLens(const cv::augocc::Reconstruction& est,
                        const cv::augocc::Reconstruction& truth);

//! True when two matrices are bitwise equal, NaN matching NaN (thread-reproducibility tests).
bool identicalWithNan(const cv::Mat& a, const cv::Mat& b);

//! Expected RMS (2D, over observations) of isotropic Gaussian pixel noise of sigma per axis.
inline double expectedNoiseRms(double sigma) { return std::sqrt(2.0) * sigma; }

} // namespace opencv_test

#endif
