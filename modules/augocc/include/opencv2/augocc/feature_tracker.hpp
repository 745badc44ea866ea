// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_FEATURE_TRACKER_HPP
#define OPENCV_AUGOCC_FEATURE_TRACKER_HPP

#include <functional>
#include <opencv2/core.hpp>
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/progress.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Feature tracks for the factorization: Shi-Tomasi corners @cite Shi1994 followed by
pyramidal Lucas-Kanade (OpenCV video module) with a forward-backward check @cite Kalal2010,
and re-detection that keeps about `maxTracks` live tracks spread over the image.

A track starts where a corner is detected and ends when Lucas-Kanade loses it, when tracking
back from the new frame does not return within `fbThreshold` pixels of where it started, when
it leaves the image or enters the exclusion mask. New corners are detected, at least
`minDistance` pixels from every live track, whenever fewer than `redetectRatio * maxTracks`
tracks are alive. The output is the contract's tracks matrix: F x P CV_32FC2, NaN where a track
is not observed; tracks observed in fewer than `minTrackLength` frames are dropped. Results do
not depend on the number of threads.
*/
class CV_EXPORTS FeatureTracker : public Algorithm
{
public:
    //! Tracking parameters; the defaults are the initializers.
    struct CV_EXPORTS Params
    {
        //! Target number of live tracks, >= 4 (more: denser tracks, slower).
        int maxTracks = 1000;
        //! Shi-Tomasi quality level, a fraction in (0, 1) of the strongest corner's response
        //! (lower accepts weaker corners).
        double quality = 0.01;
        //! Minimum distance between tracks, pixels, >= 0 (lower packs them closer).
        double minDistance = 8;
        //! Shi-Tomasi gradient window, pixels, >= 3.
        int blockSize = 3;
        //! Lucas-Kanade window, pixels, at least 5 x 5 (larger follows larger motion, smooths
        //! over detail).
        Size winSize = Size(15, 15);
        //! Pyramid levels above the base, 0..8 (more: larger motion between frames).
        int levels = 3;
        //! Forward-backward error above which a track ends, pixels, > 0 (lower ends more tracks).
        double fbThreshold = 1.0;
        //! Re-detect corners when fewer than this * maxTracks tracks are alive, in (0, 1]
        //! (higher re-detects more often).
        double redetectRatio = 0.9;
        //! Tracks observed in fewer frames are dropped, >= 1.
        int minTrackLength = 3;
        //! Tracks closer than this to the image edge end, pixels, >= 0.
        int border = 4;
        //! Optional CV_8U mask of the frame size, > 127 = no features there.
        Mat exclusionMask;
        //! Progress (stage "track"): frames tracked, after each frame.
        ProgressCallback progress;
    };

    /** @brief Creates a tracker.
    @param params tracking parameters; throws as setParams() does when they are invalid.
    */
    static Ptr<FeatureTracker> create(const Params& params);
    //! Creates a tracker with default Params.
    static Ptr<FeatureTracker> create();
    //! The current parameters.
    virtual Params getParams() const = 0;
    /** @brief Sets the parameters.
    @param params the parameters; StsBadArg when one is outside the range its field states.
    */
    virtual void setParams(const Params& params) = 0;

    /** @brief Tracks features through in-memory frames.
    @param frames BGR CV_8UC3 or grey CV_8UC1 images of one size (at least 2).
    @param out the tracks (image_size = the frames' size).
    Throws StsBadArg / StsBadSize on fewer than two frames, mixed sizes or types, or an exclusion
    mask whose size differs from the frames. */
    virtual void track(InputArrayOfArrays frames, Tracks& out) const = 0;

    /** @brief Tracks features through a frame source (video, image folder, printf pattern),
    reading it from its current position to the end.
    @param source the frames.
    @param out the tracks.
    */
    virtual void track(const Ptr<FrameSource>& source, Tracks& out) const = 0;
};

//! @}

} // namespace augocc
} // namespace cv

#endif
