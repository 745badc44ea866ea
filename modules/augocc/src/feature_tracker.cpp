// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Shi-Tomasi + pyramidal Lucas-Kanade tracking with a forward-backward check (Kalal et al.
// 2010's criterion) and re-detection, producing the tracks matrix of the factorization.

#include "precomp.hpp"

#include <opencv2/video/tracking.hpp>

namespace cv {
namespace augocc {

namespace {

// Pyramid levels above the base searched by Lucas-Kanade for a track with a velocity (around its
// predicted position: +-28 px with the 15x15 window) and by the backward (checking) pass; the
// per-level cost is the same at every level (one window per point), so the 4 levels of a plain
// pyramidal search cost a third more. Tracks that fail the short search get the full pyramid.
// One level fewer in either pass was 1.5x faster again, but moved `augocc demo` from 99.87% to
// 99.83% pixel agreement (occlusion boundary 1.66 -> 2.27 px; cameras the same): measured.
// Likewise a backward pass that stops early (10 iterations, 0.1 px: it only decides pass/fail)
// cut the Lucas-Kanade time by 16% but moved the demo's occlusion boundary 1.62 -> 4.50 px
// (cameras the same, 0.061 deg: a few tracks more or less move the clone boxes that place the
// virtual dome): measured, not adopted.
const int kPredictedLevels = 2;
const int kBackwardLevels = 2;
// Slices of the tracked points handed to the threads (a fixed number: thread-independent).
const size_t kLkChunks = 16;

// One tracking session: frames are fed one at a time.
class TrackingSession
{
public:
    TrackingSession(const FeatureTracker::Params& p, Size size) : p_(p), size_(size)
    {
        if (!p_.exclusionMask.empty())
        {
            if (p_.exclusionMask.size() != size)
                CV_Error(Error::StsBadSize, cv::format("exclusion mask is %dx%d, frames are "
                         "%dx%d", p_.exclusionMask.cols, p_.exclusionMask.rows, size.width,
                         size.height));
            if (p_.exclusionMask.type() != CV_8UC1)
                CV_Error(Error::StsBadArg, "exclusion mask must be 8-bit single channel");
            excluded_ = p_.exclusionMask > 127;
        }
        // OpenCV's 30 iterations / 0.01 px and a 15x15 window. (An 11x11 window with 10 / 0.03
        // once gave `augocc demo` cameras 23 degrees off; that was the orthographic
        // depth-reversal twin, picked by chance, not tracking: recoverCameras now chooses it.)
        criteria_ = TermCriteria(TermCriteria::COUNT | TermCriteria::EPS, 30, 0.01);
    }

    void addFrame(const Mat& frame)
    {
        if (frame.size() != size_)
            CV_Error(Error::StsBadSize, cv::format("frame %d is %dx%d, the first was %dx%d",
                     frameIndex_, frame.cols, frame.rows, size_.width, size_.height));
        Mat gray;
        if (frame.type() == CV_8UC3)
        {
            cvtColor(frame, gray_, COLOR_BGR2GRAY);  // the buffer is reused frame to frame
            gray = gray_;
        }
        else if (frame.type() == CV_8UC1)
            gray = frame;
        else
            CV_Error(Error::StsUnsupportedFormat, cv::format("frame %d has type %s; expected "
                     "8-bit BGR or grey", frameIndex_, typeToString(frame.type()).c_str()));
        // Two pyramids alternate (this frame's and the previous one), so that their buffers
        // are allocated once per session, not once per frame.
        std::vector<Mat>& pyr = nextPyr_;
        buildOpticalFlowPyramid(gray, pyr, p_.winSize, p_.levels, true);
        if (!live_.empty())
            trackLive(pyr);
        if ((int)live_.size() < p_.redetectRatio * p_.maxTracks)
            detect(gray);
        std::swap(prevPyr_, nextPyr_);
        frameIndex_++;
    }

    Tracks finish() const
    {
        std::vector<int> keep;
        for (int k = 0; k < (int)tracks_.size(); k++)
            if ((int)tracks_[k].pts.size() >= p_.minTrackLength)
                keep.push_back(k);
        Tracks::Builder out(size_, frameIndex_);
        for (int c = 0; c < (int)keep.size(); c++)
        {
            const TrackRec& t = tracks_[keep[c]];
            out.addTrack();
            for (size_t i = 0; i < t.pts.size(); i++)
                out.add(t.start + (int)i, t.pts[i]);
        }
        return out.build("FeatureTracker");
    }

    int frames() const { return frameIndex_; }

private:
    struct TrackRec
    {
        int start;
        std::vector<Point2f> pts;
    };

    bool usable(const Point2f& q) const
    {
        const float b = (float)p_.border;
        if (!(q.x >= b && q.y >= b && q.x <= size_.width - 1 - b && q.y <= size_.height - 1 - b))
            return false;
        return excluded_.empty() || !excluded_.at<uchar>(cvRound(q.y), cvRound(q.x));
    }

    void trackLive(const std::vector<Mat>& pyr)
    {
        const int n = (int)live_.size();
        prev_.resize(n);
        next_.resize(n);
        std::vector<int> predicted, full;
        for (int i = 0; i < n; i++)
        {
            const std::vector<Point2f>& pts = tracks_[live_[i]].pts;
            prev_[i] = pts.back();
            next_[i] = pts.back();
            if (pts.size() >= 2)
            {
                // Constant-velocity prediction: the search starts where the track is expected
                // and only has to cover the change of motion, a short pyramid.
                next_[i] = 2 * pts.back() - pts[pts.size() - 2];
                predicted.push_back(i);
            }
            else
            {
                full.push_back(i);
            }
        }
        std::vector<uchar> ok(n, 0);
        trackSubset(pyr, predicted, std::min(p_.levels, kPredictedLevels), ok);
        // New tracks and those the short search lost (the motion changed): the full pyramid,
        // from no motion, as a plain pyramidal tracker would.
        for (int i : predicted)
        {
            if (!ok[i])
            {
                next_[i] = prev_[i];
                full.push_back(i);
            }
        }
        trackSubset(pyr, full, p_.levels, ok);
        std::vector<int> still;
        still.reserve(n);
        for (int i = 0; i < n; i++)
        {
            if (!ok[i] || !usable(next_[i]))
                continue;
            tracks_[live_[i]].pts.push_back(next_[i]);
            still.push_back(live_[i]);
        }
        live_.swap(still);
    }

    // Forward Lucas-Kanade of the live tracks idx from prev_ (search started at next_, result
    // in next_) over `levels` pyramid levels, then the forward-backward check; ok[i] = passed.
    void trackSubset(const std::vector<Mat>& pyr, const std::vector<int>& idx, int levels,
                     std::vector<uchar>& ok)
    {
        if (idx.empty())
            return;
        const size_t m = idx.size();
        from_.resize(m);
        to_.resize(m);
        for (size_t k = 0; k < m; k++)
        {
            from_[k] = prev_[idx[k]];
            to_[k] = next_[idx[k]];
        }
        // OpenCV 4.6 runs one calcOpticalFlowPyrLK call on one thread (measured: the same time
        // with 1 or 2 threads); every point is tracked independently, so fixed slices of the
        // points are tracked in parallel: results do not depend on the number of threads.
        std::vector<uchar> pass(m, 0);
        const int chunks = (int)std::min<size_t>(m, kLkChunks);
        const std::vector<Mat>& prevPyr = prevPyr_;
        parallel_for_(Range(0, chunks), [&](const Range& r) {
            std::vector<Point2f> from, to, back;
            std::vector<uchar> st, stBack;
            std::vector<float> err;
            for (int c = r.start; c < r.end; c++)
            {
                const size_t a = m * c / chunks, b = m * (c + 1) / chunks;
                from.assign(from_.begin() + a, from_.begin() + b);
                to.assign(to_.begin() + a, to_.begin() + b);
                calcOpticalFlowPyrLK(prevPyr, pyr, from, to, st, err, p_.winSize, levels,
                                     criteria_, OPTFLOW_USE_INITIAL_FLOW);
                // The backward pass starts at the original point: a good track returns there
                // within the threshold, a drifted one converges to where its new window came
                // from; that search needs no more than kBackwardLevels levels.
                back = from;
                calcOpticalFlowPyrLK(pyr, prevPyr, to, back, stBack, err, p_.winSize,
                                     std::min(levels, kBackwardLevels), criteria_,
                                     OPTFLOW_USE_INITIAL_FLOW);
                const double fb2 = p_.fbThreshold * p_.fbThreshold;
                for (size_t k = a; k < b; k++)
                {
                    const Point2f d = back[k - a] - from[k - a];
                    to_[k] = to[k - a];
                    pass[k] = st[k - a] && stBack[k - a] && d.dot(d) <= fb2;
                }
            }
        });
        for (size_t k = 0; k < m; k++)
        {
            next_[idx[k]] = to_[k];
            ok[idx[k]] = pass[k];
        }
    }

    void detect(const Mat& gray)
    {
        Mat mask(size_, CV_8U, Scalar(255));
        if (!excluded_.empty())
            mask.setTo(0, excluded_);
        const int b = p_.border;
        mask.rowRange(0, b).setTo(0);
        mask.rowRange(size_.height - b, size_.height).setTo(0);
        mask.colRange(0, b).setTo(0);
        mask.colRange(size_.width - b, size_.width).setTo(0);
        const int r = std::max(1, (int)std::ceil(p_.minDistance));
        for (int k : live_)
            circle(mask, tracks_[k].pts.back(), r, Scalar(0), FILLED);
        const int want = p_.maxTracks - (int)live_.size();
        if (want <= 0)
            return;
        std::vector<Point2f> corners;
        goodFeaturesToTrack(gray, corners, want, p_.quality, p_.minDistance, mask,
                            p_.blockSize);
        if (corners.empty())
            return;
        // Sub-pixel corner positions: the start of a track is an observation like any other.
        cornerSubPix(gray, corners, Size(3, 3), Size(-1, -1),
                     TermCriteria(TermCriteria::COUNT | TermCriteria::EPS, 20, 0.01));
        for (const Point2f& c : corners)
        {
            if (!usable(c))
                continue;
            live_.push_back((int)tracks_.size());
            tracks_.push_back(TrackRec{frameIndex_, {c}});
        }
    }

    FeatureTracker::Params p_;
    Size size_;
    Mat excluded_;
    TermCriteria criteria_;
    Mat gray_;
    std::vector<Mat> prevPyr_, nextPyr_;
    std::vector<Point2f> prev_, next_, from_, to_;   // buffers of trackLive
    std::vector<TrackRec> tracks_;
    std::vector<int> live_;
    int frameIndex_ = 0;
};

class FeatureTrackerImpl CV_FINAL : public FeatureTracker
{
public:
    explicit FeatureTrackerImpl(const Params& p) { setParams(p); }

    Params getParams() const CV_OVERRIDE { return params_; }

    void setParams(const Params& p) CV_OVERRIDE
    {
        if (p.maxTracks < 4)
            CV_Error(Error::StsBadArg, cv::format("FeatureTracker: maxTracks = %d must be >= 4",
                     p.maxTracks));
        if (!(p.quality > 0 && p.quality < 1) || !(p.minDistance >= 0) || p.blockSize < 3)
            CV_Error(Error::StsBadArg, "FeatureTracker: quality must be in (0, 1), minDistance "
                     ">= 0, blockSize >= 3");
        if (p.winSize.width < 5 || p.winSize.height < 5 || p.levels < 0 || p.levels > 8)
            CV_Error(Error::StsBadArg, "FeatureTracker: winSize must be at least 5x5 and "
                     "levels in 0..8");
        if (!(p.fbThreshold > 0) || !(p.redetectRatio > 0 && p.redetectRatio <= 1) ||
            p.minTrackLength < 1 || p.border < 0)
            CV_Error(Error::StsBadArg, "FeatureTracker: fbThreshold must be positive, "
                     "redetectRatio in (0, 1], minTrackLength >= 1, border >= 0");
        params_ = p;
    }

    void track(InputArrayOfArrays framesArg, Tracks& out) const CV_OVERRIDE
    {
        std::vector<Mat> frames;
        framesArg.getMatVector(frames);
        if (frames.size() < 2)
            CV_Error(Error::StsBadArg, cv::format("FeatureTracker: %d frames; tracking needs "
                     "at least 2", (int)frames.size()));
        TrackingSession s(params_, frames[0].size());
        for (const Mat& f : frames)
        {
            s.addFrame(f);
            detail::reportProgress(params_.progress, "track", "", s.frames(),
                                   (int64)frames.size(), "frames");
        }
        out = s.finish();
    }

    void track(const Ptr<FrameSource>& source, Tracks& out) const CV_OVERRIDE
    {
        if (source.empty())
            CV_Error(Error::StsBadArg, "FeatureTracker: no frame source");
        TrackingSession s(params_, source->size());
        const int total = std::max(0, source->count() - source->position());
        Mat frame;
        while (source->read(frame))
        {
            s.addFrame(frame);
            detail::reportProgress(params_.progress, "track", "", s.frames(),
                                   std::max(total, s.frames()), "frames");
        }
        if (s.frames() < 2)
            CV_Error(Error::StsBadArg, cv::format("FeatureTracker: the input has %d frame(s); "
                     "tracking needs at least 2", s.frames()));
        source->checkUnchanged();  // tracks of two versions of the input are no tracks
        out = s.finish();
    }

private:
    Params params_;
};

} // namespace

Ptr<FeatureTracker> FeatureTracker::create(const Params& params)
{
    return makePtr<FeatureTrackerImpl>(params);
}

Ptr<FeatureTracker> FeatureTracker::create()
{
    return create(Params());
}

} // namespace augocc
} // namespace cv
