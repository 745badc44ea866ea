// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_FEATURE_TRACKER_HPP
#define OPENCV_AUGOCC_FEATURE_TRACKER_HPP

#include <functional>
#include <opencv2/core.hpp>
#include "opencv2/augocc/io.hpp"

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
    struct CV_EXPORTS Params
    {
        int maxTracks = 1000;          //!< target number of live tracks
        double quality = 0.01;         //!< Shi-Tomasi quality level, relative to the best
        double minDistance = 8;        //!< minimum distance between tracks, pixels
        int blockSize = 3;             //!< Shi-Tomasi gradient window
        Size winSize = Size(15, 15);   //!< Lucas-Kanade window
        int levels = 3;                //!< pyramid levels above the base
        double fbThreshold = 1.0;      //!< forward-backward error above which a track ends, px
        double redetectRatio = 0.9;    //!< re-detect when live tracks < this * maxTracks
        int minTrackLength = 3;        //!< drop tracks seen in fewer frames
        int border = 4;                //!< tracks closer than this to the image edge end, px
        //! optional CV_8U mask of the frame size, > 127 = no features there
        Mat exclusionMask;
    };

    static Ptr<FeatureTracker> create(const Params& params);
    //! Creates a tracker with default Params.
    static Ptr<FeatureTracker> create();
    virtual Params getParams() const = 0;
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
    @param progress optional, called after each frame with (frames done, frames expected).
    */
    virtual void track(const Ptr<FrameSource>& source, Tracks& out,
                       const std::function<void(int, int)>& progress = nullptr) const = 0;
};

//! @}

} // namespace augocc
} // namespace cv

#endif
