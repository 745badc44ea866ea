// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Steps 1-3 of the paper's Section 6 @cite Ong1998: the points of each object clustered by its
// silhouettes, the box oriented (the vertical from the cameras, then the least footprint) and
// enlarged until every key-frame silhouette pixel's ray meets it, and the dense grid over it.

#include "precomp.hpp"
#include "clone/passes.hpp"

#include <climits>

namespace cv {
namespace augocc {
namespace detail {

namespace {

// Step 2 (auto): the cameras' x axes must span the horizontal plane for the vertical to be their
// common normal: second eigenvalue / largest of their scatter above this (about a 3 degree spread).
const double kMinHorizontalSpread = 1e-3;
// Step 2 (auto): footprint-area search over the rotation about the vertical, in degrees.
const double kAzimuthStepDeg = 1.0;

} // namespace

void Box::include(const Vec3d& b)
{
    if (!valid)
    {
        lo = hi = b;
        valid = true;
        return;
    }
    for (int a = 0; a < 3; a++)
    {
        lo[a] = std::min(lo[a], b[a]);
        hi[a] = std::max(hi[a], b[a]);
    }
}

Vec3d Box::clamp(const Vec3d& b) const
{
    Vec3d c;
    for (int a = 0; a < 3; a++)
        c[a] = std::min(std::max(b[a], lo[a]), hi[a]);
    return c;
}

double Box::distance(const Vec3d& X) const
{
    const Vec3d b = toBox(X);
    return cv::norm(b - clamp(b));
}

Vec3d estimateVertical(const Reconstruction& rec)
{
    Matx33d S = Matx33d::zeros();
    Vec3d down(0, 0, 0);
    for (const Camera& c : rec.cameras)
    {
        const Vec3d x(c.R(0, 0), c.R(0, 1), c.R(0, 2));
        S += x * x.t();
        down += Vec3d(c.R(1, 0), c.R(1, 1), c.R(1, 2));
    }
    Mat evals, evecs;
    eigen(Mat(S), evals, evecs);  // descending
    Vec3d up = -down;
    if (evals.at<double>(1) > kMinHorizontalSpread * evals.at<double>(0))
    {
        // Cameras that orbit without roll keep their x axis horizontal: the vertical is normal to
        // every x axis, the scatter's least eigenvector.
        Vec3d e(evecs.at<double>(2, 0), evecs.at<double>(2, 1), evecs.at<double>(2, 2));
        up = e.dot(up) < 0 ? -e : e;
    }
    return up / cv::norm(up);
}

namespace {

// ---------------------------------------------------------------------------------------------
// Step 1: clustering

// Silhouette evidence of point X for `object`: -1 when a key frame where it is seen puts it outside
// every silhouette of this object and of the others (it cannot be the object's), else the number
// of key frames whose silhouette of this object holds it.
int silhouetteVotes(const Reconstruction& rec, const ObjectMasks& all, const String& object,
                    const Tracks* tracks, int p, const Vec3d& X, const Mat* inFrame)
{
    const FrameMasks& masks = all.at(object);
    const Rect img(Point(0, 0), rec.imageSize);
    int inCount = 0;
    for (const auto& fm : masks)
    {
        const int f = fm.first;
        if (tracks && (f >= tracks->frames() || !tracks->observed(f, p)))
            continue;
        const Point2d uv = rec.project(f, X);
        const Point px(cvRound(uv.x), cvRound(uv.y));
        if (!img.contains(px) || (inFrame && !inFrame->at<uchar>(px)))
        {
            if (tracks)
                return -1;  // seen in the frame but projects off it: inconsistent point
            continue;
        }
        if (fm.second.at<uchar>(px) > 127)
        {
            inCount++;
            continue;
        }
        // Under another object's silhouette the point may be hidden there: no evidence.
        bool hidden = false;
        for (const auto& other : all)
        {
            if (other.first == object)
                continue;
            auto it = other.second.find(f);
            if (it != other.second.end() && it->second.at<uchar>(px) > 127)
            {
                hidden = true;
                break;
            }
        }
        if (!hidden)
            return -1;
    }
    return inCount;
}

// Step 1: the points of `object`: consistent with its silhouettes (silhouetteVotes >= 1) and, when
// they are consistent with other objects too (a point behind one object and seen inside another's
// silhouette), held by this object's silhouettes in at least as many key frames as by any other's.
std::vector<Vec3d> clusterPoints(const Reconstruction& rec, const ObjectMasks& all,
                                 const String& object, const Tracks* tracks,
                                 const Mat* inFrame, std::vector<int>* indices = nullptr)
{
    std::vector<Vec3d> out;
    if (rec.points.empty())
        return out;
    const int P = rec.points.rows;
    for (int p = 0; p < P; p++)
    {
        if (!rec.hasPoint(p))
            continue;
        const Vec3d X = rec.point(p);
        const int mine = silhouetteVotes(rec, all, object, tracks, p, X, inFrame);
        if (mine <= 0)
            continue;
        bool best = true;
        for (const auto& other : all)
            if (other.first != object &&
                silhouetteVotes(rec, all, other.first, tracks, p, X, inFrame) > mine)
            {
                best = false;
                break;
            }
        if (best)
        {
            out.push_back(X);
            if (indices)
                indices->push_back(p);
        }
    }
    return out;
}

// Trimmed extent of values: [q, 1 - q] quantiles.
void trimmedRange(std::vector<double>& v, double trim, double& lo, double& hi)
{
    std::sort(v.begin(), v.end());
    const int n = (int)v.size();
    const int cut = std::min((int)std::floor(trim * n), (n - 1) / 2);
    lo = v[cut];
    hi = v[n - 1 - cut];
}

// Step 1's trimmed extent, with the trimmed values that continue the rest given back at the ends
// whose box face no key frame sees (its outward normal points away from every key frame's camera:
// the bottom of an object on the ground seen from above): walking outwards from the trimmed end
// while the gap to the next value is at most this fraction of the trimmed extent. Trimming is there
// for outliers, which stand apart; it also dropped the true extremes of a part few points sample
// (issue 18: a thin stem's foot, its lowest 2% of points 0.1-0.2 above the ground). At a face some
// key frame sees, Step 3 restores what the trim cut (the rays of that side's outline pixels miss
// the cut box); at a face none sees, those rays rise towards the cameras through the box above
// the cut and touch it, and the growth (passGridGrowth) ignores a strip within 3 px of the
// outline: 1.8% (scaled orthographic) / 2.2% (perspective) of the mushroom tower's true volume,
// its foot, was outside the grid. Giving back at every end instead added 0.3 units of conjectured
// volume to the synthesized L-block, hidden behind the building (perspective 0.980 -> 0.965).
const double kMaxTrimGapFraction = 0.10;

// Step 1's points are the object's only where they are: without tracks, a point its silhouettes
// hold in every key frame may also lie behind it, hidden there (the ground behind a building; with
// tracks, silhouetteVotes counts only the key frames that see a point). Such points stand apart
// from the object's own, which sample its surface densely; more of them than the trim takes would
// stretch the box into conjecture behind the object (issue 18: the hillside's box 5 units deep for
// a true 1.8). So the trimmed range also ends at the first gap, walking outwards from the
// interquartile core, wider than this fraction of the core's width or this many times the mean
// spacing of the values in it.
const double kMaxCoreGapFraction = 0.25;
const double kMaxCoreGapSpacings = 8.0;
// A box axis is horizontal (the gap rule applies) within 60 degrees of the horizontal plane.
const double kMaxHorizontalAxisCos = 0.5;

// Index reached from i stepping by `step` (+1 or -1) over sorted v while each next value lies
// within `gap` of the last and the index within [first, last].
int walkContiguous(const std::vector<double>& v, int i, int step, int first, int last, double gap)
{
    while (i + step >= first && i + step <= last && std::abs(v[i + step] - v[i]) <= gap)
        i += step;
    return i;
}

void coreContiguous(const std::vector<double>& v, int cut, double& lo, double& hi)
{
    const int n = (int)v.size();
    const int q1 = n / 4, q3 = std::max(q1, n - 1 - n / 4);
    const double core = v[q3] - v[q1];
    const double gap = std::max(kMaxCoreGapFraction * core,
                                kMaxCoreGapSpacings * core / std::max(1, q3 - q1));
    if (!(gap > 0))
        return;
    lo = std::max(lo, v[walkContiguous(v, q1, -1, cut, n - 1 - cut, gap)]);
    hi = std::min(hi, v[walkContiguous(v, q3, +1, cut, n - 1 - cut, gap)]);
}

void contiguousRange(std::vector<double>& v, double trim, bool giveLo, bool giveHi, bool core,
                     double& lo, double& hi)
{
    trimmedRange(v, trim, lo, hi);  // sorts v
    const int n = (int)v.size();
    const int cut = std::min((int)std::floor(trim * n), (n - 1) / 2);
    const double trimmedLo = lo, trimmedHi = hi;
    if (core)
        coreContiguous(v, cut, lo, hi);
    // An end at a gap has nothing beyond it to give back.
    giveLo = giveLo && lo == trimmedLo;
    giveHi = giveHi && hi == trimmedHi;
    const double gap = kMaxTrimGapFraction * (hi - lo);
    if (giveLo)
        lo = v[walkContiguous(v, cut, -1, 0, n - 1, gap)];
    if (giveHi)
        hi = v[walkContiguous(v, n - 1 - cut, +1, 0, n - 1, gap)];
}

// True when no key frame sees the face of `box` with outward normal `n` (world): it faces away
// from every key frame's camera (perspective: along the line from the camera to the box centre).
bool faceUnseen(const Reconstruction& rec, const FrameMasks& masks, const Vec3d& n,
                const Vec3d& centre)
{
    for (const auto& fm : masks)
    {
        const Camera& cam = rec.camera(fm.first);
        const Vec3d d = cam.model == PERSPECTIVE ? centre - cam.center() : cam.viewDirection();
        if (n.dot(d) <= 0)
            return false;
    }
    return true;
}

// Step 1's box. Without tracks (`noTracks`), the horizontal extents also end at the first wide gap
// from the core (coreContiguous): nothing then says which key frames see a point.
Box robustBox(const std::vector<Vec3d>& pts, const Matx33d& R, double trim,
              const Reconstruction& rec, const FrameMasks& masks, const Vec3d& up, bool noTracks)
{
    Box b;
    b.R = R;
    std::vector<double> c[3];
    for (const Vec3d& X : pts)
    {
        const Vec3d y = R.t() * X;
        for (int a = 0; a < 3; a++)
            c[a].push_back(y[a]);
    }
    for (int a = 0; a < 3; a++)
        trimmedRange(c[a], trim, b.lo[a], b.hi[a]);
    const Vec3d centre = R * (0.5 * (b.lo + b.hi));
    // The points hidden behind an object lie beyond it horizontally; along the vertical an
    // object's own points may be sparse over a long stretch (a thin stem under a wide cap).
    for (int a = 0; a < 3; a++)
    {
        const Vec3d axis(R(0, a), R(1, a), R(2, a));
        const bool core = noTracks && std::abs(axis.dot(up)) < kMaxHorizontalAxisCos;
        contiguousRange(c[a], trim, faceUnseen(rec, masks, -axis, centre),
                        faceUnseen(rec, masks, axis, centre), core, b.lo[a], b.hi[a]);
    }
    b.valid = true;
    return b;
}

// ---------------------------------------------------------------------------------------------
// Step 2: orientation

Matx33d basisFromUp(const Vec3d& up, const Vec3d& hint)
{
    Vec3d a = hint - up * hint.dot(up);
    if (cv::norm(a) < 1e-9)
    {
        a = std::abs(up[0]) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 0, 1);
        a = a - up * a.dot(up);
    }
    a /= cv::norm(a);
    const Vec3d b = a.cross(up);
    return Matx33d(a[0], up[0], b[0], a[1], up[1], b[1], a[2], up[2], b[2]);
}

Matx33d autoOrientation(const Reconstruction& rec, const std::vector<Vec3d>& pts, double trim,
                        int minPoints, const Vec3d& up)
{
    Vec3d meanX(0, 0, 0);
    for (const Camera& c : rec.cameras)
        meanX += Vec3d(c.R(0, 0), c.R(0, 1), c.R(0, 2));
    const Matx33d B0 = basisFromUp(up, meanX);
    if ((int)pts.size() < minPoints)
        return B0;
    // Least footprint area about the vertical (buildings: aligned with their facades).
    const Vec3d a0(B0(0, 0), B0(1, 0), B0(2, 0)), b0(B0(0, 2), B0(1, 2), B0(2, 2));
    double bestArea = std::numeric_limits<double>::infinity(), bestTheta = 0;
    std::vector<double> ca(pts.size()), cb(pts.size());
    for (double deg = 0; deg < 90.0; deg += kAzimuthStepDeg)
    {
        const double th = deg * CV_PI / 180.0;
        const Vec3d a = std::cos(th) * a0 + std::sin(th) * b0;
        const Vec3d b = a.cross(up);
        for (size_t i = 0; i < pts.size(); i++)
        {
            ca[i] = pts[i].dot(a);
            cb[i] = pts[i].dot(b);
        }
        double l0, h0, l1, h1;
        trimmedRange(ca, trim, l0, h0);
        trimmedRange(cb, trim, l1, h1);
        const double area = (h0 - l0) * (h1 - l1);
        if (area < bestArea - 1e-12)
        {
            bestArea = area;
            bestTheta = th;
        }
    }
    const Vec3d a = std::cos(bestTheta) * a0 + std::sin(bestTheta) * b0;
    return basisFromUp(up, a);
}

// ---------------------------------------------------------------------------------------------
// Fallback: the box bounding the intersection of the back-projected silhouette rectangles (an LP
// per box face; each rectangle edge is a half-space for both camera models).

Box boxFromSilhouettes(const Reconstruction& rec, const FrameMasks& masks, const Matx33d& R,
                       const String& object)
{
    std::vector<Vec4d> rows;  // a . Y <= b  as (a0, a1, a2, b)
    for (const auto& fm : masks)
    {
        const Rect r = boundingRect(fm.second > 127);
        const Camera& cam = rec.camera(fm.first);
        const Matx34d P = cam.projectionMatrix();
        Vec3d pr[3];
        double p4[3];
        for (int i = 0; i < 3; i++)
        {
            const Vec3d row(P(i, 0), P(i, 1), P(i, 2));
            pr[i] = R.t() * row;  // row . X = row . (R Y) = (R^T row) . Y
            p4[i] = P(i, 3);
        }
        const double ulo = r.x - 0.5, uhi = r.x + r.width - 0.5;
        const double vlo = r.y - 0.5, vhi = r.y + r.height - 0.5;
        // u >= ulo  <=>  (p0 - ulo p2) . Y + (p04 - ulo p24) >= 0 (w > 0)
        const double lim[4] = {ulo, uhi, vlo, vhi};
        for (int e = 0; e < 4; e++)
        {
            const int axis = e / 2;
            const Vec3d a = pr[axis] - lim[e] * pr[2];
            const double c = p4[axis] - lim[e] * p4[2];
            if (e % 2 == 0)
                rows.push_back(Vec4d(-a[0], -a[1], -a[2], c));
            else
                rows.push_back(Vec4d(a[0], a[1], a[2], -c));
        }
    }
    // Free variables Y = Y+ - Y-, all >= 0, as cv::solveLP requires.
    Mat A((int)rows.size(), 7, CV_64F);
    for (int i = 0; i < (int)rows.size(); i++)
    {
        double* a = A.ptr<double>(i);
        for (int k = 0; k < 3; k++)
        {
            a[k] = rows[i][k];
            a[k + 3] = -rows[i][k];
        }
        a[6] = rows[i][3];
    }
    Box b;
    b.R = R;
    for (int axis = 0; axis < 3; axis++)
        for (int sgn = -1; sgn <= 1; sgn += 2)
        {
            Mat f = Mat::zeros(1, 6, CV_64F), z;
            f.at<double>(axis) = sgn;
            f.at<double>(axis + 3) = -sgn;
            const int res = solveLP(f, A, z);
            if (res == SOLVELP_UNFEASIBLE)
                CV_Error(Error::StsBadArg, "object '" + object + "': its key-frame silhouettes "
                         "are inconsistent with the cameras (their back-projections do not meet)");
            if (res == SOLVELP_UNBOUNDED)
                CV_Error(Error::StsBadArg, "object '" + object + "': no reconstructed point falls "
                         "in its silhouettes and the key frames do not bound it (need views from "
                         "at least two directions)");
            const double y = z.at<double>(axis) - z.at<double>(axis + 3);
            if (sgn > 0)
                b.hi[axis] = y;
            else
                b.lo[axis] = y;
        }
    b.valid = true;
    return b;
}

// The rectangles' intersection is loose; a coarse visual hull carved against generously dilated
// silhouettes (so that it keeps every coarse voxel the true visual hull touches) bounds the object
// much more tightly, and with it the voxel count at a given resolution.
const int kCoarseVoxelsLongAxis = 64;

Box tightenBySilhouettes(const Box& box, const Reconstruction& rec, const FrameMasks& masks)
{
    const Vec3d ext = box.hi - box.lo;
    const double hc = std::max(ext[0], std::max(ext[1], ext[2])) / kCoarseVoxelsLongAxis;
    if (!(hc > 0))
        return box;
    VoxelGrid g;
    Vec3i dims;
    for (int a = 0; a < 3; a++)
        dims[a] = std::max(1, (int)std::ceil(ext[a] / hc)) + 2;
    g.create(dims, box.R, box.toWorld(box.lo - Vec3d(hc, hc, hc)), hc, 1);
    std::vector<CarveView> views;
    for (const auto& fm : masks)
    {
        const Camera& cam = rec.camera(fm.first);
        double zmin = std::numeric_limits<double>::infinity();
        for (int c = 0; c < 8; c++)
            zmin = std::min(zmin, cam.depth(box.corner(c)));
        const double ppu = cam.model == PERSPECTIVE && zmin > 0 ? cam.pixelsPerUnit(zmin)
                                                                : cam.pixelsPerUnit(1.0);
        // Footprint pixels lie within 2 * (half extent) + 1 of any point of the voxel.
        const int r = 2 * (int)std::ceil(0.87 * hc * ppu) + 2;
        Mat keep;
        dilate(fm.second, keep, getStructuringElement(MORPH_RECT, Size(2 * r + 1, 2 * r + 1)));
        views.push_back(g.carveView(cam, keep));
    }
    g.carve(views);
    Vec3i lo(INT_MAX, INT_MAX, INT_MAX), hi(-1, -1, -1);
    for (int k = 0; k < dims[2]; k++)
        for (int j = 0; j < dims[1]; j++)
            for (int i = 0; i < dims[0]; i++)
                if (g.data[g.index(i, j, k)])
                {
                    lo = Vec3i(std::min(lo[0], i), std::min(lo[1], j), std::min(lo[2], k));
                    hi = Vec3i(std::max(hi[0], i), std::max(hi[1], j), std::max(hi[2], k));
                }
    if (hi[0] < 0)
        return box;  // nothing survived: keep the rectangles' box, carving will tell
    Box t = box;
    const Vec3d o = box.lo - Vec3d(hc, hc, hc);
    for (int a = 0; a < 3; a++)
    {
        t.lo[a] = std::max(box.lo[a], o[a] + hc * (lo[a] - 1));
        t.hi[a] = std::min(box.hi[a], o[a] + hc * (hi[a] + 2));
    }
    return t;
}

// ---------------------------------------------------------------------------------------------
// Step 3: enlargement

// True when the ray meets the box (a line for the orthographic model, a half line else).
bool rayHitsBox(const Box& box, const Ray& ray, bool halfLine)
{
    const Vec3d o = box.toBox(ray.origin), d = box.toBox(ray.direction);
    double t0 = halfLine ? 0.0 : -std::numeric_limits<double>::infinity();
    double t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; a++)
    {
        if (std::abs(d[a]) < 1e-15)
        {
            if (o[a] < box.lo[a] || o[a] > box.hi[a])
                return false;
            continue;
        }
        double ta = (box.lo[a] - o[a]) / d[a], tb = (box.hi[a] - o[a]) / d[a];
        if (ta > tb)
            std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1)
            return false;
    }
    return true;
}

// The paper: corner C of the box nearest the ray, then the point of the ray nearest C joins the
// box. Returns true when the box grew.
bool enlargeForPixel(Box& box, const Camera& cam, const Point2d& px)
{
    const Ray ray = cam.backproject(px);
    const bool half = cam.model == PERSPECTIVE;
    if (rayHitsBox(box, ray, half))
        return false;
    double best = std::numeric_limits<double>::infinity();
    Vec3d bestX;
    for (int c = 0; c < 8; c++)
    {
        const Vec3d C = box.corner(c);
        double t = (C - ray.origin).dot(ray.direction);
        if (half)
            t = std::max(t, 0.0);
        const Vec3d X = ray.at(t);
        const double d = cv::norm(X - C);
        if (d < best)
        {
            best = d;
            bestX = X;
        }
    }
    const Vec3d lo0 = box.lo, hi0 = box.hi;
    box.include(box.toBox(bestX));
    return box.lo != lo0 || box.hi != hi0;
}

// Per key frame: the extreme silhouette points on each edge of its bounding rectangle (eight or
// fewer), the paper's test points.
std::vector<Point> extremeEdgePoints(const Mat& bin)
{
    std::vector<Point> pts;
    const Rect r = boundingRect(bin);
    const int xs[2] = {r.x, r.x + r.width - 1}, ys[2] = {r.y, r.y + r.height - 1};
    for (int e = 0; e < 2; e++)
    {
        // Top and bottom rows: leftmost and rightmost silhouette pixel.
        const uchar* row = bin.ptr<uchar>(ys[e]);
        int a = -1, b = -1;
        for (int x = r.x; x < r.x + r.width; x++)
            if (row[x])
            {
                if (a < 0) a = x;
                b = x;
            }
        if (a >= 0)
        {
            pts.push_back(Point(a, ys[e]));
            if (b != a) pts.push_back(Point(b, ys[e]));
        }
        // Left and right columns: topmost and bottommost.
        a = b = -1;
        for (int y = r.y; y < r.y + r.height; y++)
            if (bin.at<uchar>(y, xs[e]))
            {
                if (a < 0) a = y;
                b = y;
            }
        if (a >= 0)
        {
            pts.push_back(Point(xs[e], a));
            if (b != a) pts.push_back(Point(xs[e], b));
        }
    }
    return pts;
}

// Silhouette pixels the box's projection misses: the vertices of their convex hull.
std::vector<Point> uncoveredHull(const Box& box, const Camera& cam, const Mat& bin)
{
    std::vector<Point> proj;
    const int shift = 8;
    for (int c = 0; c < 8; c++)
    {
        const Point2d p = cam.project(box.corner(c));
        proj.push_back(Point(cvRound(p.x * (1 << shift)), cvRound(p.y * (1 << shift))));
    }
    std::vector<Point> hull;
    convexHull(proj, hull);
    Mat cover(bin.size(), CV_8U, Scalar(0));
    fillConvexPoly(cover, hull, Scalar(255), LINE_8, shift);
    // One pixel of slack: rasterisation and the exact ray test may disagree on the border.
    dilate(cover, cover, Mat());
    Mat miss = bin & ~cover;
    std::vector<Point> pts, out;
    findNonZero(miss, pts);
    if (pts.empty())
        return out;
    convexHull(pts, out);
    return out;
}

void enlargeBox(Box& box, const Reconstruction& rec, const std::map<int, Mat>& bins, int maxIter)
{
    for (int it = 0; it < maxIter; it++)
    {
        bool grew = false;
        for (const auto& fm : bins)
        {
            const Camera& cam = rec.camera(fm.first);
            for (const Point& p : extremeEdgePoints(fm.second))
                grew |= enlargeForPixel(box, cam, Point2d(p));
        }
        // Beyond the eight points: any silhouette part the box still misses (a silhouette may
        // bulge beyond the hull of the eight points).
        for (const auto& fm : bins)
        {
            const Camera& cam = rec.camera(fm.first);
            for (const Point& p : uncoveredHull(box, cam, fm.second))
                grew |= enlargeForPixel(box, cam, Point2d(p));
        }
        if (!grew)
            return;
    }
    CV_LOG_WARNING(NULL, "augocc: box enlargement stopped after maxEnlargeIterations passes");
}

Matx33d orientationFor(const Reconstruction& rec, const std::vector<Vec3d>& pts,
                       const CloneBuilder::BoxParams& p, const Vec3d& up)
{
    if (p.orientation == CloneBuilder::ORIENT_WORLD)
        return Matx33d::eye();
    if (p.orientation == CloneBuilder::ORIENT_USER)
        return rotationFromRodrigues(p.userRotation);
    return autoOrientation(rec, pts, p.trimFraction, p.minPoints, up);
}

} // namespace

void makeGrid(ObjectClone& obj, const Box& box, const PassContext& ctx)
{
    const Reconstruction& rec = ctx.rec;
    const CloneBuilder::Params& params = ctx.params;
    // Voxel edge: voxelPixels pixels in the key frame that sees the box largest.
    double ppu = 0;
    for (const auto& fm : obj.masks)
    {
        const Camera& cam = rec.camera(fm.first);
        double zmin = std::numeric_limits<double>::infinity();
        for (int c = 0; c < 8; c++)
            zmin = std::min(zmin, cam.depth(box.corner(c)));
        if (cam.model == PERSPECTIVE && !(zmin > 0))
            CV_Error(Error::StsBadArg, cv::format("object '%s': its box reaches behind the camera "
                     "of key frame %d", obj.name.c_str(), fm.first));
        ppu = std::max(ppu, cam.pixelsPerUnit(zmin));
    }
    double h = params.voxelPixels / ppu;
    Vec3d ext = box.hi - box.lo;
    Vec3i dims;
    for (int attempt = 0; attempt < 64; attempt++)
    {
        for (int a = 0; a < 3; a++)
            dims[a] = std::max(1, (int)std::ceil(ext[a] / h)) + 2 * kGridMarginVoxels;
        const double total = (double)dims[0] * dims[1] * dims[2];
        const int maxDim = std::max(dims[0], std::max(dims[1], dims[2]));
        double grow = 1.0;
        if (total > (double)params.maxVoxels)
            grow = std::max(grow, std::cbrt(total / (double)params.maxVoxels) * 1.001);
        if (maxDim > kMaxGridDim)
            grow = std::max(grow, (double)maxDim / kMaxGridDim * 1.001);
        if (grow <= 1.0)
            break;
        h *= grow;
    }
    if (h > params.voxelPixels / ppu * 1.0001)
        CV_LOG_INFO(NULL, cv::format("augocc: object '%s': voxel enlarged to %.3g px to respect "
                                     "maxVoxels", obj.name.c_str(), h * ppu));
    // Centre the grid on the box.
    const Vec3d size(dims[0] * h, dims[1] * h, dims[2] * h);
    const Vec3d loBox = 0.5 * (box.lo + box.hi) - 0.5 * size;
    obj.grid.create(dims, box.R, box.toWorld(loBox), h, 1);
}


namespace {

// Steps 1-2 and Step 1's box (before Step 3 enlarges it): obj.points, and the box. A function of
// the inputs alone (the reconstruction, the tracks, every object's silhouettes), so a job that
// builds other objects computes the same box, and the same depth-order centre, as build().
Box initialBox(ObjectClone& obj, const PassContext& ctx)
{
    const CloneBuilder::BoxParams& p = ctx.params.box;
    const Reconstruction& rec = ctx.rec;
    obj.points.clear();
    std::vector<Vec3d> pts = clusterPoints(rec, *ctx.keyFrameMasks, obj.name, ctx.tracks,
                                           ctx.inFrame, &obj.points);
    const Vec3d up = estimateVertical(rec);
    const Matx33d R = orientationFor(rec, pts, p, up);
    Box box;
    if ((int)pts.size() >= p.minPoints)
        box = robustBox(pts, R, p.trimFraction, rec, obj.masks, up, ctx.tracks == nullptr);
    else
    {
        CV_LOG_INFO(NULL, cv::format("augocc: object '%s': %d reconstructed points in its "
                    "silhouettes; box from the silhouettes alone", obj.name.c_str(),
                    (int)pts.size()));
        box = boxFromSilhouettes(rec, obj.masks, R, obj.name);
        box = tightenBySilhouettes(box, rec, obj.masks);
    }
    return box;
}

} // namespace

int64 passCentre(ObjectClone& obj, const PassContext& ctx)
{
    obj.centre = initialBox(obj, ctx).centre();
    obj.points.clear();
    return 0;
}

int64 passBox(ObjectClone& obj, const PassContext& ctx)
{
    const CloneBuilder::BoxParams& p = ctx.params.box;
    const Reconstruction& rec = ctx.rec;
    Box box = initialBox(obj, ctx);
    obj.centre = box.centre();
    enlargeBox(box, rec, obj.masks, p.maxEnlargeIterations);
    obj.box = box;
    makeGrid(obj, box, ctx);
    return (int64)obj.grid.total();
}

} // namespace detail
} // namespace augocc
} // namespace cv
