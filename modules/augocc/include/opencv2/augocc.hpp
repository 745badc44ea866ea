// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_HPP
#define OPENCV_AUGOCC_HPP

/** @defgroup augocc Resolving occlusion in image sequences

Virtual objects inserted into a video of a static real scene, hidden correctly by the real
objects in front of them, after Ong, Teh & Tan @cite Ong1998, in stages: feature tracks
(cv::augocc::FeatureTracker), Tomasi-Kanade factorization @cite Tomasi1992
(cv::augocc::FactorizationSfM), camera refinement (cv::augocc::OrthoCameraRefiner,
cv::augocc::recoverCameras()), user silhouettes in key frames (cv::augocc::SilhouetteEditor),
voxel clones of the real objects (cv::augocc::CloneBuilder, cv::augocc::CloneSet), and compositing
by depth test (cv::augocc::Compositor). cv::augocc::SceneSynthesizer renders scenes with their
ground truth for tests and demos.

@section augocc_conventions Conventions

Every type, function and file of the module follows these; headers do not restate them.

@subsection augocc_conventions_camera Cameras
- World to camera: `Xc = R * Xw + t`, R a 3x3 rotation (camera from world), t a 3-vector; the
  camera centre is `-R^T * t`. Rotations are 3x3 matrices; a rotation given as a 3-vector is a
  Rodrigues vector in radians.
- The camera looks along its +z axis; its x axis points right in the image, y down.
- Depth of a point is its camera-space `Xc.z` (larger = farther) in every camera model, so that
  the depths of clones and of virtual objects compare whatever the model. Depth images are
  CV_32F camera-space z, +inf where nothing is seen.
- cv::augocc::SCALED_ORTHOGRAPHIC (the paper's model): `u = s * Xc.x + cx`,
  `v = s * Xc.y + cy`, with s the zoom in pixels per world unit and (cx, cy) the principal point.
- cv::augocc::PERSPECTIVE (OpenCV's pinhole, intrinsics K, no lens distortion):
  `u = fx * Xc.x / Xc.z + skew * Xc.y / Xc.z + cx`, `v = fy * Xc.y / Xc.z + cy`.

@subsection augocc_conventions_pixels Pixels, images and masks
- Image coordinates are pixels: (0, 0) is the centre of the top-left pixel, x to the right,
  y down (OpenCV's convention), so pixel column x, row y covers [x - 0.5, x + 0.5] x
  [y - 0.5, y + 0.5].
- Frames are BGR CV_8UC3 (CV_8UC1 grey where a function says so), of one size per sequence.
- Masks (silhouettes, mattes) are CV_8U images of the frame size; a pixel > 127 is the object.
  Masks the module writes are 0 or 255.

@subsection augocc_conventions_units Units and indices
- Lengths are in world units, the reconstruction's own (cv::augocc::FactorizationSfM chooses the
  unit that makes the zoom s = 1, 1 on average on its incremental path); image quantities are in
  pixels; angles are in degrees unless the name or the comment says radians.
- Frame indices are 0-based, counted in the input sequence as decoded (frame i is the i-th image
  of a video, of a folder sorted by name or of a printf pattern).
- Tracks: cv::augocc::Tracks::at(f, p) is track p in frame f, NaN where it is not observed (the
  tracks are stored sparse, one entry per observation); row p of
  cv::augocc::Reconstruction::points is the 3D point of track p, a row of NaN where the track
  has none.
*/

#include "opencv2/augocc/progress.hpp"
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/lens.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/chunks.hpp"
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
#include "opencv2/augocc/blender_export.hpp"
#include "opencv2/augocc/evaluation.hpp"
#include "opencv2/augocc/silhouette_editor.hpp"
#include "opencv2/augocc/image_viewport.hpp"
#include "opencv2/augocc/placement_editor.hpp"
#include "opencv2/augocc/key_frames.hpp"
#include "opencv2/augocc/visualization.hpp"
#include "opencv2/augocc/sun_estimation.hpp"

#endif
