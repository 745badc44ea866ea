// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "clone/ideal_space.hpp"

namespace cv {
namespace augocc {
namespace detail {

IdealSpace makeIdealSpace(const Reconstruction& rec, const char* who)
{
    IdealSpace space;
    const Camera* lens = nullptr;
    for (const Camera& c : rec.cameras)
        if (c.hasDistortion())
        {
            lens = &c;
            break;
        }
    if (!lens)
        return space;
    for (const Camera& c : rec.cameras)
        if (c.K != lens->K || c.distortion != lens->distortion)
            CV_Error(Error::StsBadArg, cv::format("%s: cameras of frames %d and %d have different "
                     "intrinsics or lens distortion; the clone stage takes one lens per "
                     "reconstruction", who, lens->frame, c.frame));
    space.view = LensView::get(*lens, rec.imageSize);
    space.rec.model = rec.model;
    space.rec.imageSize = space.view->idealSize();
    space.rec.points = rec.points;
    space.rec.cameras.reserve(rec.cameras.size());
    for (const Camera& c : rec.cameras)
        space.rec.cameras.push_back(space.view->idealCamera(c));
    // Seen: every ideal pixel whose bilinear source lies wholly inside the frame (the ring of
    // partly covered pixels along the edge counts as unknown).
    Mat ones(rec.imageSize, CV_8U, Scalar(255)), seen;
    space.view->toIdeal(ones, seen, INTER_LINEAR, Scalar(0));
    space.inFrame = seen >= 255;
    return space;
}

Mat IdealSpace::mask(const Mat& frameMask) const
{
    if (!active())
        return frameMask;
    // The silhouette's boundary is carried as a signed distance (to the curve halfway between
    // the pixel centres in and out), which is smooth where the binary image is a staircase:
    // bilinear resampling keeps its zero level where the user drew it to a fraction of a pixel.
    Mat in = frameMask > 127, out = ~in, dIn, dOut;
    distanceTransform(in, dIn, DIST_L2, DIST_MASK_PRECISE);
    distanceTransform(out, dOut, DIST_L2, DIST_MASK_PRECISE);
    Mat sdf = dIn - dOut;  // in: d - 0 > 0, out: 0 - d < 0; the boundary halfway, at 0
    Mat ideal;
    view->toIdeal(sdf, ideal, INTER_LINEAR, Scalar(-1e6));
    return ideal > 0;
}

Mat IdealSpace::image(const Mat& frame) const
{
    if (!active())
        return frame;
    Mat ideal;
    view->toIdeal(frame, ideal, INTER_LINEAR, Scalar::all(0));
    return ideal;
}

Tracks IdealSpace::tracks(const Tracks& t) const
{
    if (!active())
        return t;
    const Ptr<const LensView> v = view;
    return t.mapped([&](int, int, const Point2f& q) {
        const Point2d r = v->frameToIdeal(Point2d(q.x, q.y));
        return Point2f((float)r.x, (float)r.y);
    }, view->idealSize());
}

IdealMasks::IdealMasks(CloneSetImpl& set, const IdealSpace& space) : set_(set)
{
    if (!space.active())
        return;
    for (const String& name : set.objectNames())
    {
        ObjectClone& o = set.get(name);
        std::map<int, Mat>& keep = frameMasks_[name];
        for (auto& m : o.masks)
        {
            keep[m.first] = m.second;
            m.second = space.mask(m.second);
        }
    }
}

IdealMasks::~IdealMasks()
{
    for (auto& o : frameMasks_)
        set_.get(o.first).masks = o.second;
}

} // namespace detail
} // namespace augocc
} // namespace cv
