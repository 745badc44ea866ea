// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_BLENDER_EXPORT_HPP
#define OPENCV_AUGOCC_BLENDER_EXPORT_HPP

#include <opencv2/core.hpp>
#include "opencv2/augocc/clone_builder.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/scene.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

//! Options of writeBlenderShot() (`augocc export-blender`).
struct CV_EXPORTS BlenderShotOptions
{
    //! The footage (video, image folder or printf pattern, as FrameSource opens it); empty: the
    //! shot has no movie clip.
    String footage;
    double fps = 0;          //!< frame rate of the shot; 0: the footage's (25 without footage)
    int firstFrame = 0;      //!< first frame of the shot
    int endFrame = -1;       //!< one past the last frame; -1: the footage's end (or last camera)
    String blendPath;        //!< if set, the script saves the built shot there (`.blend`)
    int samples = 64;        //!< Cycles samples per pixel the script sets, >= 1
    //! Name of the reconstruction in error messages (its file, when it comes from one).
    String reconstructionName = "reconstruction";
};

/** @brief Writes a Python script that Blender (3.4 or later) runs, `blender -b -P shot.py`, to
build the shot: the footage as movie clip and camera background (and, in the compositor, behind
the render), the camera animated with a keyframe per frame (pose and intrinsics), the clones of
the real objects as holdout objects (each key frame's patch voxels shown in the frames whose
patch set holds it, CloneSet::patchFrames()), the estimated ground as a shadow catcher, the
virtual objects where placeScene() puts them, and the light: the scene's sun when it has one
(resolveSun(): its direction, a SUN of strength pi (1 - sky) and a world of radiance sky, the
penumbra as the sun's angular diameter; the clones then also cast shadows and catch them), the
fixed light of the shading convention otherwise (doc/blender.md).

Conventions (written in the script too): Blender frame = augocc frame + 1 (Blender numbers clips
from 1). The shot's objects are children of an empty `augocc_world` whose transform takes the
reconstruction's world to Blender's z-up world (x right of the mean view, y away from the viewer,
z up, the ground at z = 0: estimateGround()), so every asset is written in the reconstruction's
world. OpenCV's camera looks down +z with y down, Blender's down -z with y up: the camera's
axes in the world are the columns of R^T diag(1, -1, -1). Intrinsics with sensor fit
HORIZONTAL on a frame of W x H pixels: `ortho_scale` = W / s (scaled orthographic) or lens =
fx * sensor_width / W (perspective); shift_x = (W / 2 - cx - 0.5) / W and shift_y =
(cy + 0.5 - H / 2) / W (OpenCV's pixel centres are at integers, Blender's frame spans [0, W]).
Lens distortion (k1, k2, k3; p1, p2) goes to the movie clip's tracking camera (POLYNOMIAL, or
BROWN with tangential terms) and to a Movie Distortion node on the render in the compositor.

Assets go to `<script stem>_assets/` beside the script, written as one folder (atomically): the
clones (CloneSet::exportPly()) and each virtual object's meshes as PLY in the reconstruction's
world. Paths in the script are relative to its folder.

@param scriptPath the script to write (`shot.py`), atomically.
@param rec the reconstruction: a camera for every frame of the shot.
@param clones the clones of the real objects.
@param scene the virtual objects (readScene()).
@param options footage, frames, `.blend` output.
Throws StsBadArg / StsBadSize / StsOutOfRange naming the reconstruction or footage when they do
not belong together or a frame of the shot has no camera, StsNotImplemented for lens distortion
Blender has no model of (rational, thin prism or tilt terms), before anything is written.
*/
CV_EXPORTS void writeBlenderShot(const String& scriptPath, const Reconstruction& rec,
                                 const CloneSet& clones, const VirtualScene& scene,
                                 const BlenderShotOptions& options = BlenderShotOptions());

//! @}

} // namespace augocc
} // namespace cv

#endif
