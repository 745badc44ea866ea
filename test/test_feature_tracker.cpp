// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "sfm_test_utils.hpp"
#include "stats.hpp"

#include <fstream>
#include <opencv2/imgproc.hpp>

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;

// A textured plane moved by a known similarity per frame: every track must follow the true
// motion. Lucas-Kanade on a blurred random texture is accurate to a few hundredths of a pixel;
// 0.1 px median and 0.5 px at the 95th percentile leave room for interpolation of the warp.
const double kTrackMedianPx = 0.1;
const double kTrackP95Px = 0.5;

Mat makeTexture(Size size, uint64 seed)
{
    RNG rng(seed);
    Mat noise(size, CV_8U);
    rng.fill(noise, RNG::UNIFORM, 0, 255);
    Mat tex;
    GaussianBlur(noise, tex, Size(0, 0), 2.0);
    normalize(tex, tex, 0, 255, NORM_MINMAX);
    Mat bgr;
    cvtColor(tex, bgr, COLOR_GRAY2BGR);
    return bgr;
}

// Frame f = texture warped by A_f (2x3): a drift of `speed` px per frame and a slow rotation.
Matx23d frameWarp(int f, double speed, Point2d centre)
{
    const double ang = 0.2 * f;  // degrees
    Matx23d A = Matx23d(getRotationMatrix2D(centre, ang, 1.0));
    A(0, 2) += speed * f;
    A(1, 2) += 0.3 * speed * f;
    return A;
}

std::vector<Mat> makeFrames(int n, Size size, double speed, const Mat& texture)
{
    std::vector<Mat> frames;
    const Point2d c(texture.cols * 0.5, texture.rows * 0.5);
    for (int f = 0; f < n; f++)
    {
        Matx23d A = frameWarp(f, speed, c);
        // Crop the centre of the big texture into the frame.
        A(0, 2) -= (texture.cols - size.width) * 0.5;
        A(1, 2) -= (texture.rows - size.height) * 0.5;
        Mat out;
        warpAffine(texture, out, Mat(A), size, INTER_CUBIC, BORDER_REFLECT);
        frames.push_back(out);
    }
    return frames;
}

// True position in frame f of the point seen at q in frame f0.
Point2d transfer(const Point2d& q, int f0, int f, double speed, Size size, Size tex)
{
    const Point2d c(tex.width * 0.5, tex.height * 0.5);
    const Point2d off((tex.width - size.width) * 0.5, (tex.height - size.height) * 0.5);
    Matx33d A0 = Matx33d::eye(), A1 = Matx33d::eye();
    const Matx23d a0 = frameWarp(f0, speed, c), a1 = frameWarp(f, speed, c);
    for (int r = 0; r < 2; r++)
        for (int k = 0; k < 3; k++)
        {
            A0(r, k) = a0(r, k);
            A1(r, k) = a1(r, k);
        }
    const Vec3d texPt = A0.inv() * Vec3d(q.x + off.x, q.y + off.y, 1.0);
    const Vec3d out = A1 * texPt;
    return Point2d(out[0] - off.x, out[1] - off.y);
}

TEST(Augocc_FeatureTracker, can_create_default)
{
    Ptr<FeatureTracker> t = FeatureTracker::create();
    ASSERT_FALSE(t.empty());
    EXPECT_EQ(1000, t->getParams().maxTracks);
}

TEST(Augocc_FeatureTracker, accuracy_known_motion)
{
    const Size size(320, 240);
    const Mat tex = makeTexture(Size(640, 480), 5);
    const double speed = 3.0;  // px per frame: tracks leave the image and new ones start
    const std::vector<Mat> frames = makeFrames(30, size, speed, tex);
    FeatureTracker::Params p;
    p.maxTracks = 300;
    Tracks tr;
    FeatureTracker::create(p)->track(frames, tr);
    ASSERT_EQ(30, tr.frames());
    ASSERT_GT(tr.points(), 250);
    EXPECT_EQ(size, tr.imageSize);
    std::vector<double> err;
    int lateStarts = 0, earlyEnds = 0;
    for (int c = 0; c < tr.points(); c++)
    {
        int f0 = -1, last = -1;
        for (int f = 0; f < tr.frames(); f++)
        {
            if (!tr.observed(f, c))
                continue;
            if (f0 < 0)
                f0 = f;
            else
            {
                const Point2d q = transfer(Point2d(tr.at(f0, c)), f0, f, speed, size,
                                           tex.size());
                err.push_back(cv::norm(q - Point2d(tr.at(f, c))));
            }
            last = f;
        }
        ASSERT_GE(f0, 0);
        ASSERT_GE(tr.observationCount(c), p.minTrackLength);
        lateStarts += f0 > 0;
        earlyEnds += last < tr.frames() - 1;
    }
    EXPECT_GT(lateStarts, 0);  // tracks start anywhere
    EXPECT_GT(earlyEnds, 0);   // and end anywhere
    const double median = augocc::detail::median(err);
    std::sort(err.begin(), err.end());
    std::cout << "known motion: " << tr.points() << " tracks, " << err.size()
              << " observations, track error median " << median << " px, p95 "
              << err[(size_t)(0.95 * err.size())] << " px" << std::endl;
    EXPECT_LT(median, kTrackMedianPx);
    EXPECT_LT(err[(size_t)(0.95 * err.size())], kTrackP95Px);
}

TEST(Augocc_FeatureTracker, exclusion_mask)
{
    const Size size(320, 240);
    const Mat tex = makeTexture(Size(640, 480), 6);
    const std::vector<Mat> frames = makeFrames(10, size, 1.0, tex);
    FeatureTracker::Params p;
    p.maxTracks = 300;
    p.exclusionMask = Mat::zeros(size, CV_8U);
    const Rect box(100, 60, 120, 100);
    p.exclusionMask(box).setTo(255);
    Tracks tr;
    FeatureTracker::create(p)->track(frames, tr);
    ASSERT_GT(tr.points(), 100);
    for (int f = 0; f < tr.frames(); f++)
        for (int c = 0; c < tr.points(); c++)
            if (tr.observed(f, c))
            {
                const Point2f q = tr.at(f, c);
                EXPECT_FALSE(box.contains(Point(cvRound(q.x), cvRound(q.y))))
                    << "frame " << f << " track " << c;
            }
}

TEST(Augocc_FeatureTracker, bad_arg)
{
    const Mat tex = makeTexture(Size(320, 240), 7);
    Ptr<FeatureTracker> t = FeatureTracker::create();
    Tracks tr;
    std::vector<Mat> one(1, tex);
    EXPECT_THROW(t->track(one, tr), cv::Exception);
    std::vector<Mat> mixed = {tex, Mat(100, 100, CV_8UC3, Scalar::all(0))};
    EXPECT_THROW(t->track(mixed, tr), cv::Exception);
    std::vector<Mat> wrongType = {Mat(240, 320, CV_32F, Scalar(0)),
                                  Mat(240, 320, CV_32F, Scalar(0))};
    EXPECT_THROW(t->track(wrongType, tr), cv::Exception);
    FeatureTracker::Params p;
    p.exclusionMask = Mat::zeros(10, 10, CV_8U);
    std::vector<Mat> two = {tex, tex};
    EXPECT_THROW(FeatureTracker::create(p)->track(two, tr), cv::Exception);
    p = FeatureTracker::Params();
    p.maxTracks = 0;
    EXPECT_THROW(FeatureTracker::create(p), cv::Exception);
    p = FeatureTracker::Params();
    p.fbThreshold = -1;
    EXPECT_THROW(FeatureTracker::create(p), cv::Exception);
    EXPECT_THROW(t->track(Ptr<FrameSource>(), tr), cv::Exception);
}

TEST(Augocc_FeatureTracker, multithread_reproducibility)
{
    const Size size(320, 240);
    const Mat tex = makeTexture(Size(640, 480), 8);
    const std::vector<Mat> frames = makeFrames(10, size, 2.0, tex);
    Tracks a, b;
    setNumThreads(1);
    FeatureTracker::create()->track(frames, a);
    setNumThreads(4);
    FeatureTracker::create()->track(frames, b);
    EXPECT_TRUE(identicalWithNan(a.dense(), b.dense()));
}

// `augocc track` then `augocc sfm` on a synthesized video, no ground-truth tracks: the issue's
// target is a mean rotation error <= 0.3 degrees after alignment.
TEST(Augocc_FeatureTracker, cli_track_then_sfm_on_synthesized_video)
{
    const std::string bin = augoccBinary();
    if (bin.empty())
        GTEST_SKIP() << "augocc binary not built";
    SceneSynthesizer::Params sp;
    sp.frames = 40;
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    const std::string dir = tempDir("sfm_cli");
    for (int f = 0; f < sp.frames; f++)
        ASSERT_TRUE(imwrite(dir + cv::format("/%04d.png", f), scene.frames[f]));
    std::string out;
    ASSERT_EQ(0, runCommand(bin + " track --input " + dir + "/%04d.png --out " + dir +
                            "/tracks.yml", &out)) << out;
    ASSERT_EQ(0, runCommand(bin + " sfm --tracks " + dir + "/tracks.yml --out " + dir +
                            "/rec.yml --model scaled_orthographic --colmap " + dir +
                            "/colmap --ply " + dir + "/points.ply", &out)) << out;
    const Reconstruction rec = readReconstruction(dir + "/rec.yml");
    const CameraComparison c = compareCameras(rec, scene.groundTruth);
    std::cout << "augocc track + sfm on a synthesized video (" << sp.frames
              << " frames): mean rotation error " << c.meanRotationDeg << " deg, max "
              << c.maxRotationDeg << " deg\n" << out << std::endl;
    const double kCliRotDeg = 0.3;  // the target
    EXPECT_EQ(sp.frames, c.frames);
    EXPECT_LT(c.meanRotationDeg, kCliRotDeg);
    // Exports exist and are non-trivial.
    const Tracks tracks = readTracks(dir + "/tracks.yml");
    EXPECT_EQ(sp.frames, tracks.frames());
    std::ifstream cams(dir + "/colmap/cameras.txt"), pts(dir + "/points.ply");
    EXPECT_TRUE(cams.good());
    EXPECT_TRUE(pts.good());
    // Bad input: exit 2 and a message naming the flag.
    EXPECT_EQ(2, runCommand(bin + " track --input " + dir + "/nothing_%04d.png --out " + dir +
                            "/t2.yml", &out)) << out;
    EXPECT_EQ(2, runCommand(bin + " sfm --tracks " + dir + "/tracks.yml --out " + dir +
                            "/r2.yml --model fisheye", &out)) << out;
    EXPECT_NE(std::string::npos, out.find("--model")) << out;
}

} // namespace
} // namespace opencv_test
