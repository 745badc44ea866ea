// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "pinhole.hpp"

#include <list>
#include <mutex>

namespace cv {
namespace augocc {

namespace {

// The backward map (frame -> ideal) is exact on this grid and bilinear between: the map's second
// derivative is about 6 |k1| r / f per pixel, so the error is below h^2 / 8 of it (< 0.005 px
// for |k1| <= 0.5 at f >= 500 px).
const int kGridStep = 4;
// The ideal view is at most this many times the frame's width and height (a lens whose border
// undistorts farther, a fish-eye modelled by OpenCV's pinhole coefficients, is cut there).
const double kMaxGrowth = 3.0;
const double kMarginPx = 2.0;

using detail::normalizedOf;
using detail::pixelOf;

// Samples of the frame's border (pixel edges) and interior for the view's bounds and density.
std::vector<Point2d> borderSamples(Size size)
{
    std::vector<Point2d> pts;
    const double x0 = -0.5, y0 = -0.5, x1 = size.width - 0.5, y1 = size.height - 0.5;
    const int nx = std::max(2, size.width / 8), ny = std::max(2, size.height / 8);
    for (int i = 0; i <= nx; i++)
    {
        const double x = x0 + (x1 - x0) * i / nx;
        pts.push_back(Point2d(x, y0));
        pts.push_back(Point2d(x, y1));
    }
    for (int j = 1; j < ny; j++)
    {
        const double y = y0 + (y1 - y0) * j / ny;
        pts.push_back(Point2d(x0, y));
        pts.push_back(Point2d(x1, y));
    }
    return pts;
}

} // namespace

LensView::LensView(const Camera& camera, Size frameSize)
    : frameSize_(frameSize)
{
    CV_Assert(frameSize.width > 0 && frameSize.height > 0);
    if (camera.model != PERSPECTIVE)
        CV_Error(Error::StsBadArg, "LensView: the camera is not perspective");
    lens_ = Camera::perspective(Matx33d::eye(), Vec3d(0, 0, 0), camera.K, 0, camera.distortion);
    const Matx33d& K = lens_.K;

    // Ray of every border sample; check that the model inverts there.
    const std::vector<Point2d> border = borderSamples(frameSize);
    std::vector<Point2d> rays(border.size());
    for (size_t i = 0; i < border.size(); i++)
    {
        const Point2d nd = normalizedOf(K, border[i]);
        rays[i] = lens_.undistortNormalized(nd);
        const Point2d back = pixelOf(K, lens_.distortNormalized(rays[i]));
        if (!(cv::norm(back - border[i]) < 1e-3))
            CV_Error(Error::StsBadArg, cv::format("lens distortion folds over the frame: no "
                     "ideal ray distorts to border pixel (%.1f, %.1f) of the %dx%d frame (the "
                     "coefficients are not invertible there)", border[i].x, border[i].y,
                     frameSize.width, frameSize.height));
    }
    // Density: the smallest stretch (singular value) of frame -> ideal at f' = f, over the border
    // and a coarse interior grid; where it is below 1 the ideal view would undersample.
    double minStretch = 1.0;
    {
        std::vector<Point2d> probes = border;
        for (int j = 0; j <= 8; j++)
            for (int i = 0; i <= 8; i++)
                probes.push_back(Point2d((frameSize.width - 1) * i / 8.0,
                                         (frameSize.height - 1) * j / 8.0));
        for (const Point2d& p : probes)
        {
            const double h = 0.5;
            const Point2d c0 = pixelOf(K, lens_.undistortNormalized(normalizedOf(K, p)));
            const Point2d cx = pixelOf(K, lens_.undistortNormalized(normalizedOf(K, p + Point2d(h, 0))));
            const Point2d cy = pixelOf(K, lens_.undistortNormalized(normalizedOf(K, p + Point2d(0, h))));
            const Matx22d J((cx.x - c0.x) / h, (cy.x - c0.x) / h, (cx.y - c0.y) / h, (cy.y - c0.y) / h);
            Vec2d w;
            cv::SVD::compute(J, w, SVD::NO_UV);
            minStretch = std::min(minStretch, w[1]);
        }
    }
    const double scale = std::min(2.0, 1.0 / std::max(minStretch, 0.5));
    // Bounds of the border's rays at f' = scale * f, same principal point offset.
    const double fx = K(0, 0) * scale, fy = K(1, 1) * scale, skew = K(0, 1) * scale;
    double minx = 1e300, miny = 1e300, maxx = -1e300, maxy = -1e300;
    for (const Point2d& r : rays)
    {
        const double u = fx * r.x + skew * r.y, v = fy * r.y;
        minx = std::min(minx, u);
        maxx = std::max(maxx, u);
        miny = std::min(miny, v);
        maxy = std::max(maxy, v);
    }
    const double cx0 = K(0, 2) + 0.5, cy0 = K(1, 2) + 0.5;  // frame centre offset, pixel edges
    minx = std::max(minx, -kMaxGrowth * scale * cx0);
    miny = std::max(miny, -kMaxGrowth * scale * cy0);
    maxx = std::min(maxx, kMaxGrowth * scale * (frameSize.width - cx0));
    maxy = std::min(maxy, kMaxGrowth * scale * (frameSize.height - cy0));
    minx -= kMarginPx;
    miny -= kMarginPx;
    maxx += kMarginPx;
    maxy += kMarginPx;
    // Pixel centres: the ideal image's edge at -0.5 sits at u <= minx, its principal point
    // scale * (cx, cy) plus whole pixels, so that at scale 1 the ideal pixels are the frame's
    // pixel grid extended: where the lens moves a point by less than half a pixel, a binary
    // layer (a rasterised object, a matte) warped back to the frame keeps its pixels. With
    // any other offset it comes back shifted by that offset, up to half a pixel (a virtual
    // object composited through the lens was 0.15-0.2 px off: doc/blender.md).
    const double cx = K(0, 2) * scale + std::ceil(-minx - 0.5 - K(0, 2) * scale);
    const double cy = K(1, 2) * scale + std::ceil(-miny - 0.5 - K(1, 2) * scale);
    minx = -cx - 0.5;
    miny = -cy - 0.5;
    idealK_ = Matx33d(fx, skew, cx, 0, fy, cy, 0, 0, 1);
    idealSize_ = Size((int)std::ceil(maxx - minx), (int)std::ceil(maxy - miny));

    // Forward map: ideal pixel -> frame pixel (exact).
    toIdealMap_.create(idealSize_, CV_32FC2);
    const Matx33d Ki = idealK_;
    const Camera lens = lens_;
    Mat& fwd = toIdealMap_;
    parallel_for_(Range(0, idealSize_.height), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            Vec2f* row = fwd.ptr<Vec2f>(y);
            for (int x = 0; x < idealSize_.width; x++)
            {
                const Point2d p = pixelOf(K, lens.distortNormalized(normalizedOf(Ki, Point2d(x, y))));
                row[x] = Vec2f((float)p.x, (float)p.y);
            }
        }
    });
    // Backward map: frame pixel -> ideal pixel, exact on the grid, bilinear between.
    const int gw = (frameSize.width - 1) / kGridStep + 2, gh = (frameSize.height - 1) / kGridStep + 2;
    Mat grid(gh, gw, CV_64FC2);
    parallel_for_(Range(0, gh), [&](const Range& r) {
        for (int j = r.start; j < r.end; j++)
            for (int i = 0; i < gw; i++)
            {
                const Point2d n = lens.undistortNormalized(
                    normalizedOf(K, Point2d(i * kGridStep, j * kGridStep)));
                const Point2d q = pixelOf(Ki, n);
                grid.at<Vec2d>(j, i) = Vec2d(q.x, q.y);
            }
    });
    toFrameMap_.create(frameSize, CV_32FC2);
    Mat& bwd = toFrameMap_;
    parallel_for_(Range(0, frameSize.height), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            const int j = y / kGridStep;
            const double b = (y - j * kGridStep) / (double)kGridStep;
            Vec2f* row = bwd.ptr<Vec2f>(y);
            const Vec2d* g0 = grid.ptr<Vec2d>(j);
            const Vec2d* g1 = grid.ptr<Vec2d>(j + 1);
            for (int x = 0; x < frameSize.width; x++)
            {
                const int i = x / kGridStep;
                const double a = (x - i * kGridStep) / (double)kGridStep;
                const Vec2d q = (1 - b) * ((1 - a) * g0[i] + a * g0[i + 1]) +
                                b * ((1 - a) * g1[i] + a * g1[i + 1]);
                row[x] = Vec2f((float)q[0], (float)q[1]);
            }
        }
    });
}

Camera LensView::idealCamera(const Camera& frameCamera) const
{
    return Camera::perspective(frameCamera.R, frameCamera.t, idealK_, frameCamera.frame);
}

Point2d LensView::frameToIdeal(const Point2d& px) const
{
    return pixelOf(idealK_, lens_.undistortNormalized(normalizedOf(lens_.K, px)));
}

Point2d LensView::idealToFrame(const Point2d& px) const
{
    return pixelOf(lens_.K, lens_.distortNormalized(normalizedOf(idealK_, px)));
}

void LensView::toIdeal(InputArray frameImage, OutputArray idealImage, int interpolation,
                       const Scalar& border) const
{
    CV_Assert(frameImage.size() == frameSize_);
    cv::remap(frameImage, idealImage, toIdealMap_, noArray(), interpolation, BORDER_CONSTANT,
              border);
}

void LensView::toFrame(InputArray idealImage, OutputArray frameImage, int interpolation,
                       const Scalar& border) const
{
    CV_Assert(idealImage.size() == idealSize_);
    cv::remap(idealImage, frameImage, toFrameMap_, noArray(), interpolation, BORDER_CONSTANT,
              border);
}

Ptr<const LensView> LensView::get(const Camera& camera, Size frameSize)
{
    struct Entry
    {
        Matx33d K;
        std::vector<double> distortion;
        Size size;
        Ptr<const LensView> view;
    };
    static std::mutex mutex;
    static std::list<Entry> cache;
    const size_t kCapacity = 8;
    {
        std::lock_guard<std::mutex> lock(mutex);
        for (auto it = cache.begin(); it != cache.end(); ++it)
            if (it->size == frameSize && it->K == camera.K && it->distortion == camera.distortion)
            {
                cache.splice(cache.begin(), cache, it);
                return cache.front().view;
            }
    }
    Ptr<const LensView> view = makePtr<LensView>(camera, frameSize);
    std::lock_guard<std::mutex> lock(mutex);
    cache.push_front(Entry{camera.K, camera.distortion, frameSize, view});
    if (cache.size() > kCapacity)
        cache.pop_back();
    return view;
}

} // namespace augocc
} // namespace cv
