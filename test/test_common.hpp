// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_TEST_COMMON_HPP
#define OPENCV_AUGOCC_TEST_COMMON_HPP

#include <string>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"

namespace opencv_test {

//! Compares two matrices element-wise with NORM_INF, reporting size/type mismatch and the worst
//! element.
testing::AssertionResult matNear(const char* expr1, const char* expr2, const char* exprEps,
                                 cv::InputArray a, cv::InputArray b, double eps);
#define EXPECT_MAT_NEAR(a, b, eps) EXPECT_PRED_FORMAT3(opencv_test::matNear, a, b, eps)
#define ASSERT_MAT_NEAR(a, b, eps) ASSERT_PRED_FORMAT3(opencv_test::matNear, a, b, eps)

//! Path of a data set in ../shared/data, or "" when absent (tests GTEST_SKIP then).
std::string sharedDataPath(const std::string& relative);
//! Skips the current test when ../shared/data/<relative> is absent.
#define AUGOCC_REQUIRE_SHARED_DATA(var, relative)                                     \
    const std::string var = opencv_test::sharedDataPath(relative);                    \
    if (var.empty())                                                                  \
        GTEST_SKIP() << "shared data " << relative << " absent (../shared/data)"

//! A fresh empty temporary folder for the current test, removed by the caller if wanted.
std::string tempDir(const std::string& tag);

//! Writes `text` to `dir`/`name` and returns that path.
std::string writeText(const std::string& dir, const std::string& name, const std::string& text);

//! The whole content of a file (empty if it cannot be read).
std::string fileText(const std::string& path);

//! The regular files under `dir`, recursively, as paths relative to it, sorted.
std::vector<std::string> filesUnder(const std::string& dir);

//! Path of the built augocc binary.
std::string augoccBinary();
//! Runs a shell command, returns its exit status; stdout+stderr are captured into *output.
int runCommand(const std::string& cmd, std::string* output = nullptr);

//! Intersection over union of two binary masks (> 0 = in).
double maskIoU(const cv::Mat& a, const cv::Mat& b);

//! M = K R by RQ decomposition, K's diagonal made positive (the signs moved into R's rows).
void decomposeKR(const cv::Matx33d& M, cv::Matx33d& K, cv::Matx33d& R);
//! A 3x4 projection matrix (P maps X to (col, row, w), up to scale and sign) as a perspective
//! Camera: K upper triangular with a positive diagonal and K(2,2) = 1, det R = +1.
cv::augocc::Camera cameraFromProjection(const cv::Matx34d& P, int frame);

} // namespace opencv_test

#endif
