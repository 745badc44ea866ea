// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_PROGRESS_HPP
#define OPENCV_AUGOCC_PROGRESS_HPP

#include <functional>
#include <opencv2/core.hpp>

/*
The one progress report of every long stage (track, sfm, clone, matte, composite, synth): what the
library tells a caller while it works, so that a command line or a GUI can show it. Each
algorithm carries the callback in its Params (FeatureTracker, CloneBuilder, SceneSynthesizer) or
options struct (SfmOptions, CompositeOptions, RunOptions, DemoOptions); the few free functions
without either (writeMattes, writeSyntheticScene) take it as their last argument. Results never
depend on whether a callback is set.
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Where a long stage is.

Within one (stage, step) `done` never decreases; a new step of a stage starts again from 0 (the
bundle adjustments of sfm are steps, each counting its iterations). The callback is called from
the thread that called the library function, never from a parallel_for_ body, between units of
work: a caller may print or redraw from it, and must return quickly. */
struct CV_EXPORTS Progress
{
    String stage;    //!< "track", "sfm", "clone", "matte", "composite", "synth"
    String step;     //!< part of the stage ("scaled-orthographic BA", "photo-consistency"), or ""
    int64 done = 0;  //!< units done in this step
    int64 total = 0; //!< units in this step; 0: unknown (an upper bound when the work may stop
                     //!< early, as a solver's iterations)
    String unit;     //!< what is counted: "frames", "iterations", "passes"
    String message;  //!< optional detail of the unit just done ("carve: building")
};

//! Receives Progress reports; empty: none.
typedef std::function<void(const Progress&)> ProgressCallback;

//! @}

} // namespace augocc
} // namespace cv

#endif
