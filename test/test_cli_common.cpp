// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The command line's one frame syntax (samples/augocc/cli_common.hpp): a, a:b (half-open), a:,
// a:b:s, lists of them.

#include "test_precomp.hpp"
#include "cli_common.hpp"

namespace opencv_test {
namespace {

using augocc_cli::FrameRange;
using augocc_cli::UsageError;
using augocc_cli::listFrames;
using augocc_cli::parseFrameRanges;

std::set<int> framesOf(const std::string& text, int frameCount)
{
    return listFrames("--frames", text, parseFrameRanges("--frames", text), frameCount);
}

TEST(Augocc_CliFrameRanges, accuracy)
{
    const std::vector<FrameRange> r = parseFrameRanges("--frames", "7,2:5,10:,3:20:4,6::2");
    ASSERT_EQ(r.size(), 5u);
    EXPECT_EQ(r[0].first, 7);
    EXPECT_EQ(r[0].end, 8);
    EXPECT_EQ(r[0].step, 1);
    EXPECT_EQ(r[1].first, 2);
    EXPECT_EQ(r[1].end, 5);   // half-open: 5 is not in
    EXPECT_EQ(r[2].first, 10);
    EXPECT_EQ(r[2].end, -1);  // to the end
    EXPECT_EQ(r[3].step, 4);
    EXPECT_EQ(r[4].end, -1);
    EXPECT_EQ(r[4].step, 2);

    EXPECT_EQ(framesOf("2:5", 10), std::set<int>({2, 3, 4}));
    EXPECT_EQ(framesOf("4", 10), std::set<int>({4}));
    EXPECT_EQ(framesOf("7:", 10), std::set<int>({7, 8, 9}));
    EXPECT_EQ(framesOf("1:8:3", 10), std::set<int>({1, 4, 7}));
    EXPECT_EQ(framesOf("5::2", 10), std::set<int>({5, 7, 9}));
    EXPECT_EQ(framesOf("9,0:2,1", 10), std::set<int>({0, 1, 9}));  // sorted, each once
    EXPECT_EQ(framesOf("0:10", 10).size(), 10u);                   // the whole input
}

TEST(Augocc_CliFrameRanges, bad_arg)
{
    for (const char* bad : {"", "3,", ",3", "1,,2", "3:2", "2:2", "-1", "-1:3", "a", "a:b", "1:x",
                            "1.5", "1:5:0", "1:5:-1", "1:2:3:4", " 1", "1 ", "99999999999"})
    {
        try
        {
            parseFrameRanges("--frames", bad);
            ADD_FAILURE() << "'" << bad << "' accepted";
        }
        catch (const UsageError& e)
        {
            // The message names the flag.
            EXPECT_EQ(std::string(e.what()).rfind("--frames", 0), 0u) << e.what();
        }
    }
    // Syntax fine, but past the input's last frame (frames 0..9).
    for (const char* beyond : {"10", "5:11", "10:", "2,12"})
        EXPECT_THROW(framesOf(beyond, 10), UsageError) << beyond;
}

} // namespace
} // namespace opencv_test
