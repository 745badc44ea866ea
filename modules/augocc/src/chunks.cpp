// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Joining frame chunks (doc/farm.md): PNG files copied unchanged, a video encoded once.

#include "precomp.hpp"

#include "opencv2/augocc/chunks.hpp"

#include "atomic_write.hpp"
#include "video_out.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

// Frame index -> file of one folder of `%04d.png` frames; StsBadArg naming a file of any other
// name (a chunk holds its stage's frames and nothing else).
std::map<int, fs::path> listFrameFiles(const fs::path& dir)
{
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        CV_Error(Error::StsBadArg, dir.string() + ": no such chunk folder");
    std::map<int, fs::path> files;
    for (const fs::directory_entry& e : fs::directory_iterator(dir))
    {
        const String name = e.path().filename().string();
        const String stem = e.path().stem().string();
        const bool digits = !stem.empty() && stem.size() <= 9 &&
                            std::all_of(stem.begin(), stem.end(),
                                        [](unsigned char c) { return std::isdigit(c) != 0; });
        if (!e.is_regular_file() || !digits || e.path().extension() != ".png")
            CV_Error(Error::StsBadArg, e.path().string() + ": not a frame of a chunk (NNNN.png)");
        files[std::stoi(stem)] = e.path();
    }
    return files;
}

std::vector<char> readBytes(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof())
        CV_Error(Error::StsError, file.string() + ": cannot be read");
    return bytes;
}

void copyInto(const fs::path& from, const fs::path& tmpFile, const fs::path& shown)
{
    const std::vector<char> bytes = readBytes(from);
    detail::writeFileBytes(tmpFile.string(), bytes.data(), bytes.size(), shown.string());
}

} // namespace

int joinFrameChunks(const std::vector<String>& chunkDirs, const String& output, double fps)
{
    if (output.empty())
        CV_Error(Error::StsBadArg, "joinFrameChunks: no output given");
    if (chunkDirs.empty())
        CV_Error(Error::StsBadArg, output + ": no chunk to join");
    if (!(fps > 0) || !std::isfinite(fps))
        CV_Error(Error::StsBadArg, output + cv::format(": frame rate %g is not positive", fps));
    std::map<int, fs::path> frames;
    for (const String& dir : chunkDirs)
        for (const auto& f : listFrameFiles(dir))
        {
            auto it = frames.find(f.first);
            if (it != frames.end())
                CV_Error(Error::StsBadArg, f.second.string() + cv::format(": frame %d is also in "
                         "%s (chunks must not overlap)", f.first, it->second.string().c_str()));
            frames[f.first] = f.second;
        }
    if (frames.empty())
        CV_Error(Error::StsBadArg, output + ": the chunks hold no frame");
    int expected = frames.begin()->first;
    for (const auto& f : frames)
    {
        if (f.first != expected)
            CV_Error(Error::StsBadArg, output + cv::format(": frames %d..%d are in no chunk "
                     "(the chunks leave a gap before ", expected, f.first - 1) +
                     f.second.string() + ")");
        expected++;
    }
    const int n = (int)frames.size();
    if (!detail::isVideoPath(output))
    {
        writeAtomically(output, [&](const String& tmp) {
            detail::createDirectories(tmp, output);
            for (const auto& f : frames)
                copyInto(f.second, fs::path(tmp) / f.second.filename(),
                         fs::path(output) / f.second.filename());
        });
        return n;
    }
    writeAtomically(output, [&](const String& tmp) {
        VideoWriter writer;
        Size size;
        for (const auto& f : frames)
        {
            const Mat img = imread(f.second.string(), IMREAD_COLOR);
            if (img.empty())
                CV_Error(Error::StsBadArg, f.second.string() + ": cannot be decoded as an image");
            if (!writer.isOpened())
            {
                size = img.size();
                writer = detail::openVideo(tmp, output, fps, size);
            }
            else if (img.size() != size)
                CV_Error(Error::StsBadSize, f.second.string() + cv::format(": %dx%d, the first "
                         "frame is %dx%d", img.cols, img.rows, size.width, size.height));
            writer.write(img);
        }
        writer.release();
        detail::checkVideoFile(tmp, n, output);
    });
    return n;
}

int joinMaskChunks(const std::vector<String>& chunkDirs, const String& output)
{
    if (output.empty())
        CV_Error(Error::StsBadArg, "joinMaskChunks: no output given");
    if (chunkDirs.empty())
        CV_Error(Error::StsBadArg, output + ": no chunk to join");
    // object -> frame -> file
    std::map<String, std::map<int, fs::path> > files;
    for (const String& dir : chunkDirs)
    {
        std::error_code ec;
        if (!fs::is_directory(dir, ec))
            CV_Error(Error::StsBadArg, dir + ": no such chunk folder");
        for (const fs::directory_entry& e : fs::directory_iterator(dir))
        {
            if (!e.is_directory())
                CV_Error(Error::StsBadArg, e.path().string() + ": not an object folder of a "
                         "chunk (DIR/<object>/NNNN.png)");
            std::map<int, fs::path>& obj = files[e.path().filename().string()];
            for (const auto& f : listFrameFiles(e.path()))
            {
                auto it = obj.find(f.first);
                if (it != obj.end())
                    CV_Error(Error::StsBadArg, f.second.string() + cv::format(": frame %d of "
                             "this object is also in %s (chunks must not overlap)", f.first,
                             it->second.string().c_str()));
                obj[f.first] = f.second;
            }
        }
    }
    if (files.empty())
        CV_Error(Error::StsBadArg, output + ": the chunks hold no object folder");
    int n = 0;
    writeAtomically(output, [&](const String& tmp) {
        for (const auto& obj : files)
        {
            const fs::path dir = fs::path(tmp) / obj.first;
            detail::createDirectories(dir.string(), (fs::path(output) / obj.first).string());
            for (const auto& f : obj.second)
                copyInto(f.second, dir / f.second.filename(),
                         fs::path(output) / obj.first / f.second.filename());
        }
    });
    for (const auto& obj : files)
        n += (int)obj.second.size();
    return n;
}

} // namespace augocc
} // namespace cv
