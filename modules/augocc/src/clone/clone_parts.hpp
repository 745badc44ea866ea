// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CLONE_PARTS_HPP
#define OPENCV_AUGOCC_CLONE_PARTS_HPP

#include <vector>
#include "clone/clone_set.hpp"

// What lets CloneBuilder::mergeParts() refuse parts that were not built from the same inputs:
// fingerprints (64-bit FNV-1a, as hex) of what the per-object passes read, and the parameters as
// text (so that the message can name the one that differs).

namespace cv {
namespace augocc {
namespace detail {

//! Every parameter that changes a clone (all of Params but the progress callback), as
//! "name=value" words separated by blanks, numbers with 17 significant digits.
CV_EXPORTS String paramsText(const CloneBuilder::Params& params);
//! The cameras, image size, model and points of `rec`, bit for bit.
CV_EXPORTS String fingerprintReconstruction(const Reconstruction& rec);
//! Every object's name, key frames and binary silhouettes (> 127).
CV_EXPORTS String fingerprintMasks(const ObjectMasks& masks);
//! The observations of `tracks`; "none" for null.
CV_EXPORTS String fingerprintTracks(const Tracks* tracks);

/** @brief The objects of `parts` moved into one complete set (not partial), after checking them
against one another and against `expected` (the fingerprints of the inputs mergeParts() was
given): StsBadArg naming the part and the object for a part that is not partial, an object in
two parts, an object of the masks in no part, or other inputs. The parts are left empty. */
CV_EXPORTS Ptr<CloneSetImpl> combineParts(const std::vector<CloneSetImpl*>& parts,
                                          const PartInfo& expected);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
