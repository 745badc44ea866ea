// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_PLACEMENT_EDITOR_HPP
#define OPENCV_AUGOCC_PLACEMENT_EDITOR_HPP

#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/clone_builder.hpp"
#include "opencv2/augocc/compositor.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/scene.hpp"
#include "opencv2/augocc/sun_estimation.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Interactive placement of the virtual objects of a scene file over the frames of a shot:
pick, drag on the estimated ground, turn about the vertical, scale, raise, snap against a clone's
face, add an object from a mesh file, light the scene: estimate the sun from the footage
(estimateSun()), turn it and change its sky share; undo and redo, preview the composite, save
scene.yml.

The paper's users placed the virtual objects "interactively through a GUI" @cite Ong1998. All
the logic lives here, headless, so that it is tested without a window; `augocc place` only
forwards the mouse and the keys (as `augocc annotate` does for SilhouetteEditor).

Geometry: the ground is estimateGround() of the reconstruction (GroundFrame; the same frame
scenePoses() places the helpers in). A cursor pixel becomes a ray through the current frame's
Camera (Camera::backproject()), intersected with the ground plane. Each object's *base point* is
the centre of its footprint at its lowest point: the centre of the (right, back) extent of its
placed vertices, at their lowest height above the ground. Dragging moves the object horizontally
so that its base point follows the ground point under the cursor (with the offset it was
grabbed at), so an object on the ground stays on it; raise() lifts it. Turning and scaling keep
the base point fixed.

Saving: every object the user changed is written with an absolute `position`, `rotation` and
`scale` (world frame); an object placed by a helper (`behind: <clone>` ...) and left alone keeps
its helper, and snapToClone() writes one. The preview composites with the poses the saved file
gives back (every edit is stored in the scene file's own fields, full double precision, and the
pose is recomputed from them by scenePoses()), with the Compositor parameters that `augocc
composite` uses, so the saved scene.yml composites to the preview's pixels.
*/
class CV_EXPORTS PlacementEditor : public Algorithm
{
public:
    //! Faces of a clone's ground-aligned box that snapToClone() places an object against.
    enum SnapSide
    {
        SNAP_BEHIND = 0,    //!< beyond the clone, away from the viewer (`behind:`)
        SNAP_IN_FRONT = 1,  //!< between the clone and the viewer (`in_front_of:`)
        SNAP_LEFT = 2,      //!< left of it as seen (`on_ground_beside:`, `side: left`)
        SNAP_RIGHT = 3      //!< right of it as seen (`on_ground_beside:`, `side: right`)
    };

    //! Preview and editing parameters; the defaults are the initializers.
    struct CV_EXPORTS Params
    {
        //! Compositor::Params::supersample of the preview, in [1, 8]; `augocc composite`'s
        //! default (its `--hard-edges` is 1).
        int supersample = Compositor::Params().supersample;
        //! Compositor::Params::antialiasVirtual of the preview (`composite --antialias-virtual`).
        bool antialiasVirtual = Compositor::Params().antialiasVirtual;
        //! addObject(): largest dimension of an added object, as a fraction of
        //! getSceneSize(), > 0.
        double addedSize = 0.15;
        //! Edits kept for undo(), >= 1 (older ones are forgotten).
        int maxUndo = 200;
    };

    /** @brief Creates an editor over a reconstruction, its clones and a scene.
    @param rec the reconstruction (cameras of the frames that can be shown; validated).
    @param clones the clones of the real objects (occluders of the preview, anchors of the
    helpers); not null.
    @param scene the parsed scene (readScene()); may have no object.
    @param params preview and editing parameters (StsBadArg when outside their ranges).
    Throws as scenePoses() does when a helper names an unknown clone.
    */
    static Ptr<PlacementEditor> create(const Reconstruction& rec, const Ptr<CloneSet>& clones,
                                       const VirtualScene& scene, const Params& params);
    //! Creates an editor with default Params.
    static Ptr<PlacementEditor> create(const Reconstruction& rec, const Ptr<CloneSet>& clones,
                                       const VirtualScene& scene);
    //! The current parameters.
    virtual Params getParams() const = 0;
    //! Sets the parameters (StsBadArg when one is outside the range its field states).
    virtual void setParams(const Params& params) = 0;

    //! The ground frame every placement refers to (estimateGround() of the reconstruction).
    virtual GroundFrame getGround() const = 0;
    /** @brief Size of the scene: the diagonal of the clones' joint footprint on the ground
    (union of their estimateCloneBounds() boxes, right and back axes), world units. The unit of
    addObject()'s size; `place` steps raise() by a fraction of it. */
    virtual double getSceneSize() const = 0;
    /** @brief Ground-aligned box of a clone (estimateCloneBounds(), cached).
    @param clone clone name; StsObjectNotFound when unknown.
    @param minCorner output (right, up, back) minimum, ground coordinates.
    @param maxCorner output maximum. */
    virtual void getCloneBounds(const String& clone, Vec3d& minCorner, Vec3d& maxCorner) const = 0;

    /** @brief Shows a frame: the camera of `frameIndex` is used for every pixel from now on.
    @param frameIndex frame index; StsBadArg when the reconstruction has no camera for it.
    @param image the frame, BGR CV_8UC3 of the reconstruction's image size (StsBadSize else).
    */
    virtual void setFrame(int frameIndex, InputArray image) = 0;
    //! Index of the current frame (-1 before setFrame()).
    virtual int getFrame() const = 0;
    //! Camera of the current frame (StsError before setFrame()).
    virtual Camera getCamera() const = 0;

    /** @brief The ground point seen at a pixel of the current frame.
    @param px pixel (@ref augocc_conventions_pixels "pixel conventions").
    @param world output world point on the ground plane.
    @return false when the ray misses the ground (parallel to it, or the ground is behind a
    perspective camera). */
    virtual bool groundPoint(Point2d px, Vec3d& world) const = 0;
    /** @brief The object under a pixel of the current frame: the nearest (by camera depth of
    its box centre) of the objects whose ground-aligned box projects over the pixel.
    @return its index, or -1. */
    virtual int pickObject(Point2d px) const = 0;

    //! Number of objects.
    virtual int getObjectCount() const = 0;
    //! Selects an object (-1: none); StsOutOfRange for another index.
    virtual void selectObject(int index) = 0;
    //! The selected object, -1 when none.
    virtual int getSelected() const = 0;
    //! The scene-file fields of one object as save() writes them (`meshes` left empty: no copy).
    virtual SceneObject getObject(int index) const = 0;
    //! The scene as save() writes it (meshes included).
    virtual VirtualScene getScene() const = 0;
    //! Model matrix (object to world) of an object, as scenePoses() gives it for the saved file.
    virtual Matx44d getPose(int index) const = 0;
    //! World base point of an object (see the class description).
    virtual Vec3d getBasePoint(int index) const = 0;
    /** @brief Ground-aligned box of an object's placed vertices.
    @param index the object.
    @param minCorner output (right, up, back) minimum, ground coordinates.
    @param maxCorner output maximum. */
    virtual void getObjectBounds(int index, Vec3d& minCorner, Vec3d& maxCorner) const = 0;

    /** @brief Starts a drag: selects the object under px (pickObject()) and remembers the
    horizontal offset from the ground point under px to its base point.
    @return false (nothing changes) when no object is under px or the ray misses the ground. */
    virtual bool beginDrag(Point2d px) = 0;
    /** @brief Moves the dragged object so that its base point is above the ground point under px
    plus the grab offset (horizontally; its height above the ground is kept).
    @return false when no drag is under way or the ray misses the ground. */
    virtual bool dragTo(Point2d px) = 0;
    //! Ends the drag (the whole drag is one undo step). False when none was under way.
    virtual bool endDrag() = 0;
    //! True between beginDrag() and endDrag().
    virtual bool isDragging() const = 0;
    /** @brief Moves the selected object's base point horizontally to above the ground point under
    px (undoable). @return false when nothing is selected or the ray misses the ground. */
    virtual bool moveTo(Point2d px) = 0;
    /** @brief Turns the selected object about the vertical through its base point (then puts
    the base point back where it was: the footprint's box centre moves when the object is not
    symmetric about that axis).
    @param degrees counter-clockwise seen from above (about GroundFrame::up).
    @return false when nothing is selected. */
    virtual bool rotate(double degrees) = 0;
    /** @brief Scales the selected object uniformly about its base point.
    @param factor > 0 (StsBadArg else). @return false when nothing is selected. */
    virtual bool scale(double factor) = 0;
    /** @brief Lifts the selected object along the up axis.
    @param height world units (negative lowers). @return false when nothing is selected. */
    virtual bool raise(double height) = 0;
    /** @brief Places the selected object on the ground against a face of a clone's ground-aligned
    box, centred on that face, `gap` world units away from it ("behind the building, 2 m back"):
    the scene file's placement helper (`behind:`, `in_front_of:`, `on_ground_beside:`) with
    `distance` = gap / clone size, the object's turn and scale kept.
    @param clone clone name (StsObjectNotFound when unknown).
    @param side a SnapSide.
    @param gap >= 0, world units (StsBadArg else).
    @return false when nothing is selected. */
    virtual bool snapToClone(const String& clone, int side, double gap) = 0;
    /** @brief snapToClone() against the clone whose box centre is nearest (on the ground) to the
    selected object's base point. @return that clone's name, empty when nothing is selected. */
    virtual String snapToNearestClone(int side, double gap) = 0;
    /** @brief Adds the meshes of a file (loadMeshes(): OBJ, PLY, glTF..., as readScene() loads
    `mesh:`) as a new object standing on the ground point under px, y up, scaled so that its
    largest dimension is Params::addedSize * getSceneSize(); selects it (undoable).
    @param meshFile the file; loadMeshes()'s StsParseError naming it when it does not load.
    @param px pixel of the current frame; when the ray misses the ground, below the image
    centre's ground point.
    @return its index. */
    virtual int addObject(const String& meshFile, Point2d px) = 0;
    //! addObject() for a procedural shape (proceduralShape(); StsBadArg when unknown).
    virtual int addShape(const String& shape, Point2d px) = 0;
    //! Removes an object (undoable); StsOutOfRange for a bad index.
    virtual void removeObject(int index) = 0;

    /** @brief The scene's sun as save() writes it (form SceneSun::SUN_NONE: no sun, the
    preview is lit by the fixed light and casts no shadow). */
    virtual SceneSun getSun() const = 0;
    /** @brief Sets the scene's sun (undoable); the preview is lit by it from the next render().
    @param sun any SceneSun form (SUN_NONE removes the sun); StsBadArg, and nothing changes, when
    resolveSun() or Sun::validate() rejects it (a sky share outside [0, 1), a bad date...). */
    virtual void setSun(const SceneSun& sun) = 0;
    /** @brief The sun's azimuth (degrees clockwise from north seen from above, [0, 360)) and
    elevation (degrees above the ground) in the editor's ground frame, north the sun's own
    SceneSun::north (zero: -GroundFrame::back, the mean view direction), whatever its form.
    @return false when the scene has no sun. */
    virtual bool getSunAngles(double& azimuthDeg, double& elevationDeg) const = 0;
    /** @brief Turns the sun (undoable): it becomes the azimuth / elevation form at the current
    angles plus the given ones, north, sky and penumbra kept; the elevation is held in [1, 89]
    degrees (a sun at the horizon or the zenith casts no useful shadow).
    @param dAzimuthDeg degrees, clockwise seen from above.
    @param dElevationDeg degrees, up.
    @return false, nothing changed, when the scene has no sun. */
    virtual bool turnSun(double dAzimuthDeg, double dElevationDeg) = 0;
    /** @brief Changes the sun's sky share by `delta`, held in [0, 0.95] (undoable).
    @return false, nothing changed, when the scene has no sun. */
    virtual bool changeSky(double delta) = 0;
    /** @brief Estimates the sun from frames of the footage (estimateSun() with the editor's
    reconstruction, clones and ground) and makes it the scene's sun (undoable): the azimuth /
    elevation form at the estimate's angles relative to the current sun's north, the estimate's
    sky share (held in [0, 0.95]), the current penumbra (SceneSun's default without a sun).
    @param frames BGR (or grey) CV_8U frames `frameNumbers` (sunEstimationFrames() picks them).
    @param frameNumbers their frame numbers (each with a camera).
    @param params estimateSun()'s parameters.
    @return the estimate, its uncertainty included; getSunEstimate() keeps it for display.
    Throws as estimateSun() does (nothing changes then). */
    virtual SunEstimate estimateSunFromFrames(const std::vector<Mat>& frames,
                                              const std::vector<int>& frameNumbers,
                                              const SunEstimationParams& params =
                                                  SunEstimationParams()) = 0;
    //! The last estimateSunFromFrames() result (SunEstimate::frames is 0 before the first).
    virtual SunEstimate getSunEstimate() const = 0;

    //! Undoes the last edit; false when there is nothing to undo.
    virtual bool undo() = 0;
    //! Redoes the last undone edit; false when there is nothing to redo.
    virtual bool redo() = 0;
    //! True when there is an edit to undo.
    virtual bool canUndo() const = 0;
    //! True when there is an undone edit to redo.
    virtual bool canRedo() const = 0;
    //! True when the scene differs from the one last saved (or given to create()).
    virtual bool isModified() const = 0;

    /** @brief Writes the scene (writeScene(): atomic; mesh paths relative to its folder).
    @param path scene.yml; StsBadArg when the scene has no object (readScene() would reject the
    file). */
    virtual void save(const String& path) = 0;

    /** @brief Composites the current frame with the scene as it stands (the Compositor with the
    clones as occluders, lit in the ground frame: compositeSequence()'s frame).
    @param preview output BGR CV_8UC3.
    @param virtualLayer optional output BGRA (Compositor::composite()). */
    virtual void render(OutputArray preview, OutputArray virtualLayer = noArray()) = 0;
    /** @brief Draws the selection over a canvas of the frame size: the selected object's
    ground-aligned box and its base point; the other objects' base points.
    @param canvas CV_8UC3 image to draw on. */
    virtual void drawOverlay(InputOutputArray canvas) const = 0;
};

//! @}

} // namespace augocc
} // namespace cv

#endif
