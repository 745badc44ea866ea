// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_FEATURE_TRACKER_HPP
#define OPENCV_AUGOCC_FEATURE_TRACKER_HPP

#include <opencv2/core.hpp>

#endif
