// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CLONE_INTERNAL_HPP
#define OPENCV_AUGOCC_CLONE_INTERNAL_HPP

#include <map>
#include <vector>
#include "opencv2/augocc/clone_builder.hpp"
#include "voxel_grid.hpp"

namespace cv {
namespace augocc {
namespace detail {

//! One object's clone: the trimmed model, its surface, and per key frame the silhouette and the
//! patch voxels (packed coordinates, sorted).
struct ObjectClone
{
    String name;
    VoxelGrid grid;
    SurfaceVoxels surface;
    Vec3d centre;                                   //!< world point used to order objects by depth
    std::map<int, Mat> masks;                       //!< key-frame silhouettes (0 / 255)
    std::map<int, std::vector<uint32_t> > patches;  //!< key frame -> patch voxels
};

//! The CloneSet implementation shared by the builder, load() and the tests.
class CV_EXPORTS CloneSetImpl CV_FINAL : public CloneSet
{
public:
    std::map<String, ObjectClone> objects;
    int patchRule = CloneBuilder::PATCH_NEAREST;

    std::vector<String> objectNames() const CV_OVERRIDE;
    void render(const String& object, int frame, const Camera& camera, Size imageSize,
                OutputArray matte, OutputArray depth) const CV_OVERRIDE;
    void save(const String& path) const CV_OVERRIDE;
    std::vector<int> keyFrames(const String& object) const CV_OVERRIDE;
    std::vector<int> patchFrames(const String& object, int frame) const CV_OVERRIDE;
    int voxelCount(const String& object) const CV_OVERRIDE;
    int patchVoxelCount(const String& object, int keyFrame) const CV_OVERRIDE;
    Vec3i gridSize(const String& object) const CV_OVERRIDE;
    double voxelSize(const String& object) const CV_OVERRIDE;
    void gridPose(const String& object, Matx33d& Rbox, Vec3d& origin) const CV_OVERRIDE;
    void exportPly(const String& dir) const CV_OVERRIDE;

    const ObjectClone& get(const String& object) const;
    ObjectClone& get(const String& object);
};

/** @brief Step 5 for one key frame: the patch voxels that make the clone cover `silhouette`
exactly (the paper's two-pass algorithm, several rays per pixel). `keep` (silhouette or unknown)
bounds where patch footprints may fall. */
CV_EXPORTS std::vector<uint32_t> computePatches(const ObjectClone& obj, const Camera& camera,
                                                const Mat& silhouette, const Mat& keep,
                                                int raysPerPixel);

//! Photo-consistency carving parameters (CloneBuilder::Params::photo*).
struct PhotoCarveParams
{
    double threshold = 15;
    double minAgreement = 0.95;
    int minViews = 4;
    int rounds = 1;
    int patchStep = 0;
    int maxViews = 0;  // 0: every camera
};

/** @brief Space carving by photo-consistency on every frame with a camera (CloneBuilder::refine):
carves inconsistent surface voxels of every object's grid, never one that a key-frame silhouette
pixel needs; updates the grids and surfaces (not the patches). `frames[f]` is the BGR image of
frame f (validated by the caller). Returns the voxels carved per object. */
CV_EXPORTS std::map<String, int64> photoCarve(CloneSetImpl& set, const Reconstruction& rec,
                                              const std::vector<Mat>& frames,
                                              const PhotoCarveParams& params);

//! Free-space carving parameters (CloneBuilder::Params::freeSpace*).
struct FreeSpaceParams
{
    int minViews = 2;          // a voxel goes when at least this many frames show it free
    double marginVoxels = 3;   // free space ends at least this many voxel edges before the points
    double edgeMargin = 0.5;   // ... and this fraction of the triangle's longest edge
    double maxEdgeRatio = 2;   // triangles longer than this times the frame's median edge
                               // (span gaps) are not used
    double maxReprojPx = 2;    // observations farther than this from their point are not used
    int maxViews = 30;         // frames used, evenly spaced (0: all)
    double planarDeg = 0;      // triangles on one plane with their three neighbours (normals
                               // within this angle, degrees) follow their plane (0: every
                               // triangle is flat at its nearest vertex)
};

/** @brief Free-space carving from the tracks: in every frame, the triangles (Delaunay, in the
image) of the object's points seen there are empty in front of their nearest vertex by a margin
(planar ones, on one facade with their neighbours, in front of their plane by marginVoxels);
voxels shown free by at least params.minViews frames go, peeled from the surface, never one that
a key-frame silhouette pixel needs. `members` lists each object's points (Step 1). Updates the
grids and surfaces (not the patches). Returns the voxels carved per object. */
CV_EXPORTS std::map<String, int64> freeSpaceCarve(CloneSetImpl& set, const Reconstruction& rec,
                                                  const Tracks& tracks,
                                                  const std::map<String, std::vector<int> >& members,
                                                  const FreeSpaceParams& params);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
