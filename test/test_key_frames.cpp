// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "test_silhouette_scene.hpp"

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// Exhaustive reference: every increasing chain 0 = k0 < ... < k(K-1) = N-1.
void bruteForce(const Mat& change, int K, double& bottleneck, double& sumSq)
{
    const int N = change.rows;
    bottleneck = std::numeric_limits<double>::infinity();
    sumSq = std::numeric_limits<double>::infinity();
    for (int bits = 0; bits < (1 << (N - 2)); ++bits)
    {
        std::vector<int> keys(1, 0);
        for (int i = 1; i < N - 1; ++i)
            if (bits & (1 << (i - 1)))
                keys.push_back(i);
        keys.push_back(N - 1);
        if (int(keys.size()) != K)
            continue;
        double mx = 0, sq = 0;
        for (size_t i = 1; i < keys.size(); ++i)
        {
            const double c = change.at<double>(keys[i - 1], keys[i]);
            mx = std::max(mx, c);
            sq += c * c;
        }
        if (mx < bottleneck - 1e-12 || (mx <= bottleneck + 1e-12 && sq < sumSq))
        {
            if (mx < bottleneck - 1e-12)
                sumSq = sq;
            bottleneck = std::min(bottleneck, mx);
            sumSq = std::min(sumSq, sq);
        }
    }
}

TEST(Augocc_KeyFrames, select_matches_exhaustive_search)
{
    RNG rng(11);
    for (int trial = 0; trial < 20; ++trial)
    {
        const int N = rng.uniform(4, 13), K = rng.uniform(2, N + 1);
        Mat change(N, N, CV_64F);
        rng.fill(change, RNG::UNIFORM, 0.0, 1.0);
        const std::vector<int> keys = selectKeyFrames(change, K);
        ASSERT_EQ(K, int(keys.size()));
        EXPECT_EQ(0, keys.front());
        EXPECT_EQ(N - 1, keys.back());
        double mx = 0, sq = 0;
        for (size_t i = 1; i < keys.size(); ++i)
        {
            ASSERT_LT(keys[i - 1], keys[i]);
            const double c = change.at<double>(keys[i - 1], keys[i]);
            mx = std::max(mx, c);
            sq += c * c;
        }
        double refMax, refSq;
        bruteForce(change, K, refMax, refSq);
        EXPECT_NEAR(refMax, mx, 1e-12) << "N " << N << " K " << K;
        EXPECT_NEAR(refSq, sq, 1e-9) << "N " << N << " K " << K;
    }
}

TEST(Augocc_KeyFrames, bad_arg)
{
    EXPECT_THROW(selectKeyFrames(Mat(), 2), cv::Exception);
    EXPECT_THROW(selectKeyFrames(Mat::zeros(3, 4, CV_64F), 2), cv::Exception);
    EXPECT_THROW(selectKeyFrames(Mat::zeros(5, 5, CV_64F), 1), cv::Exception);
    Mat nan = Mat::zeros(4, 4, CV_64F);
    nan.at<double>(0, 2) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(selectKeyFrames(nan, 2), cv::Exception);
    EXPECT_THROW(viewChangeMatrix(Reconstruction()), cv::Exception);
    const Tracks t = Tracks::fromDense(Size(100, 100), Mat(5, 3, CV_32FC2, Scalar(10, 10)));
    EXPECT_THROW(visibilityChangeMatrix(t, std::vector<uchar>(2, 1)), cv::Exception);
    FrameMasks wrongSize;
    wrongSize[0] = Mat::zeros(50, 50, CV_8U);
    EXPECT_THROW(objectTracksFromMasks(t, wrongSize), cv::Exception);
    FrameMasks outOfRange;
    outOfRange[9] = Mat::zeros(100, 100, CV_8U);
    EXPECT_THROW(objectTracksFromMasks(t, outOfRange), cv::Exception);
    Reconstruction rec;
    rec.cameras.push_back(orbitCamera(0, 20, 10, Size(100, 100)));
    EXPECT_THROW(suggestKeyFrames(t, rec, 2, FrameMasks(), 0.0), cv::Exception);
    // One frame: it is the only key frame.
    EXPECT_EQ(std::vector<int>(1, 0), selectKeyFrames(Mat::zeros(1, 1, CV_64F), 3));
}

// The camera holds still for 30 frames, then turns 60 degrees in 30 frames: the key frames go
// where the view turns.
TEST(Augocc_KeyFrames, accuracy_view_change)
{
    Reconstruction rec;
    rec.imageSize = Size(640, 480);
    for (int f = 0; f < 60; ++f)
    {
        const double az = f < 30 ? 0.0 : 2.0 * (f - 29);
        Camera c = orbitCamera(az, 25, 30, rec.imageSize);
        c.frame = f;
        rec.cameras.push_back(c);
    }
    const Mat view = viewChangeMatrix(rec);
    // Same elevation, azimuth apart by d: the axes are at most d apart (less, by cos(elevation)).
    EXPECT_NEAR(0.0, view.at<double>(0, 29), 1e-9);
    EXPECT_LE(view.at<double>(0, 59), 60.0 + 1e-9);
    EXPECT_GT(view.at<double>(0, 59), 50.0);
    const std::vector<int> keys = suggestKeyFrames(rec, 5);
    ASSERT_EQ(5u, keys.size());
    EXPECT_EQ(0, keys.front());
    EXPECT_EQ(59, keys.back());
    for (size_t i = 1; i + 1 < keys.size(); ++i)
        EXPECT_GE(keys[i], 29) << "a key frame where the view does not change";
    // The turn is uniform, so the key frames split it evenly (~15 degrees each, +-1 frame).
    EXPECT_NEAR(44, keys[2], 1);
}

// A facet turns into view: its 20 tracks appear one per frame over frames 20..39. Before and
// after, the set of visible tracks does not change, so the key frames go into 20..40.
TEST(Augocc_KeyFrames, accuracy_facet_appearing)
{
    const int F = 60, P = 70;
    Mat m(F, P, CV_32FC2, Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    for (int f = 0; f < F; ++f)
        for (int p = 0; p < P; ++p)
        {
            const bool seen = p < 50 || f >= 20 + (p - 50);
            if (seen)
                m.at<Point2f>(f, p) = Point2f(10.f + p, 10.f + f);
        }
    const Tracks t = Tracks::fromDense(Size(640, 480), m);
    const std::vector<int> keys = suggestKeyFrames(t, 4);
    ASSERT_EQ(4u, keys.size());
    EXPECT_EQ(0, keys.front());
    EXPECT_EQ(F - 1, keys.back());
    for (int i = 1; i <= 2; ++i)
    {
        EXPECT_GE(keys[i], 20);
        EXPECT_LE(keys[i], 40);
    }
    // Restricted to the first 50 tracks (an object whose look never changes), no frame is
    // preferred; the bottleneck is zero.
    std::vector<uchar> steady(P, 0);
    for (int p = 0; p < 50; ++p)
        steady[p] = 1;
    const Mat vis = visibilityChangeMatrix(t, steady);
    EXPECT_EQ(0.0, norm(vis, NORM_INF));
}

TEST(Augocc_KeyFrames, object_tracks_from_masks)
{
    Mat d(3, 4, CV_32FC2, Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    // Track 0 inside in frame 0; track 1 inside in frame 0 but outside in frame 2; track 2
    // outside; track 3 only seen in frame 1 (no mask there).
    d.at<Point2f>(0, 0) = Point2f(20, 20);
    d.at<Point2f>(0, 1) = Point2f(25, 25);
    d.at<Point2f>(2, 1) = Point2f(80, 80);
    d.at<Point2f>(0, 2) = Point2f(80, 80);
    d.at<Point2f>(1, 3) = Point2f(20, 20);
    const Tracks t = Tracks::fromDense(Size(100, 100), d);
    FrameMasks m;
    m[0] = Mat::zeros(100, 100, CV_8U);
    m[2] = Mat::zeros(100, 100, CV_8U);
    rectangle(m[0], Rect(10, 10, 30, 30), Scalar::all(255), FILLED);
    rectangle(m[2], Rect(10, 10, 30, 30), Scalar::all(255), FILLED);
    const std::vector<uchar> flags = objectTracksFromMasks(t, m);
    EXPECT_EQ(std::vector<uchar>({1, 0, 0, 0}), flags);

    // With a reconstruction: track 3's point projects inside both silhouettes (visual hull).
    Reconstruction rec;
    rec.imageSize = t.imageSize;
    for (int f : {0, 2})
    {
        Camera c = Camera::orthographic(Matx33d::eye(), Vec3d(0, 0, 10), 1.0, Point2d(0, 0), f);
        rec.cameras.push_back(c);
    }
    rec.points = Mat(4, 3, CV_64F, Scalar::all(std::numeric_limits<double>::quiet_NaN()));
    rec.points.at<Vec3d>(3) = Vec3d(20, 20, 0);
    rec.points.at<Vec3d>(2) = Vec3d(20, 90, 0);  // outside in both: not the object's
    const std::vector<uchar> withRec = objectTracksFromMasks(t, m, &rec);
    EXPECT_EQ(std::vector<uchar>({1, 0, 0, 1}), withRec);
}

TEST(Augocc_KeyFrames, multithread_reproducibility)
{
    RNG rng(3);
    Mat d(80, 300, CV_32FC2, Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    for (int p = 0; p < 300; ++p)
    {
        const int a = rng.uniform(0, 80), b = rng.uniform(a, 80);
        for (int f = a; f <= b; ++f)
            d.at<Point2f>(f, p) = Point2f(1.f, 1.f);
    }
    const Tracks t = Tracks::fromDense(Size(640, 480), d);
    setNumThreads(1);
    const Mat one = visibilityChangeMatrix(t);
    const std::vector<int> k1 = suggestKeyFrames(t, 6);
    setNumThreads(4);
    const Mat four = visibilityChangeMatrix(t);
    const std::vector<int> k4 = suggestKeyFrames(t, 6);
    EXPECT_EQ(0.0, norm(one, four, NORM_INF));
    EXPECT_EQ(k1, k4);
}

} // namespace
} // namespace opencv_test

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

// On a synthesized sequence: the building's tracks are found from its two default key-frame
// silhouettes, and the suggested key frames spread the appearance change better than uniform
// spacing does (their largest step is no larger: the partition is optimal).
TEST(Augocc_KeyFrames, accuracy_synthesized_scene)
{
    SceneSynthesizer::Params p;
    p.frames = 30;
    p.numKeyFrames = 2;  // first and last: the default key frames of the paper
    p.numTracks = 400;
    p.partialFraction = 0.3;
    SyntheticScene s;
    SceneSynthesizer::create(p)->synthesize(s);
    const FrameMasks& masks = s.keyFrameMasks.at("building");
    const std::vector<uchar> own = objectTracksFromMasks(s.tracks, masks, &s.groundTruth);
    // The flagged tracks' true points lie on the building (its box, grown by 2% for noise).
    const int b = int(std::find(s.objectNames.begin(), s.objectNames.end(), "building") -
                      s.objectNames.begin());
    Vec3f lo, hi;
    s.objectMeshes[b].bounds(lo, hi);
    const Vec3f pad = 0.02f * (hi - lo);
    int flagged = 0, onBuilding = 0;
    for (int i = 0; i < s.tracks.points(); ++i)
    {
        if (!own[i])
            continue;
        ++flagged;
        const Vec3d X = s.groundTruth.points.at<Vec3d>(i);
        bool in = true;
        for (int k = 0; k < 3; ++k)
            in = in && X[k] >= lo[k] - pad[k] && X[k] <= hi[k] + pad[k];
        onBuilding += in ? 1 : 0;
    }
    const double kMinPrecision = 0.9;  // visual-hull membership from two views admits a few
    ASSERT_GT(flagged, 10);
    EXPECT_GE(double(onBuilding) / flagged, kMinPrecision) << onBuilding << "/" << flagged;

    const int count = 5;
    const double degreesPerChange = 30.0;  // the default of suggestKeyFrames
    const std::vector<int> keys = suggestKeyFrames(s.tracks, s.groundTruth, count, masks);
    ASSERT_EQ(size_t(count), keys.size());
    EXPECT_EQ(0, keys.front());
    EXPECT_EQ(p.frames - 1, keys.back());
    const Mat view = viewChangeMatrix(s.groundTruth), vis = visibilityChangeMatrix(s.tracks, own);
    auto change = [&](int a, int c) {
        return std::max(view.at<double>(a, c) / degreesPerChange, vis.at<double>(a, c));
    };
    auto bottleneck = [&](const std::vector<int>& k) {
        double m = 0;
        for (size_t i = 1; i < k.size(); ++i)
            m = std::max(m, change(k[i - 1], k[i]));
        return m;
    };
    std::vector<int> uniform;
    for (int i = 0; i < count; ++i)
        uniform.push_back(cvRound(double(i) * (p.frames - 1) / (count - 1)));
    std::string list;
    for (int k : keys)
        list += format(" %d", k);
    std::cout << format("[ key frames ]%s: largest step %.3f (uniform spacing: %.3f)",
                        list.c_str(), bottleneck(keys), bottleneck(uniform))
              << std::endl;
    EXPECT_LE(bottleneck(keys), bottleneck(uniform) + 1e-12);
}

} // namespace
} // namespace opencv_test
