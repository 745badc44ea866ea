// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CLONE_SET_HPP
#define OPENCV_AUGOCC_CLONE_SET_HPP

#include <map>
#include <vector>
#include "opencv2/augocc/clone_builder.hpp"
#include "voxel_grid.hpp"

namespace cv {
namespace augocc {
namespace detail {

//! An oriented box: axes are the columns of R (world), extent [lo, hi] in box coordinates.
struct Box
{
    Matx33d R = Matx33d::eye();
    Vec3d lo, hi;
    bool valid = false;

    //! Grows the box to hold box coordinates b.
    void include(const Vec3d& b);
    Vec3d toBox(const Vec3d& X) const { return R.t() * X; }
    Vec3d toWorld(const Vec3d& b) const { return R * b; }
    //! Corner c in world coordinates, c in [0, 8): bit a set = hi along axis a.
    Vec3d corner(int c) const
    {
        return toWorld(Vec3d(c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]));
    }
    Vec3d centre() const { return toWorld(0.5 * (lo + hi)); }
    //! Box coordinates b clamped into the box.
    Vec3d clamp(const Vec3d& b) const;
    //! Distance from world point X to the box (0 inside).
    double distance(const Vec3d& X) const;
};

/** @brief One object's clone: the trimmed model, its surface, and per key frame the silhouette and
the patch voxels (packed coordinates, sorted). `box` and `points` are what the builder's first pass
hands to the later ones; a clone read from a file has neither. */
struct ObjectClone
{
    String name;
    VoxelGrid grid;
    SurfaceVoxels surface;
    Vec3d centre;                                   //!< world point used to order objects by depth
    std::map<int, Mat> masks;                       //!< key-frame silhouettes (0 / 255)
    std::map<int, std::vector<uint32_t> > patches;  //!< key frame -> patch voxels
    Box box;                  //!< Step 3's box (the grid holds it, with a margin)
    std::vector<int> points;  //!< Step 1: track columns of the object's reconstructed points
};

/** @brief What a partial set (CloneBuilder::buildPart()) records for mergeParts() to check:
every object of the shot and fingerprints of the inputs it was built from (clone/clone_parts.cpp).
*/
struct PartInfo
{
    std::vector<String> allObjects;  //!< every object of the key-frame masks, sorted
    String params;                   //!< paramsText() of the builder's parameters
    String reconstruction;           //!< fingerprintReconstruction()
    String masks;                    //!< fingerprintMasks()
    String tracks;                   //!< fingerprintTracks(), "none" without tracks
    String source;                   //!< the file it was loaded from (for messages), or empty
};

//! The CloneSet implementation shared by the builder, load() and the tests.
class CV_EXPORTS CloneSetImpl CV_FINAL : public CloneSet
{
public:
    int patchRule = CloneBuilder::PATCH_NEAREST;
    //! A partial set (buildPart()): `part` says what it was built from.
    bool partial = false;
    PartInfo part;

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
    bool isPartial() const CV_OVERRIDE { return partial; }

    //! Moves `clone` into the set under its name (which must not be there yet).
    void insert(ObjectClone&& clone);
    //! Removes the object of that name (nothing when there is none).
    void erase(const String& object)
    {
        version_ = nextVersion();
        objects_.erase(object);
    }

    //! The object named `object`; throws StsObjectNotFound.
    const ObjectClone& get(const String& object) const;
    ObjectClone& get(const String& object);
    //! Adds an empty object (its name set) or returns the one of that name.
    ObjectClone& add(const String& object);
    //! Every object, by name.
    const std::map<String, ObjectClone>& objects() const { return objects_; }
    /** A process-wide unique stamp of the set's state: new for every set made and at every
    access that can change an object (the non-const get(), add(), insert(), erase()), so two
    sets never share one. What caches of a set's renders (the compositor's clone shadow map)
    compare, instead of the voxels. */
    uint64 version() const { return version_; }

private:
    //! The next stamp (thread-safe).
    static uint64 nextVersion();

    std::map<String, ObjectClone> objects_;
    uint64 version_ = nextVersion();
};

/** @brief Reads a clones file written by CloneSetImpl::save(): a complete one when `part` is
false, a partial one when true; the other kind is StsBadArg naming the file. */
CV_EXPORTS Ptr<CloneSetImpl> loadCloneSet(const String& path, bool part);

//! Throws StsBadArg naming `who` when `clones` is a partial set (what needs every object).
CV_EXPORTS void checkComplete(const CloneSet& clones, const char* who);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
