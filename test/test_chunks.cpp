// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Joining frame chunks (opencv2/augocc/chunks.hpp): files copied unchanged, the video encoded
// once with every frame once, bad chunk sets refused naming the file.

#include "test_precomp.hpp"
#include "test_common.hpp"
#include "opencv2/augocc/chunks.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace opencv_test {
namespace {

namespace fs = std::filesystem;
using namespace cv;

std::string bytesOf(const fs::path& p)
{
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Frame f: a flat grey of level 10 * f with its index written on it (distinct frames).
Mat frameImage(int f)
{
    Mat m(48, 64, CV_8UC3, Scalar::all(10 * f));
    putText(m, std::to_string(f), Point(4, 40), FONT_HERSHEY_SIMPLEX, 1.0, Scalar(0, 0, 255), 2);
    return m;
}

void writeChunk(const fs::path& dir, int first, int end)
{
    fs::create_directories(dir);
    for (int f = first; f < end; f++)
        imwrite((dir / cv::format("%04d.png", f)).string(), frameImage(f));
}

std::string errorOf(const std::function<void()>& fn)
{
    try
    {
        fn();
    }
    catch (const cv::Exception& e)
    {
        return e.err;
    }
    return "no error";
}

TEST(Augocc_JoinChunks, frames_to_folder_and_video)
{
    const fs::path dir = tempDir("join_frames");
    writeChunk(dir / "c2", 6, 9);
    writeChunk(dir / "c0", 0, 3);
    writeChunk(dir / "c1", 3, 6);
    const std::vector<String> chunks = {(dir / "c2").string(), (dir / "c0").string(),
                                        (dir / "c1").string()};
    EXPECT_EQ(cv::augocc::joinFrameChunks(chunks, (dir / "all").string()), 9);
    for (int f = 0; f < 9; f++)
    {
        const std::string name = cv::format("%04d.png", f);
        const fs::path from = dir / (f < 3 ? "c0" : f < 6 ? "c1" : "c2") / name;
        EXPECT_EQ(bytesOf(dir / "all" / name), bytesOf(from)) << name;  // copied unchanged
    }
    EXPECT_EQ(std::distance(fs::directory_iterator(dir / "all"), fs::directory_iterator()), 9);

    const fs::path video = dir / "all.mp4";
    EXPECT_EQ(cv::augocc::joinFrameChunks(chunks, video.string(), 10), 9);
    VideoCapture cap(video.string(), CAP_FFMPEG);
    ASSERT_TRUE(cap.isOpened());
    Mat img;
    int n = 0;
    while (cap.read(img))
    {
        // In order: frame n's grey level. Tolerance: lossy H.264 of a flat area, a few levels
        // (measured at most 2 here; 6 leaves room and still tells neighbours, 10 apart).
        const Scalar mean = cv::mean(img(Rect(40, 0, 24, 10)));
        EXPECT_NEAR(mean[0], 10.0 * n, 6.0) << "frame " << n;
        n++;
    }
    EXPECT_EQ(n, 9);
    fs::remove_all(dir);
}

TEST(Augocc_JoinChunks, bad_chunks)
{
    const fs::path dir = tempDir("join_bad");
    writeChunk(dir / "a", 0, 3);
    writeChunk(dir / "b", 4, 6);  // frame 3 missing
    writeChunk(dir / "c", 2, 4);  // overlaps a
    const std::string out = (dir / "out").string();
    EXPECT_EQ(errorOf([&] {
        cv::augocc::joinFrameChunks({(dir / "a").string(), (dir / "b").string()}, out);
    }), out + ": frames 3..3 are in no chunk (the chunks leave a gap before " +
        (dir / "b" / "0004.png").string() + ")");
    EXPECT_NE(errorOf([&] {
        cv::augocc::joinFrameChunks({(dir / "a").string(), (dir / "c").string()}, out);
    }).find("frame 2 is also in"), std::string::npos);
    EXPECT_EQ(errorOf([&] {
        cv::augocc::joinFrameChunks({(dir / "a").string(), (dir / "none").string()}, out);
    }), (dir / "none").string() + ": no such chunk folder");
    std::ofstream(dir / "a" / "notes.txt") << "x";
    EXPECT_EQ(errorOf([&] { cv::augocc::joinFrameChunks({(dir / "a").string()}, out); }),
              (dir / "a" / "notes.txt").string() + ": not a frame of a chunk (NNNN.png)");
    EXPECT_FALSE(fs::exists(out));  // nothing written on failure
    fs::remove_all(dir);
}

TEST(Augocc_JoinChunks, masks)
{
    const fs::path dir = tempDir("join_masks");
    writeChunk(dir / "m0" / "house", 0, 2);
    writeChunk(dir / "m0" / "tree", 0, 2);
    writeChunk(dir / "m1" / "house", 2, 4);  // no tree in this chunk
    const String out = (dir / "mattes").string();
    EXPECT_EQ(cv::augocc::joinMaskChunks({(dir / "m0").string(), (dir / "m1").string()}, out),
              6);
    EXPECT_EQ(bytesOf(dir / "mattes" / "house" / "0003.png"),
              bytesOf(dir / "m1" / "house" / "0003.png"));
    EXPECT_TRUE(fs::exists(dir / "mattes" / "tree" / "0001.png"));
    EXPECT_FALSE(fs::exists(dir / "mattes" / "tree" / "0002.png"));
    writeChunk(dir / "m2" / "house", 1, 2);
    fs::remove_all(out);
    EXPECT_NE(errorOf([&] {
        cv::augocc::joinMaskChunks({(dir / "m0").string(), (dir / "m2").string()}, out);
    }).find("frame 1 of this object is also in"), std::string::npos);
    EXPECT_FALSE(fs::exists(out));
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test
