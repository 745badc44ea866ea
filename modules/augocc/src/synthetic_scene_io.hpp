// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The one writer of a synthesized data set (synthetic_scene_io.cpp), for a scene held in memory
// (writeSyntheticScene) and for one rendered frame by frame (SceneSynthesizer::write).

#ifndef OPENCV_AUGOCC_SYNTHETIC_SCENE_IO_HPP
#define OPENCV_AUGOCC_SYNTHETIC_SCENE_IO_HPP

#include "opencv2/augocc/scene_synthesizer.hpp"

#include <functional>

namespace cv {
namespace augocc {
namespace detail {

//! One frame of a data set with its per-frame truth (SyntheticScene's per-frame members).
struct SyntheticFrame
{
    Mat bgr, labels, depth;
    std::vector<Mat> whole, visible;  // SyntheticScene::objectNames order
};

/** @brief Writes the data set DIR (writeSyntheticScene's layout) for objects `names`. The
per-frame files come from `frame(f, out)`, called for f = 0, 1, ... in order from the calling
thread, a batch at a time (memory holds one batch); everything else from the scene `rest()`
returns once every frame is written (its per-frame members are not read). `maxDepth` bounds
every finite depth: the 16-bit depth's scale follows from it. */
void writeSyntheticScene(const String& dir, const std::vector<String>& names,
                         const SceneSynthesizer::Params& p, int frames, double maxDepth,
                         const std::function<void(int, SyntheticFrame&)>& frame,
                         const std::function<const SyntheticScene&()>& rest,
                         const ProgressCallback& progress);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
