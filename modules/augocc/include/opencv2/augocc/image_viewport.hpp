// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_IMAGE_VIEWPORT_HPP
#define OPENCV_AUGOCC_IMAGE_VIEWPORT_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Zoom and pan of a frame shown in a window: the exact mapping between view (window)
pixels and frame pixels, and the drawing of the view, headless so that it is tested without a
window (`augocc annotate` at 1080p and 4K).

Both sides use the module's pixel convention (@ref augocc_conventions_pixels "pixels": (0, 0)
is the centre of the top-left pixel, pixel x covers [x - 0.5, x + 0.5]). A frame point u is shown
at view point `v = scale * u + offset` (scale: view pixels per frame pixel). View pixel p shows
the frame pixel whose area holds p's centre: `floor((p - offset) / scale + 0.5)` per axis; render()
draws exactly that pixel (nearest) when scale >= 1; below, the frame area-averaged by the
integer factor floor(1 / scale), then bilinear (a 4K frame at its fit in a few milliseconds).

The scale stays in [fitScale(), getMaxScale()]: zoomed out to the fit, the whole frame is
visible and centred; zoomed in, the offset is clamped so that the frame always covers the view
(no empty margin beside a frame larger than the view). A value type, like Camera.
*/
class CV_EXPORTS ImageViewport
{
public:
    //! Largest zoom over the fit, view pixels per frame pixel (a frame pixel 32 view pixels wide).
    static constexpr double kMaxScale = 32.0;

    /** @brief The view size that shows a frame whole within `maxView`: the frame scaled by
    min(1, maxView.width / width, maxView.height / height), rounded (a frame that fits is shown
    1:1, never enlarged).
    @param imageSize frame size, positive.
    @param maxView the largest view, positive.
    */
    static Size fitViewSize(Size imageSize, Size maxView);

    //! An empty viewport (no frame).
    ImageViewport();
    /** @brief A viewport of `viewSize` over frames of `imageSize`, at the fit (fit()).
    Throws StsBadSize when a size is not positive. */
    ImageViewport(Size imageSize, Size viewSize);

    Size getImageSize() const { return imageSize_; }  //!< the frame's size
    Size getViewSize() const { return viewSize_; }    //!< the view's size

    //! Scale at which the whole frame fits the view: min(view / frame) per axis.
    double fitScale() const;
    //! Largest scale: max(kMaxScale, fitScale()).
    double getMaxScale() const;
    //! Current scale, view pixels per frame pixel.
    double getScale() const { return scale_; }
    //! Current zoom over the fit: getScale() / fitScale() (1 = the whole frame).
    double getZoom() const { return scale_ / fitScale(); }
    //! View position of frame point (0, 0) (the `offset` of the mapping), view pixels.
    Point2d getOffset() const { return offset_; }

    //! Back to the fit: fitScale(), frame centred.
    void fit();
    /** @brief Sets the scale (clamped to [fitScale(), getMaxScale()]) keeping the frame point
    under view point `anchor` where it is (zoom about the cursor), then clamps the offset.
    @param scale view pixels per frame pixel.
    @param anchor view point, pixels (e.g. the cursor).
    */
    void setScale(double scale, Point2d anchor);
    //! setScale(getScale() * factor, anchor).
    void zoomBy(double factor, Point2d anchor);
    //! Moves the frame by `delta` view pixels (a drag), clamped.
    void pan(Point2d delta);

    //! Frame point shown at view point `view` (sub-pixel), frame pixels.
    Point2d viewToImage(Point2d view) const;
    //! View point where frame point `image` is shown, view pixels.
    Point2d imageToView(Point2d image) const;
    /** @brief The frame pixel that view pixel `view` shows (what a click there means); may lie
    outside the frame when the view shows a margin (check with Rect(Point(), size).contains). */
    Point imagePixelAt(Point view) const;

    /** @brief Draws the view of `image`: nearest frame pixels at scale >= 1 (each exactly
    imagePixelAt()); below 1, INTER_AREA by the integer factor floor(1 / scale), then bilinear.
    @param image frame of getImageSize(), any type cv::resize takes.
    @param view output of getViewSize(), image's type.
    @param background colour of the margins (where no frame pixel is shown).
    */
    void render(InputArray image, OutputArray view, const Scalar& background = Scalar()) const;

private:
    void clampOffset();

    Size imageSize_, viewSize_;
    double scale_ = 1;
    Point2d offset_;
};

//! @}

} // namespace augocc
} // namespace cv

#endif
