// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_PERF_PRECOMP_HPP
#define OPENCV_AUGOCC_PERF_PRECOMP_HPP

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include "opencv2/augocc.hpp"

#endif
