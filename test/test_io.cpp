// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"

#include "frame_pattern.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/videoio.hpp>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;
namespace fs = std::filesystem;

const float kNaN = std::numeric_limits<float>::quiet_NaN();

Tracks makeTracks(int frames, int points)
{
    Mat m(frames, points, CV_32FC2);
    RNG rng(3);
    for (int f = 0; f < frames; f++)
        for (int p = 0; p < points; p++)
            m.at<Point2f>(f, p) = ((p % 3 == 0) && (f > p % frames))
                                      ? Point2f(kNaN, kNaN)
                                      : Point2f(rng.uniform(0.f, 640.f),
                                                rng.uniform(0.f, 480.f));
    return Tracks::fromDense(Size(640, 480), m);
}

Reconstruction makeReconstruction(CameraModel model)
{
    Reconstruction r;
    r.model = model;
    r.imageSize = Size(640, 480);
    for (int f = 0; f < 4; f++)
    {
        const Matx33d R = rotationFromRodrigues(Vec3d(0.1 * f, 0.2, -0.05 * f));
        if (model == SCALED_ORTHOGRAPHIC)
            r.cameras.push_back(Camera::orthographic(R, Vec3d(0.1 * f, 0.2, 30), 20.0 + f,
                                                     Point2d(320, 240), 2 * f));
        else
            r.cameras.push_back(Camera::perspective(R, Vec3d(0.1 * f, 0.2, 30),
                                                    Matx33d(700, 0, 320, 0, 700, 240, 0, 0, 1),
                                                    2 * f));
    }
    r.points = (Mat_<double>(3, 3) << 1, 2, 3, NAN, NAN, NAN, -1.5, 0.25, 7);
    return r;
}

// Expects fn to throw a cv::Exception whose message contains every fragment.
template <typename Fn>
void expectErrorMentions(Fn fn, std::initializer_list<std::string> fragments)
{
    try
    {
        fn();
        ADD_FAILURE() << "no exception";
    }
    catch (const cv::Exception& e)
    {
        for (const std::string& f : fragments)
            EXPECT_NE(e.err.find(f), std::string::npos) << "'" << f << "' not in: " << e.err;
    }
}

TEST(Augocc_Tracks, regression_round_trip)
{
    const std::string dir = tempDir("io");
    const Tracks t = makeTracks(7, 11);
    for (const char* name : {"tracks.yml", "tracks.yml.gz", "tracks.json"})
    {
        const std::string p = dir + "/" + name;
        writeTracks(p, t);
        const Tracks r = readTracks(p);
        EXPECT_EQ(r.imageSize, t.imageSize);
        ASSERT_EQ(r.frames(), t.frames());
        ASSERT_EQ(r.points(), t.points());
        ASSERT_EQ(r.observations(), t.observations());
        for (int f = 0; f < t.frames(); f++)
            for (int p2 = 0; p2 < t.points(); p2++)
            {
                EXPECT_EQ(r.observed(f, p2), t.observed(f, p2));
                if (t.observed(f, p2))
                {
                    EXPECT_EQ(r.at(f, p2), t.at(f, p2)); // float -> text -> float is exact
                }
            }
    }
    // No temporary file left behind.
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir))
        files += e.path().filename().string()[0] == '.' ? 100 : 1;
    EXPECT_EQ(files, 3);
}

TEST(Augocc_Tracks, bad_arg)
{
    const std::string dir = tempDir("io");
    expectErrorMentions([&] { readTracks(dir + "/missing.yml"); }, {"missing.yml", "not found"});
    const std::string garbage = writeText(dir, "garbage.yml", "%YAML:1.0\n: : [\n");
    expectErrorMentions([&] { readTracks(garbage); }, {"garbage.yml"});
    const std::string head = "%YAML:1.0\n---\n";
    const std::string noSize = writeText(dir, "nosize.yml", head + "frames: 1\npoints: 1\n");
    expectErrorMentions([&] { readTracks(noSize); }, {"nosize.yml", "image_size"});
    const std::string mat1x1 = "tracks: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: \"2f\"\n"
                               "   data: [ 1., 2. ]\n";
    const std::string sz = "image_size: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: i\n"
                           "   data: [ 640, 480 ]\n";
    const std::string noFrames = writeText(dir, "noframes.yml", head + sz + "points: 1\n" + mat1x1);
    expectErrorMentions([&] { readTracks(noFrames); }, {"noframes.yml", "frames"});
    const std::string mismatch = writeText(dir, "mismatch.yml", head + sz + "frames: 2\n"
                                           "points: 1\n" + mat1x1);
    expectErrorMentions([&] { readTracks(mismatch); }, {"mismatch.yml", "frames = 2"});
    const std::string wrongType = writeText(dir, "type.yml", head + sz + "frames: 1\npoints: 1\n"
        "tracks: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: i\n   data: [ 1 ]\n");
    expectErrorMentions([&] { readTracks(wrongType); }, {"type.yml", "tracks"});
    const std::string badSize = writeText(dir, "badsize.yml", head +
        "image_size: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: i\n   data: [ 0, 480 ]\n"
        "frames: 1\npoints: 1\n" + mat1x1);
    expectErrorMentions([&] { readTracks(badSize); }, {"badsize.yml", "image_size"});
    const std::string halfNaN = writeText(dir, "halfnan.yml", head + sz + "frames: 1\npoints: 1\n"
        "tracks: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: \"2f\"\n   data: [ 1., .Nan ]\n");
    expectErrorMentions([&] { readTracks(halfNaN); }, {"halfnan.yml", "NaN"});
}

// Tracks of a long shot with re-detection: every track lives `len` frames, a new one starts
// every `every` frames, so N = P * len grows linearly with F while F x P grows with F^2.
Tracks makeLongTracks(int frames, int len, int perStart, int every = 1)
{
    Tracks::Builder b(Size(640, 360), frames);
    RNG rng(5);
    for (int s = 0; s + len <= frames; s += every)
        for (int k = 0; k < perStart; k++)
        {
            b.addTrack();
            Point2f q(rng.uniform(0.f, 640.f), rng.uniform(0.f, 360.f));
            for (int f = s; f < s + len; f++)
                b.add(f, q += Point2f(0.5f, 0.25f));
        }
    return b.build();
}

std::string readBytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void expectSameTracks(const Tracks& r, const Tracks& t)
{
    EXPECT_EQ(r.imageSize, t.imageSize);
    ASSERT_EQ(r.frames(), t.frames());
    ASSERT_EQ(r.points(), t.points());
    ASSERT_EQ(r.observations(), t.observations());
    for (int i = 0; i < t.observations(); i++)
    {
        ASSERT_EQ(r.frameOf(i), t.frameOf(i));
        ASSERT_EQ(r.pointOf(i), t.pointOf(i));
        ASSERT_EQ(r.uv(i), t.uv(i)) << i;  // float -> text (or base64) -> float is exact
    }
}

TEST(Augocc_Tracks, regression_round_trip_both_forms)
{
    const std::string dir = tempDir("io");
    // 64 observations (text) and 1200 (base64 in the sparse form).
    for (const Tracks& t : {makeTracks(7, 11), makeLongTracks(300, 20, 10, 50)})
        for (TracksForm form : {TRACKS_DENSE, TRACKS_SPARSE, TRACKS_SMALLER})
            for (const char* name : {"tracks.yml", "tracks.yml.gz", "tracks.json"})
            {
                SCOPED_TRACE(cv::format("%d observations, form %d, %s", t.observations(),
                                        (int)form, name));
                const std::string p = dir + "/" + name;
                writeTracks(p, t, form);
                expectSameTracks(readTracks(p), t);
            }
    // The dense form is the file the dense writer always wrote, byte for byte.
    const Tracks t = makeTracks(7, 11);
    writeTracks(dir + "/dense.yml", t, TRACKS_DENSE);
    FileStorage fs(".yml", FileStorage::WRITE | FileStorage::MEMORY);
    fs << "image_size" << (Mat_<int>(1, 2) << 640, 480) << "frames" << 7 << "points" << 11
       << "tracks" << t.dense();
    EXPECT_EQ(readBytes(dir + "/dense.yml"), fs.releaseAndGetString());
    // The sparse form follows the contract: obs_index (frame, point) sorted by point, then frame.
    writeTracks(dir + "/sparse.yml", t, TRACKS_SPARSE);
    FileStorage in(dir + "/sparse.yml", FileStorage::READ);
    Mat index, uv;
    in["obs_index"] >> index;
    in["obs_uv"] >> uv;
    EXPECT_TRUE(in["tracks"].empty());
    ASSERT_EQ(index.type(), CV_32S);
    ASSERT_EQ(uv.type(), CV_32F);
    ASSERT_EQ(index.rows, t.observations());
    for (int i = 1; i < index.rows; i++)
        EXPECT_LT(std::make_pair(index.at<int>(i - 1, 1), index.at<int>(i - 1, 0)),
                  std::make_pair(index.at<int>(i, 1), index.at<int>(i, 0)));
}

TEST(Augocc_Tracks, regression_observation_order)
{
    // Any order of observations reads the same; the frame index lists points increasing.
    const Tracks t = makeTracks(7, 11);
    const int N = t.observations();
    Mat index(N, 2, CV_32S), uv(N, 2, CV_32F);
    for (int i = 0; i < N; i++)
    {
        const int j = (i * 7) % N;  // a permutation: N is not a multiple of 7 (asserted)
        index.at<int>(j, 0) = t.frameOf(i);
        index.at<int>(j, 1) = t.pointOf(i);
        uv.at<float>(j, 0) = t.uv(i).x;
        uv.at<float>(j, 1) = t.uv(i).y;
    }
    ASSERT_NE(N % 7, 0);
    expectSameTracks(Tracks::fromObservations(t.imageSize, 7, 11, index, uv), t);
    for (int f = 0; f < t.frames(); f++)
    {
        const Range r = t.frame(f);
        for (int k = r.start; k < r.end; k++)
        {
            EXPECT_EQ(t.frameOf(t.byFrame(k)), f);
            if (k > r.start)
            {
                EXPECT_LT(t.pointOf(t.byFrame(k - 1)), t.pointOf(t.byFrame(k)));
            }
        }
    }
    EXPECT_MAT_NEAR(Tracks::fromDense(t.imageSize, t.dense()).dense(), t.dense(), 0);
    // A sub-block: frames {6, 0}, points {3, 1}.
    const Mat block = t.dense({6, 0}, {3, 1});
    ASSERT_EQ(block.size(), Size(2, 2));
    for (int r = 0; r < 2; r++)
        for (int c = 0; c < 2; c++)
        {
            const Point2f a = block.at<Point2f>(r, c), b = t.at(r ? 0 : 6, c ? 1 : 3);
            EXPECT_TRUE(a == b || (std::isnan(a.x) && std::isnan(b.x)));
        }
}

TEST(Augocc_Tracks, regression_size_rule)
{
    // writeTracks picks the smaller text: the dense form for full tracks, the sparse one for
    // short ones; whichever it writes is the smaller of the two (compared before compression).
    const std::string dir = tempDir("io");
    const std::string p = dir + "/tracks.yml";
    int dense = 0, sparse = 0;
    for (int len : {2, 10, 40, 60})
    {
        const Tracks t = makeLongTracks(60, len, 12, 3);
        SCOPED_TRACE(cv::format("tracks of %d frames, %d observations", len, t.observations()));
        const size_t d = tracksFileBytes(p, t, TRACKS_DENSE);
        const size_t s = tracksFileBytes(p, t, TRACKS_SPARSE);
        writeTracks(p, t);
        const std::string text = readBytes(p);
        EXPECT_EQ(text.size(), std::min(d, s));
        const bool isSparse = text.find("obs_index") != std::string::npos;
        EXPECT_EQ(isSparse, s < d);
        EXPECT_NE(isSparse, text.find("tracks:") != std::string::npos);
        (isSparse ? sparse : dense)++;
        // The rule's shortcut: every dense cell takes at least 8 bytes of text.
        EXPECT_GE(d, (size_t)8 * t.frames() * t.points());
    }
    EXPECT_GT(dense, 0) << "full tracks: dense";
    EXPECT_GT(sparse, 0) << "short tracks: sparse";
}

TEST(Augocc_Tracks, regression_long_shot_linear_size)
{
    // A 1800-frame shot whose tracks live 30 frames, 4 new each frame (re-detection): N = 2.1e5,
    // F x P = 1800 x 7084 = 1.3e7 cells. The file is sparse and its size linear in N: bytes per
    // observation at 1800 frames within 2 % of that at 180 (fixed headers are the difference).
    const std::string dir = tempDir("io");
    double perObs[2];
    int k = 0;
    for (int frames : {180, 1800})
    {
        const Tracks t = makeLongTracks(frames, 30, 4);
        const std::string p = dir + cv::format("/long%d.yml", frames);
        writeTracks(p, t);
        const std::string text = readBytes(p);
        EXPECT_NE(text.find("obs_index"), std::string::npos);
        perObs[k++] = (double)text.size() / t.observations();
        if (frames == 1800)
            expectSameTracks(readTracks(p), t);
    }
    EXPECT_NEAR(perObs[1] / perObs[0], 1.0, 0.02) << perObs[0] << " " << perObs[1];
    // 16 bytes an observation in base64: FileStorage's lines hold 48 bytes in 64 characters,
    // indented 6 and broken by 1, so 16 x 71 / 48 = 23.7 bytes of text.
    EXPECT_LT(perObs[1], 24.0);
}

TEST(Augocc_Tracks, bad_arg_sparse)
{
    const std::string dir = tempDir("io");
    const std::string head = "%YAML:1.0\n---\n"
                             "image_size: !!opencv-matrix\n   rows: 1\n   cols: 2\n   dt: i\n"
                             "   data: [ 640, 480 ]\nframes: 3\npoints: 2\n";
    auto mat = [](const char* key, int rows, int cols, const char* dt, const char* data) {
        return cv::format("%s: !!opencv-matrix\n   rows: %d\n   cols: %d\n   dt: %s\n"
                          "   data: [ %s ]\n", key, rows, cols, dt, data);
    };
    const std::string uv2 = mat("obs_uv", 2, 2, "f", "1., 2., 3., 4.");
    const std::string good = writeText(dir, "good.yml", head + mat("obs_index", 2, 2, "i",
                                       "0, 0, 2, 1") + uv2);
    const Tracks t = readTracks(good);
    EXPECT_EQ(t.observations(), 2);
    EXPECT_EQ(t.at(2, 1), Point2f(3, 4));
    EXPECT_FALSE(t.observed(1, 1));
    const std::string dense = mat("tracks", 3, 2, "\"2f\"", ".Nan, .Nan, .Nan, .Nan, .Nan, "
                                  ".Nan, .Nan, .Nan, .Nan, .Nan, .Nan, .Nan");
    struct Case { const char* name; std::string text; std::vector<std::string> says; };
    const std::vector<Case> cases = {
        {"both.yml", head + dense + mat("obs_index", 2, 2, "i", "0, 0, 2, 1") + uv2,
         {"both", "tracks", "obs_index"}},
        {"nouv.yml", head + mat("obs_index", 2, 2, "i", "0, 0, 2, 1"), {"obs_uv"}},
        {"noindex.yml", head + uv2, {"obs_index"}},
        {"shape.yml", head + mat("obs_index", 2, 3, "i", "0, 0, 0, 2, 1, 0") + uv2,
         {"obs_index", "N x 2"}},
        {"type.yml", head + mat("obs_index", 2, 2, "f", "0., 0., 2., 1.") + uv2,
         {"obs_index", "32S"}},
        {"uvtype.yml", head + mat("obs_index", 2, 2, "i", "0, 0, 2, 1") +
         mat("obs_uv", 2, 2, "i", "1, 2, 3, 4"), {"obs_uv", "32F"}},
        {"rows.yml", head + mat("obs_index", 1, 2, "i", "0, 0") + uv2, {"rows"}},
        {"frame.yml", head + mat("obs_index", 2, 2, "i", "0, 0, 3, 1") + uv2,
         {"obs_index", "row 1", "(3, 1)"}},
        {"point.yml", head + mat("obs_index", 2, 2, "i", "0, -1, 2, 1") + uv2,
         {"obs_index", "row 0"}},
        {"twice.yml", head + mat("obs_index", 2, 2, "i", "2, 1, 2, 1") + uv2,
         {"twice", "frame 2", "point 1"}},
        {"nan.yml", head + mat("obs_index", 2, 2, "i", "0, 0, 2, 1") +
         mat("obs_uv", 2, 2, "f", "1., .Nan, 3., 4."), {"obs_uv", "row 0", "not finite"}},
        {"inf.yml", head + mat("obs_index", 2, 2, "i", "0, 0, 2, 1") +
         mat("obs_uv", 2, 2, "f", "1., 2., .Inf, 4."), {"obs_uv", "row 1", "not finite"}},
        {"zero.yml", "%YAML:1.0\n---\nimage_size: !!opencv-matrix\n   rows: 1\n   cols: 2\n"
         "   dt: i\n   data: [ 640, 480 ]\nframes: 0\npoints: 2\n" +
         mat("obs_index", 2, 2, "i", "0, 0, 2, 1") + uv2, {"frames = 0"}},
    };
    for (const Case& c : cases)
    {
        SCOPED_TRACE(c.name);
        const std::string path = writeText(dir, c.name, c.text);
        try
        {
            readTracks(path);
            ADD_FAILURE() << "no exception";
        }
        catch (const cv::Exception& e)
        {
            EXPECT_NE(e.err.find(c.name), std::string::npos) << e.err;
            for (const std::string& f : c.says)
                EXPECT_NE(e.err.find(f), std::string::npos) << "'" << f << "' not in: " << e.err;
        }
    }
    // A dense value that is infinite is refused when read, naming the entry.
    const std::string inf = writeText(dir, "denseinf.yml", head + mat("tracks", 3, 2, "\"2f\"",
        "1., 2., .Nan, .Nan, .Nan, .Nan, .Nan, .Nan, .Inf, .Inf, .Nan, .Nan"));
    expectErrorMentions([&] { readTracks(inf); }, {"denseinf.yml", "(2, 0)", "not finite"});
}

class Augocc_Reconstruction_P : public testing::TestWithParam<int> {};

TEST_P(Augocc_Reconstruction_P, regression_round_trip)
{
    const std::string dir = tempDir("io");
    const Reconstruction rec = makeReconstruction((CameraModel)GetParam());
    const std::string p = dir + "/reconstruction.yml";
    writeReconstruction(p, rec);
    const Reconstruction r = readReconstruction(p);
    EXPECT_EQ(r.model, rec.model);
    EXPECT_EQ(r.imageSize, rec.imageSize);
    ASSERT_EQ(r.cameras.size(), rec.cameras.size());
    for (size_t i = 0; i < rec.cameras.size(); i++)
    {
        EXPECT_EQ(r.cameras[i].frame, rec.cameras[i].frame);
        // FileStorage writes doubles with 16 significant digits.
        const double kTextEps = 1e-12;
        EXPECT_MAT_NEAR(Mat(r.cameras[i].R), Mat(rec.cameras[i].R), kTextEps);
        EXPECT_MAT_NEAR(Mat(r.cameras[i].t), Mat(rec.cameras[i].t), kTextEps);
        const Vec3d X(0.3, -0.7, 1.1);
        EXPECT_LT(cv::norm(r.cameras[i].project(X) - rec.cameras[i].project(X)), 1e-9);
    }
    ASSERT_EQ(r.points.size(), rec.points.size());
    EXPECT_EQ(r.validPointCount(), 2);
    EXPECT_TRUE(std::isnan(r.points.at<double>(1, 0)));
    EXPECT_EQ(r.findCamera(4), 2);
    EXPECT_EQ(r.findCamera(5), -1);
    EXPECT_THROW(r.camera(5), cv::Exception);
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_Reconstruction_P,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

TEST(Augocc_Reconstruction, bad_arg)
{
    const std::string dir = tempDir("io");
    const std::string good = dir + "/good.yml";
    writeReconstruction(good, makeReconstruction(SCALED_ORTHOGRAPHIC));
    std::string text;
    {
        std::ifstream in(good);
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
        std::string t = text;
        const size_t pos = t.find(from);
        EXPECT_NE(pos, std::string::npos) << from;
        if (pos != std::string::npos)
            t.replace(pos, from.size(), to);
        return writeText(dir, name, t);
    };
    // Missing key.
    const std::string noModel = variant("nomodel.yml", "model:", "modelx:");
    expectErrorMentions([&] { readReconstruction(noModel); }, {"nomodel.yml", "'model'"});
    const std::string badModel = variant("badmodel.yml", "scaled_orthographic", "fisheye");
    expectErrorMentions([&] { readReconstruction(badModel); }, {"badmodel.yml", "fisheye"});
    const std::string noS = variant("nos.yml", "      s:", "      q:");
    expectErrorMentions([&] { readReconstruction(noS); }, {"nos.yml", "cameras[0]", "'s'"});
    // Non-positive scale.
    const std::string zeroS = variant("zeros.yml", "      s: 20.", "      s: -20.");
    expectErrorMentions([&] { readReconstruction(zeroS); }, {"zeros.yml", "scale"});
    // R not a rotation.
    const std::string notRot = variant("notrot.yml", "data: [ 9.8006657784124163e-01", "data: [ 1.5");
    expectErrorMentions([&] { readReconstruction(notRot); }, {"notrot.yml", "not a rotation"});
    // Wrong matrix shape.
    const std::string shape = variant("shape.yml", "rows: 3\n         cols: 1", "rows: 1\n         cols: 3");
    expectErrorMentions([&] { readReconstruction(shape); }, {"shape.yml", "'t'", "3x1"});
    // Points of the wrong width.
    const std::string pts = variant("pts.yml", "points: !!opencv-matrix\n   rows: 3\n   cols: 3",
                                    "points: !!opencv-matrix\n   rows: 9\n   cols: 1");
    expectErrorMentions([&] { readReconstruction(pts); }, {"pts.yml", "points"});
    // Frames out of order.
    Reconstruction r = makeReconstruction(SCALED_ORTHOGRAPHIC);
    std::swap(r.cameras[0], r.cameras[1]);
    expectErrorMentions([&] { writeReconstruction(dir + "/order.yml", r); }, {"frame"});
    EXPECT_FALSE(fs::exists(dir + "/order.yml"));
}

TEST(Augocc_Masks, regression_round_trip)
{
    const std::string dir = tempDir("io") + "/masks";
    ObjectMasks masks;
    Mat a = Mat::zeros(48, 64, CV_8U), b = Mat::zeros(48, 64, CV_8U);
    cv::rectangle(a, Rect(5, 6, 20, 10), Scalar(255), FILLED);
    cv::circle(b, Point(40, 30), 9, Scalar(255), FILLED);
    masks["front"][0] = a;
    masks["front"][12] = b;
    masks["tower"][3] = b;
    writeMasks(dir, masks);
    EXPECT_TRUE(fs::exists(dir + "/front/0012.png"));
    const ObjectMasks r = readMasks(dir, Size(64, 48));
    ASSERT_EQ(r.size(), 2u);
    ASSERT_EQ(r.at("front").size(), 2u);
    EXPECT_MAT_NEAR(r.at("front").at(12), b, 0);
    EXPECT_MAT_NEAR(r.at("tower").at(3), b, 0);
    // Writing again replaces the folder, leaving no stale frames.
    masks.erase("tower");
    writeMasks(dir, masks);
    EXPECT_EQ(readMasks(dir).size(), 1u);
}

TEST(Augocc_Masks, bad_arg)
{
    const std::string dir = tempDir("io");
    expectErrorMentions([&] { readMasks(dir + "/none"); }, {"none", "not found"});
    fs::create_directories(dir + "/m/obj");
    expectErrorMentions([&] { readMasks(dir + "/m"); }, {"no <object>"});
    cv::imwrite(dir + "/m/obj/0001.png", Mat::zeros(10, 12, CV_8U));
    expectErrorMentions([&] { readMasks(dir + "/m", Size(64, 48)); },
                        {"0001.png", "12x10", "64x48"});
    writeText(dir + "/m/obj", "0002.png", "not a png");
    expectErrorMentions([&] { readMasks(dir + "/m"); }, {"0002.png", "cannot read"});
    fs::remove(dir + "/m/obj/0002.png");
    cv::imwrite(dir + "/m/obj/frame.png", Mat::zeros(10, 12, CV_8U));
    expectErrorMentions([&] { readMasks(dir + "/m"); }, {"frame.png", "frame index"});
}

TEST(Augocc_WriteAtomically, regression_stale_temporaries)
{
    // What a killed run leaves beside its output goes with the next write of the same output;
    // a live writer's temporary and other names stay.
    const std::string dir = tempDir("io");
    const std::vector<std::string> stale = {".tracks.tmp4242.yml", ".tracks.tmp999999999-7.yml"};
    const std::vector<std::string> kept = {cv::format(".tracks.tmp%d-9.yml", (int)getpid()),
                                           ".tracks.tmp12.yml.gz", ".tracks.tmp.yml",
                                           ".tracks.tmp1-x.yml", "tracks.tmp1.yml"};
    for (const std::string& n : stale)
        writeText(dir, n, "half a file");
    for (const std::string& n : kept)
        writeText(dir, n, "another file");
    writeTracks(dir + "/tracks.yml", makeTracks(4, 5));
    for (const std::string& n : stale)
        EXPECT_FALSE(fs::exists(dir + "/" + n)) << n;
    for (const std::string& n : kept)
        EXPECT_TRUE(fs::exists(dir + "/" + n)) << n;
    // Folder outputs too.
    fs::create_directories(dir + "/.masks.tmp17/obj");
    writeText(dir + "/.masks.tmp17/obj", "0000.png", "half");
    ObjectMasks m;
    m["obj"][0] = Mat::zeros(4, 4, CV_8U);
    writeMasks(dir + "/masks", m);
    EXPECT_FALSE(fs::exists(dir + "/.masks.tmp17"));
}

TEST(Augocc_WriteAtomically, regression_zombie_writer_is_dead)
{
    // A writer killed with its parent stays a zombie where PID 1 does not reap orphans (CI's
    // micro-VM): kill(pid, 0) succeeds on it, yet its temporary is stale. Made here as a child
    // that exits and is not waited for until the sweep has run.
    const std::string dir = tempDir("io");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0)
        _exit(0);
    // The child is a zombie once its state in /proc says so (it exits at once).
    const std::string stat = "/proc/" + std::to_string(child) + "/stat";
    bool zombie = false;
    for (int i = 0; i < 500 && !zombie; ++i)
    {
        std::ifstream in(stat);
        std::string line;
        std::getline(in, line);
        const size_t close = line.rfind(')');
        zombie = close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
        if (!zombie)
            usleep(2000);
    }
    const std::string name = cv::format(".tracks.tmp%d-1.yml", (int)child);
    writeText(dir, name, "half a file");
    writeTracks(dir + "/tracks.yml", makeTracks(4, 5));
    const bool swept = !fs::exists(dir + "/" + name);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(zombie) << "the child never showed as a zombie in " << stat;
    EXPECT_TRUE(swept) << name << " kept: its writer is a zombie, not at work";
}

TEST(Augocc_WriteAtomically, bad_arg)
{
    const std::string dir = tempDir("io");
    const std::string path = dir + "/out.yml";
    std::string tmp;
    // A std::filesystem error of the writer becomes StsError naming the output and the reason.
    try
    {
        writeAtomically(path, [&](const String& t) {
            tmp = t;
            writeText(dir, fs::path(t).filename().string(), "partial");
            throw fs::filesystem_error("create_directories", t,
                                       std::make_error_code(std::errc::read_only_file_system));
        });
        ADD_FAILURE() << "no exception";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_EQ(Error::StsError, e.code);
        EXPECT_NE(std::string::npos, e.err.find(path)) << e.err;
        EXPECT_NE(std::string::npos, e.err.find("Read-only file system")) << e.err;
    }
    EXPECT_FALSE(tmp.empty());
    EXPECT_FALSE(fs::exists(tmp));
    expectErrorMentions([&] { writeAtomically(path, [](const String&) {}); },
                        {path, "nothing was written"});
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(Augocc_FramePattern, accuracy)
{
    using cv::augocc::detail::FramePattern;
    using cv::augocc::detail::parseFramePattern;
    const FramePattern a = parseFramePattern("frames/%04d.png");
    EXPECT_EQ("frames/", a.prefix);
    EXPECT_EQ(".png", a.suffix);
    EXPECT_EQ("frames/0007.png", a.expand(7));
    EXPECT_EQ("frames/12345.png", a.expand(12345));
    EXPECT_EQ("f3.png", parseFramePattern("f%d.png").expand(3));
    EXPECT_EQ("f  3.png", parseFramePattern("f%3d.png").expand(3));
    EXPECT_EQ("f0000000042", parseFramePattern("f%010d").expand(42));
    // %% is a literal '%', on either side of the conversion.
    EXPECT_EQ("100%/x_05%.png", parseFramePattern("100%%/x_%02d%%.png").expand(5));
    // What printf would write, for every accepted form.
    for (const char* fmt : {"%d", "%0d", "%1d", "%5d", "%05d", "%10d", "%010d", "a%%%03d%%b"})
        for (int i : {0, 1, 9, 10, 999, 123456, std::numeric_limits<int>::max()})
            EXPECT_EQ(cv::format(fmt, i), parseFramePattern(fmt).expand(i)) << fmt << " " << i;
}

TEST(Augocc_FramePattern, bad_arg)
{
    // Each is StsBadArg naming the pattern, never handed to printf.
    for (const char* bad : {"%s.png", "%n", "%d%d", "%5s", "x/%04d_%d.png", "%", "frame%",
                            "%%", "none", "%ld", "%i", "%x", "%u", "%-4d", "%+d", "% d", "%.3d",
                            "%*d", "%00d", "%011d", "%123d", "%04s", "%1$d", "%p", "%04d%n"})
    {
        try
        {
            cv::augocc::detail::parseFramePattern(bad);
            ADD_FAILURE() << "accepted: " << bad;
        }
        catch (const cv::Exception& e)
        {
            EXPECT_EQ(Error::StsBadArg, e.code) << bad;
            EXPECT_NE(e.err.find(String("'") + bad + "'"), String::npos) << e.err;
            EXPECT_NE(e.err.find("frame pattern"), String::npos) << e.err;
        }
    }
}

TEST(Augocc_FrameSource, accuracy)
{
    const std::string dir = tempDir("io");
    fs::create_directories(dir + "/frames");
    for (int i = 0; i < 5; i++)
        cv::imwrite(cv::format("%s/frames/%04d.png", dir.c_str(), i),
                    Mat(24, 32, CV_8UC3, Scalar(10 * i, 20, 30)));
    for (const std::string& input : {dir + "/frames", dir + "/frames/%04d.png"})
    {
        Ptr<FrameSource> src = FrameSource::open(input);
        EXPECT_EQ(src->count(), 5);
        EXPECT_EQ(src->size(), Size(32, 24));
        Mat f;
        int n = 0;
        while (src->read(f))
        {
            EXPECT_EQ(f.at<Vec3b>(0, 0)[0], 10 * n);
            n++;
        }
        EXPECT_EQ(n, 5);
        src->seek(3);
        ASSERT_TRUE(src->read(f));
        EXPECT_EQ(f.at<Vec3b>(0, 0)[0], 30);
    }
    // '%' in a folder name is written %%; a file that exists is read as itself, '%' or not.
    fs::create_directories(dir + "/100%");
    for (int i = 1; i <= 3; i++)
        cv::imwrite(cv::format("%s/100%%/f%d.png", dir.c_str(), i),
                    Mat(24, 32, CV_8UC3, Scalar(i, 0, 0)));
    Ptr<FrameSource> pct = FrameSource::open(dir + "/100%%/f%d.png");
    EXPECT_EQ(3, pct->count());
    Mat first;
    ASSERT_TRUE(pct->read(first));
    EXPECT_EQ(1, first.at<Vec3b>(0, 0)[0]);
    cv::imwrite(dir + "/lit%s.png", Mat(24, 32, CV_8UC3, Scalar::all(7)));
    EXPECT_EQ(1, FrameSource::open(dir + "/lit%s.png")->count());
    // A video written with OpenCV reads back frame for frame.
    const std::string video = dir + "/v.avi";
    {
        VideoWriter w(video, VideoWriter::fourcc('M', 'J', 'P', 'G'), 25, Size(32, 24));
        ASSERT_TRUE(w.isOpened());
        for (int i = 0; i < 6; i++)
            w.write(Mat(24, 32, CV_8UC3, Scalar(40 * i, 40 * i, 40 * i)));
    }
    Ptr<FrameSource> v = FrameSource::open(video);
    EXPECT_EQ(v->size(), Size(32, 24));
    Mat f;
    int n = 0;
    while (v->read(f))
        n++;
    EXPECT_EQ(n, 6);
    v->seek(2);
    ASSERT_TRUE(v->read(f));
    const int kJpegTol = 8; // MJPG is lossy
    EXPECT_NEAR(f.at<Vec3b>(12, 16)[1], 80, kJpegTol);
}

TEST(Augocc_FrameSource, bad_arg)
{
    const std::string dir = tempDir("io");
    expectErrorMentions([&] { FrameSource::open(dir + "/nothing.mp4"); }, {"nothing.mp4"});
    const std::string corrupt = writeText(dir, "corrupt.mp4", std::string(4096, 'x'));
    expectErrorMentions([&] { FrameSource::open(corrupt); }, {"corrupt.mp4"});
    fs::create_directories(dir + "/empty");
    expectErrorMentions([&] { FrameSource::open(dir + "/empty"); }, {"empty", "no image"});
    expectErrorMentions([&] { FrameSource::open(dir + "/x/%04d.png"); }, {"pattern"});
    // A pattern is never a format: each of these crashed or read garbage through printf.
    for (const char* bad : {"%s.png", "%n", "%d%d", "%5s", "%n%s%s%s%s%s%s%s%s.png"})
        expectErrorMentions([&] { FrameSource::open(dir + "/" + bad); },
                            {dir + "/" + bad, "not a frame pattern"});
    fs::create_directories(dir + "/mixed");
    cv::imwrite(dir + "/mixed/0000.png", Mat(24, 32, CV_8UC3, Scalar::all(0)));
    cv::imwrite(dir + "/mixed/0001.png", Mat(20, 32, CV_8UC3, Scalar::all(0)));
    Ptr<FrameSource> src = FrameSource::open(dir + "/mixed");
    Mat f;
    EXPECT_TRUE(src->read(f));
    expectErrorMentions([&] { src->read(f); }, {"0001.png", "32x20"});
}

TEST(Augocc_FrameSource, regression_input_replaced_while_read)
{
    // An input replaced or rewritten between open() and the last read() gave an output made of
    // two versions of it, with no word said (issue 17). Each way a file changes is named.
    const std::string dir = tempDir("io_replaced");
    auto writeFrames = [&](const std::string& folder) {
        fs::remove_all(folder);
        fs::create_directories(folder);
        cv::RNG rng(7);
        for (int i = 0; i < 5; i++)
        {
            Mat m(48, 64, CV_8UC3);
            rng.fill(m, cv::RNG::UNIFORM, 0, 255);
            cv::imwrite(cv::format("%s/%04d.png", folder.c_str(), i), m);
        }
    };
    const std::string frames = dir + "/frames";
    writeFrames(frames);
    const Mat other(48, 64, CV_8UC3, Scalar::all(9));
    for (const std::string& input : {frames, frames + "/%04d.png"})
    {
        // Replaced (a new file renamed over it, as editors and sync tools do).
        Ptr<FrameSource> src = FrameSource::open(input);
        Mat f;
        ASSERT_TRUE(src->read(f));
        EXPECT_NO_THROW(src->checkUnchanged());
        cv::imwrite(dir + "/new.png", other);
        fs::rename(dir + "/new.png", frames + "/0003.png");
        expectErrorMentions([&] { src->checkUnchanged(); },
                            {input, frames + "/0003.png", "replaced", "two versions"});
        // Rewritten in place (same inode, another size).
        writeFrames(frames);
        src = FrameSource::open(input);
        {
            std::ofstream(frames + "/0001.png", std::ios::app) << "appended";
        }
        expectErrorMentions([&] { src->checkUnchanged(); }, {frames + "/0001.png", "rewritten"});
        // Removed.
        writeFrames(frames);
        src = FrameSource::open(input);
        fs::remove(frames + "/0004.png");
        expectErrorMentions([&] { src->checkUnchanged(); }, {frames + "/0004.png", "removed"});
        writeFrames(frames);
    }
    // A video replaced while read (seek() opens it again by name).
    const std::string video = dir + "/v.avi";
    auto writeVideo = [&](const std::string& path, int value) {
        VideoWriter w(path, VideoWriter::fourcc('M', 'J', 'P', 'G'), 25, Size(32, 24));
        ASSERT_TRUE(w.isOpened());
        for (int i = 0; i < 4; i++)
            w.write(Mat(24, 32, CV_8UC3, Scalar::all(value)));
    };
    writeVideo(video, 50);
    Ptr<FrameSource> v = FrameSource::open(video);
    Mat f;
    while (v->read(f))
        ;
    EXPECT_NO_THROW(v->checkUnchanged());
    writeVideo(dir + "/w.avi", 200);
    fs::rename(dir + "/w.avi", video);
    expectErrorMentions([&] { v->checkUnchanged(); }, {video, "replaced"});
    // The tracker checks before it returns tracks: a frame replaced half-way is an error.
    writeFrames(frames);
    FeatureTracker::Params tp;
    bool replaced = false;
    tp.progress = [&](const Progress& p) {
        if (replaced || p.done < 2)
            return;
        cv::imwrite(dir + "/new.png", other);
        fs::rename(dir + "/new.png", frames + "/0004.png");
        replaced = true;
    };
    Tracks tracks;
    expectErrorMentions([&] { FeatureTracker::create(tp)->track(FrameSource::open(frames),
                                                                  tracks); },
                        {frames + "/0004.png", "replaced"});
    EXPECT_TRUE(replaced);
    EXPECT_EQ(0, tracks.frames());
}

} // namespace
} // namespace opencv_test
