// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Internals of the camera recovery shared by factorization_sfm.cpp, camera_refiner.cpp,
// sfm_export.cpp and the tests.

#ifndef OPENCV_AUGOCC_SFM_DETAIL_HPP
#define OPENCV_AUGOCC_SFM_DETAIL_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"

namespace cv {
namespace augocc {
namespace detail {

//! COLMAP's minimum triangulation angle (its mapper's min_tri_angle and filter_min_tri_angle),
//! degrees: points seen under less are not triangulated (incremental path) nor kept after the
//! last adjustment (recoverCameras): their depth is set by the errors, not the parallax.
const double kMinTriangulationDeg = 1.5;

//! One observation of a track in a frame.
struct SfmObservation
{
    int frame;
    int point;
    double u, v;
};

/** @brief Observations of a track matrix, grouped by frame and by point (CSR layout).
Throws StsBadArg naming `what` when a value is infinite (NaN pairs are "unobserved"). */
struct CV_EXPORTS ObservationIndex
{
    int frames = 0, points = 0;
    std::vector<SfmObservation> byFrame;   //!< sorted by (frame, point)
    std::vector<int> frameStart;           //!< frames + 1 offsets into byFrame
    std::vector<int> byPoint;              //!< indices into byFrame, sorted by (point, frame)
    std::vector<int> pointStart;           //!< points + 1 offsets into byPoint

    void build(const Tracks& tracks, const String& what);
    int frameCount(int f) const { return frameStart[f + 1] - frameStart[f]; }
    int pointCount(int p) const { return pointStart[p + 1] - pointStart[p]; }
};

/** @brief Affine camera model w_fp = A_f X_p + b_f of the factorization.
A is F x 6 (row-major 2x3 per frame), b F x 2, X P x 3, all CV_64F; solvedFrame/solvedPoint flag
which rows hold an estimate. */
struct CV_EXPORTS AffineModel
{
    Mat A, b, X;
    std::vector<uchar> solvedFrame, solvedPoint;
};

//! A scaled-orthographic view of the incremental reconstruction: u = s (R X + t).xy + c, with c
//! the image centre (Camera::orthographic with t = (t.x, t.y, any depth)).
struct CV_EXPORTS OrthoView
{
    Matx33d R = Matx33d::eye();
    Vec2d t = Vec2d(0, 0);
    double s = 0;
    bool solved = false;
};

/** @brief Incremental scaled-orthographic reconstruction (resection of metric cameras,
triangulation, local and global bundle adjustment; incremental_sfm.cpp) grown from a start.
@param idx the observations.
@param usable tracks that may be used (one flag per track).
@param pp the principal point (image centre).
@param outlierThreshold floor of the track rejection threshold, pixels RMS.
@param outlierSigmas the threshold is max(floor, this x the median track RMS residual).
@param views in: the start (solved views, at least three), out: every view reconstructed.
@param X in/out: P x 3 CV_64F points, NaN rows for tracks without a point (rejected ones too). */
CV_EXPORTS void growIncremental(const ObservationIndex& idx, const std::vector<uchar>& usable,
                                const Point2d& pp, double outlierThreshold,
                                double outlierSigmas, std::vector<OrthoView>& views, Mat& X);

/** @brief Metric upgrade of an affine motion (Tomasi-Kanade): least squares for the symmetric
L = Q Q^T under i^T L i = 1, j^T L j = 1, i^T L j = 0 for every solved frame, nearest
positive-definite repair, Q = V sqrt(D).
@param A F x 6 affine motion (rows of solved frames used).
@param solved solved-frame flags.
@param Q output 3x3.
Throws StsBadArg ("fewer than three distinct views") when the constraints do not determine L. */
CV_EXPORTS void metricUpgrade(const Mat& A, const std::vector<uchar>& solved, Matx33d& Q);

//! Nearest rotation (Frobenius) to a 3x3 matrix, det = +1.
CV_EXPORTS Matx33d nearestRotation(const Matx33d& M);

/** @brief Least-squares 3D point from its observations through known cameras (either model:
perspective uses the linear DLT-like equations, then a few Gauss-Newton steps).
@return false when the observations do not determine the point (fewer than two frames, or
nearly parallel lines of sight). */
CV_EXPORTS bool triangulatePoint(const std::vector<const Camera*>& cams,
                                 const std::vector<Point2d>& obs, Vec3d& X);

//! Depth-reversed (mirror through the image plane) twin of a scaled-orthographic reconstruction:
//! R_f -> Z R_f Z, X -> Z X, Z = diag(1, 1, -1). Projects to exactly the same pixels.
CV_EXPORTS Reconstruction mirrorDepth(const Reconstruction& rec);

//! RMS radius of the finite rows of an N x 3 matrix about their centroid, and the centroid.
CV_EXPORTS double rmsRadius(const Mat& points, Vec3d* centroid = nullptr);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
