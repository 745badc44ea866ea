// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SCENE_HPP
#define OPENCV_AUGOCC_SCENE_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/clone_builder.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/lighting.hpp"
#include "opencv2/augocc/mesh.hpp"

/*
The scene file (scene.yml, a cv::FileStorage YAML/JSON file; format in doc/compositor.md): the
virtual objects to insert, each a mesh file or a procedural shape, placed either by position,
rotation and scale in the reconstruction's world frame, or relative to what the user sees: on the
ground beside a real object's clone, behind it or in front of it by a distance in clone sizes.

Ground coordinates (GroundFrame): x to the right of the mean view, y up (height above the ground),
z back towards the viewer; right-handed; origin on the ground plane below the world origin.
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

//! One virtual object of a scene file, as parsed (object coordinates, y up for the helpers).
struct CV_EXPORTS SceneObject
{
    //! How the object is placed.
    enum Placement
    {
        PLACE_ABSOLUTE = 0,   //!< `position` in the reconstruction's world frame
        PLACE_BESIDE = 1,     //!< `on_ground_beside: <clone>`
        PLACE_BEHIND = 2,     //!< `behind: <clone>`
        PLACE_IN_FRONT = 3    //!< `in_front_of: <clone>`
    };

    String name;                         //!< object name (default `object_<i>`)
    String shape;                        //!< procedural shape (dome, tree, box...) or empty
    String meshFile;                     //!< mesh file (relative to the scene's folder) or empty
    std::vector<Mesh> meshes;            //!< loaded geometry, object coordinates
    int placement = PLACE_ABSOLUTE;      //!< Placement
    Vec3d position = Vec3d(0, 0, 0);     //!< PLACE_ABSOLUTE: world position of the object origin
    Vec3d rotationDeg = Vec3d(0, 0, 0);  //!< Euler angles in degrees, R = Rz * Ry * Rx
    Vec3d scale = Vec3d(1, 1, 1);        //!< per-axis scale (object coordinates)
    double size = 0;                     //!< helpers: largest dimension in clone sizes (0: keep)
    String anchor;                       //!< helpers: the clone object placed against
    double distance = 0.25;              //!< helpers: gap to the clone in clone sizes
    int side = 1;                        //!< PLACE_BESIDE: +1 right, -1 left (as seen)
    Vec3d offset = Vec3d(0, 0, 0);       //!< helpers: extra shift, ground axes, clone sizes
    /** The file's `material` overrides, as given (already applied to `meshes`), kept so that
    writeScene() writes them back. */
    struct MaterialOverride
    {
        bool hasDiffuse = false;         //!< `diffuse` given
        Vec3f diffuse;                   //!< RGB in [0, 1]
        bool hasAmbient = false;         //!< `ambient` given
        Vec3f ambient;                   //!< RGB in [0, 1]
        String texture;                  //!< `texture`: the image file (resolved) or empty
        //! True when the file gave no override.
        bool empty() const { return !hasDiffuse && !hasAmbient && texture.empty(); }
    };
    MaterialOverride material;           //!< the file's `material` overrides
};

/** @brief The `sun` node of a scene file, as parsed (resolveSun() turns it into a Sun of the
reconstruction's world). One of three forms:
- `direction: [x, y, z]`, towards the sun in the reconstruction's world frame;
- `azimuth` and `elevation`, degrees: elevation above the reconstruction's ground
  (estimateGround()), azimuth clockwise from north seen from above (east = 90);
- `date: "YYYY-MM-DD"`, `time: "HH:MM[:SS]"` (UTC), `latitude`, `longitude` (degrees, north and
  east positive): solarPosition() gives azimuth and elevation.

North (`north: [x, y, z]`, world frame, its horizontal part): by default the ground frame's
forward direction `-back`, i.e. the mean view direction: "the camera looks north". For a
factorization the world frame is the first camera's, so `north: [0, 0, 1]` is straight ahead of
the first frame. `sky` is Sun::sky; `penumbra` the soft shadow edge in pixels of the first
camera at the ground origin (resolveSun() converts it to world units). */
struct CV_EXPORTS SceneSun
{
    //! Which form the file gave.
    enum Form
    {
        SUN_NONE = 0,               //!< no `sun` node: no sun, no shadows
        SUN_DIRECTION = 1,          //!< `direction`
        SUN_AZIMUTH_ELEVATION = 2,  //!< `azimuth`, `elevation`
        SUN_DATE_TIME = 3           //!< `date`, `time`, `latitude`, `longitude`
    };
    int form = SUN_NONE;                  //!< Form
    Vec3d direction = Vec3d(0, 0, 0);     //!< SUN_DIRECTION: world frame
    double azimuthDeg = 0;                //!< SUN_AZIMUTH_ELEVATION (SUN_DATE_TIME: computed)
    double elevationDeg = 45;             //!< SUN_AZIMUTH_ELEVATION (SUN_DATE_TIME: computed)
    String date;                          //!< SUN_DATE_TIME: "YYYY-MM-DD"
    String time;                          //!< SUN_DATE_TIME: "HH:MM[:SS]", UTC
    double latitudeDeg = 0;               //!< SUN_DATE_TIME
    double longitudeDeg = 0;              //!< SUN_DATE_TIME
    Vec3d north = Vec3d(0, 0, 0);         //!< world frame; zero: the ground frame's -back
    double sky = Sun().sky;               //!< Sun::sky
    double penumbraPx = 3.0;              //!< soft edge, pixels of the first camera
};

//! A parsed scene file.
struct CV_EXPORTS VirtualScene
{
    String path;                        //!< the file it came from
    std::vector<SceneObject> objects;   //!< the objects, in file order
    SceneSun sun;                       //!< the `sun` node (form SUN_NONE without one)
};

/** @brief Reads and validates a scene file; loads its meshes (files relative to the scene file's
folder, or procedural). Throws StsParseError naming the file and the key for an unknown key, a
wrong value type, a missing mesh/shape, an unknown clone placement or shape; mesh errors are
loadMeshes()'s.
@param path scene.yml (FileStorage YAML or JSON).
*/
CV_EXPORTS VirtualScene readScene(const String& path);

/** @brief Writes a scene file that readScene() reads back (meshes are referenced, not written);
atomic. */
CV_EXPORTS void writeScene(const String& path, const VirtualScene& scene);

/** @brief The procedural shapes of scene files: unit size, base on y = 0, centred on the y axis.
`dome` (radius 1), `tree` (trunk and cone of foliage, height 1), `box` (unit cube), `sphere`,
`cylinder`, `cone` (diameter 1, height 1). Throws StsBadArg on an unknown name.
@return one mesh per material (a tree has two).
*/
CV_EXPORTS std::vector<Mesh> proceduralShape(const String& shape);

/** @brief Where "up" and the ground are in a reconstruction (whose world frame is the first
camera's for a factorization, so up is unknown a priori).

Up: the cameras of a hand-held or orbiting shot have horizontal image x axes (no roll), so up is
the direction most orthogonal to all of them (least eigenvector of sum x x^T), signed to agree with
the cameras' mean image-up vector; when the x axes do not span the horizontal (a camera that never
turns about the vertical) it is the mean image-up vector. Ground: a RANSAC plane through the
reconstructed points whose normal lies within 15 degrees of that up, among the lowest half of the
points; when found it refines up and gives the height. Otherwise the ground is the 2nd percentile
of the points' heights (or 0 without points).
*/
struct CV_EXPORTS GroundFrame
{
    Vec3d up = Vec3d(0, 1, 0);        //!< unit up, world frame
    Vec3d right = Vec3d(1, 0, 0);     //!< unit, horizontal, right of the mean view direction
    Vec3d back = Vec3d(0, 0, 1);      //!< unit, horizontal, towards the viewer (right x up)
    double height = 0;                //!< ground plane: up . X == height
    bool fromPlane = false;           //!< true when a ground plane was fitted to points

    //! World point to ground coordinates (right, up above the ground, back).
    Vec3d toGround(const Vec3d& Xw) const;
    //! Ground coordinates to a world point.
    Vec3d fromGround(const Vec3d& g) const;
    //! Rows (right, up, back): world directions to ground axes; the Compositor's lightRotation
    //! of `composite` (CompositeOptions::lightFromGround).
    Matx33d rotation() const;
};

//! @brief Estimates the ground frame of a reconstruction (see GroundFrame).
CV_EXPORTS GroundFrame estimateGround(const Reconstruction& rec);

/** @brief Bounds of a clone in ground coordinates, from the clone surfaces seen in a few frames
(rendered depth unprojected to world points: first, middle and last camera).
@param clones the clones.
@param object object name.
@param rec the reconstruction (cameras, image size).
@param ground the ground frame.
@param minCorner output minimum (right, up, back).
@param maxCorner output maximum.
Throws StsObjectNotFound when the object is unknown or its clone is seen in no frame.
*/
CV_EXPORTS void estimateCloneBounds(const CloneSet& clones, const String& object,
                                    const Reconstruction& rec, const GroundFrame& ground,
                                    Vec3d& minCorner, Vec3d& maxCorner);

/** @brief Places the objects of a scene: returns their meshes in the reconstruction's world
frame (one per material), ready for Compositor::setVirtualObjects().
@param scene the parsed scene.
@param rec the reconstruction.
@param clones the clones (needed by the placement helpers; may be null when none is used).
Throws StsBadArg naming the scene file and object when a helper names an unknown clone or no
clones are given.
*/
CV_EXPORTS std::vector<Mesh> placeScene(const VirtualScene& scene, const Reconstruction& rec,
                                        const CloneSet* clones);

/** @brief Direction towards the sun (world frame, unit) from azimuth and elevation relative to a
ground frame: `cos(el) (cos(az) N + sin(az) E) + sin(el) up`, N the horizontal part of `north`
(zero: -ground.back), E = N x up (east: clockwise from north seen from above).
Throws StsBadArg when north is vertical. */
CV_EXPORTS Vec3d sunDirection(const GroundFrame& ground, double azimuthDeg, double elevationDeg,
                              const Vec3d& north = Vec3d(0, 0, 0));

/** @brief The scene's sun in the reconstruction's world: direction (SceneSun's forms, ground
and north from estimateGround(rec)), sky share, and the penumbra converted from pixels of the
first camera at the ground origin to world units. A disabled Sun when the scene has none. */
CV_EXPORTS Sun resolveSun(const VirtualScene& scene, const Reconstruction& rec);

//! @brief Model matrix (object to world) of each object, as placeScene() computes it.
CV_EXPORTS std::vector<Matx44d> scenePoses(const VirtualScene& scene, const Reconstruction& rec,
                                           const CloneSet* clones);

//! @}

} // namespace augocc
} // namespace cv

#endif
