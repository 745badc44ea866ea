// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SILHOUETTE_EDITOR_HPP
#define OPENCV_AUGOCC_SILHOUETTE_EDITOR_HPP

#include <map>
#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Contour editing for one object in one frame: anchors joined by live-wire or straight
segments, closed contours filled into a mask, undo and redo, editing of an existing mask, and
outlines proposed from a coarse matte snapped to the image edges.

Silhouette tracing (the paper's Section 5 @cite Ong1998): the user outlines a real object in a
key frame with Intelligent Scissors @cite Mortensen1995 (OpenCV's
cv::segmentation::IntelligentScissorsMB) plus a straight-line tool. Points are integer pixels
(@ref augocc_conventions_pixels "pixel conventions"). All the logic lives here, so that it is
tested headless; the `augocc annotate` window only forwards clicks and keys.

A silhouette is a set of closed contours (their filled union is the mask) plus at most one open
contour being traced. Every contour is a cyclic list of anchors; segment i joins anchor i-1 to
anchor i (segment 0 joins the last anchor to the first once the contour is closed) and has its
own mode (LIVE_WIRE or STRAIGHT), fixed when the segment is made.

Typical use: setImage(frame); addPoint() per click; closeContour(); getMask(). For an existing
mask: setImage(frame); loadMask(mask); moveAnchor()/removeAnchor()/insertAnchor(); getMask().
*/
class CV_EXPORTS SilhouetteEditor : public Algorithm
{
public:
    //! How a new segment joins the previous anchor to the new one.
    enum SegmentMode
    {
        LIVE_WIRE = 0, //!< minimum-cost path on the image edges (Intelligent Scissors)
        STRAIGHT = 1   //!< straight line, no snapping (the paper's line tool)
    };

    //! Editing and snapping parameters; the defaults are the initializers.
    struct CV_EXPORTS Params
    {
        //! Intelligent Scissors weight of the non-edge feature (a pixel off the Canny edges of
        //! the frame); the three weights are those of Mortensen & Barrett.
        float weightNonEdge = 0.43f;
        //! Intelligent Scissors weight of the gradient-direction feature.
        float weightGradientDirection = 0.43f;
        //! Intelligent Scissors weight of the gradient-magnitude feature.
        float weightGradientMagnitude = 0.14f;
        //! Gradient magnitude at or above which a pixel costs nothing (lower snaps to weaker
        //! edges; 0: the frame's largest magnitude instead).
        float gradientMagnitudeMax = 150.f;
        //! Lower Canny threshold of the edge feature (as in OpenCV's scissors demo).
        double cannyLow = 32;
        //! Upper Canny threshold of the edge feature (as in OpenCV's scissors demo).
        double cannyHigh = 100;
        //! LIVE_WIRE clicks are moved to the strongest edge pixel within this radius, pixels,
        //! >= 0 (0 keeps the click as given).
        int clickSnapRadius = 2;
        //! Live wire is searched inside the bounding box of its two anchors grown by this
        //! margin, pixels, >= 0: bounded cost, and no detour through far-away texture.
        int searchMargin = 24;
        //! Once a contour is closed its outside is known: live-wire pixels up to outerEdgeBand
        //! pixels inside the chord of their segment cost up to this much more (gradient-
        //! magnitude feature, range [0, 1]), so the wire takes the outer of two parallel edges
        //! (a silhouette rather than a trim just inside it). Higher prefers the outer edge
        //! more; 0 disables.
        float outerEdgeBias = 0.5f;
        //! Width of that band inside the chord, pixels, >= 0 (0 disables).
        int outerEdgeBand = 4;
        //! loadMask(): tolerance of the polygon approximation of a mask outline, pixels, > 0
        //! (higher: fewer anchors, a coarser outline).
        double outlineTolerance = 1.0;
        //! snapMask(): spacing of the outline samples that are snapped, pixels, >= 2.
        int snapSpacing = 10;
        //! snapMask(): how far along the outline normal a sample may move, pixels, >= 0.
        int snapRadius = 4;
        //! snapMask(): preference for small moves, in [0, 1]: an edge at the full snapRadius
        //! scores this fraction less than the same edge on the proposed outline (higher keeps
        //! the outline closer to the proposal).
        float snapDistancePenalty = 0.3f;
        //! Contours whose area is below this are ignored when a mask is loaded, pixels, >= 0.
        double minContourArea = 20;
        //! getMask(): a live-wire pixel on the mask's boundary is kept only when its colour is
        //! nearer to the inside neighbour's than to the outside one's (the wire runs on edge
        //! pixels, which belong to either side).
        bool refineBoundary = true;
    };

    /** @brief Creates an editor.
    @param params editing and snapping parameters; throws as setParams() does when they are
    invalid.
    */
    static Ptr<SilhouetteEditor> create(const Params& params);
    //! Creates an editor with default Params.
    static Ptr<SilhouetteEditor> create();
    //! The current parameters.
    virtual Params getParams() const = 0;
    /** @brief Sets the parameters.
    @param params the parameters; StsBadArg when one is outside the range its field states.
    */
    virtual void setParams(const Params& params) = 0;

    /** @brief Sets the frame to trace on and clears the silhouette and the undo history.
    @param image CV_8UC1 or CV_8UC3 (BGR), not empty.
    */
    virtual void setImage(InputArray image) = 0;
    //! Size of the current image (empty before setImage()).
    virtual Size getImageSize() const = 0;

    //! Mode of the segments made from now on (LIVE_WIRE by default). @param mode a SegmentMode.
    virtual void setSegmentMode(int mode) = 0;
    //! The SegmentMode of the segments made from now on.
    virtual int getSegmentMode() const = 0;

    /** @brief Adds an anchor at pt (clamped to the image) to the open contour, starting one if
    none is open; the segment from the previous anchor uses the current mode.
    @param pt click position in image pixels.
    @return the anchor as placed (after the LIVE_WIRE click snap).
    */
    virtual Point addPoint(Point pt) = 0;

    /** @brief The segment addPoint(pt) would make now (for drawing under the cursor).
    @param pt cursor position in image pixels.
    @param path output polyline from the last anchor to pt (empty when no contour is open).
    */
    virtual void previewSegment(Point pt, OutputArray path) = 0;

    /** @brief Closes the open contour with a segment from its last anchor to its first (current
    mode) and adds it to the silhouette.
    @return false (and nothing changes) when no contour is open or it has fewer than 3 anchors.
    */
    virtual bool closeContour() = 0;

    //! Removes the last anchor of the open contour (the open contour itself when it is the only
    //! one); false when no contour is open.
    virtual bool removeLastPoint() = 0;

    /** @brief Finds the anchor nearest to pt within maxDistance.
    @param pt position in image pixels.
    @param maxDistance search radius in pixels.
    @param contour output: index of the contour (the open contour, if any, is the last one).
    @param anchor output: index of the anchor in it.
    @return true when one was found.
    */
    virtual bool findAnchor(Point pt, double maxDistance, int& contour, int& anchor) const = 0;
    //! Moves an anchor; both of its segments are recomputed with their own modes.
    virtual void moveAnchor(int contour, int anchor, Point pt) = 0;
    //! Removes an anchor; its neighbours are joined with the mode of the removed one's segment.
    //! A closed contour left with fewer than 3 anchors is removed.
    virtual void removeAnchor(int contour, int anchor) = 0;
    /** @brief Inserts an anchor at pt on the segment of a contour nearest to pt.
    @return false when pt is farther than maxDistance from every segment.
    */
    virtual bool insertAnchor(Point pt, double maxDistance) = 0;
    //! Removes a whole contour.
    virtual void removeContour(int contour) = 0;

    //! Undoes the last edit; false when there is nothing to undo.
    virtual bool undo() = 0;
    //! Redoes the last undone edit; false when there is nothing to redo.
    virtual bool redo() = 0;
    //! True when there is an edit to undo.
    virtual bool canUndo() const = 0;
    //! True when there is an undone edit to redo.
    virtual bool canRedo() const = 0;
    //! Forgets the undo and redo history (e.g. after loading a saved mask).
    virtual void clearHistory() = 0;
    //! Removes every contour (undoable).
    virtual void clear() = 0;

    //! Number of contours, the open one included.
    virtual int getContourCount() const = 0;
    //! True when there is an open contour (always the last one).
    virtual bool hasOpenContour() const = 0;
    //! Anchors of a contour.
    virtual std::vector<Point> getAnchors(int contour) const = 0;
    //! Whole polyline of a contour (every pixel of its segments, in order).
    virtual std::vector<Point> getContour(int contour) const = 0;
    //! Total number of anchors placed in the silhouette (all contours).
    virtual int getAnchorCount() const = 0;

    /** @brief The silhouette as a mask: union of the filled closed contours.
    @param mask output CV_8U of the image size, 255 inside, 0 outside.
    */
    virtual void getMask(OutputArray mask) const = 0;

    /** @brief Replaces the silhouette by the outline of an existing mask (undoable): each outer
    contour of the mask becomes a closed contour whose anchors are the vertices of its polygon
    approximation (Params::outlineTolerance), joined by STRAIGHT segments, ready for editing.
    Holes are not kept.
    @param mask CV_8U of the image size, > 127 = object.
    @param snapToEdges first snap the outline to the image edges (snapMask()) and keep the snapped
    live-wire segments.
    */
    virtual void loadMask(InputArray mask, bool snapToEdges = false) = 0;

    /** @brief Proposes an outline from a coarse mask (e.g. a clone's matte projected into this
    frame): samples its outline every Params::snapSpacing pixels, moves each sample along the
    outline normal (within Params::snapRadius) to the strongest image edge that runs along the
    outline, then joins the samples with the live wire.
    @param proposed CV_8U of the image size, > 127 = object.
    @param snapped output CV_8U mask, 255 inside the snapped outline.
    */
    virtual void snapMask(InputArray proposed, OutputArray snapped) = 0;

    /** @brief Draws the silhouette over a canvas of the image size: filled closed contours
    (translucent), segments, anchors; the open contour in another colour.
    @param canvas CV_8UC3 image to draw on.
    @param cursor if inside the image and a contour is open, the preview segment to it is drawn.
    */
    virtual void drawOverlay(InputOutputArray canvas, Point cursor = Point(-1, -1)) = 0;
};

/** @brief Snaps a coarse mask to the edges of an image with a default SilhouetteEditor
(convenience for SilhouetteEditor::snapMask()).
@param image frame, CV_8UC1 or CV_8UC3.
@param proposed CV_8U mask of the image size, > 127 = object.
@param snapped output CV_8U mask.
@param params editor parameters.
*/
CV_EXPORTS void snapMaskToEdges(InputArray image, InputArray proposed, OutputArray snapped,
                                const SilhouetteEditor::Params& params =
                                    SilhouetteEditor::Params());

/** @brief Visible parts of several objects' mattes by a depth test: a pixel of object i's matte
is visible unless another object's matte covers it at a smaller depth.
@param mattes per object CV_8U (> 127 inside), all of one size.
@param depths per object CV_32F camera-space z (where the matte is set), same size.
@param visible output per object CV_8U, 255 where visible.
*/
CV_EXPORTS void resolveVisibleSilhouettes(const std::vector<Mat>& mattes,
                                          const std::vector<Mat>& depths,
                                          std::vector<Mat>& visible);

class CloneSet;

/** @brief Proposed silhouettes of every object of a clone set in one frame (the paper's stated
future work): each clone is rendered into the frame, what nearer clones hide is removed
(resolveVisibleSilhouettes()), and the outline is snapped to the frame's edges
(SilhouetteEditor::snapMask()). The user then only corrects.
@param clones the clones.
@param frame frame index (selects the patch set).
@param camera the frame's camera.
@param image the frame, CV_8UC1 or CV_8UC3.
@param proposals output: object name -> CV_8U mask (255 inside); objects that are not visible get
an all-zero mask.
@param snap snap to the image edges (false: the depth-resolved mattes as they are).
@param params snapping parameters.
*/
CV_EXPORTS void proposeSilhouettes(const CloneSet& clones, int frame, const Camera& camera,
                                   InputArray image, std::map<String, Mat>& proposals,
                                   bool snap = true,
                                   const SilhouetteEditor::Params& params =
                                       SilhouetteEditor::Params());

//! @}

} // namespace augocc
} // namespace cv

#endif
