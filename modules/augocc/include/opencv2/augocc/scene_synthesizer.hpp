// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SCENE_SYNTHESIZER_HPP
#define OPENCV_AUGOCC_SCENE_SYNTHESIZER_HPP

#include <functional>
#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/lighting.hpp"
#include "opencv2/augocc/mesh.hpp"
#include "opencv2/augocc/progress.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Everything a synthesized data set holds: frames and their ground truth.

World frame: y is up, the ground is the plane y = 0, objects stand on it near the origin; scene
size (the diameter of the objects' footprint) about 10 world units.

Tracks (columns p of `tracks`, `cleanTracks`, rows of `groundTruth.points`):
- Inlier tracks are 3D points sampled on the surfaces of the objects (about 60%) and of the ground
  that are visible (front-facing and not hidden) in the middle frame, and that project inside
  every frame with a 2 px margin. A full track is observed in EVERY frame, even where another
  object hides its point in that frame: occlusion is ignored on purpose, so that the full
  measurement matrix of the factorization is available (tests of the paper's method need it).
- `cleanTracks` are the exact projections through the true cameras; `tracks` add independent
  Gaussian noise of standard deviation Params::noiseSigma to u and v (so the reprojection RMS per
  coordinate equals noiseSigma).
- Partial tracks (Params::partialFraction of all tracks, chosen at random) are observed only on
  one random contiguous range of frames, at least 20% of the sequence long and shorter than it;
  both `tracks` and `cleanTracks` are NaN outside that range.
- Outlier tracks (Params::outlierFraction, chosen at random, flagged in `outlierTrack`) are 2D
  random walks that follow no 3D point; their `groundTruth.points` row is NaN and their
  `cleanTracks` hold the same 2D positions as `tracks` (no noise is added to them), so both
  matrices have the same NaN pattern.

Masks are CV_8U, 255 inside, 0 outside; `visibleMasks` are the pixels where `labels` names the
object, so they are always inside `wholeMasks`. Depth is camera-space z (Camera::depth); the ground
is a 120 x 120 square, so the depth is +inf only where the sky shows (perspective views with a
wide field of view).
*/
struct CV_EXPORTS SyntheticScene
{
    //! BGR CV_8UC3, one per frame
    std::vector<Mat> frames;
    //! true camera of every frame, and true 3D point per track (NaN row: outlier track)
    Reconstruction groundTruth;
    //! measured tracks: noise, partial and outlier tracks per Params
    Tracks tracks;
    //! noise-free projections of the same tracks (same NaN pattern; outliers as in `tracks`)
    Tracks cleanTracks;
    //! 1 where track p is a gross outlier (not a 3D point)
    std::vector<uchar> outlierTrack;
    //! real objects ("building", "lblock", "tower"); front to back is not implied
    std::vector<String> objectNames;
    //! true geometry of each real object, world coordinates
    std::vector<Mesh> objectMeshes;
    //! per object, every frame: the whole silhouette (as if alone)
    ObjectMasks wholeMasks;
    //! per object, every frame: the silhouette others leave visible
    ObjectMasks visibleMasks;
    //! the user's input: visible silhouettes in the key frames
    ObjectMasks keyFrameMasks;
    //! key frames (first and last included)
    std::vector<int> keyFrames;
    //! CV_32F camera-space z per pixel (+inf where nothing)
    std::vector<Mat> depth;
    //! CV_8U: 0 ground/background, i + 1 where object i is seen
    std::vector<Mat> labels;
};

/** @brief Renders, headless through OSMesa, a textured static scene (a ground plane and several
real objects: a box building in front, an L-shaped block, a mushroom-shaped tower like the paper's
hotel) seen by a camera orbiting far away, with its ground truth. Deterministic for a seed.

Objects (names as in SyntheticScene::objectNames): "building" (a box in front), "lblock" (an
L-shaped, non-convex block on the left), "tower" (a narrow round shaft under a wide cap and a
conical roof, behind). The building hides part of the tower early in the default orbit and part of
the L-block late in it.

Camera: it looks at the scene centre from distance D = distanceRatio * scene size, at azimuth
swept linearly over orbitDegrees (centred on the +z axis) and elevation elevationDegrees, with a
small smooth hand-held jitter (about 1 degree) in elevation and roll. SCALED_ORTHOGRAPHIC uses one
constant s for the whole sequence so that the scene fills about 60% of the frame width (its
cameras also sit at distance D, so that depths are positive); PERSPECTIVE uses f = s * D, i.e.
the same framing at the scene centre. Principal point at the image centre ((W-1)/2, (H-1)/2).

Lighting (frames and virtual objects alike; src/shading.hpp holds the constants and a GL mesh
drawer for the compositor): one directional light fixed in the world, towards
normalize(0.35, 0.8, 0.5) (above, +z and +x side), white; per-vertex colour
base * (Material::ambient + Material::diffuse * max(0, n . L)) clamped to [0, 1], base = the vertex
colour or white, multiplied by Material::texture (u right, v up).
With Params::sun set, the light is that sun instead, with cast shadows (shadow maps, percentage-
closer filtered: lighting.hpp and doc/lighting.md): the real objects' and the ground's materials
are split into the sky share and the sun's (ambient = sky (a + d), diffuse = (1 - sky) (a + d)),
so a real pixel is albedo * (sky + (1 - sky) * V * max(0, n . L)); virtual objects keep their
own material, colour = base * (ambient + diffuse * V * max(0, n . L)).

Rendering happens on the calling thread with one offscreen OpenGL context owned by the object and
reused by every call; calls on one object are serialized by a mutex. Each call makes that context
current on the calling thread.
*/
class CV_EXPORTS SceneSynthesizer : public Algorithm
{
public:
    //! Camera paths of Params::path.
    enum CameraPath
    {
        /** The orbit described above the class: far away, azimuth swept over orbitDegrees at
        elevationDegrees, about 1 degree of jitter. */
        PATH_ORBIT = 0,
        /** Street-level hand-held: a walker at D = distanceRatio * scene size from the scene
        centre (horizontally, +-kHandheldSwayUnits) sweeping orbitDegrees of azimuth past the
        scene, the camera at kHandheldHeightFraction of the tallest object's height above the
        ground (about 1.6 units: the front building is 3.2 units tall, two storeys, so about 3 m)
        with smooth sway of the hand (+-kHandheldSwayUnits per axis), aim wobble (yaw and pitch,
        +-kHandheldWobbleDeg) and roll (+-kHandheldRollDeg) around the line of sight to the
        scene centre. Every motion is a sum of three sinusoids of 0.6-3.2 cycles per shot with
        phases from the seed (elevationDegrees is not used). */
        PATH_HANDHELD = 1
    };
    //! Largest frame size: UHD 3840 x 2160 (or 2160 x 3840).
    static constexpr int kMaxImageWidth = 3840;
    //! Largest frame size: the other side.
    static constexpr int kMaxImageHeight = 2160;
    //! PATH_HANDHELD: camera height over the tallest object's height.
    static constexpr double kHandheldHeightFraction = 0.25;
    //! PATH_HANDHELD: peak sway of the camera centre per axis, world units.
    static constexpr double kHandheldSwayUnits = 0.12;
    //! PATH_HANDHELD: peak aim wobble (yaw, pitch), degrees.
    static constexpr double kHandheldWobbleDeg = 1.5;
    //! PATH_HANDHELD: peak roll, degrees.
    static constexpr double kHandheldRollDeg = 1.5;
    //! Lens distortion: the finest sampling of labels, depth and masks (see Params::distortion).
    static constexpr int kLensMaskSupersample = 2;
    //! Lens distortion: at most this many samples per label / depth / mask render.
    static constexpr int kLensMaskPixels = 12 * 1000 * 1000;

    /** @brief Parameters of the synthesized scene; the defaults are the initializers.

    Valid ranges (setParams() throws StsBadArg/StsOutOfRange otherwise): frames >= 2, both image
    sides >= 32, distanceRatio >= 1, orbitDegrees in [0, 360], elevationDegrees in (0, 90),
    numTracks >= 1, noiseSigma >= 0, both fractions in [0, 1], numKeyFrames in [2, frames],
    frameSupersample in [1, 8], both image sides within kMaxImageWidth x kMaxImageHeight (either
    orientation), distortion empty or 4, 5, 8, 12 or 14 finite values with model PERSPECTIVE
    (and no fold-over inside the frame, see LensView::get()), path HANDHELD with model
    PERSPECTIVE, |exposureDrift| and |whiteBalanceDrift| < 1, videoBitrateMbps in [0, 200]. */
    struct CV_EXPORTS Params
    {
        //! Number of frames.
        int frames = 60;
        //! Frame size, pixels.
        Size imageSize = Size(640, 480);
        //! Camera model of the frames and of the ground truth.
        CameraModel model = SCALED_ORTHOGRAPHIC;
        //! Camera distance / scene size; the framing stays the same (lower: stronger
        //! perspective in PERSPECTIVE frames).
        double distanceRatio = 10.0;
        //! Azimuth swept by the camera over the sequence, degrees.
        double orbitDegrees = 50.0;
        //! Mean elevation of the camera above the ground, degrees.
        double elevationDegrees = 25.0;
        //! Tracks (3D points on the objects and the ground).
        int numTracks = 600;
        //! Gaussian noise of `tracks`, pixels, standard deviation per axis.
        double noiseSigma = 0.5;
        //! Fraction of tracks that start/end mid-sequence.
        double partialFraction = 0.0;
        //! Fraction of tracks that are gross outliers.
        double outlierFraction = 0.0;
        //! Key frames, evenly spaced, first and last included.
        int numKeyFrames = 6;
        //! Random seed (textures, jitter, points, noise).
        uint64 seed = 1;
        /** Frames are rendered at this factor and averaged down (INTER_AREA), i.e. anti-aliased
        like a camera integrating over each pixel; masks, labels and depth are always sampled at
        pixel centres. 1 = one sample per pixel (hard, aliased edges). */
        int frameSupersample = 1;
        /** Lens distortion of the true cameras (OpenCV's k1, k2, p1, p2[, k3 ...], exactly
        cv::projectPoints' model), PERSPECTIVE only; empty = an ideal pinhole (today's frames).
        Frames, labels, depth and masks are rendered in the ideal pinhole view of LensView and
        warped into the distorted frame: colours bilinearly; labels, depth and masks from a
        view rendered kLensMaskSupersample times finer (fewer for large frames: at most
        kLensMaskPixels samples) by nearest sample, i.e. a frame pixel's mask is the object its
        ray through a point within 0.5 / factor ideal pixels of its centre hits. */
        std::vector<double> distortion;
        //! Camera path (see CameraPath).
        CameraPath path = PATH_ORBIT;
        /** Auto-exposure drift: the frames' gain moves smoothly (a raised-cosine ramp) from 1 at
        the first frame to 1 + exposureDrift at the last, multiplying the rendered BGR values
        (saturated to 255). Frames only: masks, depth, labels and cameras are unchanged. */
        double exposureDrift = 0.0;
        /** White-balance change over the shot on the same ramp: red gain 1 + w, blue gain
        1 - w, green 1, with w going from 0 to whiteBalanceDrift (positive: warmer). */
        double whiteBalanceDrift = 0.0;
        /** writeSyntheticScene(): bit rate of video.mp4, Mbit/s (H.264, libx264 through the
        `ffmpeg` tool, a phone's 8-16 Mbit/s at 1080p); 0 = OpenCV's VideoWriter with its own
        rate (H.264, else MPEG-4 part 2). */
        double videoBitrateMbps = 0.0;
        /** The sun (lighting.hpp): disabled (the default), the fixed light above and no
        shadows; set, its direction (world, y up: direction[1] > 0, above the horizon) lights
        the scene with cast shadows, the sky share and the penumbra (world units) it holds. */
        Sun sun;
        //! Progress of synthesize() (stage "synth"): frames rendered.
        ProgressCallback progress;
    };

    /** @brief The per-frame gains of Params::exposureDrift and Params::whiteBalanceDrift.
    @param params the parameters.
    @param frame frame index in [0, frames).
    @return (blue, green, red) gains multiplying the rendered frame. */
    static Vec3d frameGains(const Params& params, int frame);

    //! Creates a synthesizer; throws as setParams() does on invalid parameters.
    //! @param params scene parameters.
    static Ptr<SceneSynthesizer> create(const Params& params);
    //! Creates a synthesizer with default Params.
    static Ptr<SceneSynthesizer> create();
    //! The current parameters.
    virtual Params getParams() const = 0;
    //! Validates and sets the parameters (see Params for the ranges).
    virtual void setParams(const Params& params) = 0;

    //! Synthesizes the whole sequence with its ground truth.
    virtual void synthesize(SyntheticScene& scene) const = 0;

    /** @brief Writes the data set to a folder as writeSyntheticScene() does, rendering it frame
    by frame: memory holds a few frames, not the shot (a 1280x720 shot of 1800 frames held whole
    needs about 16 GB). The files are those synthesize() + writeSyntheticScene() write, except
    the 16-bit depth's scale (gt/depth/depth.yml), chosen from the scene's bounds rather than
    the depths rendered (it may be one power of ten smaller). Progress: stage "synth", step
    "write", frames written (Params::progress).
    @param dir output folder, built under a temporary name and renamed into place.
    */
    virtual void write(const String& dir) const = 0;

    /** @brief Renders one frame of the sequence with virtual objects inserted using the true
    geometry (the compositor's ground truth). Under Params::sun the virtual objects are
    rendered as if real: lit by the sun, they cast shadows onto the ground, the real objects and
    each other, and receive the real objects' shadows (the truth of the compositor's shadows). Through the lens when the cameras have one (the
    distorted frame). With exposure or white-balance drift (Params) the real scene's pixels
    carry the frame's gains and the virtual objects' do not: the truth is what a compositor that
    draws the virtual objects at the nominal exposure onto the filmed frame produces (augocc's
    compositor does not model the camera's exposure); edge pixels blend the two by coverage.
    @param frame frame index.
    @param virtualObjects meshes in world coordinates.
    @param image output BGR CV_8UC3.
    @param supersample render at this factor and average down (anti-aliased ground truth);
    with no virtual object and supersample == Params::frameSupersample the result is the frame.
    */
    virtual void renderWithVirtual(int frame, const std::vector<Mesh>& virtualObjects,
                                   OutputArray image, int supersample = 1) const = 0;

    /** @brief Renders one frame with its per-frame ground truth: the per-frame part of
    synthesize(), for the perf suite and for tools that need a single frame.
    @param frame frame index in [0, frames).
    @param image output BGR CV_8UC3, identical to SyntheticScene::frames[frame].
    @param depth optional output CV_32F camera-space z (+inf where nothing).
    @param labels optional output CV_8U, 0 ground/sky, i + 1 where object i is seen.
    @param wholeMasks optional output, one CV_8U mask per object (objectNames() order), each
    object rendered as if alone.
    */
    virtual void renderFrame(int frame, OutputArray image, OutputArray depth = noArray(),
                             OutputArray labels = noArray(),
                             OutputArrayOfArrays wholeMasks = noArray()) const = 0;

    //! True camera of a frame (the same as SyntheticScene::groundTruth.camera(frame)).
    virtual Camera getCamera(int frame) const = 0;
    //! Names of the real objects, in label order.
    virtual std::vector<String> getObjectNames() const = 0;
    //! True geometry of the real objects (world coordinates, textured), in label order.
    virtual std::vector<Mesh> getObjectMeshes() const = 0;
};

/** @brief Writes a synthesized data set to a folder, as `augocc synth` does: frames/%04d.png,
video.mp4 (H.264, else MPEG-4 part 2; at Params::videoBitrateMbps when set), calibration.yml
(the true intrinsics as OpenCV's calibration file: camera_matrix, distortion_coefficients,
image_width, image_height; PERSPECTIVE only), tracks.yml, input/masks (key frames), gt/masks (whole),
gt/visible_masks, gt/reconstruction.yml, gt/clean_tracks.yml, gt/depth (16-bit PNG, z = value /
scale, scale in gt/depth/depth.yml, 0 = nothing), gt/labels, `gt/meshes/<object>.ply` and
gt/synth.yml (parameters, objects, key frames, outlier flags). See doc/synthesizer.md.

The folder is built under a temporary name beside `dir` and renamed into place: a failure leaves
no partial folder; an existing `dir` is replaced on success only.
@param dir output folder.
@param scene the data set (from SceneSynthesizer::synthesize).
@param params the parameters it was made with (recorded in gt/synth.yml).
@param progress optional (stage "synth", step "write"): frames written, from the calling thread.
*/
CV_EXPORTS void writeSyntheticScene(const String& dir, const SyntheticScene& scene,
                                    const SceneSynthesizer::Params& params,
                                    const ProgressCallback& progress = ProgressCallback());

//! @}

} // namespace augocc
} // namespace cv

#endif
