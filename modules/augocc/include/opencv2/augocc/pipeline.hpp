// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_PIPELINE_HPP
#define OPENCV_AUGOCC_PIPELINE_HPP

#include <functional>
#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera_refiner.hpp"
#include "opencv2/augocc/clone_builder.hpp"
#include "opencv2/augocc/compositor.hpp"
#include "opencv2/augocc/evaluation.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/mesh.hpp"
#include "opencv2/augocc/progress.hpp"
#include "opencv2/augocc/scene_synthesizer.hpp"

/*
The end-to-end runs behind `augocc composite`, `augocc run` and `augocc demo`, so that the command
line stays a thin shell: a sequence composited to a video or PNG folder with its optional outputs,
the whole pipeline from frames and masks, and the embedded demo (scored with the helpers of
evaluation.hpp).
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

//! Options of compositeSequence().
struct CV_EXPORTS CompositeOptions
{
    int firstFrame = 0;        //!< first frame composited
    int endFrame = -1;         //!< one past the last frame (-1: the end of the input)
    //! Compositor::Params::supersample (1: hard edges)
    int supersample = Compositor::Params().supersample;
    //! Compositor::Params::antialiasVirtual
    bool antialiasVirtual = Compositor::Params().antialiasVirtual;
    String mattesDir;          //!< if set: the clones' mattes, `DIR/<object>/%04d.png` (contract)
    /** if set: per frame `DIR/%04d.png`, 16-bit, camera-space z of the nearest surface (clone or
    virtual) as `(value - 1) / scale + offset`, 0 where nothing; `DIR/depth.yml` holds `scale`
    and `offset` */
    String depthDir;
    String virtualLayerDir;    //!< if set: per frame `DIR/%04d.png`, BGRA, the virtual objects
    double fps = 0;            //!< output video frame rate (0: the input's)
    //! Light frame (Compositor::Params::lightRotation); default: from estimateGround(rec).
    bool lightFromGround = true;
    /** The scene's sun (resolveSun()): disabled, the fixed light; set, Compositor::Params::sun
    with the ground of estimateGround(rec) receiving the virtual objects' shadows. */
    Sun sun;
    ProgressCallback progress; //!< stage "composite": frames written, after every frame
    //! Name of the reconstruction in error messages (its file, when it comes from one).
    String reconstructionName = "reconstruction";
};

/** @brief Composites frames [firstFrame, endFrame) of a sequence and writes the result.

@param input a video, an image folder or a printf pattern (FrameSource).
@param rec the reconstruction: a camera for every composited frame, image size = the frames'.
@param clones the clones of the real objects.
@param virtualObjects the virtual meshes, world frame of `rec`.
@param output a video file (`.mp4`, `.avi`, `.mkv`, `.mov`: H.264 through OpenCV's FFmpeg
backend, MPEG-4 part 2 when H.264 is unavailable) or a folder for `%04d.png` (frame indices of
the input).
@param options frames, optional outputs, progress.
@return the number of frames written.

Every output is written under a temporary name and renamed when all frames are done, so a failure
leaves no partial output. Throws (naming the file or argument): StsObjectNotFound / StsParseError
for an unreadable input, StsOutOfRange for a frame range outside the input, StsBadSize /
StsBadArg when the reconstruction does not match the input (image size, a frame without a camera,
cameras beyond the input's end), StsError when an output cannot be written.
*/
CV_EXPORTS int compositeSequence(const String& input, const Reconstruction& rec,
                                 const CloneSet& clones, const std::vector<Mesh>& virtualObjects,
                                 const String& output,
                                 const CompositeOptions& options = CompositeOptions());

//! Options of runPipeline() (`augocc run`).
struct CV_EXPORTS RunOptions
{
    String input;            //!< video, image folder or printf pattern
    String masksDir;         //!< key-frame masks, `MASKS/<object>/%04d.png`
    String scenePath;        //!< scene.yml; empty: stop after the mattes
    String outDir;           //!< every intermediate file and the composite go here
    /** Frames processed: [firstFrame, endFrame) of the input (`augocc run --frames a:b`, half-
    open), at least three (camera recovery needs three views). Every output keeps the input's
    frame numbers (tracks.yml has endFrame frames, the first firstFrame of them empty; cameras,
    `mattes/<object>/%04d.png` and the composite cover firstFrame..endFrame-1). Key-frame masks
    outside the range are ignored (RunResult::ignoredMasks); an object with none inside it is
    an error. */
    int firstFrame = 0;
    int endFrame = -1;       //!< one past the last frame processed; -1: the input's end
    //! Compositor::Params::supersample (1: hard edges)
    int supersample = Compositor::Params().supersample;
    //! Compositor::Params::antialiasVirtual
    bool antialiasVirtual = Compositor::Params().antialiasVirtual;
    //! Carve the clones further by photo-consistency over every frame (CloneBuilder::refine).
    bool photoRefine = true;
    /** Known intrinsics: OpenCV's calibration file (readCalibration(), scaled to the frames),
    read before any stage; empty: none (SfmOptions::calibration). */
    String calibrationPath;
    double focal = 0;               //!< known focal only, pixels (SfmOptions::focal); 0: none
    bool refineIntrinsics = false;  //!< SfmOptions::refineIntrinsics
    //! SfmOptions::selfCalibrate: false ignores lens distortion when nothing is known.
    bool selfCalibrate = true;
    //! SfmOptions::model: "auto", "scaled_orthographic" or "perspective".
    String model = SfmOptions().model;
    //! CloneBuilder::Params::voxelPixels (> 0).
    double voxelPixels = CloneBuilder::Params().voxelPixels;
    //! Carve the free space the tracks show (CloneBuilder::Params::freeSpace); false: the
    //! silhouettes only.
    bool freeSpace = true;
    /** Redo every stage. Otherwise a stage whose output in outDir is complete and whose
    manifest (`<output>.manifest.yml`: the inputs' signatures and the options that matter)
    matches this run is reused, not run again (see README, "Resume"). */
    bool force = false;
    //! Every stage's progress (track, sfm, clone, matte, composite), see Progress.
    ProgressCallback progress;
};

//! What runPipeline() produced.
struct CV_EXPORTS RunResult
{
    Tracks tracks;                      //!< as written to tracks.yml
    Reconstruction reconstruction;      //!< as written to reconstruction.yml
    SfmReport sfm;                      //!< what recoverCameras() did (lens model and why)
    Ptr<CloneSet> clones;               //!< as written to clones.yml.gz
    std::vector<Mesh> virtualObjects;   //!< placed, world frame of the reconstruction
    String compositePath;               //!< empty without a scene
    std::vector<std::pair<String, double> > stageSeconds;  //!< wall time per stage
    //! Stages whose output was reused from an earlier run (RunOptions::force); their
    //! stageSeconds are the reading. `tracks` stays empty when no stage run needed it, `sfm`
    //! when sfm was reused.
    std::vector<String> reused;
    //! Key-frame mask files left out because their frame is outside the frames processed
    //! (RunOptions::firstFrame, endFrame).
    std::vector<String> ignoredMasks;
};

/** @brief track -> sfm -> clone -> matte -> composite, writing into outDir: tracks.yml,
reconstruction.yml, clones.yml.gz, mattes/, composite.mp4 (contract), each with its manifest.

Every input is checked before the first stage (the frames, every key-frame mask: size, frame
within the input, neither empty nor the whole frame; the scene with its meshes and the clones it
is placed against; the calibration; the options): a bad one throws naming it and nothing is
written. A stage whose output and manifest match the inputs and options is reused (unless
RunOptions::force); one that runs rewrites its output atomically, then its manifest. Throws as
the stages do. */
CV_EXPORTS RunResult runPipeline(const RunOptions& options);

//! DemoOptions::lens.
enum DemoLens
{
    DEMO_LENS_SELF_CALIBRATE = 0,  //!< the lens from the footage (SfmOptions::selfCalibrate)
    DEMO_LENS_CALIBRATION = 1,     //!< the synthesized calibration.yml given to the run
    DEMO_LENS_IGNORED = 2          //!< no lens model
};

//! Options of runDemo() (`augocc demo`).
struct CV_EXPORTS DemoOptions
{
    String outDir = "augocc_demo";  //!< everything is written here
    //! Frames synthesized (SceneSynthesizer::Params::frames).
    int frames = SceneSynthesizer::Params().frames;
    //! Frame size (SceneSynthesizer::Params::imageSize).
    Size imageSize = SceneSynthesizer::Params().imageSize;
    //! Camera model of the synthesized footage (SceneSynthesizer::Params::model).
    CameraModel model = SceneSynthesizer::Params().model;
    //! Camera distance over the scene size (SceneSynthesizer::Params::distanceRatio; small values
    //! give strong perspective, as hand-held footage near a building).
    double distanceRatio = SceneSynthesizer::Params().distanceRatio;
    //! Camera path (SceneSynthesizer::Params::path).
    SceneSynthesizer::CameraPath path = SceneSynthesizer::Params().path;
    //! Azimuth swept by the camera, degrees (SceneSynthesizer::Params::orbitDegrees).
    double orbitDegrees = SceneSynthesizer::Params().orbitDegrees;
    //! Key frames given masks (SceneSynthesizer::Params::numKeyFrames).
    int numKeyFrames = SceneSynthesizer::Params().numKeyFrames;
    /** The lens of the synthesized footage (SceneSynthesizer::Params::distortion). The demo
    writes the true intrinsics to DemoResult::calibrationPath; the pipeline run does not read
    them (it recovers the cameras from the footage alone). */
    std::vector<double> distortion = SceneSynthesizer::Params().distortion;
    //! SceneSynthesizer::Params::exposureDrift.
    double exposureDrift = SceneSynthesizer::Params().exposureDrift;
    //! SceneSynthesizer::Params::whiteBalanceDrift.
    double whiteBalanceDrift = SceneSynthesizer::Params().whiteBalanceDrift;
    /** Bit rate of the footage, Mbit/s (SceneSynthesizer::Params::videoBitrateMbps). When set,
    the pipeline runs on that H.264 video, as a user's footage; 0: on lossless PNG frames. */
    double videoBitrateMbps = SceneSynthesizer::Params().videoBitrateMbps;
    /** How the run learns the lens: DEMO_LENS_SELF_CALIBRATE (from the footage alone, the
    default), DEMO_LENS_CALIBRATION (`augocc run --calibration` with the synthesized
    calibration.yml; needs videoBitrateMbps > 0, which writes it), DEMO_LENS_IGNORED (no lens
    model: what augocc did before issue 15, for comparison). */
    int lens = DEMO_LENS_SELF_CALIBRATE;
    bool photoRefine = true;  //!< RunOptions::photoRefine
    /** The demo scene's sun (demoSun()): the footage is synthesized under it (real shadows)
    and scene.yml carries it, so the composite has shadows both ways; false: the fixed light
    of the shading convention and no shadows (the "before" of doc/lighting.md). */
    bool sun = true;
    //! Progress of the synthesis (stage "synth") and of the run (RunOptions::progress).
    ProgressCallback progress;
};

/** @brief The hand-held demo (`augocc demo --model handheld`): street-level hand-held 1280x720
footage through a lens with k1 = -0.12, the camera 1.5 scene sizes away walking 30 degrees past
the scene, 90 frames, 6 key frames, exposure drift 0.15, white-balance drift 0.05, H.264 at 8
Mbit/s (a phone's rate at 720p). */
CV_EXPORTS DemoOptions handheldDemoOptions();

//! What runDemo() produced and measured.
struct CV_EXPORTS DemoResult
{
    String compositePath;     //!< the composited video
    String contactSheetPath;  //!< input frames above their composites (PNG)
    String scenePath;         //!< the scene file the demo placed its virtual objects with
    RunResult run;            //!< what the pipeline run on the synthesized video produced
    double fractionWithin = 0;   //!< mean over frames, composite vs ground truth (8 grey levels)
    double boundaryDistance = 0; //!< occlusion boundary, px: mean over the boundaryFrames
    int boundaryFrames = 0;      //!< frames where the truth or the composite has one
    double rotationErrorDeg = 0; //!< mean camera rotation error after alignment
    //! measureSlide() of the recovered cameras against the true ones (with their lens)
    SlideStats slide;
    //! PERSPECTIVE: |f_recovered / f_true - 1| of the first camera, percent
    double focalErrorPercent = 0;
    /** Mattes against the true visible silhouettes, outside the pixels where another object is
    seen (there the clone is behind it, by design): the lowest IoU over the objects' key frames,
    and the mean over every object's non-key frames. */
    double keyFrameIoU = 1;
    double nonKeyIoU = 0;  //!< see keyFrameIoU
    //! The true intrinsics (OpenCV's calibration.yml) of PERSPECTIVE footage written as a data
    //! set (DemoOptions::videoBitrateMbps > 0); else empty.
    String calibrationPath;
    /** DemoOptions::sun: scoreShadows() of the composite against the synthesizer's truth over
    the scored frames (band pixels pooled): the virtual objects' shadows on the real surfaces
    (no virtual object in either image), and the real objects' shadows on the virtual ones
    (covered in both). fractionWithin and bandPixels pool the frames' bands; boundaryDistance
    is the mean over the frames with a shadow boundary, boundaryPixels counts those frames.
    bandPixels 0: no shadow in any frame. */
    ShadowScore shadowReal;
    //! The real objects' shadows on the virtual ones, scored as shadowReal.
    ShadowScore shadowVirtual;
};

/** @brief The demo scene's sun: azimuth 150 degrees (clockwise from north, north = the mean
view direction: from behind the camera, on its right), elevation 55 degrees, sky share 0.5,
penumbra 3 px: the building's shadow falls on the dome, the dome's and the tree's on the ground.
(Elevation 40 with sky 0.4 left the L-block's inner corner in deep shadow, where the clones
carved worse: occlusion boundary 5.5 px against 0.4 px; doc/lighting.md.) */
CV_EXPORTS SceneSun demoSun();

/** @brief The embedded demo: synthesizes a scene, writes its video and key-frame masks, a
scene.yml with a procedural dome behind the front building and a tree in front of it, runs
runPipeline() on the synthesized frames from tracking on, writes a contact sheet of frames
before and after, and scores the composite against the synthesizer's ground truth (the
reconstruction aligned to the true world by alignReconstructions()). */
CV_EXPORTS DemoResult runDemo(const DemoOptions& options);

/** @brief The demo's virtual objects after the paper's Fig. 3: a dome behind the front building
("building") and a tree in front of it, placed by the scene helpers.
@param path the scene's path (meshes are procedural; the path names the scene in messages). */
CV_EXPORTS VirtualScene demoVirtualScene(const String& path);

//! @}

} // namespace augocc
} // namespace cv

#endif
