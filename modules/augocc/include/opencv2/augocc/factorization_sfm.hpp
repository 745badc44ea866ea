// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_FACTORIZATION_SFM_HPP
#define OPENCV_AUGOCC_FACTORIZATION_SFM_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Tomasi-Kanade factorization under (scaled) orthography @cite Tomasi1992, as used by
Ong, Teh & Tan @cite Ong1998 (Section 3), made to survive real tracks.

Steps: registration (per-frame centroid), rank-3 affine factorization, metric upgrade (linear
least squares for the symmetric L = Q Q^T under the scaled-orthographic constraints
|i_f|^2 = |j_f|^2, i_f . j_f = 0, with a nearest positive-definite repair), world aligned to the
first reconstructed frame, one global zoom s (pixels per world unit).

Beyond the paper:
- missing data: tracks that do not span the sequence are used. The affine factorization is
  initialised on the largest complete block of frames x tracks, grown by affine triangulation and
  resection, and then refined by alternation (the ALS baseline of Buchanan & Fitzgibbon
  @cite Buchanan2005) over every observation;
- long sequences with short tracks (mean track length below a quarter of the frames, at least
  12 frames): the affine alternation may bend along the chain of short overlaps, so the
  reconstruction is built incrementally with metric cameras instead (@cite Snavely2006,
  @cite Schoenberger2016, specialised to scaled orthography): metric upgrade of the largest
  complete block, then resection of one scaled-orthographic camera at a time from the
  triangulated points, triangulation of the tracks seen twice, local and periodic global
  bundle adjustment with track rejection. Its cameras keep their own zoom (mean 1); if it
  cannot start (no complete block of three distinct views), the factorization path runs;
- gross outliers: tracks whose RMS residual to the affine fit exceeds a robust threshold are
  rejected, the fit redone without them, and so on until the set is stable; a rejected track's
  row in `points` is NaN;
- degenerate input throws cv::Exception (StsBadArg): fewer than three frames or three distinct
  views (Ullman; e.g. pure translation with a fixed line of sight), affine rank below 3, fewer
  than 4 usable tracks, non-finite values other than the NaN pairs of unobserved entries.

Output conventions (beyond the @ref augocc_conventions "module's"): scaled-orthographic cameras
`u = s * (R X + t).x + cx` with (cx, cy) the image centre; world origin at the centroid of the
reconstructed points, world axes those of the first reconstructed camera (R = I), world unit
chosen so that s = 1 (one world unit is one pixel); every camera's t.z is the same positive
depth, `depthRatio` times the scene's RMS radius, so that depths are positive and consistent
between frames (t.z does not change the image under orthography). Orthography leaves a
depth-reversal ambiguity (the mirror image of the scene through the image plane,
R_f -> Z R_f Z, X -> Z X with Z = diag(1, 1, -1), projects to the same pixels): the images do
not decide it and this class returns one of the two; the perspective refinement
(OrthoCameraRefiner::PERSPECTIVE_BA) resolves it when perspective is measurable.
*/
class CV_EXPORTS FactorizationSfM : public Algorithm
{
public:
    //! Factorization parameters; the defaults are the initializers.
    struct CV_EXPORTS Params
    {
        //! Tracks observed in fewer frames are not used, >= 2.
        int minTrackLength = 2;
        //! Missing data: alternation sweeps at most, >= 0.
        int maxAlternations = 300;
        //! Missing data: the alternation stops when a sweep improves the RMS by less than this
        //! fraction, >= 0 (lower iterates longer).
        double alternationTol = 1e-7;
        //! Reject gross-outlier tracks (false keeps every usable track).
        bool rejectOutliers = true;
        //! Floor of the rejection threshold, pixels RMS, > 0 (lower rejects more).
        double outlierThreshold = 2.5;
        //! Rejection threshold = max(outlierThreshold, this * robust sigma of the residuals),
        //! > 0 (lower rejects more).
        double outlierSigmas = 4.0;
        //! Fit / reject / refit rounds at most, >= 1.
        int maxRejectionRounds = 8;
        //! Every camera's t.z = this * RMS radius of the points, > 0: the depth of the scene in
        //! front of the cameras (t.z does not change the image under orthography).
        double depthRatio = 10.0;
    };

    /** @brief Creates an instance.
    @param params factorization parameters; throws as setParams() does when they are invalid.
    */
    static Ptr<FactorizationSfM> create(const Params& params);
    //! Creates an instance with default Params.
    static Ptr<FactorizationSfM> create();
    //! The current parameters.
    virtual Params getParams() const = 0;
    /** @brief Sets the parameters.
    @param params the parameters; StsBadArg when one is outside the range its field states.
    */
    virtual void setParams(const Params& params) = 0;

    /** @brief Recovers scaled-orthographic cameras and 3D points from tracks.
    @param tracks F x P tracks (NaN where unobserved), validated.
    @param out reconstruction: one camera per frame with at least 4 usable observations
    (frames with fewer are left out), `points` P x 3 with NaN rows for rejected or unusable tracks.
    @param inliers optional output, P x 1 CV_8U, 1 where the track was used and kept.
    @return false (reason logged) when the missing-data fit does not connect enough frames and
    tracks to reconstruct; throws on degenerate or bad input (see the class description).
    */
    virtual bool reconstruct(const Tracks& tracks, Reconstruction& out,
                             OutputArray inliers = noArray()) const = 0;
};

//! @}

} // namespace augocc
} // namespace cv

#endif
