// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Order statistics shared by the library and the tests: the one median of augocc.

#ifndef OPENCV_AUGOCC_STATS_HPP
#define OPENCV_AUGOCC_STATS_HPP

#include <algorithm>
#include <vector>
#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

/** @brief Median of `values`, reordering them (std::nth_element, O(n)): for a scratch buffer,
where median() would copy.

Convention, the one of every median in augocc: element n / 2 (0-based) of the sorted values,
that is the middle value for an odd count and the upper of the two middle values for an even
count (no averaging, so the result is always one of the values). Throws StsBadSize on an empty
vector.
*/
template <typename T>
T medianInPlace(std::vector<T>& values)
{
    if (values.empty())
        CV_Error(Error::StsBadSize, "median of an empty vector");
    const auto mid = values.begin() + values.size() / 2;
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
}

//! @brief Median of `values` (medianInPlace() on a copy: the caller's order is kept).
template <typename T>
T median(std::vector<T> values)
{
    return medianInPlace(values);
}

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
