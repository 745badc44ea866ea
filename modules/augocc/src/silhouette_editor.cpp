// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// SilhouetteEditor: the annotate window's logic, headless (tracing, live wire, straight segments,
// proposals from the clones, undo). Over 800 lines in one file because it is one class whose
// methods share its private editing state; splitting it would put that state in a header.

#include "precomp.hpp"
#include "stats.hpp"

#include <opencv2/imgproc/segmentation.hpp>

namespace cv {
namespace augocc {

namespace {

// A segment joins the previous anchor to its own anchor; `path` holds every pixel of it, both
// ends included, from the previous anchor to this one.
struct Segment
{
    int mode = SilhouetteEditor::STRAIGHT;
    std::vector<Point> path;
};

// anchors[i] ends segs[i]; segs[0] joins the last anchor to the first (empty path while open).
struct ContourData
{
    std::vector<Point> anchors;
    std::vector<Segment> segs;
    bool closed = false;
};

typedef std::vector<ContourData> State;

// Every pixel of the straight line a -> b, both ends included.
std::vector<Point> straightPath(Point a, Point b)
{
    std::vector<Point> path;
    LineIterator it(a, b, 8);
    path.reserve(it.count);
    for (int i = 0; i < it.count; ++i, ++it)
        path.push_back(it.pos());
    if (path.empty())
        path.push_back(a);
    return path;
}

// Bilinear sample of a CV_32F map, clamped at the border.
float sampleBilinear(const Mat& m, Point2f p)
{
    const float x = std::min(std::max(p.x, 0.f), float(m.cols - 1));
    const float y = std::min(std::max(p.y, 0.f), float(m.rows - 1));
    const int x0 = std::min(int(x), m.cols - 2 < 0 ? 0 : m.cols - 2);
    const int y0 = std::min(int(y), m.rows - 2 < 0 ? 0 : m.rows - 2);
    const int x1 = std::min(x0 + 1, m.cols - 1), y1 = std::min(y0 + 1, m.rows - 1);
    const float ax = x - x0, ay = y - y0;
    const float v00 = m.at<float>(y0, x0), v01 = m.at<float>(y0, x1);
    const float v10 = m.at<float>(y1, x0), v11 = m.at<float>(y1, x1);
    return (1 - ay) * ((1 - ax) * v00 + ax * v01) + ay * ((1 - ax) * v10 + ax * v11);
}

// Polygon of a contour: the concatenated segment paths without repeated joints.
std::vector<Point> contourPolyline(const ContourData& c)
{
    std::vector<Point> poly;
    const int n = int(c.anchors.size());
    if (n == 0)
        return poly;
    poly.push_back(c.anchors[0]);
    for (int i = 1; i <= n; ++i)
    {
        const int k = i % n;
        if (k == 0 && !c.closed)
            break;
        const std::vector<Point>& p = c.segs[k].path;
        for (size_t j = 1; j < p.size(); ++j)
            poly.push_back(p[j]);
    }
    if (c.closed && poly.size() > 1 && poly.back() == poly.front())
        poly.pop_back();
    return poly;
}

// +1 / -1 by the sign of the anchor polygon's shoelace area, 0 while open or degenerate.
int orientation(const ContourData& c)
{
    if (!c.closed || c.anchors.size() < 3)
        return 0;
    double a = 0;
    const size_t n = c.anchors.size();
    for (size_t i = 0; i < n; ++i)
    {
        const Point p = c.anchors[i], q = c.anchors[(i + 1) % n];
        a += double(p.x) * q.y - double(q.x) * p.y;
    }
    return a > 0 ? 1 : (a < 0 ? -1 : 0);
}

double pointSegmentDistance(Point2d p, Point2d a, Point2d b)
{
    const Point2d d = b - a;
    const double len2 = d.dot(d);
    double t = len2 > 0 ? (p - a).dot(d) / len2 : 0.0;
    t = std::min(1.0, std::max(0.0, t));
    const Point2d q = a + t * d;
    return std::hypot(p.x - q.x, p.y - q.y);
}

class SilhouetteEditorImpl CV_FINAL : public SilhouetteEditor
{
public:
    explicit SilhouetteEditorImpl(const Params& p) { setParams(p); }

    Params getParams() const CV_OVERRIDE { return params_; }

    void setParams(const Params& p) CV_OVERRIDE
    {
        if (p.clickSnapRadius < 0 || p.searchMargin < 0 || p.snapSpacing < 2 || p.snapRadius < 0)
            CV_Error(Error::StsBadArg,
                     format("SilhouetteEditor: clickSnapRadius (%d), searchMargin (%d), "
                            "snapRadius (%d) must be >= 0 and snapSpacing (%d) >= 2",
                            p.clickSnapRadius, p.searchMargin, p.snapRadius, p.snapSpacing));
        if (!(p.snapDistancePenalty >= 0 && p.snapDistancePenalty <= 1))
            CV_Error(Error::StsBadArg, format("SilhouetteEditor: snapDistancePenalty (%g) must be "
                                              "in [0, 1]", p.snapDistancePenalty));
        if (!(p.outerEdgeBias >= 0) || p.outerEdgeBand < 0)
            CV_Error(Error::StsBadArg,
                     format("SilhouetteEditor: outerEdgeBias (%g) and outerEdgeBand (%d) must be "
                            ">= 0", p.outerEdgeBias, p.outerEdgeBand));
        if (!(p.outlineTolerance > 0) || !(p.minContourArea >= 0))
            CV_Error(Error::StsBadArg,
                     format("SilhouetteEditor: outlineTolerance (%g) must be > 0 and "
                            "minContourArea (%g) >= 0", p.outlineTolerance, p.minContourArea));
        params_ = p;
    }

    void setImage(InputArray _image) CV_OVERRIDE
    {
        Mat image = _image.getMat();
        if (image.empty())
            CV_Error(Error::StsBadArg, "SilhouetteEditor::setImage: empty image");
        if (image.type() != CV_8UC1 && image.type() != CV_8UC3)
            CV_Error(Error::StsUnsupportedFormat,
                     format("SilhouetteEditor::setImage: image type %s, expected CV_8UC1 or "
                            "CV_8UC3", typeToString(image.type()).c_str()));
        image.copyTo(image_);
        computeGradients();
        state_.clear();
        undo_.clear();
        redo_.clear();
    }

    Size getImageSize() const CV_OVERRIDE { return image_.size(); }

    void setSegmentMode(int mode) CV_OVERRIDE
    {
        if (mode != LIVE_WIRE && mode != STRAIGHT)
            CV_Error(Error::StsBadArg, format("SilhouetteEditor: unknown segment mode %d", mode));
        mode_ = mode;
    }
    int getSegmentMode() const CV_OVERRIDE { return mode_; }

    Point addPoint(Point pt) CV_OVERRIDE
    {
        requireImage("addPoint");
        pt = placeClick(pt, mode_);
        pushUndo();
        if (!hasOpenContour())
        {
            ContourData c;
            c.anchors.push_back(pt);
            c.segs.push_back(Segment());
            state_.push_back(c);
            return pt;
        }
        ContourData& c = state_.back();
        Segment s;
        s.mode = mode_;
        s.path = makePath(c.anchors.back(), pt, mode_);
        c.anchors.push_back(pt);
        c.segs.push_back(s);
        return pt;
    }

    void previewSegment(Point pt, OutputArray path) CV_OVERRIDE
    {
        requireImage("previewSegment");
        std::vector<Point> p;
        if (hasOpenContour())
            p = makePath(state_.back().anchors.back(), placeClick(pt, mode_), mode_);
        Mat(p).copyTo(path);
    }

    bool closeContour() CV_OVERRIDE
    {
        if (!hasOpenContour() || state_.back().anchors.size() < 3)
            return false;
        pushUndo();
        ContourData& c = state_.back();
        c.segs[0].mode = mode_;
        c.closed = true;
        // Now that inside and outside are known, the live-wire segments are traced again with
        // the preference for the outer of two parallel edges (see liveWire()).
        for (int k = 0; k < int(c.anchors.size()); ++k)
            if (k == 0 || c.segs[k].mode == LIVE_WIRE)
                recomputeSegment(c, k);
        return true;
    }

    bool removeLastPoint() CV_OVERRIDE
    {
        if (!hasOpenContour())
            return false;
        pushUndo();
        ContourData& c = state_.back();
        c.anchors.pop_back();
        c.segs.pop_back();
        if (c.anchors.empty())
            state_.pop_back();
        return true;
    }

    bool findAnchor(Point pt, double maxDistance, int& contour, int& anchor) const CV_OVERRIDE
    {
        double best = maxDistance;
        bool found = false;
        for (size_t ci = 0; ci < state_.size(); ++ci)
            for (size_t ai = 0; ai < state_[ci].anchors.size(); ++ai)
            {
                const Point d = state_[ci].anchors[ai] - pt;
                const double dist = std::sqrt(double(d.dot(d)));
                if (dist <= best)
                {
                    best = dist;
                    contour = int(ci);
                    anchor = int(ai);
                    found = true;
                }
            }
        return found;
    }

    void moveAnchor(int contour, int anchor, Point pt) CV_OVERRIDE
    {
        checkAnchor(contour, anchor, "moveAnchor");
        pushUndo();
        ContourData& c = state_[contour];
        c.anchors[anchor] = clampToImage(pt);
        const int n = int(c.anchors.size());
        recomputeSegment(c, anchor);
        if (anchor + 1 < n || c.closed)
            recomputeSegment(c, (anchor + 1) % n);
    }

    void removeAnchor(int contour, int anchor) CV_OVERRIDE
    {
        checkAnchor(contour, anchor, "removeAnchor");
        pushUndo();
        ContourData& c = state_[contour];
        const int n = int(c.anchors.size());
        const bool wasClosed = c.closed;
        if (wasClosed && n <= 3)
        {
            state_.erase(state_.begin() + contour);
            return;
        }
        // The segment after the removed anchor now starts at the anchor before it; it keeps the
        // mode of the removed anchor's own segment (the one the user drew up to it).
        const int removedMode = c.segs[anchor].mode;
        c.anchors.erase(c.anchors.begin() + anchor);
        c.segs.erase(c.segs.begin() + anchor);
        const int m = int(c.anchors.size());
        if (m == 0)
        {
            state_.erase(state_.begin() + contour);
            return;
        }
        if (!wasClosed && anchor == 0)
        {
            c.segs[0] = Segment();  // the new first anchor of an open contour has no segment
            return;
        }
        if (anchor < m || wasClosed)
        {
            const int k = anchor % m;
            if (k != 0 || wasClosed)
            {
                c.segs[k].mode = removedMode;
                recomputeSegment(c, k);
            }
        }
    }

    bool insertAnchor(Point pt, double maxDistance) CV_OVERRIDE
    {
        int bestC = -1, bestS = -1;
        double best = maxDistance;
        for (size_t ci = 0; ci < state_.size(); ++ci)
        {
            const ContourData& c = state_[ci];
            for (size_t si = 0; si < c.segs.size(); ++si)
            {
                const std::vector<Point>& p = c.segs[si].path;
                for (size_t j = 0; j + 1 < p.size(); ++j)
                {
                    const double d = pointSegmentDistance(pt, p[j], p[j + 1]);
                    if (d <= best)
                    {
                        best = d;
                        bestC = int(ci);
                        bestS = int(si);
                    }
                }
            }
        }
        if (bestC < 0)
            return false;
        pushUndo();
        ContourData& c = state_[bestC];
        const Point q = clampToImage(pt);
        // The new anchor ends a new segment (mode of the split one) and splits segment bestS.
        Segment s;
        s.mode = c.segs[bestS].mode;
        if (bestS == 0)
        {
            // Segment 0 joins last -> first: the new anchor becomes the last one.
            c.anchors.push_back(q);
            c.segs.push_back(s);
            const int n = int(c.anchors.size());
            recomputeSegment(c, n - 1);
            recomputeSegment(c, 0);
        }
        else
        {
            c.anchors.insert(c.anchors.begin() + bestS, q);
            c.segs.insert(c.segs.begin() + bestS, s);
            recomputeSegment(c, bestS);
            recomputeSegment(c, bestS + 1);
        }
        return true;
    }

    void removeContour(int contour) CV_OVERRIDE
    {
        if (contour < 0 || contour >= int(state_.size()))
            CV_Error(Error::StsOutOfRange,
                     format("SilhouetteEditor::removeContour: contour %d of %d", contour,
                            int(state_.size())));
        pushUndo();
        state_.erase(state_.begin() + contour);
    }

    bool undo() CV_OVERRIDE
    {
        if (undo_.empty())
            return false;
        redo_.push_back(state_);
        state_ = undo_.back();
        undo_.pop_back();
        return true;
    }

    bool redo() CV_OVERRIDE
    {
        if (redo_.empty())
            return false;
        undo_.push_back(state_);
        state_ = redo_.back();
        redo_.pop_back();
        return true;
    }

    bool canUndo() const CV_OVERRIDE { return !undo_.empty(); }
    bool canRedo() const CV_OVERRIDE { return !redo_.empty(); }

    void clearHistory() CV_OVERRIDE
    {
        undo_.clear();
        redo_.clear();
    }

    void clear() CV_OVERRIDE
    {
        if (state_.empty())
            return;
        pushUndo();
        state_.clear();
    }

    int getContourCount() const CV_OVERRIDE { return int(state_.size()); }
    bool hasOpenContour() const CV_OVERRIDE { return !state_.empty() && !state_.back().closed; }

    std::vector<Point> getAnchors(int contour) const CV_OVERRIDE
    {
        checkContour(contour, "getAnchors");
        return state_[contour].anchors;
    }

    std::vector<Point> getContour(int contour) const CV_OVERRIDE
    {
        checkContour(contour, "getContour");
        return contourPolyline(state_[contour]);
    }

    int getAnchorCount() const CV_OVERRIDE
    {
        int n = 0;
        for (const ContourData& c : state_)
            n += int(c.anchors.size());
        return n;
    }

    void getMask(OutputArray _mask) const CV_OVERRIDE
    {
        requireImage("getMask");
        _mask.create(image_.size(), CV_8U);
        Mat mask = _mask.getMat();
        mask.setTo(Scalar::all(0));
        Mat liveBand = Mat::zeros(image_.size(), CV_8U);
        bool anyLive = false;
        for (const ContourData& c : state_)
        {
            if (!c.closed)
                continue;
            std::vector<std::vector<Point>> poly(1, contourPolyline(c));
            // Each contour is filled on its own: the silhouette is the union (no even-odd holes).
            fillPoly(mask, poly, Scalar::all(255), LINE_8);
            for (const Segment& s : c.segs)
                if (s.mode == LIVE_WIRE)
                {
                    for (const Point& p : s.path)
                        liveBand.at<uchar>(p) = 255;
                    anyLive = true;
                }
        }
        if (anyLive && params_.refineBoundary)
            refineBoundary(mask, liveBand);
    }

    void loadMask(InputArray _mask, bool snapToEdges) CV_OVERRIDE
    {
        requireImage("loadMask");
        Mat mask = checkMask(_mask, "loadMask");
        State loaded;
        if (snapToEdges)
            loaded = snapOutlines(mask);
        else
            loaded = polygonOutlines(mask);
        pushUndo();
        state_ = loaded;
    }

    void snapMask(InputArray _proposed, OutputArray snapped) CV_OVERRIDE
    {
        requireImage("snapMask");
        Mat mask = checkMask(_proposed, "snapMask");
        State saved = state_;
        state_ = snapOutlines(mask);
        getMask(snapped);
        state_ = saved;
    }

    void drawOverlay(InputOutputArray _canvas, Point cursor) CV_OVERRIDE
    {
        Mat canvas = _canvas.getMat();
        CV_CheckTypeEQ(canvas.type(), CV_8UC3, "SilhouetteEditor::drawOverlay: canvas");
        if (canvas.size() != image_.size())
            CV_Error(Error::StsBadSize, "SilhouetteEditor::drawOverlay: canvas size differs "
                                        "from the image size");
        // The tint is blended inside the closed contours' bounding box only (a 4K frame is
        // 25 MB; the silhouettes cover a part of it).
        std::vector<std::vector<Point>> closedLines;
        Rect box;
        for (const ContourData& c : state_)
            if (c.closed)
            {
                closedLines.push_back(contourPolyline(c));
                box |= boundingRect(closedLines.back());
            }
        box &= Rect(Point(), canvas.size());
        if (!box.empty())
        {
            Mat fill = Mat::zeros(box.size(), CV_8U);
            for (const std::vector<Point>& l : closedLines)
                fillPoly(fill, std::vector<std::vector<Point>>(1, l), Scalar::all(255), LINE_8,
                         0, -box.tl());
            Mat roi = canvas(box), blended;
            addWeighted(roi, 0.65, Mat(box.size(), CV_8UC3, Scalar(0, 200, 0)), 0.35, 0,
                        blended);
            blended.copyTo(roi, fill);
        }
        for (const ContourData& c : state_)
        {
            const Scalar closedLive(0, 255, 255), closedStraight(255, 160, 0);
            const Scalar open(255, 255, 0);
            for (size_t i = 0; i < c.segs.size(); ++i)
            {
                const Segment& s = c.segs[i];
                const Scalar col = !c.closed ? open
                                   : (s.mode == LIVE_WIRE ? closedLive : closedStraight);
                if (s.path.size() > 1)
                    polylines(canvas, std::vector<std::vector<Point>>(1, s.path), false, col, 1,
                              LINE_8);
            }
            for (const Point& a : c.anchors)
                rectangle(canvas, Rect(a.x - 2, a.y - 2, 5, 5), Scalar(0, 0, 255), FILLED);
        }
        if (hasOpenContour() && Rect(Point(), canvas.size()).contains(cursor))
        {
            std::vector<Point> p;
            previewSegment(cursor, p);
            if (p.size() > 1)
                polylines(canvas, std::vector<std::vector<Point>>(1, p), false,
                          Scalar(255, 0, 255), 1, LINE_8);
        }
    }

private:
    void requireImage(const char* what) const
    {
        if (image_.empty())
            CV_Error(Error::StsError, format("SilhouetteEditor::%s: call setImage() first", what));
    }

    Mat checkMask(InputArray _mask, const char* what) const
    {
        Mat mask = _mask.getMat();
        if (mask.empty())
            CV_Error(Error::StsBadArg, format("SilhouetteEditor::%s: empty mask", what));
        CV_CheckTypeEQ(mask.type(), CV_8UC1, "SilhouetteEditor: mask must be CV_8UC1");
        if (mask.size() != image_.size())
            CV_Error(Error::StsBadSize,
                     format("SilhouetteEditor::%s: mask is %dx%d, image is %dx%d", what,
                            mask.cols, mask.rows, image_.cols, image_.rows));
        return mask > 127;
    }

    void checkContour(int contour, const char* what) const
    {
        if (contour < 0 || contour >= int(state_.size()))
            CV_Error(Error::StsOutOfRange, format("SilhouetteEditor::%s: contour %d of %d", what,
                                                  contour, int(state_.size())));
    }

    void checkAnchor(int contour, int anchor, const char* what) const
    {
        checkContour(contour, what);
        if (anchor < 0 || anchor >= int(state_[contour].anchors.size()))
            CV_Error(Error::StsOutOfRange,
                     format("SilhouetteEditor::%s: anchor %d of %d", what, anchor,
                            int(state_[contour].anchors.size())));
    }

    void pushUndo()
    {
        undo_.push_back(state_);
        redo_.clear();
    }

    Point clampToImage(Point p) const
    {
        return Point(std::min(std::max(p.x, 0), image_.cols - 1),
                     std::min(std::max(p.y, 0), image_.rows - 1));
    }

    // Live-wire clicks move to the strongest edge pixel nearby (nearest among equals), so a
    // click a few pixels off a building's corner still starts the wire on its outline.
    Point placeClick(Point pt, int mode) const
    {
        pt = clampToImage(pt);
        const int r = params_.clickSnapRadius;
        if (mode != LIVE_WIRE || r == 0)
            return pt;
        Point best = pt;
        float bestMag = magnitude_.at<float>(pt);
        int bestD2 = 0;
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx)
            {
                const int d2 = dx * dx + dy * dy;
                const Point q(pt.x + dx, pt.y + dy);
                if (d2 > r * r || !Rect(Point(), image_.size()).contains(q))
                    continue;
                const float m = magnitude_.at<float>(q);
                if (m > bestMag || (m == bestMag && d2 < bestD2))
                {
                    best = q;
                    bestMag = m;
                    bestD2 = d2;
                }
            }
        return best;
    }

    std::vector<Point> makePath(Point a, Point b, int mode, int margin = -1, int orient = 0) const
    {
        if (mode == STRAIGHT || a == b)
            return straightPath(a, b);
        return liveWire(a, b, margin < 0 ? params_.searchMargin : margin, orient);
    }

    // Minimum-cost path a -> b (Intelligent Scissors) inside the bounding box of a and b grown
    // by `margin`: the Dijkstra search of buildMap() then costs the box, not the whole frame.
    // With `orient` != 0 (a closed contour: +1/-1 its orientation) the outside of the chord a->b
    // is known, and pixels up to Params::outerEdgeBand inside the chord get an extra gradient-
    // magnitude cost (up to Params::outerEdgeBias): a silhouette is the outermost edge, and a
    // facade's trim or shadow line just inside it would otherwise compete with it.
    std::vector<Point> liveWire(Point a, Point b, int margin, int orient) const
    {
        Rect roi(Point(std::min(a.x, b.x) - margin, std::min(a.y, b.y) - margin),
                 Point(std::max(a.x, b.x) + margin + 1, std::max(a.y, b.y) + margin + 1));
        roi &= Rect(Point(), image_.size());
        if (roi.width < 3 || roi.height < 3)
            return straightPath(a, b);
        segmentation::IntelligentScissorsMB tool;
        tool.setWeights(params_.weightNonEdge, params_.weightGradientDirection,
                        params_.weightGradientMagnitude);
        // Features of the whole frame, computed once in setImage() from the colour gradient
        // (the scissors' own extractor takes direction and magnitude from the grey image, where
        // two differently coloured surfaces of equal brightness show no edge).
        Mat magCost = magnitudeCost_(roi).clone();
        if (orient != 0 && params_.outerEdgeBias > 0 && params_.outerEdgeBand > 0)
        {
            const Point2f d = Point2f(b - a);
            const float len = std::sqrt(d.dot(d));
            // Outward normal: right of a->b for a positive shoelace area, left otherwise.
            const Point2f out = (orient > 0 ? Point2f(d.y, -d.x) : Point2f(-d.y, d.x)) / len;
            const float band = float(params_.outerEdgeBand);
            for (int y = 0; y < roi.height; ++y)
            {
                float* row = magCost.ptr<float>(y);
                for (int x = 0; x < roi.width; ++x)
                {
                    const Point2f q(float(x + roi.x - a.x), float(y + roi.y - a.y));
                    const float inward = -(q.x * out.x + q.y * out.y);
                    if (inward > 0)
                        row[x] = std::min(1.f, row[x] + params_.outerEdgeBias *
                                                            std::min(inward, band) / band);
                }
            }
        }
        tool.applyImageFeatures(nonEdge_(roi).clone(), direction_(roi).clone(), magCost);
        std::vector<Point> path;
        try
        {
            tool.buildMap(a - roi.tl());
            tool.getContour(b - roi.tl(), path);
        }
        catch (const cv::Exception& e)
        {
            // OpenCV 4.6's getContour() rejects some maps it built itself ("Contour loop is
            // detected"); a straight segment is then the honest answer, not a failed edit.
            CV_LOG_DEBUG(NULL, "SilhouetteEditor: live wire " << a << " -> " << b
                         << " failed, straight segment used: " << e.what());
            path.clear();
        }
        if (path.empty())
            return straightPath(a, b);
        for (Point& p : path)
            p += roi.tl();
        if (path.front() != a)
            path.insert(path.begin(), a);
        if (path.back() != b)
            path.push_back(b);
        return path;
    }

    void recomputeSegment(ContourData& c, int k) const
    {
        const int n = int(c.anchors.size());
        if (k == 0 && !c.closed)
        {
            c.segs[0].path.clear();
            return;
        }
        const Point from = c.anchors[(k - 1 + n) % n];
        c.segs[k].path = makePath(from, c.anchors[k], c.segs[k].mode, -1, orientation(c));
    }

    // Gradient of the smoothed image, per pixel from the channel of largest magnitude (as the
    // scissors' own features do on colour images).
    void computeGradients()
    {
        Mat smooth;
        GaussianBlur(image_, smooth, Size(3, 3), 0.8);
        Mat f;
        smooth.convertTo(f, CV_32F);
        std::vector<Mat> ch;
        split(f, ch);
        magnitude_ = Mat::zeros(image_.size(), CV_32F);
        gx_ = Mat::zeros(image_.size(), CV_32F);
        gy_ = Mat::zeros(image_.size(), CV_32F);
        for (const Mat& c : ch)
        {
            Mat dx, dy, mag;
            Sobel(c, dx, CV_32F, 1, 0, 3);
            Sobel(c, dy, CV_32F, 0, 1, 3);
            cv::magnitude(dx, dy, mag);
            Mat better = mag > magnitude_;
            mag.copyTo(magnitude_, better);
            dx.copyTo(gx_, better);
            dy.copyTo(gy_, better);
        }
        // Scissors features (Mortensen & Barrett's f_Z, f_D, f_G) from the colour gradient:
        // non-edge = not a Canny edge of the colour image; direction = unit gradient; magnitude
        // cost = 1 - min(|g|, max) / max.
        Mat edges;
        Canny(image_, edges, params_.cannyLow, params_.cannyHigh);
        nonEdge_ = Mat(image_.size(), CV_8U);
        nonEdge_.setTo(1);
        nonEdge_.setTo(0, edges);
        direction_.create(image_.size(), CV_32FC2);
        for (int y = 0; y < image_.rows; ++y)
        {
            const float* mx = gx_.ptr<float>(y);
            const float* my = gy_.ptr<float>(y);
            const float* mm = magnitude_.ptr<float>(y);
            Point2f* d = direction_.ptr<Point2f>(y);
            for (int x = 0; x < image_.cols; ++x)
                d[x] = mm[x] > FLT_EPSILON ? Point2f(mx[x] / mm[x], my[x] / mm[x]) : Point2f(0, 0);
        }
        double maxMag = params_.gradientMagnitudeMax;
        if (maxMag <= 0)
            minMaxLoc(magnitude_, nullptr, &maxMag);
        if (maxMag <= FLT_EPSILON)
            magnitudeCost_ = Mat::zeros(image_.size(), CV_32F);
        else
        {
            Mat clipped;
            threshold(magnitude_, clipped, maxMag, 0, THRESH_TRUNC);
            clipped.convertTo(magnitudeCost_, CV_32F, -1.0 / maxMag, 1.0);
        }
    }

    // The live wire runs through edge pixels; a step edge lies between two pixels and the wire
    // takes either, so the filled polygon would be up to one pixel too large along live-wire
    // segments. Each mask-boundary pixel on the wire is kept only if its colour is closer to the
    // inside neighbour than to the outside one (4-neighbours, across the boundary).
    void refineBoundary(Mat& mask, const Mat& liveBand) const
    {
        Mat band;
        dilate(liveBand, band, Mat());
        Mat f;
        image_.convertTo(f, CV_32F);
        const int cn = f.channels();
        const Mat in = mask.clone();
        const int dxs[4] = {1, -1, 0, 0}, dys[4] = {0, 0, 1, -1};
        auto colourDist = [&](Point a, Point b) {
            const float* pa = f.ptr<float>(a.y) + a.x * cn;
            const float* pb = f.ptr<float>(b.y) + b.x * cn;
            float d = 0;
            for (int c = 0; c < cn; ++c)
                d += (pa[c] - pb[c]) * (pa[c] - pb[c]);
            return d;
        };
        const Rect bounds(Point(), mask.size());
        for (int y = 0; y < mask.rows; ++y)
            for (int x = 0; x < mask.cols; ++x)
            {
                if (!band.at<uchar>(y, x) || !in.at<uchar>(y, x))
                    continue;
                const Point p(x, y);
                double toIn = 0, toOut = 0;
                int nIn = 0, nOut = 0;
                for (int k = 0; k < 4; ++k)
                {
                    const Point q(x + dxs[k], y + dys[k]), r(x - dxs[k], y - dys[k]);
                    if (!bounds.contains(q) || !bounds.contains(r))
                        continue;
                    // q outside and r inside: p sits on the boundary in direction k.
                    if (!in.at<uchar>(q) && in.at<uchar>(r))
                    {
                        toOut += colourDist(p, q);
                        toIn += colourDist(p, r);
                        ++nOut;
                        ++nIn;
                    }
                }
                if (nOut > 0 && toOut < toIn)
                    mask.at<uchar>(p) = 0;
            }
    }

    std::vector<std::vector<Point>> outerContours(const Mat& mask) const
    {
        std::vector<std::vector<Point>> contours, kept;
        findContours(mask, contours, RETR_EXTERNAL, CHAIN_APPROX_NONE);
        for (const std::vector<Point>& c : contours)
            if (contourArea(c) >= params_.minContourArea && c.size() >= 3)
                kept.push_back(c);
        return kept;
    }

    State polygonOutlines(const Mat& mask) const
    {
        State s;
        for (const std::vector<Point>& c : outerContours(mask))
        {
            std::vector<Point> approx;
            approxPolyDP(c, approx, params_.outlineTolerance, true);
            if (approx.size() < 3)
                continue;
            ContourData cd;
            cd.anchors = approx;
            cd.closed = true;
            cd.segs.resize(approx.size());
            for (size_t k = 0; k < approx.size(); ++k)
            {
                cd.segs[k].mode = STRAIGHT;
                recomputeSegment(cd, int(k));
            }
            s.push_back(cd);
        }
        return s;
    }

    // Outline samples moved along the normal to the strongest edge that runs along the outline
    // (gradient parallel to the normal), then joined by the live wire.
    State snapOutlines(const Mat& mask) const
    {
        State s;
        const int R = params_.snapRadius;
        for (const std::vector<Point>& c : outerContours(mask))
        {
            const int n = int(c.size());
            const int samples = std::max(6, (n + params_.snapSpacing - 1) / params_.snapSpacing);
            std::vector<Point2f> base(samples), normal(samples);
            std::vector<float> offset(samples, 0.f), score(samples, 0.f);
            // Tangent over +-kTangentHalf contour pixels: long enough to smooth the staircase.
            const int kTangentHalf = 3;
            for (int k = 0; k < samples; ++k)
            {
                const int i = int((int64)k * n / samples);
                const Point2f a = c[(i - kTangentHalf + n) % n], b = c[(i + kTangentHalf) % n];
                Point2f t = b - a;
                const float len = std::sqrt(t.dot(t));
                t = len > 0 ? t * (1.f / len) : Point2f(1, 0);
                base[k] = c[i];
                normal[k] = Point2f(t.y, -t.x);
                float best = -1.f, bestT = 0.f;
                // Half-pixel steps; a preference for small moves (Params::snapDistancePenalty
                // of the score at the full radius) keeps the sample near the proposal.
                const float kDistancePenalty = params_.snapDistancePenalty;
                for (int j = -2 * R; j <= 2 * R; ++j)
                {
                    const float tt = 0.5f * j;
                    const Point2f q = base[k] + tt * normal[k];
                    const float gx = sampleBilinear(gx_, q), gy = sampleBilinear(gy_, q);
                    const float along = std::abs(gx * normal[k].x + gy * normal[k].y);
                    const float sc = along * (1.f - kDistancePenalty * std::abs(tt) /
                                                        std::max(1, R));
                    if (sc > best)
                    {
                        best = sc;
                        bestT = tt;
                    }
                }
                offset[k] = bestT;
                score[k] = best;
            }
            // Samples with no real edge (weaker than kWeakEdgeRatio of the median) stay put;
            // single samples that jumped to a texture edge are pulled back to the running median
            // of their neighbours (kMedianHalf each side), since a clone's error varies slowly.
            const float kWeakEdgeRatio = 0.25f;
            const int kMedianHalf = 2;
            const float kOutlierPx = 1.5f;
            const float medScore = detail::median(score);
            for (int k = 0; k < samples; ++k)
                if (score[k] < kWeakEdgeRatio * medScore)
                    offset[k] = 0.f;
            std::vector<float> filtered(samples);
            for (int k = 0; k < samples; ++k)
            {
                std::vector<float> w;
                for (int d = -kMedianHalf; d <= kMedianHalf; ++d)
                    w.push_back(offset[(k + d + samples) % samples]);
                const float m = detail::medianInPlace(w);
                filtered[k] = std::abs(offset[k] - m) > kOutlierPx ? m : offset[k];
            }
            ContourData cd;
            cd.closed = true;
            for (int k = 0; k < samples; ++k)
            {
                const Point2f q = base[k] + filtered[k] * normal[k];
                const Point p = clampToImage(Point(cvRound(q.x), cvRound(q.y)));
                if (!cd.anchors.empty() && cd.anchors.back() == p)
                    continue;
                cd.anchors.push_back(p);
            }
            if (cd.anchors.size() > 1 && cd.anchors.back() == cd.anchors.front())
                cd.anchors.pop_back();
            if (cd.anchors.size() < 3)
                continue;
            const int m = int(cd.anchors.size());
            cd.segs.resize(m);
            // The wire between two snapped samples only needs room for a corner between them.
            const int margin = R + 4;
            const int orient = orientation(cd);
            for (int k = 0; k < m; ++k)
            {
                cd.segs[k].mode = LIVE_WIRE;
                cd.segs[k].path = makePath(cd.anchors[(k - 1 + m) % m], cd.anchors[k], LIVE_WIRE,
                                           margin, orient);
            }
            s.push_back(cd);
        }
        return s;
    }

    Params params_;
    Mat image_, magnitude_, gx_, gy_;
    Mat nonEdge_, direction_, magnitudeCost_;  // Intelligent Scissors features
    int mode_ = LIVE_WIRE;
    State state_;
    std::vector<State> undo_, redo_;
};

} // namespace

Ptr<SilhouetteEditor> SilhouetteEditor::create(const Params& params)
{
    return makePtr<SilhouetteEditorImpl>(params);
}

Ptr<SilhouetteEditor> SilhouetteEditor::create()
{
    return create(Params());
}

void snapMaskToEdges(InputArray image, InputArray proposed, OutputArray snapped,
                     const SilhouetteEditor::Params& params)
{
    Ptr<SilhouetteEditor> editor = SilhouetteEditor::create(params);
    editor->setImage(image);
    editor->snapMask(proposed, snapped);
}

void resolveVisibleSilhouettes(const std::vector<Mat>& mattes, const std::vector<Mat>& depths,
                               std::vector<Mat>& visible)
{
    if (mattes.size() != depths.size())
        CV_Error(Error::StsBadSize, format("resolveVisibleSilhouettes: %d mattes but %d depth "
                                           "maps", int(mattes.size()), int(depths.size())));
    const size_t n = mattes.size();
    visible.assign(n, Mat());
    if (n == 0)
        return;
    const Size size = mattes[0].size();
    for (size_t i = 0; i < n; ++i)
    {
        CV_CheckTypeEQ(mattes[i].type(), CV_8UC1, "resolveVisibleSilhouettes: mattes");
        CV_CheckTypeEQ(depths[i].type(), CV_32FC1, "resolveVisibleSilhouettes: depths");
        if (mattes[i].size() != size || depths[i].size() != size)
            CV_Error(Error::StsBadSize, format("resolveVisibleSilhouettes: object %d has a "
                                               "matte or depth map of another size", int(i)));
    }
    // Nearest depth over all objects' mattes, then each object keeps the pixels where it is the
    // nearest (ties: visible for both).
    Mat nearest(size, CV_32F, Scalar::all(std::numeric_limits<float>::infinity()));
    for (size_t i = 0; i < n; ++i)
    {
        Mat in = mattes[i] > 127;
        Mat d = Mat(size, CV_32F, Scalar::all(std::numeric_limits<float>::infinity()));
        depths[i].copyTo(d, in);
        min(nearest, d, nearest);
    }
    for (size_t i = 0; i < n; ++i)
    {
        Mat in = mattes[i] > 127;
        Mat front = depths[i] <= nearest;
        visible[i] = in & front;
    }
}

void proposeSilhouettes(const CloneSet& clones, int frame, const Camera& camera,
                        InputArray _image, std::map<String, Mat>& proposals, bool snap,
                        const SilhouetteEditor::Params& params)
{
    Mat image = _image.getMat();
    if (image.empty())
        CV_Error(Error::StsBadArg, format("proposeSilhouettes: empty image for frame %d", frame));
    const std::vector<String> names = clones.objectNames();
    std::vector<Mat> mattes(names.size()), depths(names.size()), visible;
    for (size_t i = 0; i < names.size(); ++i)
        clones.render(names[i], frame, camera, image.size(), mattes[i], depths[i]);
    resolveVisibleSilhouettes(mattes, depths, visible);
    proposals.clear();
    Ptr<SilhouetteEditor> editor;
    if (snap)
    {
        editor = SilhouetteEditor::create(params);
        editor->setImage(image);
    }
    for (size_t i = 0; i < names.size(); ++i)
    {
        Mat out;
        if (snap && countNonZero(visible[i]) > 0)
            editor->snapMask(visible[i], out);
        else
            out = visible[i];
        proposals[names[i]] = out;
    }
}

} // namespace augocc
} // namespace cv
