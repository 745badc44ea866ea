// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include <opencv2/calib3d.hpp>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

namespace opencv_test {

testing::AssertionResult matNear(const char* expr1, const char* expr2, const char* /*exprEps*/,
                                 cv::InputArray a_, cv::InputArray b_, double eps)
{
    cv::Mat a = a_.getMat(), b = b_.getMat();
    if (a.size() != b.size() || a.type() != b.type())
        return testing::AssertionFailure()
               << expr1 << " and " << expr2 << " differ in size or type: " << a.size() << " "
               << cv::typeToString(a.type()) << " vs " << b.size() << " "
               << cv::typeToString(b.type());
    if (a.empty())
        return testing::AssertionSuccess();
    cv::Mat diff;
    cv::absdiff(a.reshape(1), b.reshape(1), diff);
    double maxVal = 0;
    cv::Point maxLoc;
    cv::minMaxLoc(diff, nullptr, &maxVal, nullptr, &maxLoc);
    if (maxVal <= eps)
        return testing::AssertionSuccess();
    return testing::AssertionFailure() << expr1 << " and " << expr2 << " differ by " << maxVal
                                       << " > " << eps << " at (row " << maxLoc.y << ", col "
                                       << maxLoc.x << ")";
}

std::string sharedDataPath(const std::string& relative)
{
    const char* env = std::getenv("AUGOCC_SHARED_DATA");
    std::filesystem::path base = env ? env : AUGOCC_SHARED_DATA_PATH;
    std::filesystem::path p = base / relative;
    return std::filesystem::exists(p) ? p.string() : std::string();
}

std::string writeText(const std::string& dir, const std::string& name, const std::string& text)
{
    const std::string path = dir + "/" + name;
    std::ofstream(path) << text;
    return path;
}

std::string fileText(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<std::string> filesUnder(const std::string& dir)
{
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
        if (e.is_regular_file())
            files.push_back(std::filesystem::relative(e.path(), dir).string());
    std::sort(files.begin(), files.end());
    return files;
}

std::string tempDir(const std::string& tag)
{
    const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
    std::string name = tag;
    if (info)
        name = std::string(info->test_suite_name()) + "." + info->name() + "." + tag;
    for (char& c : name)
        if (c == '/')
            c = '_';
    std::filesystem::path p = std::filesystem::temp_directory_path() / "augocc_test" / name;
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    return p.string();
}

std::string augoccBinary()
{
    const char* env = std::getenv("AUGOCC_BIN");
    return env ? std::string(env) : std::string(AUGOCC_BINARY_DIR) + "/bin/augocc";
}

int runCommand(const std::string& cmd, std::string* output)
{
    std::string full = cmd + " 2>&1";
    FILE* pipe = popen(full.c_str(), "r");
    if (!pipe)
        return -1;
    std::array<char, 4096> buf;
    std::string out;
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0)
        out.append(buf.data(), n);
    const int status = pclose(pipe);
    if (output)
        *output = out;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

double maskIoU(const cv::Mat& a, const cv::Mat& b)
{
    CV_Assert(a.size() == b.size());
    cv::Mat ia = a > 0, ib = b > 0;
    const double inter = cv::countNonZero(ia & ib);
    const double uni = cv::countNonZero(ia | ib);
    return uni > 0 ? inter / uni : 1.0;
}

void decomposeKR(const cv::Matx33d& M, cv::Matx33d& K, cv::Matx33d& R)
{
    cv::RQDecomp3x3(M, K, R);
    for (int d = 0; d < 3; d++)
        if (K(d, d) < 0)
        {
            for (int r = 0; r < 3; r++)
                K(r, d) = -K(r, d);
            for (int c = 0; c < 3; c++)
                R(d, c) = -R(d, c);
        }
}

cv::augocc::Camera cameraFromProjection(const cv::Matx34d& P0, int frame)
{
    cv::Matx34d P = P0;
    cv::Matx33d M = P.get_minor<3, 3>(0, 0);
    if (cv::determinant(M) < 0)
    {
        // P and -P are the same camera; with K's diagonal positive, det R = sign(det M).
        P = P * -1.0;
        M = M * -1.0;
    }
    cv::Matx33d K, R;
    decomposeKR(M, K, R);
    const cv::Vec3d t = K.inv() * cv::Vec3d(P(0, 3), P(1, 3), P(2, 3));
    K *= 1.0 / K(2, 2);
    K(1, 0) = K(2, 0) = K(2, 1) = 0;  // RQ's round-off below the diagonal
    return cv::augocc::Camera::perspective(R, t, K, frame);
}

} // namespace opencv_test
