// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The clone stage as a list of passes (doc/clones.md, "How the clone stage works"). Every pass has
// one entry point of one shape,
//
//     int64 passX(ObjectClone& obj, const PassContext& ctx);
//
// changes only `obj`, reads its parameters from ctx.params, and returns the number of voxels it
// removed from obj's grid (passBox: the voxels of the grid it made; passPatches: the patch voxels
// it made). CloneBuilder::build() runs them over every object in this order:
//
//   1. passBox         Steps 1-3: points clustered by silhouette, box oriented and enlarged, grid
//   2. passCarve       Step 4: silhouette carving (occlusion-aware), voxels no key frame shows
//   3. passGridGrowth  the visual hull the key frames need beyond Step 3's box
//   4. passFreeSpace   the free space the tracks show (with tracks)
//   5. passUnobserved  vertical runs no frame sees
//   6. passPatches     Step 5: patch voxels per key frame
//
// Passes 1-4 of object A read, of the other objects, only their key-frame silhouettes and their
// centres (unknownMask: which object is nearer in a key frame), and a centre is a function of the
// inputs (passCentre); passes 5 and 6 read the other clones' voxels (observeSurfaces) or follow
// a pass that does. So CloneBuilder::buildPart() runs 1-4 for some objects (the centres of all)
// and mergeParts() runs 5-6 over the merged set; build() is the two in a row.
//
// CloneBuilder::refine() runs passPhoto, then passPatches. Passes that look at the other
// clones' voxels (passUnobserved, passPhoto) must see them as they stood before the pass ran on
// any object: their driver prepares that view once (observeSurfaces(), preparePhotoViews()) and
// hands it over in the context.

#ifndef OPENCV_AUGOCC_CLONE_PASSES_HPP
#define OPENCV_AUGOCC_CLONE_PASSES_HPP

#include <map>
#include <vector>
#include "clone/clone_set.hpp"

namespace cv {
namespace augocc {
namespace detail {

struct ObservedSurfaces;
struct PhotoViews;
struct PassContext;

//! Makes obj's grid (every voxel in) to hold `box` with a margin, the voxel edge from
//! params.voxelPixels and params.maxVoxels.
CV_EXPORTS void makeGrid(ObjectClone& obj, const Box& box, const PassContext& ctx);

//! What a pass may read besides its object.
struct PassContext
{
    PassContext(const Reconstruction& r, const CloneSetImpl& s, const CloneBuilder::Params& p)
        : rec(r), clones(s), params(p)
    {
    }

    const Reconstruction& rec;
    //! Every object (the one a pass changes too): the others' silhouettes and centres.
    const CloneSetImpl& clones;
    const CloneBuilder::Params& params;
    //! Every object's binary key-frame silhouettes (passBox: Step 1 weighs them all).
    const ObjectMasks* keyFrameMasks = nullptr;
    //! The tracks rec.points came from (passBox, passFreeSpace), or null.
    const Tracks* tracks = nullptr;
    //! passCarve: carve with this key frame only (addKeyFrame); -1: with every key frame.
    int carveFrame = -1;
    //! passUnobserved: what each frame sees, made by observeSurfaces().
    const ObservedSurfaces* observed = nullptr;
    //! passPhoto: the compared frames and the other clones' depth, made by preparePhotoViews().
    const PhotoViews* photo = nullptr;
    /** With lens distortion (clone/ideal_space.hpp): CV_8U of rec.imageSize, 255 where the frame
    sees; the rest of the ideal image is unknown, as pixels off the image. Null: all seen. */
    const Mat* inFrame = nullptr;
};

//! Steps 1-3 (the paper's Section 6): obj.points, obj.box, obj.centre and the full grid. obj.masks
//! must hold the object's binary key-frame silhouettes.
CV_EXPORTS int64 passBox(ObjectClone& obj, const PassContext& ctx);
//! obj.centre alone, exactly as passBox() sets it (Step 1's box, before Step 3): what the passes
//! of the other objects read of obj (unknownMask's depth order) in a job that does not build it.
CV_EXPORTS int64 passCentre(ObjectClone& obj, const PassContext& ctx);

//! Step 4: carves obj's grid with its key frames (ctx.carveFrame: one of them), then drops the
//! voxels no key frame shows as the object; updates the surface.
CV_EXPORTS int64 passCarve(ObjectClone& obj, const PassContext& ctx);

//! Beyond Step 3: when the carved clone leaves deep silhouette pixels uncovered that the visual
//! hull holds outside obj.box, the grid grows to hold them and is carved again (passCarve).
CV_EXPORTS int64 passGridGrowth(ObjectClone& obj, const PassContext& ctx);

//! Free-space carving from ctx.tracks (params.freeSpace) with obj.points; updates the surface.
CV_EXPORTS int64 passFreeSpace(ObjectClone& obj, const PassContext& ctx);

//! Per object, the indices into its surface of the voxels some frame sees (params.unobserved).
struct ObservedSurfaces
{
    std::map<String, std::vector<uint32_t> > seen;
};
//! What passUnobserved needs: every clone's surface drawn into the frames it asks, at once.
CV_EXPORTS ObservedSurfaces observeSurfaces(const CloneSetImpl& clones,
                                            const Reconstruction& rec,
                                            const CloneBuilder::UnobservedParams& params,
                                            const Mat* inFrame = nullptr);
//! Removes vertical runs of obj's grid of which ctx.observed shows no voxel.
CV_EXPORTS int64 passUnobserved(ObjectClone& obj, const PassContext& ctx);

//! Step 5: recomputes every key frame's patch voxels of obj (params.patches).
CV_EXPORTS int64 passPatches(ObjectClone& obj, const PassContext& ctx);

/** @brief Step 5 for one key frame: the patch voxels that make the clone cover `silhouette`
exactly (the paper's two-pass algorithm, several rays per pixel). `keep` (silhouette or unknown)
bounds where patch footprints may fall. */
CV_EXPORTS std::vector<uint32_t> computePatches(const ObjectClone& obj, const Camera& camera,
                                                const Mat& silhouette, const Mat& keep,
                                                int raysPerPixel);

//! One object's part of PhotoViews, per compared frame.
struct PhotoObjectViews
{
    std::vector<VoxelProjector> proj;
    std::vector<Rect> roi;          //!< image rectangle holding every footprint of the grid
    std::vector<Mat> others;        //!< CV_32F over roi: the other clones' nearest depth, or empty
    std::vector<const Mat*> image;  //!< the frame
};
//! The frames photo-consistency compares and, per object, what each shows of the others.
struct PhotoViews
{
    std::vector<const Camera*> cameras;
    std::map<String, PhotoObjectViews> objects;
};
/** @brief What passPhoto needs for one round: the frames compared (params.photo.maxViews) and,
per object, its projection into each and the nearest depth of the other clones as they stand.
`frames[f]` is the BGR image of frame f (validated by the caller). */
CV_EXPORTS PhotoViews preparePhotoViews(const CloneSetImpl& clones, const Reconstruction& rec,
                                        const std::vector<Mat>& frames,
                                        const CloneBuilder::PhotoParams& params,
                                        const Mat* inFrame = nullptr);
//! One round of space carving by photo-consistency of obj (params.photo); updates the surface.
CV_EXPORTS int64 passPhoto(ObjectClone& obj, const PassContext& ctx);

//! Unknown pixels of `object` in `frame`: silhouettes of the other objects nearer the camera.
CV_EXPORTS Mat unknownMask(const CloneSetImpl& clones, const String& object, int frame,
                           const Camera& cam, Size size);
//! Where a key frame's carving and patches may keep the object: its silhouette, and with
//! params.occlusionAware the pixels unknown under nearer objects.
CV_EXPORTS Mat keepMask(const ObjectClone& obj, const PassContext& ctx, int frame);

//! The vertical the cameras give (cameras that orbit without roll keep their x axis horizontal).
CV_EXPORTS Vec3d estimateVertical(const Reconstruction& rec);

//! Grid margin in voxels around the enlarged box: room for patch voxels just outside it.
const int kGridMarginVoxels = 2;

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
