// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_HPP
#define OPENCV_AUGOCC_HPP

/** @defgroup augocc Resolving occlusion in image sequences

Virtual objects inserted into a video of a static real scene, hidden correctly by the real
objects in front of them, after Ong, Teh & Tan @cite Ong1998: feature tracks, Tomasi-Kanade
factorization @cite Tomasi1992, camera refinement, user silhouettes in key frames, voxel clones of
the real objects, and compositing by depth test.
*/

#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/mesh.hpp"
#include "opencv2/augocc/scene_synthesizer.hpp"
#include "opencv2/augocc/feature_tracker.hpp"
#include "opencv2/augocc/factorization_sfm.hpp"
#include "opencv2/augocc/camera_refiner.hpp"
#include "opencv2/augocc/sfm_export.hpp"
#include "opencv2/augocc/clone_builder.hpp"
#include "opencv2/augocc/compositor.hpp"
#include "opencv2/augocc/scene.hpp"
#include "opencv2/augocc/pipeline.hpp"
#include "opencv2/augocc/evaluation.hpp"
#include "opencv2/augocc/silhouette_editor.hpp"
#include "opencv2/augocc/key_frames.hpp"
#include "opencv2/augocc/visualization.hpp"

#endif
