// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"

#include <opencv2/core/utils/logger.hpp>

namespace {

// Mirrors OpenCV's CV__TEST_INIT: every test starts from the same RNG state and thread count.
class ResetListener : public testing::EmptyTestEventListener
{
public:
    explicit ResetListener(int threads) : threads_(threads) {}
    void OnTestStart(const testing::TestInfo&) override
    {
        cv::theRNG().state = 0x123456789ULL;
        cv::setNumThreads(threads_);
    }

private:
    int threads_;
};

} // namespace

int main(int argc, char** argv)
{
    testing::InitGoogleTest(&argc, argv);
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
    testing::UnitTest::GetInstance()->listeners().Append(new ResetListener(cv::getNumThreads()));
    return RUN_ALL_TESTS();
}
