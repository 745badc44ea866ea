// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// ImageViewport: zoom and pan of a frame in a window, the view <-> frame pixel mapping.

#include "precomp.hpp"

#include <cstring>

#include "opencv2/augocc/image_viewport.hpp"

namespace cv {
namespace augocc {

Size ImageViewport::fitViewSize(Size imageSize, Size maxView)
{
    if (imageSize.width <= 0 || imageSize.height <= 0 || maxView.width <= 0 ||
        maxView.height <= 0)
        CV_Error(Error::StsBadSize, cv::format("ImageViewport: frame %dx%d and view %dx%d must "
                 "be positive", imageSize.width, imageSize.height, maxView.width,
                 maxView.height));
    const double s = std::min(1.0, std::min((double)maxView.width / imageSize.width,
                                            (double)maxView.height / imageSize.height));
    return Size(std::max(1, (int)std::lround(imageSize.width * s)),
                std::max(1, (int)std::lround(imageSize.height * s)));
}

ImageViewport::ImageViewport() {}

ImageViewport::ImageViewport(Size imageSize, Size viewSize)
    : imageSize_(imageSize), viewSize_(viewSize)
{
    fitViewSize(imageSize, viewSize);  // the size checks
    fit();
}

double ImageViewport::fitScale() const
{
    if (imageSize_.empty())
        return 1.0;
    return std::min((double)viewSize_.width / imageSize_.width,
                    (double)viewSize_.height / imageSize_.height);
}

double ImageViewport::getMaxScale() const
{
    return std::max(kMaxScale, fitScale());
}

void ImageViewport::fit()
{
    scale_ = fitScale();
    clampOffset();  // centres the frame: at the fit it is no larger than the view
}

void ImageViewport::setScale(double scale, Point2d anchor)
{
    if (!std::isfinite(scale) || !(scale > 0))
        CV_Error(Error::StsBadArg, cv::format("ImageViewport: scale %g must be positive", scale));
    const Point2d u = viewToImage(anchor);
    scale_ = std::min(std::max(scale, fitScale()), getMaxScale());
    offset_ = anchor - scale_ * u;
    clampOffset();
}

void ImageViewport::zoomBy(double factor, Point2d anchor)
{
    setScale(scale_ * factor, anchor);
}

void ImageViewport::pan(Point2d delta)
{
    offset_ += delta;
    clampOffset();
}

void ImageViewport::clampOffset()
{
    // Per axis: the frame spans view [offset - scale/2, offset + (n - 1/2) scale], the view
    // [-1/2, size - 1/2]. A frame narrower than the view is centred; a wider one covers it.
    auto clampAxis = [&](double& offset, int n, int view) {
        const double width = scale_ * n;
        double left = offset - 0.5 * scale_;
        if (width <= view)
            left = -0.5 + 0.5 * (view - width);
        else
            left = std::min(-0.5, std::max(view - 0.5 - width, left));
        offset = left + 0.5 * scale_;
    };
    clampAxis(offset_.x, imageSize_.width, viewSize_.width);
    clampAxis(offset_.y, imageSize_.height, viewSize_.height);
}

Point2d ImageViewport::viewToImage(Point2d view) const
{
    return (view - offset_) * (1.0 / scale_);
}

Point2d ImageViewport::imageToView(Point2d image) const
{
    return scale_ * image + offset_;
}

Point ImageViewport::imagePixelAt(Point view) const
{
    const Point2d u = viewToImage(Point2d(view));
    return Point((int)std::floor(u.x + 0.5), (int)std::floor(u.y + 0.5));
}

void ImageViewport::render(InputArray imageArg, OutputArray viewArg,
                           const Scalar& background) const
{
    const Mat image = imageArg.getMat();
    if (image.size() != imageSize_)
        CV_Error(Error::StsBadSize, cv::format("ImageViewport::render: frame %dx%d, the viewport "
                 "is for %dx%d", image.cols, image.rows, imageSize_.width, imageSize_.height));
    viewArg.create(viewSize_, image.type());
    Mat view = viewArg.getMat();
    if (scale_ >= 1)
    {
        // Nearest, by the same formula as imagePixelAt(): a frame pixel per view pixel,
        // separable (one source column per view column, one source row per view row).
        std::vector<int> xs(view.cols), ys(view.rows);
        for (int x = 0; x < view.cols; x++)
            xs[x] = imagePixelAt(Point(x, 0)).x;
        for (int y = 0; y < view.rows; y++)
            ys[y] = imagePixelAt(Point(0, y)).y;
        const size_t es = image.elemSize();
        Mat bg(1, 1, image.type(), background);
        parallel_for_(Range(0, view.rows), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
            {
                uchar* d = view.ptr(y);
                const bool rowIn = ys[y] >= 0 && ys[y] < image.rows;
                const uchar* s = rowIn ? image.ptr(ys[y]) : nullptr;
                for (int x = 0; x < view.cols; x++, d += es)
                {
                    const bool in = rowIn && xs[x] >= 0 && xs[x] < image.cols;
                    std::memcpy(d, in ? s + xs[x] * es : bg.ptr(), es);
                }
            }
        });
        return;
    }
    // Below 1: the frame area-averaged by the integer factor k = floor(1 / scale) (INTER_AREA's
    // fast path when k divides the size: 4K to 1080p in a few ms, where a fractional INTER_AREA
    // takes over 100 ms), then bilinear over the remaining factor (in (1/2, 1]) and the
    // placement. The resize maps centre coordinates as small = (u + 1/2) * kx - 1/2, kx = small
    // size / frame size per axis.
    const int k = std::max(1, (int)std::floor(1.0 / scale_));
    Mat small = image;
    if (k > 1)
        resize(image, small, Size(std::max(1, image.cols / k), std::max(1, image.rows / k)), 0, 0,
               INTER_AREA);
    const double kx = (double)small.cols / image.cols, ky = (double)small.rows / image.rows;
    // v = scale * u + offset with u = (small + 1/2) / k - 1/2.
    const double ax = scale_ / kx, ay = scale_ / ky;
    const Matx23d M(ax, 0, offset_.x + 0.5 * ax - 0.5 * scale_,
                    0, ay, offset_.y + 0.5 * ay - 0.5 * scale_);
    warpAffine(small, view, M, viewSize_, INTER_LINEAR, BORDER_CONSTANT, background);
}

} // namespace augocc
} // namespace cv
