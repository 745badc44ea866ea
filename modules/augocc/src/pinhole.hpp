// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_PINHOLE_HPP
#define OPENCV_AUGOCC_PINHOLE_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

//! Pixel to normalised image point through an upper-triangular K (skew included).
inline Point2d normalizedOf(const Matx33d& K, const Point2d& px)
{
    const double y = (px.y - K(1, 2)) / K(1, 1);
    return Point2d((px.x - K(0, 2) - K(0, 1) * y) / K(0, 0), y);
}

//! Normalised image point to pixel through K.
inline Point2d pixelOf(const Matx33d& K, const Point2d& n)
{
    return Point2d(K(0, 0) * n.x + K(0, 1) * n.y + K(0, 2), K(1, 1) * n.y + K(1, 2));
}

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
