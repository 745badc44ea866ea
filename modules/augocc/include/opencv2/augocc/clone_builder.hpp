// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CLONE_BUILDER_HPP
#define OPENCV_AUGOCC_CLONE_BUILDER_HPP

#include <map>
#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/progress.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief The clones of the real objects (the paper's Section 6 @cite Ong1998): per object a
dense voxel grid (the trimmed model) and a set of patch voxels per key frame.

This is what the compositor and `augocc matte` consume. Made by CloneBuilder::build() or load().

Conventions of a clone (the module's own are in @ref augocc_conventions):
- The grid's axes are the columns of a rotation `Rbox` (box axes in world coordinates); voxel
  (i, j, k) has its centre at `origin + Rbox * (voxelSize * (i + 0.5, j + 0.5, k + 0.5))`.
- The footprint of a voxel in an image is the set of pixel centres inside the bounding rectangle
  of its projected cube, plus the pixel its centre rounds to. Carving keeps a voxel only when its
  whole footprint lies in the silhouette (or in an "unknown" pixel), and render() draws exactly
  the footprints: one rule, so that in a key frame the clone never covers a pixel outside the
  silhouette and the patch voxels make up the rest exactly.
- Depth is the camera-space z of the nearest voxel centre, as everywhere in the module.
*/
class CV_EXPORTS CloneSet
{
public:
    virtual ~CloneSet();

    //! Names of the objects, sorted.
    virtual std::vector<String> objectNames() const = 0;

    /** @brief Renders one object's clone into a frame: matte and camera-space depth.
    @param object object name (one of objectNames()).
    @param frame frame index; selects the patch set that applies to it.
    @param camera the frame's camera.
    @param imageSize frame size.
    @param matte output CV_8U, 255 where the clone (with the frame's patches) projects, else 0.
    @param depth optional output CV_32F, camera-space z of the nearest clone surface, +inf elsewhere.
    */
    virtual void render(const String& object, int frame, const Camera& camera, Size imageSize,
                        OutputArray matte, OutputArray depth = noArray()) const = 0;

    //! Saves to a FileStorage file (`.yml.gz` recommended); atomic. A partial set is written
    //! as a partial clones file (`format: augocc_clones_part`), which only loadPart() reads.
    virtual void save(const String& path) const = 0;
    /** @brief Loads a clones file written by save(); throws naming the file on error.

    A partial clones file (a set made by CloneBuilder::buildPart()) is refused with StsBadArg
    naming the file and its objects: its clones lack the passes that need every object, so
    rendering it would give wrong mattes. Merge the parts first (CloneBuilder::mergeParts(),
    `augocc clone --merge`). */
    static Ptr<CloneSet> load(const String& path);
    /** @brief Loads a partial clones file (a set made by CloneBuilder::buildPart() and saved),
    for CloneBuilder::mergeParts(). Throws naming the file on error, and StsBadArg when the file
    is a complete clones file (there is nothing to merge in it: use load()). */
    static Ptr<CloneSet> loadPart(const String& path);
    /** @brief True for a partial set: made by CloneBuilder::buildPart() or loadPart(), it holds
    some objects' clones before the passes that look at every object (unobserved volume, patch
    voxels). Such a set is input to CloneBuilder::mergeParts() only: rendering its mattes,
    refine() and addKeyFrame() refuse it. A CloneSet of another implementation is not partial
    (the default). */
    virtual bool isPartial() const;

    //! Key frames of an object (frames holding a patch set), increasing.
    virtual std::vector<int> keyFrames(const String& object) const = 0;
    //! The key frames whose patch voxels apply to `frame`: the frame itself when it is a key
    //! frame, else per the builder's PatchRule (one, or the two around it).
    virtual std::vector<int> patchFrames(const String& object, int frame) const = 0;
    //! Number of voxels of the trimmed model (without patches).
    virtual int voxelCount(const String& object) const = 0;
    //! Number of patch voxels of one key frame (0 when `keyFrame` is not a key frame).
    virtual int patchVoxelCount(const String& object, int keyFrame) const = 0;
    //! Grid dimensions (nx, ny, nz) of an object's voxel grid.
    virtual Vec3i gridSize(const String& object) const = 0;
    //! Voxel edge length in world units.
    virtual double voxelSize(const String& object) const = 0;
    /** @brief Box of an object's grid: rotation whose columns are the box axes in world
    coordinates, and the world position of the grid's corner (voxel (0,0,0)'s outer corner). */
    virtual void gridPose(const String& object, Matx33d& Rbox, Vec3d& origin) const = 0;
    /** @brief Writes `DIR/<object>_clone.ply` (the trimmed model's surface as quads split into
    triangles) and `DIR/<object>_patches_%04d.ply` (one per key frame, patch voxels as cubes), to
    open in MeshLab or Blender. Creates DIR when needed. */
    virtual void exportPly(const String& dir) const = 0;
};

/** @brief Builds clones of real objects from a reconstruction and key-frame silhouettes (the
paper's Section 6, Steps 1-5), with the extensions documented in doc/clones.md: robust point
clustering, automatic box orientation, occlusion-aware carving, both camera models, several rays
per pixel for patches and an incremental key frame.
*/
class CV_EXPORTS CloneBuilder : public Algorithm
{
public:
    //! Step 2: how the box (and the voxel grid) is oriented.
    enum Orientation
    {
        ORIENT_AUTO = 0,  //!< vertical from the cameras' horizontal x axes, then least footprint
        ORIENT_WORLD = 1, //!< the reconstruction's axes (the paper's initial box)
        ORIENT_USER = 2   //!< BoxParams::userRotation (the paper's interactive rotation)
    };
    //! Which key frames' patch voxels apply to a frame that is not a key frame.
    enum PatchRule
    {
        PATCH_NEAREST = 0,   //!< the nearest key frame (the paper); ties go to the earlier one
        PATCH_BRACKETING = 1 //!< both key frames around the frame (the nearest outside the range)
    };

    //! Steps 1-3: the box that holds the object, from its points and its silhouettes.
    struct CV_EXPORTS BoxParams
    {
        //! Step 1: fewer clustered points than this and the box comes from the silhouettes alone.
        int minPoints = 4;
        //! Step 1: fraction of the points trimmed at each end of every box axis, in [0, 0.5).
        //! Higher gives a smaller box for Step 3 to enlarge. At a box face that no key frame sees
        //! (the bottom, for cameras above the ground) the trimmed points that continue the rest
        //! (gaps up to 10% of the trimmed extent) are given back: Step 3 cannot restore that side.
        double trimFraction = 0.02;
        //! Step 2: an Orientation.
        int orientation = ORIENT_AUTO;
        //! ORIENT_USER: Rodrigues vector (radians) of the box axes in world coordinates.
        Vec3d userRotation = Vec3d(0, 0, 0);
        //! Step 3: at most this many passes over the key frames while enlarging the box.
        int maxEnlargeIterations = 20;
    };

    //! Step 5: patch voxels, per key frame, that make the clone cover its silhouette exactly.
    struct CV_EXPORTS PatchParams
    {
        //! Rays per pixel along each image axis (n x n per pixel), in [1, 8]. Higher misses
        //! fewer voxels along a pixel's footprint, at n^2 the cost.
        int raysPerPixel = 2;
        //! A PatchRule: whose patch voxels a frame that is not a key frame shows.
        int rule = PATCH_NEAREST;
    };

    /** @brief Free-space carving from the tracks (beyond the paper; build() with tracks).

    A point tracked in a frame is seen there, so in that frame the Delaunay triangles (in the
    image) between an object's points are empty in front of their nearest corner, less a margin of
    marginVoxels voxel edges or edgeMargin times the triangle's longest edge, whichever is larger.
    A voxel that at least minViews frames show free goes (peeled from the surface; never one a
    key-frame silhouette pixel needs). */
    struct CV_EXPORTS FreeSpaceParams
    {
        //! A voxel goes when at least this many frames show it free; 0 turns the pass off.
        //! Lower carves more.
        int minViews = 2;
        //! Margin per pixel of triangle edge, as a fraction of the triangle's longest edge: a
        //! triangle spanning a convex corner passes in front of it by up to about half its edge.
        //! Lower carves closer to flat facades.
        double edgeMargin = 0.5;
        /** A triangle whose 3D plane agrees with those of its three neighbours within this angle
        (degrees, in [0, 90]) lies on one facade: its free space follows its plane (the depth
        interpolated over the triangle) up to marginVoxels before it, instead of stopping at its
        nearest corner less the edge margin. 0: every triangle flat at its nearest corner. A
        triangle across a right-angled corner is about 45 degrees from its neighbours. Such
        triangles are kept however long (maxEdgeRatio is for the others). Higher carves more. */
        double planarDeg = 30;
        //! Free space ends at least this many voxel edges before the points. Lower carves more.
        double marginVoxels = 3;
        //! Triangles longer than this times the frame's median edge (which may span a gap or a
        //! notch) are not used, planar ones aside. Higher carves more.
        double maxEdgeRatio = 2;
        //! Observations farther than this (pixels) from their point's projection (a track that
        //! slid along an occluding contour) are not used.
        double maxReprojPx = 2;
        //! At most this many frames are used, evenly spaced over the cameras; 0: every frame.
        int maxViews = 30;
    };

    /** @brief What no frame sees (beyond the paper): voxels in vertical runs (along the grid axis
    nearest the vertical the cameras give) of which no frame shows a single voxel, behind other
    objects or the object's own near side in every frame, are removed: a hidden wedge of the
    visual hull, which no composite of the video shows but the object's matte as if alone does. */
    struct CV_EXPORTS UnobservedParams
    {
        //! Whether the pass runs.
        bool enabled = true;
        //! Frames asked, evenly spaced over the cameras (every key frame is asked too).
        int views = 30;
        //! A surface voxel is seen when its centre is within this many voxel edges of the nearest
        //! clone depth at its pixel. Higher removes less.
        double depthTolVoxels = 1.5;
        /** An unseen run with a seen one within this many columns across the vertical (at some of
        its heights) stays, unless regrowFromUnseen gives it back: under a top seen at a grazing
        angle only some of the top voxels pass the depth test. 0: every unseen run goes. */
        int keepNearSeen = 1;
        /** An unseen run within this many columns of an unseen run that keepNearSeen did not keep
        goes after all (the thin edges of a wide unseen region), at least keepNearSeen. */
        int regrowFromUnseen = 3;
        //! The vertical must be within this angle (degrees) of a grid axis for the runs to follow
        //! it; else the pass leaves the object alone.
        double maxTiltDeg = 20;
    };

    /** @brief refine(): photo-consistency carving over the video's frames (space carving
    @cite Kutulakos2000 with voxel colouring's visibility @cite Seitz1999). */
    struct CV_EXPORTS PhotoParams
    {
        /** A view agrees with a voxel's colour (the per-channel median over the views that see
        it) when a pixel of the 3x3 neighbourhood of the voxel's centre differs from it by at
        most this many grey levels in every channel, after an exposure gain within 10% (8-bit
        frames, in [0, 255]). Lower carves more. */
        double threshold = 15;
        //! A voxel is photo-consistent when at least this fraction of the views that see it
        //! agree, in (0, 1]. Higher carves more.
        double minAgreement = 0.95;
        //! A voxel seen in fewer frames than this is kept (no evidence), at least 2.
        int minViews = 4;
        //! Rounds of the six plane sweeps, each with the visibility the last left.
        int rounds = 1;
        /** 0 compares the voxel's centre pixel only; s > 0 (at most 8) also the four pixels s
        away along the image axes, each against its own median (a sparse patch: carves phantoms
        in front of uniform bands, but erodes true edges where the patch straddles an occluding
        contour). */
        int patchStep = 0;
        //! At most this many frames are compared, evenly spaced over the cameras of the
        //! reconstruction; 0: every frame (else at least minViews).
        int maxViews = 24;
    };

    /** @brief The builder's parameters: the voxel size and key-frame rule shared by every pass,
    then one part per pass (see doc/clones.md for the figures behind each default). */
    struct CV_EXPORTS Params
    {
        //! Voxel edge in pixels of the key frame that sees the object largest (1: a voxel
        //! projects to at most about one pixel, the paper's rule). Lower gives finer clones.
        double voxelPixels = 1.0;
        //! Upper bound on voxels per object; the voxel grows to respect it.
        int64 maxVoxels = (int64)1 << 27;
        //! Steps 4 and 5: pixels under a nearer object's silhouette are unknown, not outside, so
        //! a building in front does not bite a hole in the one behind.
        bool occlusionAware = true;
        BoxParams box;                //!< Steps 1-3
        PatchParams patches;          //!< Step 5
        FreeSpaceParams freeSpace;    //!< build() with tracks
        UnobservedParams unobserved;  //!< build(), after the free space
        PhotoParams photo;            //!< refine()
        /** Progress (stage "clone"): build() reports step "build", a unit per pass and
        object (buildPart() and mergeParts() the same step, for the passes each runs); refine()
        step "photo-consistency", a unit per object and round. */
        ProgressCallback progress;
    };

    //! Creates a builder; throws as setParams() does on invalid parameters.
    static Ptr<CloneBuilder> create(const Params& params);
    //! Creates a builder with default Params.
    static Ptr<CloneBuilder> create();
    //! The parameters in use.
    virtual Params getParams() const = 0;
    //! Validates and sets the parameters (StsBadArg naming the field when out of range).
    virtual void setParams(const Params& params) = 0;

    /** @brief Builds one clone per object of `keyFrameMasks`.
    @param rec cameras (every key frame needs one) and 3D points (may be empty: then each box comes
    from the silhouettes alone).
    @param keyFrameMasks per object, the user's silhouettes in its key frames (CV_8U, > 127 = in,
    the reconstruction's image size).
    @param tracks optional: the tracks `rec.points` came from; when given, a point is clustered by
    the key frames in which its track is observed, else by every key frame where it projects, and
    the clones are carved further by the free space the tracks show (Params::freeSpace).
    @return the clone set.
    Throws StsBadArg / StsBadSize naming the object and frame for an empty or all-white mask, a mask
    of the wrong size or for a frame with no camera.
    */
    virtual Ptr<CloneSet> build(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                                const Tracks* tracks = nullptr) const = 0;

    /** @brief The per-object part of build() for some of the objects: a partial clone set, to
    be saved and merged with the other objects' parts by mergeParts() (issue 21: clone jobs per
    object on a farm).

    build() runs the passes of doc/clones.md ("How the clone stage works") over every object.
    Those of one object that read no other object's clone are run here: the box (Steps 1-3),
    silhouette carving (Step 4), grid growth and the free space (with tracks). They depend on the
    inputs and, of the other objects, only on what the inputs give: the others' key-frame
    silhouettes and their depth-order centres (occlusion-aware carving makes a pixel under a
    nearer object's silhouette unknown; which object is nearer is decided by the centres of
    Step 1's boxes), which are computed here from the inputs for every object, as build() does.
    The passes that look at every clone (the unobserved volume, then the patch voxels, which
    follow it) are left to mergeParts(). build() is exactly buildPart() of every object followed
    by mergeParts() of that one part, so a merged set equals build()'s, voxel for voxel.

    The set records fingerprints of `rec`, `keyFrameMasks`, `tracks` and the parameters, and
    every object of `keyFrameMasks`, for mergeParts() to check.
    @param rec as for build().
    @param keyFrameMasks every object's silhouettes, as for build() (not only those of
    `objects`: Step 1 and occlusion-aware carving weigh the other objects' silhouettes).
    @param objects the objects to build, names of `keyFrameMasks`; not empty, no repeats.
    @param tracks as for build().
    @return a partial set (CloneSet::isPartial()) holding the objects of `objects`.
    Throws as build() does, and StsBadArg naming the object for a name not in `keyFrameMasks`
    or given twice.
    */
    virtual Ptr<CloneSet> buildPart(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                                    const std::vector<String>& objects,
                                    const Tracks* tracks = nullptr) const = 0;

    /** @brief Merges partial sets made by buildPart() and runs the passes that look at every
    object (the unobserved volume, then every object's patch voxels): the set build() makes.

    Checked first, each a StsBadArg naming the part (its file when loaded by
    CloneSet::loadPart()) and the object: a set that is not partial, an object in two parts, an
    object of the masks in no part, parts built from other inputs than one another or than the
    inputs given here (another reconstruction, other masks, other or no tracks, other
    parameters: the message names the first parameter that differs).
    @param parts the partial sets, in any order.
    @param rec the reconstruction the parts were built from.
    @param keyFrameMasks the masks the parts were built from (only checked against them: the
    parts hold their objects' silhouettes).
    @param tracks the tracks the parts were built from, or null if none.
    @return the complete clone set; refine() may follow, as after build().
    */
    virtual Ptr<CloneSet> mergeParts(const std::vector<Ptr<CloneSet> >& parts,
                                     const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                                     const Tracks* tracks = nullptr) const = 0;

    /** @brief Adds one key frame to an existing clone: carves with that frame only and recomputes
    the object's patch voxels, without starting over.
    @param clones a set made by build() or CloneSet::load().
    @param rec the reconstruction (camera of `frame`).
    @param object object name (must exist in `clones`).
    @param frame the new key frame (replaces the silhouette if it is already a key frame).
    @param mask its silhouette (CV_8U, > 127 = in).
    */
    virtual void addKeyFrame(CloneSet& clones, const Reconstruction& rec, const String& object,
                             int frame, InputArray mask) const = 0;

    /** @brief Carves the clones beyond the visual hull by photo-consistency over every frame
    with a camera (space carving @cite Kutulakos2000 with voxel colouring's visibility
    @cite Seitz1999), then redoes the patch voxels.

    Silhouettes cannot carve concavities (an L-shaped block's inner corner, the space under an
    overhang). Here plane sweeps along the six grid directions visit the surface voxels front to
    back for the cameras that look along the sweep; a voxel's colour is gathered from the frames
    where it is visible (all clones together hide each other, depth tolerance two voxels) and an
    inconsistent voxel is carved (PhotoParams::threshold, minAgreement), which exposes the
    voxels behind it. Safety: a voxel seen in fewer than PhotoParams::minViews frames is kept,
    and no voxel is carved whose removal would leave a pixel of a key-frame silhouette uncovered
    by the model (the user's silhouettes are the truth). Deterministic for any thread count.
    @param clones a set made by build() or CloneSet::load().
    @param rec the reconstruction: cameras of the frames (only frames with a camera are used).
    @param frames the video frames, frames[f] is frame f (BGR CV_8UC3, or CV_8UC1), the
    reconstruction's image size; only the frames photoFrames() names are read and must be
    there, the others may be empty (a long shot need not be held in memory).
    @return the number of voxels carved, all objects together.
    Throws StsBadArg / StsBadSize naming the frame for a missing, empty or mis-sized frame.
    */
    virtual int64 refine(CloneSet& clones, const Reconstruction& rec,
                         InputArrayOfArrays frames) const = 0;

    /** @brief The frames refine() compares: at most PhotoParams::maxViews, evenly spaced over
    the reconstruction's cameras, increasing. A caller streaming a long video decodes these and
    passes empty images for the rest.
    @param rec the reconstruction refine() will be given. */
    virtual std::vector<int> photoFrames(const Reconstruction& rec) const = 0;
};

/** @brief Renders every object's matte (and optionally depth) in every frame of `rec`.
@param clones the clones.
@param rec the reconstruction (one matte per camera).
@param mattes output, object -> frame -> CV_8U matte (0 / 255).
@param depth optional output, object -> frame -> CV_32F camera-space z (+inf off the clone).
@param progress optional (stage "matte"): frames rendered.
*/
CV_EXPORTS void renderMattes(const CloneSet& clones, const Reconstruction& rec,
                             ObjectMasks& mattes,
                             std::map<String, std::map<int, Mat> >* depth = nullptr,
                             const ProgressCallback& progress = ProgressCallback());

/** @brief Writes the contract's mattes folder `DIR/<object>/%04d.png` for every frame of `rec`,
and, when `depthDir` is not empty, `depthDir/<object>/%04d.tiff` (32-bit float camera-space z,
+inf off the clone). Both folders are written atomically. `progress` (optional, stage "matte"):
the frames rendered, as renderMattes() reports them. */
CV_EXPORTS void writeMattes(const String& dir, const CloneSet& clones, const Reconstruction& rec,
                            const String& depthDir = String(),
                            const ProgressCallback& progress = ProgressCallback());

//! @}

} // namespace augocc
} // namespace cv

#endif
