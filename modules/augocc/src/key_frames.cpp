// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"

#include <cstdint>

namespace cv {
namespace augocc {

namespace {

// Observed tracks of each frame as a bit set (64 tracks per word).
std::vector<std::vector<uint64_t>> visibilitySets(const Tracks& tracks,
                                                  const std::vector<uchar>& objectTracks)
{
    const int F = tracks.frames(), P = tracks.points();
    const int words = (P + 63) / 64;
    std::vector<std::vector<uint64_t>> sets(F, std::vector<uint64_t>(words, 0));
    parallel_for_(Range(0, F), [&](const Range& r) {
        for (int f = r.start; f < r.end; ++f)
        {
            const Range obs = tracks.frame(f);
            for (int k = obs.start; k < obs.end; ++k)
            {
                const int p = tracks.pointOf(tracks.byFrame(k));
                if (objectTracks.empty() || objectTracks[p])
                    sets[f][p / 64] |= uint64_t(1) << (p % 64);
            }
        }
    });
    return sets;
}

int popcount64(uint64_t v)
{
    return __builtin_popcountll(v);
}

double jaccardDistance(const std::vector<uint64_t>& a, const std::vector<uint64_t>& b)
{
    int inter = 0, uni = 0;
    for (size_t w = 0; w < a.size(); ++w)
    {
        inter += popcount64(a[w] & b[w]);
        uni += popcount64(a[w] | b[w]);
    }
    return uni > 0 ? 1.0 - double(inter) / uni : 0.0;
}

void checkTracks(const Tracks& tracks, const char* what)
{
    if (tracks.frames() <= 0 || tracks.points() <= 0)
        CV_Error(Error::StsBadArg, format("%s: tracks are empty", what));
}

void checkObjectTracks(const Tracks& tracks, const std::vector<uchar>& objectTracks,
                       const char* what)
{
    if (!objectTracks.empty() && int(objectTracks.size()) != tracks.points())
        CV_Error(Error::StsBadSize, format("%s: objectTracks has %d flags for %d tracks", what,
                                           int(objectTracks.size()), tracks.points()));
}

} // namespace

std::vector<int> selectKeyFrames(InputArray _change, int count)
{
    Mat change;
    _change.getMat().convertTo(change, CV_64F);
    if (change.empty() || change.rows != change.cols)
        CV_Error(Error::StsBadSize, format("selectKeyFrames: change must be a non-empty square "
                                           "matrix, got %dx%d", change.rows, change.cols));
    const int N = change.rows;
    for (int a = 0; a < N; ++a)
        for (int b = a + 1; b < N; ++b)
        {
            const double v = change.at<double>(a, b);
            if (!std::isfinite(v) || v < 0)
                CV_Error(Error::StsBadArg, format("selectKeyFrames: change(%d, %d) = %g is not "
                                                  "a finite non-negative number", a, b, v));
        }
    if (N == 1)
        return std::vector<int>(1, 0);
    if (count < 2)
        CV_Error(Error::StsBadArg, format("selectKeyFrames: count = %d, at least 2 (the first "
                                          "and the last frame)", count));
    const int K = std::min(count, N);
    std::vector<int> all;
    if (K == N)
    {
        for (int i = 0; i < N; ++i)
            all.push_back(i);
        return all;
    }
    const double inf = std::numeric_limits<double>::infinity();
    // Stage 1: the smallest achievable bottleneck. best[k][j] = smallest max step of a chain of
    // k + 1 key frames from 0 ending at j. Allowing fewer key frames never helps the bottleneck,
    // so chains of exactly K frames are searched (each step is between distinct frames).
    std::vector<std::vector<double>> best(K, std::vector<double>(N, inf));
    best[0][0] = 0;
    for (int k = 1; k < K; ++k)
        for (int j = k; j < N; ++j)
            for (int i = k - 1; i < j; ++i)
                if (best[k - 1][i] < inf)
                    best[k][j] = std::min(best[k][j],
                                          std::max(best[k - 1][i], change.at<double>(i, j)));
    const double bottleneck = best[K - 1][N - 1];
    // Stage 2: among chains whose every step is within the bottleneck, least sum of squares.
    // A relative slack absorbs rounding in the comparisons of stage 1.
    const double limit = bottleneck * (1 + 1e-12) + 1e-15;
    std::vector<std::vector<double>> cost(K, std::vector<double>(N, inf));
    std::vector<std::vector<int>> from(K, std::vector<int>(N, -1));
    cost[0][0] = 0;
    for (int k = 1; k < K; ++k)
        for (int j = k; j < N; ++j)
            for (int i = k - 1; i < j; ++i)
            {
                const double c = change.at<double>(i, j);
                if (cost[k - 1][i] == inf || c > limit)
                    continue;
                const double v = cost[k - 1][i] + c * c;
                if (v < cost[k][j])
                {
                    cost[k][j] = v;
                    from[k][j] = i;
                }
            }
    CV_Assert(cost[K - 1][N - 1] < inf);
    std::vector<int> keys(K);
    int j = N - 1;
    for (int k = K - 1; k >= 0; --k)
    {
        keys[k] = j;
        j = k > 0 ? from[k][j] : -1;
    }
    return keys;
}

Mat viewChangeMatrix(const Reconstruction& rec)
{
    const int N = int(rec.cameras.size());
    if (N == 0)
        CV_Error(Error::StsBadArg, "viewChangeMatrix: the reconstruction has no camera");
    Mat m(N, N, CV_64F, Scalar::all(0));
    for (int a = 0; a < N; ++a)
        for (int b = a + 1; b < N; ++b)
        {
            const Vec3d da = rec.cameras[a].viewDirection(), db = rec.cameras[b].viewDirection();
            const double c = std::max(-1.0, std::min(1.0, da.dot(db) / (norm(da) * norm(db))));
            m.at<double>(a, b) = m.at<double>(b, a) = std::acos(c) * 180.0 / CV_PI;
        }
    return m;
}

Mat visibilityChangeMatrix(const Tracks& tracks, const std::vector<uchar>& objectTracks)
{
    checkTracks(tracks, "visibilityChangeMatrix");
    checkObjectTracks(tracks, objectTracks, "visibilityChangeMatrix");
    const std::vector<std::vector<uint64_t>> sets = visibilitySets(tracks, objectTracks);
    const int F = tracks.frames();
    Mat m(F, F, CV_64F, Scalar::all(0));
    parallel_for_(Range(0, F), [&](const Range& r) {
        for (int a = r.start; a < r.end; ++a)
            for (int b = 0; b < F; ++b)
                if (b != a)
                    m.at<double>(a, b) = jaccardDistance(sets[a], sets[b]);
    });
    return m;
}

std::vector<uchar> objectTracksFromMasks(const Tracks& tracks, const FrameMasks& masks,
                                         const Reconstruction* rec)
{
    checkTracks(tracks, "objectTracksFromMasks");
    const int P = tracks.points();
    if (masks.empty())
        CV_Error(Error::StsBadArg, "objectTracksFromMasks: no mask given");
    for (const auto& fm : masks)
    {
        if (fm.first < 0 || fm.first >= tracks.frames())
            CV_Error(Error::StsOutOfRange, format("objectTracksFromMasks: mask of frame %d, the "
                                                  "tracks have %d frames", fm.first,
                                                  tracks.frames()));
        if (fm.second.type() != CV_8UC1 || fm.second.size() != tracks.imageSize)
            CV_Error(Error::StsBadSize, format("objectTracksFromMasks: mask of frame %d must be "
                                               "CV_8UC1 %dx%d", fm.first,
                                               tracks.imageSize.width, tracks.imageSize.height));
    }
    if (rec && !rec->points.empty() && rec->points.rows != P)
        CV_Error(Error::StsBadSize, format("objectTracksFromMasks: reconstruction has %d points "
                                           "for %d tracks", rec->points.rows, P));
    auto inside = [](const Mat& m, Point2d p) {
        const int x = cvRound(p.x), y = cvRound(p.y);
        return x >= 0 && y >= 0 && x < m.cols && y < m.rows && m.at<uchar>(y, x) > 127;
    };
    std::vector<uchar> flags(P, 0);
    parallel_for_(Range(0, P), [&](const Range& r) {
        for (int p = r.start; p < r.end; ++p)
        {
            bool haveHull = false;
            if (rec && rec->hasPoint(p))
            {
                bool in = true;
                int tested = 0;
                for (const auto& fm : masks)
                {
                    const int ci = rec->findCamera(fm.first);
                    if (ci < 0)
                        continue;
                    ++tested;
                    if (!inside(fm.second, rec->cameras[ci].project(rec->point(p))))
                    {
                        in = false;
                        break;
                    }
                }
                if (tested > 0)
                {
                    haveHull = true;
                    flags[p] = in ? 1 : 0;
                }
            }
            if (haveHull)
                continue;
            int in = 0, out = 0;
            for (const auto& fm : masks)
                if (tracks.observed(fm.first, p))
                    (inside(fm.second, tracks.at(fm.first, p)) ? in : out)++;
            flags[p] = (in > 0 && out == 0) ? 1 : 0;
        }
    });
    return flags;
}

std::vector<int> suggestKeyFrames(const Reconstruction& rec, int count)
{
    const std::vector<int> idx = selectKeyFrames(viewChangeMatrix(rec), count);
    std::vector<int> frames;
    for (int i : idx)
        frames.push_back(rec.cameras[i].frame);
    return frames;
}

std::vector<int> suggestKeyFrames(const Tracks& tracks, int count,
                                  const std::vector<uchar>& objectTracks)
{
    return selectKeyFrames(visibilityChangeMatrix(tracks, objectTracks), count);
}

std::vector<int> suggestKeyFrames(const Tracks& tracks, const Reconstruction& rec, int count,
                                  const FrameMasks& objectMasks, double degreesPerChange)
{
    if (!(degreesPerChange > 0))
        CV_Error(Error::StsBadArg, format("suggestKeyFrames: degreesPerChange = %g must be > 0",
                                          degreesPerChange));
    checkTracks(tracks, "suggestKeyFrames");
    const int N = int(rec.cameras.size());
    for (const Camera& c : rec.cameras)
        if (c.frame < 0 || c.frame >= tracks.frames())
            CV_Error(Error::StsOutOfRange, format("suggestKeyFrames: camera of frame %d, the "
                                                  "tracks have %d frames", c.frame,
                                                  tracks.frames()));
    std::vector<uchar> objectTracks;
    if (!objectMasks.empty())
        objectTracks = objectTracksFromMasks(tracks, objectMasks, &rec);
    const Mat view = viewChangeMatrix(rec);
    const Mat vis = visibilityChangeMatrix(tracks, objectTracks);
    Mat change(N, N, CV_64F);
    for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b)
            change.at<double>(a, b) =
                std::max(view.at<double>(a, b) / degreesPerChange,
                         vis.at<double>(rec.cameras[a].frame, rec.cameras[b].frame));
    std::vector<int> frames;
    for (int i : selectKeyFrames(change, count))
        frames.push_back(rec.cameras[i].frame);
    return frames;
}

} // namespace augocc
} // namespace cv
