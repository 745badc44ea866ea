// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// CloneBuilder: the paper's Section 6, Steps 1-4 (Step 5 and the clone set are in clone_set.cpp).

#include "precomp.hpp"
#include "clone_internal.hpp"
#include "key_frame_coverage.hpp"

#include <climits>
#include <set>

namespace cv {
namespace augocc {

CloneBuilder::Params::Params()
    : voxelPixels(1.0), maxVoxels((int64)1 << 27), maxEnlargeIterations(20),
      orientation(ORIENT_AUTO), userRotation(0, 0, 0), raysPerPixel(2), patchRule(PATCH_NEAREST),
      occlusionAware(true), trimFraction(0.02), minPoints(4), photoThreshold(15),
      photoMinAgreement(0.95), photoMinViews(4), photoRounds(1), photoPatchStep(0),
      photoMaxViews(24), freeSpaceMinViews(2), freeSpaceEdgeMargin(0.5), freeSpacePlanarDeg(30),
      dropUnobserved(true)
{
}

namespace {

using namespace detail;

// Grid margin in voxels around the enlarged box: room for patch voxels just outside it.
const int kGridMarginVoxels = 2;
// Step 2 (auto): the cameras' x axes must span the horizontal plane for the vertical to be their
// common normal: second eigenvalue / largest of their scatter above this (about a 3 degree spread).
const double kMinHorizontalSpread = 1e-3;
// Step 2 (auto): footprint-area search over the rotation about the vertical, in degrees.
const double kAzimuthStepDeg = 1.0;

// An oriented box: axes are the columns of R (world), extent [lo, hi] in box coordinates.
struct Box
{
    Matx33d R = Matx33d::eye();
    Vec3d lo, hi;
    bool valid = false;

    void include(const Vec3d& b)
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
    Vec3d toBox(const Vec3d& X) const { return R.t() * X; }
    Vec3d toWorld(const Vec3d& b) const { return R * b; }
    Vec3d corner(int c) const
    {
        return toWorld(Vec3d(c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]));
    }
    Vec3d centre() const { return toWorld(0.5 * (lo + hi)); }
    //! Box coordinates b clamped into the box.
    Vec3d clamp(const Vec3d& b) const
    {
        Vec3d c;
        for (int a = 0; a < 3; a++)
            c[a] = std::min(std::max(b[a], lo[a]), hi[a]);
        return c;
    }
    //! Distance from world point X to the box (0 inside).
    double distance(const Vec3d& X) const
    {
        const Vec3d b = toBox(X);
        return cv::norm(b - clamp(b));
    }
};

struct ObjectWork
{
    String name;
    const FrameMasks* masks = nullptr;
    std::vector<Vec3d> points;   // Step 1
    Box box;                     // Steps 2-3
    bool fromSilhouettes = false;
};

void checkMask(const Mat& m, const Reconstruction& rec, const String& object, int frame)
{
    const String where = cv::format("masks of object '%s', frame %d", object.c_str(), frame);
    if (m.empty())
        CV_Error(Error::StsBadArg, where + ": empty image");
    if (m.type() != CV_8UC1)
        CV_Error(Error::StsBadArg, where + ": must be 8-bit single channel");
    if (m.size() != rec.imageSize)
        CV_Error(Error::StsBadSize, where + cv::format(": size %dx%d differs from the "
                 "reconstruction's %dx%d", m.cols, m.rows, rec.imageSize.width,
                 rec.imageSize.height));
    if (rec.findCamera(frame) < 0)
        CV_Error(Error::StsBadArg, where + ": the reconstruction has no camera for this frame");
    const int n = countNonZero(m > 127);
    if (n == 0)
        CV_Error(Error::StsBadArg, where + ": the silhouette is empty");
    if (n == (int)m.total())
        CV_Error(Error::StsBadArg, where + ": the silhouette covers the whole frame (all white)");
}

// ---------------------------------------------------------------------------------------------
// Step 1: clustering

// Silhouette evidence of point X for `object`: -1 when a key frame where it is seen puts it outside
// every silhouette of this object and of the others (it cannot be the object's), else the number
// of key frames whose silhouette of this object holds it.
int silhouetteVotes(const Reconstruction& rec, const ObjectMasks& all, const String& object,
                    const Tracks* tracks, int p, const Vec3d& X)
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
        if (!img.contains(px))
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
                                 std::vector<int>* indices = nullptr)
{
    std::vector<Vec3d> out;
    if (rec.points.empty())
        return out;
    const int P = rec.points.rows;
    for (int p = 0; p < P; p++)
    {
        const double* q = rec.points.ptr<double>(p);
        if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
            continue;
        const Vec3d X(q[0], q[1], q[2]);
        const int mine = silhouetteVotes(rec, all, object, tracks, p, X);
        if (mine <= 0)
            continue;
        bool best = true;
        for (const auto& other : all)
            if (other.first != object &&
                silhouetteVotes(rec, all, other.first, tracks, p, X) > mine)
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

Box robustBox(const std::vector<Vec3d>& pts, const Matx33d& R, double trim)
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
    b.valid = true;
    return b;
}

// ---------------------------------------------------------------------------------------------
// Step 2: orientation

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
                        int minPoints)
{
    const Vec3d up = estimateVertical(rec);
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

// ---------------------------------------------------------------------------------------------

class CloneBuilderImpl CV_FINAL : public CloneBuilder
{
public:
    explicit CloneBuilderImpl(const Params& p) { setParams(p); }

    Params getParams() const CV_OVERRIDE { return params_; }

    void setParams(const Params& p) CV_OVERRIDE
    {
        if (!(p.voxelPixels > 0) || !std::isfinite(p.voxelPixels))
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::voxelPixels must be positive");
        if (p.maxVoxels < 8)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::maxVoxels must be at least 8");
        if (p.maxEnlargeIterations < 1)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::maxEnlargeIterations must be >= 1");
        if (p.orientation < ORIENT_AUTO || p.orientation > ORIENT_USER)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::orientation is not an Orientation");
        if (p.raysPerPixel < 1 || p.raysPerPixel > 8)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::raysPerPixel must be in [1, 8]");
        if (p.patchRule != PATCH_NEAREST && p.patchRule != PATCH_BRACKETING)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::patchRule is not a PatchRule");
        if (!(p.trimFraction >= 0 && p.trimFraction < 0.5))
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::trimFraction must be in [0, 0.5)");
        if (p.minPoints < 1)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::minPoints must be >= 1");
        if (!(p.photoThreshold >= 0 && p.photoThreshold <= 255))
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::photoThreshold must be in [0, 255]");
        if (!(p.photoMinAgreement > 0 && p.photoMinAgreement <= 1))
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::photoMinAgreement must be in (0, 1]");
        if (p.photoMinViews < 2)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::photoMinViews must be >= 2");
        if (p.photoRounds < 1)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::photoRounds must be >= 1");
        if (p.photoPatchStep < 0 || p.photoPatchStep > 8)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::photoPatchStep must be in [0, 8]");
        if (p.photoMaxViews < 0 || (p.photoMaxViews > 0 && p.photoMaxViews < p.photoMinViews))
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::photoMaxViews must be 0 (every "
                     "frame) or at least photoMinViews");
        if (p.freeSpaceMinViews < 0)
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::freeSpaceMinViews must be >= 0");
        if (!(p.freeSpaceEdgeMargin >= 0) || !std::isfinite(p.freeSpaceEdgeMargin))
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::freeSpaceEdgeMargin must be >= 0");
        if (!(p.freeSpacePlanarDeg >= 0 && p.freeSpacePlanarDeg <= 90))
            CV_Error(Error::StsBadArg, "CloneBuilder::Params::freeSpacePlanarDeg must be in [0, 90]");
        params_ = p;
    }

    Ptr<CloneSet> build(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                        const Tracks* tracks) const CV_OVERRIDE;
    void addKeyFrame(CloneSet& clones, const Reconstruction& rec, const String& object,
                     int frame, InputArray mask) const CV_OVERRIDE;
    int64 refine(CloneSet& clones, const Reconstruction& rec,
                 InputArrayOfArrays frames) const CV_OVERRIDE;

private:
    Matx33d orientationFor(const Reconstruction& rec, const std::vector<Vec3d>& pts) const
    {
        if (params_.orientation == ORIENT_WORLD)
            return Matx33d::eye();
        if (params_.orientation == ORIENT_USER)
            return rotationFromRodrigues(params_.userRotation);
        return autoOrientation(rec, pts, params_.trimFraction, params_.minPoints);
    }

    void makeGrid(ObjectClone& obj, const Box& box, const Reconstruction& rec) const;

    Params params_;
};

void CloneBuilderImpl::makeGrid(ObjectClone& obj, const Box& box, const Reconstruction& rec) const
{
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
    double h = params_.voxelPixels / ppu;
    Vec3d ext = box.hi - box.lo;
    Vec3i dims;
    for (int attempt = 0; attempt < 64; attempt++)
    {
        for (int a = 0; a < 3; a++)
            dims[a] = std::max(1, (int)std::ceil(ext[a] / h)) + 2 * kGridMarginVoxels;
        const double total = (double)dims[0] * dims[1] * dims[2];
        const int maxDim = std::max(dims[0], std::max(dims[1], dims[2]));
        double grow = 1.0;
        if (total > (double)params_.maxVoxels)
            grow = std::max(grow, std::cbrt(total / (double)params_.maxVoxels) * 1.001);
        if (maxDim > kMaxGridDim)
            grow = std::max(grow, (double)maxDim / kMaxGridDim * 1.001);
        if (grow <= 1.0)
            break;
        h *= grow;
    }
    if (h > params_.voxelPixels / ppu * 1.0001)
        CV_LOG_INFO(NULL, cv::format("augocc: object '%s': voxel enlarged to %.3g px to respect "
                                     "maxVoxels", obj.name.c_str(), h * ppu));
    // Centre the grid on the box.
    const Vec3d size(dims[0] * h, dims[1] * h, dims[2] * h);
    const Vec3d loBox = 0.5 * (box.lo + box.hi) - 0.5 * size;
    obj.grid.create(dims, box.R, box.toWorld(loBox), h, 1);
}

// Unknown pixels of `object` in `frame`: silhouettes of the other objects nearer the camera.
Mat unknownMask(const std::map<String, ObjectClone>& objs, const String& object, int frame,
                const Camera& cam, Size size)
{
    Mat unknown(size, CV_8U, Scalar(0));
    const double z = cam.depth(objs.at(object).centre);
    for (const auto& o : objs)
    {
        if (o.first == object)
            continue;
        auto it = o.second.masks.find(frame);
        if (it == o.second.masks.end())
            continue;
        if (cam.depth(o.second.centre) < z)
            unknown |= it->second;
    }
    return unknown;
}

// Beyond Step 4, for objects hidden in part: a voxel that no key frame shows as the object (its
// centre's pixel is in no key-frame silhouette of the object: unknown under nearer objects, or
// off the image, in every key frame) has no evidence for it; silhouettes cannot carve it, so it
// is the part of the box hidden in every key frame, pure conjecture. It goes. Measured on the
// synthesized scene (GT cameras, 6 key frames): whole-silhouette IoU in non-key frames of the
// tower 0.914 -> 0.959 (orthographic), of the L-block 0.958 -> 0.979 (perspective), recall of the
// whole silhouettes unchanged (>= 0.997); dropping only the components not connected to a seen
// voxel kept the first two at 0.914 / 0.958. It also keeps conjectured volume from hiding
// virtual objects placed behind the nearer object. Returns the number removed.
int64 dropUnseenVoxels(ObjectClone& obj, const Reconstruction& rec)
{
    VoxelGrid& g = obj.grid;
    const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
    std::vector<VoxelProjector> projs;
    std::vector<const Mat*> masks;
    for (const auto& fm : obj.masks)
    {
        projs.push_back(g.projector(rec.camera(fm.first), fm.second.size()));
        masks.push_back(&fm.second);
    }
    // Seeds: voxels some key frame shows (marked 2).
    const uchar kSeen = 2;
    parallel_for_(Range(0, nz), [&](const Range& r) {
        for (int k = r.start; k < r.end; k++)
            for (int j = 0; j < ny; j++)
            {
                uchar* row = &g.data[g.index(0, j, k)];
                for (int i = 0; i < nx; i++)
                {
                    if (!row[i])
                        continue;
                    for (size_t q = 0; q < projs.size(); q++)
                    {
                        Point px;
                        if (!projs[q].centrePixel(i, j, k, px))
                            continue;
                        if (px.x >= 0 && px.y >= 0 && px.x < masks[q]->cols &&
                            px.y < masks[q]->rows && masks[q]->at<uchar>(px) > 127)
                        {
                            row[i] = kSeen;
                            break;
                        }
                    }
                }
            }
    });
    if (std::find(g.data.begin(), g.data.end(), kSeen) == g.data.end())
    {
        // Nothing seen at all (silhouettes thinner than the voxel spacing): no evidence either
        // way, keep the clone as carved.
        for (uchar& v : g.data)
            v = v ? 1 : 0;
        return 0;
    }
    int64 dropped = 0;
    for (uchar& v : g.data)
    {
        dropped += v == 1;
        v = v == kSeen ? 1 : 0;
    }
    return dropped;
}

// Step 4 with the key frames `carveFrames`: carving, the unseen voxels, the surface (the patches
// are the caller's: Step 5 comes once every carve is done).
void carveObject(std::map<String, ObjectClone>& objs, ObjectClone& obj,
                 const Reconstruction& rec, const std::vector<int>& carveFrames,
                 bool occlusionAware)
{
    std::vector<CarveView> views(carveFrames.size());
    parallel_for_(Range(0, (int)carveFrames.size()), [&](const Range& r) {
        for (int q = r.start; q < r.end; q++)
        {
            const int f = carveFrames[q];
            const Camera& cam = rec.camera(f);
            Mat keep = obj.masks.at(f).clone();
            if (occlusionAware)
                keep |= unknownMask(objs, obj.name, f, cam, keep.size());
            views[q] = obj.grid.carveView(cam, keep);
        }
    });
    obj.grid.carve(views);
    if (occlusionAware)
    {
        const int64 d = dropUnseenVoxels(obj, rec);
        if (d > 0)
        {
            CV_LOG_DEBUG(NULL, cv::format("augocc: object '%s': %lld voxels no key frame shows, "
                         "apart from the seen ones, removed", obj.name.c_str(), (long long)d));
        }
    }
    obj.surface = obj.grid.surface();
}

// Beyond Step 3: the box must hold the visual hull where the key frames need it. Step 3 makes
// every silhouette pixel's ray touch the box, but the other key frames' cones may meet that ray
// only outside it: the box then cuts the object (a side facade seen in the last key frames only,
// with few tracks to place Step 1's box; a cap wider than its points suggest), and in that key
// frame patch voxels alone cover the cut, which the other frames miss. For the silhouette pixels
// more than kGrowDeepPx inside the outline that the carved clone leaves uncovered, each ray is
// walked (half-voxel steps, up to kGrowReach box diagonals beyond the box) for the point outside
// the box nearest to it that every other key frame shows in its silhouette. Positive evidence
// only, unlike carving: pixels unknown under a nearer object or off the image do not count (a
// mask with a wrong blob would otherwise grow a phantom behind the other objects, and a
// turntable's views would grow the box into space half of them do not see). Returns those
// points; none when nothing is found (the cameras or the masks disagree: Step 5's warning names
// the key frame).
const float kGrowDeepPx = 3.f;
// Uncovered deep pixels below this fraction of a silhouette are left alone (round-off).
const double kGrowMinFraction = 0.002;
// At most this many rays per key frame (evenly strided over its uncovered deep pixels).
const int kGrowMaxRays = 4000;
// The walk reaches this many box diagonals beyond the box's extent along the ray.
const double kGrowReach = 0.5;
// Candidates per ray whose path to the box is checked, nearest first.
const int kGrowMaxCandidates = 8;

std::vector<Vec3d> hullPointsOutsideBox(const Box& box, const ObjectClone& obj,
                                        const Reconstruction& rec)
{
    const VoxelGrid& g = obj.grid;
    std::vector<int> keys;
    std::vector<const Mat*> sils;
    for (const auto& m : obj.masks)
    {
        keys.push_back(m.first);
        sils.push_back(&m.second);
    }
    const double diag = cv::norm(box.hi - box.lo);
    const double step = 0.5 * g.h;
    // X projects in front of every key frame's camera, into its image and its silhouette (key
    // frame `skip` aside).
    auto inSilhouettes = [&](const Vec3d& X, int skip) {
        for (size_t o = 0; o < keys.size(); o++)
        {
            if ((int)o == skip)
                continue;
            const Camera& c2 = rec.camera(keys[o]);
            if (c2.model == PERSPECTIVE && !(c2.depth(X) > 0))
                return false;
            const Point2d p = c2.project(X);
            const Point ip(cvRound(p.x), cvRound(p.y));
            if (ip.x < 0 || ip.y < 0 || ip.x >= sils[o]->cols || ip.y >= sils[o]->rows ||
                !sils[o]->at<uchar>(ip))
                return false;
        }
        return true;
    };
    std::vector<std::vector<Vec3d> > found(keys.size());
    parallel_for_(Range(0, (int)keys.size()), [&](const Range& r) {
        for (int q = r.start; q < r.end; q++)
        {
            const Camera& cam = rec.camera(keys[q]);
            const Mat& sil = *sils[q];
            // Over the silhouette's bounding box (and a ring, so that the outline's distance is
            // right at the box's border).
            const Rect roi = Rect(boundingRect(sil) + Size(2, 2) - Point(1, 1)) &
                             Rect(Point(), sil.size());
            const VoxelProjector proj = g.projector(cam, sil.size());
            Mat zmin(roi.size(), CV_32F, Scalar(std::numeric_limits<float>::infinity()));
            splatVoxels(proj, obj.surface.ijk.data(), obj.surface.faces.data(),
                        obj.surface.size(), true, zmin, nullptr, roi.tl());
            Mat inside;
            distanceTransform(sil(roi), inside, DIST_L2, 3);
            std::vector<Point> deep;
            for (int y = 0; y < roi.height; y++)
            {
                const float* d = inside.ptr<float>(y);
                const float* z = zmin.ptr<float>(y);
                for (int x = 0; x < roi.width; x++)
                    if (d[x] > kGrowDeepPx && z[x] == std::numeric_limits<float>::infinity())
                        deep.push_back(roi.tl() + Point(x, y));
            }
            if ((double)deep.size() <= kGrowMinFraction * countNonZero(sil(roi)))
                continue;
            const size_t stride = (deep.size() + kGrowMaxRays - 1) / kGrowMaxRays;
            for (size_t d = 0; d < deep.size(); d += stride)
            {
                const Ray ray = cam.backproject(Point2d(deep[d]));
                double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
                for (int c = 0; c < 8; c++)
                {
                    const double t = (box.corner(c) - ray.origin).dot(ray.direction);
                    t0 = std::min(t0, t);
                    t1 = std::max(t1, t);
                }
                t0 -= kGrowReach * diag;
                t1 += kGrowReach * diag;
                if (cam.model == PERSPECTIVE)
                    t0 = std::max(t0, step);
                // Hull samples outside the box, nearest to it first.
                std::vector<std::pair<double, Vec3d> > cand;
                for (double t = t0; t <= t1; t += step)
                {
                    const Vec3d X = ray.at(t);
                    const double dist = box.distance(X);
                    if (dist > 0 && dist < kGrowReach * diag && inSilhouettes(X, (int)q))
                        cand.push_back(std::make_pair(dist, X));
                }
                std::stable_sort(cand.begin(), cand.end(),
                                 [](const std::pair<double, Vec3d>& u,
                                    const std::pair<double, Vec3d>& v) { return u.first < v.first; });
                // The first whose straight path to the box stays in every silhouette (this key
                // frame's too): the hull crosses the box's face there. A ghost of the visual hull
                // (or a wrong blob in a mask) beyond a gap is not taken.
                for (size_t c = 0; c < cand.size() && c < (size_t)kGrowMaxCandidates; c++)
                {
                    const Vec3d X = cand[c].second;
                    const Vec3d B = box.toWorld(box.clamp(box.toBox(X)));
                    const int n = (int)std::ceil(cv::norm(X - B) / step);
                    bool connected = true;
                    for (int k = 1; k < n && connected; k++)
                        connected = inSilhouettes(X + (B - X) * ((double)k / n), -1);
                    if (connected)
                    {
                        found[q].push_back(X);
                        break;
                    }
                }
            }
        }
    });
    std::vector<Vec3d> all;
    for (const std::vector<Vec3d>& f : found)
        all.insert(all.end(), f.begin(), f.end());
    return all;
}

// After the grid grew to hold `points`: outside `box` (and its grid margin) only the voxels next
// to those points stay, so that the larger grid does not free the rest of the visual hull beyond
// the old faces (wedges no key frame can carve: behind other objects, under the ground).
void keepOutsideBoxNear(ObjectClone& obj, const Box& box, const std::vector<Vec3d>& points)
{
    VoxelGrid& g = obj.grid;
    std::vector<uchar> near(g.data.size(), 0);
    for (const Vec3d& X : points)
    {
        const Vec3d v = g.toVoxel(X);
        const int i0 = cvRound(v[0]), j0 = cvRound(v[1]), k0 = cvRound(v[2]);
        for (int k = k0 - 1; k <= k0 + 1; k++)
            for (int j = j0 - 1; j <= j0 + 1; j++)
                for (int i = i0 - 1; i <= i0 + 1; i++)
                    if (g.inside(i, j, k))
                        near[g.index(i, j, k)] = 1;
    }
    const double margin = kGridMarginVoxels * g.h;
    parallel_for_(Range(0, g.dims[2]), [&](const Range& r) {
        for (int k = r.start; k < r.end; k++)
            for (int j = 0; j < g.dims[1]; j++)
                for (int i = 0; i < g.dims[0]; i++)
                {
                    const size_t idx = g.index(i, j, k);
                    if (!g.data[idx] || near[idx])
                        continue;
                    const Vec3d b = box.toBox(g.centre(i, j, k));
                    bool in = true;
                    for (int a = 0; a < 3 && in; a++)
                        in = b[a] >= box.lo[a] - margin && b[a] <= box.hi[a] + margin;
                    if (!in)
                        g.data[idx] = 0;
                }
    });
    obj.surface = g.surface();
}

// Beyond the paper, for what no frame can see. A part of the visual hull that is behind another
// object or behind the object's own near side in every frame of the video (the lower back of a
// tower behind a building in the first key frames and behind its own shaft in the last) is not
// constrained by any silhouette: the hull keeps it at its largest, a wedge along the lines of
// sight of the key frames that see the part. Since no frame sees it, it changes no composite of
// the video; but it is conjecture, and in the object's matte as if alone (and in any view beyond
// the video) it shows as a bulge. The prior taken here is support along the vertical: the clone's
// voxels are cut into vertical runs (the grid axis nearest the vertical the cameras give), and a
// run none of whose voxels any frame shows (first along its line of sight among every clone's
// voxels, in kObservableViews evenly spaced frames and every key frame) goes. The inside of a
// building under its seen roof, the hidden back of a shaft under its seen cap, stay (their run
// holds a seen voxel); a wedge with air above it and the ground below goes. Returns the number of
// voxels removed per object.
const int kObservableViews = 30;
// A surface voxel is seen when its centre is within this many voxel edges of the nearest clone
// depth at its pixel.
const double kObservableTolVoxels = 1.5;
// The vertical must be within this angle of a grid axis for the runs to follow it (degrees).
const double kMaxRunTiltDeg = 20;

std::map<String, int64> dropUnobservedRuns(std::map<String, ObjectClone>& objs,
                                           const Reconstruction& rec)
{
    std::map<String, int64> removed;
    std::vector<const Camera*> cams = evenlySpacedCameras(rec, kObservableViews);
    std::set<int> have;
    for (const Camera* c : cams)
        have.insert(c->frame);
    for (const auto& o : objs)
        for (const auto& m : o.second.masks)
            if (!have.count(m.first))
            {
                have.insert(m.first);
                cams.push_back(&rec.camera(m.first));
            }
    std::vector<String> names;
    for (const auto& o : objs)
        names.push_back(o.first);
    // Per frame and object, the surface voxels seen (frames in parallel, merged in order).
    std::vector<std::vector<std::vector<uint32_t> > > seenIn(
        cams.size(), std::vector<std::vector<uint32_t> >(names.size()));
    const Size size = rec.imageSize;
    parallel_for_(Range(0, (int)cams.size()), [&](const Range& r) {
        for (int ci = r.start; ci < r.end; ci++)
        {
            const Camera& cam = *cams[ci];
            Mat zbuf(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
            std::vector<VoxelProjector> projs(names.size());
            for (size_t n = 0; n < names.size(); n++)
            {
                const ObjectClone& obj = objs.at(names[n]);
                if (obj.grid.empty())
                    continue;
                projs[n] = obj.grid.projector(cam, size);
                splatVoxels(projs[n], obj.surface.ijk.data(), obj.surface.faces.data(),
                            obj.surface.size(), true, zbuf, nullptr, Point());
            }
            for (size_t n = 0; n < names.size(); n++)
            {
                const ObjectClone& obj = objs.at(names[n]);
                if (obj.grid.empty())
                    continue;
                const double tol = kObservableTolVoxels * obj.grid.h;
                for (size_t q = 0; q < obj.surface.size(); q++)
                {
                    int i, j, k;
                    unpackVoxel(obj.surface.ijk[q], i, j, k);
                    Point px;
                    if (!projs[n].centrePixel(i, j, k, px) || px.x < 0 || px.y < 0 ||
                        px.x >= size.width || px.y >= size.height)
                        continue;
                    const double z = projs[n].Z.dot(Vec3d(i, j, k)) + projs[n].z0;
                    if (z <= zbuf.at<float>(px) + tol)
                        seenIn[ci][n].push_back((uint32_t)q);
                }
            }
        }
    });
    const Vec3d up = estimateVertical(rec);
    for (size_t n = 0; n < names.size(); n++)
    {
        ObjectClone& obj = objs.at(names[n]);
        VoxelGrid& g = obj.grid;
        int64& count = removed[names[n]];
        count = 0;
        if (g.empty())
            continue;
        int axis = 0;
        double best = 0;
        for (int a = 0; a < 3; a++)
        {
            const double c = std::abs(up.dot(Vec3d(g.Rbox(0, a), g.Rbox(1, a), g.Rbox(2, a))));
            if (c > best)
            {
                best = c;
                axis = a;
            }
        }
        if (best < std::cos(kMaxRunTiltDeg * CV_PI / 180))
            continue;
        std::vector<uchar> sn(g.data.size(), 0);
        for (size_t ci = 0; ci < cams.size(); ci++)
            for (uint32_t q : seenIn[ci][n])
            {
                int i, j, k;
                unpackVoxel(obj.surface.ijk[q], i, j, k);
                sn[g.index(i, j, k)] = 1;
            }
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        std::vector<int64> perSlice(g.dims[v], 0);
        parallel_for_(Range(0, g.dims[v]), [&](const Range& r) {
            for (int b = r.start; b < r.end; b++)
                for (int a = 0; a < g.dims[u]; a++)
                {
                    int idx[3];
                    idx[u] = a;
                    idx[v] = b;
                    int start = -1;
                    bool any = false;
                    for (int t = 0; t <= g.dims[axis]; t++)
                    {
                        bool in = false;
                        size_t id = 0;
                        if (t < g.dims[axis])
                        {
                            idx[axis] = t;
                            id = g.index(idx[0], idx[1], idx[2]);
                            in = g.data[id] != 0;
                        }
                        if (in)
                        {
                            if (start < 0)
                            {
                                start = t;
                                any = false;
                            }
                            any = any || sn[id];
                            continue;
                        }
                        if (start >= 0 && !any)
                            for (int w = start; w < t; w++)
                            {
                                idx[axis] = w;
                                g.data[g.index(idx[0], idx[1], idx[2])] = 0;
                                perSlice[b]++;
                            }
                        start = -1;
                    }
                }
        });
        for (int64 c : perSlice)
            count += c;
        if (count > 0)
            obj.surface = g.surface();
    }
    return removed;
}

// Step 5 for every key frame (the clone changed, so every patch set is redone).
void recomputePatches(std::map<String, ObjectClone>& objs, ObjectClone& obj,
                      const Reconstruction& rec, bool occlusionAware, int raysPerPixel)
{
    std::vector<int> keys;
    for (const auto& m : obj.masks)
        keys.push_back(m.first);
    std::vector<std::vector<uint32_t> > patches(keys.size());
    parallel_for_(Range(0, (int)keys.size()), [&](const Range& r) {
        for (int q = r.start; q < r.end; q++)
        {
            const int f = keys[q];
            const Camera& cam = rec.camera(f);
            const Mat& sil = obj.masks.at(f);
            Mat keep = sil.clone();
            if (occlusionAware)
                keep |= unknownMask(objs, obj.name, f, cam, keep.size());
            patches[q] = computePatches(obj, cam, sil, keep, raysPerPixel);
        }
    });
    obj.patches.clear();
    for (size_t q = 0; q < keys.size(); q++)
        obj.patches[keys[q]] = std::move(patches[q]);
}

Ptr<CloneSet> CloneBuilderImpl::build(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                                      const Tracks* tracks) const
{
    if (keyFrameMasks.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::build: no object masks");
    if (rec.imageSize.width <= 0 || rec.imageSize.height <= 0)
        CV_Error(Error::StsBadSize, "CloneBuilder::build: the reconstruction has no image size");
    if (tracks && !rec.points.empty() && tracks->points() != rec.points.rows)
        CV_Error(Error::StsBadSize, cv::format("CloneBuilder::build: tracks have %d columns, the "
                 "reconstruction %d points", tracks->points(), rec.points.rows));
    if (!rec.points.empty() && (rec.points.cols != 3 || rec.points.type() != CV_64FC1))
        CV_Error(Error::StsBadArg, "CloneBuilder::build: reconstruction points must be Nx3 CV_64F");
    ObjectMasks bins;
    for (const auto& o : keyFrameMasks)
    {
        if (o.second.empty())
            CV_Error(Error::StsBadArg, "CloneBuilder::build: object '" + o.first +
                     "' has no key frame");
        for (const auto& fm : o.second)
        {
            checkMask(fm.second, rec, o.first, fm.first);
            bins[o.first][fm.first] = fm.second > 127;
        }
    }

    Ptr<CloneSetImpl> set = makePtr<CloneSetImpl>();
    set->patchRule = params_.patchRule;
    // Steps 1-3 per object.
    std::map<String, std::vector<int> > members;
    std::map<String, Box> boxes;
    for (const auto& o : bins)
    {
        std::vector<Vec3d> pts = clusterPoints(rec, bins, o.first, tracks, &members[o.first]);
        const Matx33d R = orientationFor(rec, pts);
        Box box;
        Vec3d centre;
        if ((int)pts.size() >= params_.minPoints)
        {
            box = robustBox(pts, R, params_.trimFraction);
            centre = box.centre();
        }
        else
        {
            CV_LOG_INFO(NULL, cv::format("augocc: object '%s': %d reconstructed points in its "
                        "silhouettes; box from the silhouettes alone", o.first.c_str(),
                        (int)pts.size()));
            box = boxFromSilhouettes(rec, o.second, R, o.first);
            box = tightenBySilhouettes(box, rec, o.second);
            centre = box.centre();
        }
        enlargeBox(box, rec, o.second, params_.maxEnlargeIterations);
        boxes[o.first] = box;
        ObjectClone& obj = set->objects[o.first];
        obj.name = o.first;
        obj.centre = centre;
        obj.masks = o.second;
        for (auto& m : obj.masks)
            m.second = m.second.clone();
        makeGrid(obj, box, rec);
    }
    // Step 4 per object (unknown pixels need every object's centre).
    for (auto& o : set->objects)
    {
        std::vector<int> frames;
        for (const auto& m : o.second.masks)
            frames.push_back(m.first);
        carveObject(set->objects, o.second, rec, frames, params_.occlusionAware);
        const Box& box0 = boxes.at(o.first);
        const std::vector<Vec3d> extra =
            hullPointsOutsideBox(box0, o.second, rec);
        if (!extra.empty())
        {
            Box box = box0;
            for (const Vec3d& X : extra)
            {
                const Vec3d b = box.toBox(X);
                box.include(b - Vec3d::all(o.second.grid.h));
                box.include(b + Vec3d::all(o.second.grid.h));
            }
            CV_LOG_INFO(NULL, cv::format("augocc: object '%s': grid grown to hold the visual "
                        "hull %d key-frame rays need beyond the box", o.first.c_str(),
                        (int)extra.size()));
            makeGrid(o.second, box, rec);
            carveObject(set->objects, o.second, rec, frames, params_.occlusionAware);
            keepOutsideBoxNear(o.second, box0, extra);
        }
    }
    // Beyond the paper: the free space the tracks show.
    if (tracks && params_.freeSpaceMinViews > 0)
    {
        FreeSpaceParams fp;
        fp.minViews = params_.freeSpaceMinViews;
        fp.edgeMargin = params_.freeSpaceEdgeMargin;
        fp.planarDeg = params_.freeSpacePlanarDeg;
        for (const auto& c : freeSpaceCarve(*set, rec, *tracks, members, fp))
        {
            CV_UNUSED(c);  // with the debug log compiled out
            CV_LOG_DEBUG(NULL, cv::format("augocc: object '%s': %lld voxels carved by free space",
                         c.first.c_str(), (long long)c.second));
        }
    }
    // Beyond the paper: what no frame sees.
    if (params_.dropUnobserved)
        for (const auto& c : dropUnobservedRuns(set->objects, rec))
        {
            CV_UNUSED(c);  // with the debug log compiled out
            CV_LOG_DEBUG(NULL, cv::format("augocc: object '%s': %lld voxels in vertical runs no "
                         "frame sees removed", c.first.c_str(), (long long)c.second));
        }
    // Step 5 per object.
    for (auto& o : set->objects)
        recomputePatches(set->objects, o.second, rec, params_.occlusionAware,
                         params_.raysPerPixel);
    return set;
}

void CloneBuilderImpl::addKeyFrame(CloneSet& clones, const Reconstruction& rec,
                                   const String& object, int frame, InputArray mask) const
{
    CloneSetImpl* set = dynamic_cast<CloneSetImpl*>(&clones);
    if (!set)
        CV_Error(Error::StsBadArg, "addKeyFrame: the clone set was not made by CloneBuilder or "
                 "CloneSet::load");
    ObjectClone& obj = set->get(object);
    Mat m = mask.getMat();
    checkMask(m, rec, object, frame);
    obj.masks[frame] = m > 127;
    carveObject(set->objects, obj, rec, std::vector<int>(1, frame), params_.occlusionAware);
    recomputePatches(set->objects, obj, rec, params_.occlusionAware, params_.raysPerPixel);
}

int64 CloneBuilderImpl::refine(CloneSet& clones, const Reconstruction& rec,
                               InputArrayOfArrays framesArr) const
{
    CloneSetImpl* set = dynamic_cast<CloneSetImpl*>(&clones);
    if (!set)
        CV_Error(Error::StsBadArg, "CloneBuilder::refine: the clone set was not made by "
                 "CloneBuilder or CloneSet::load");
    if (rec.cameras.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::refine: the reconstruction has no camera");
    if (framesArr.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::refine: no frames");
    if (!framesArr.isMatVector() && !framesArr.isUMatVector())
        CV_Error(Error::StsBadArg, "CloneBuilder::refine: frames must be a vector of images");
    const int nframes = (int)framesArr.total();
    std::vector<Mat> frames(nframes);
    for (const Camera& cam : rec.cameras)
    {
        const int f = cam.frame;
        if (f < 0 || f >= nframes)
            CV_Error(Error::StsBadArg, cv::format("CloneBuilder::refine: the reconstruction has a "
                     "camera for frame %d but %d frames are given", f, nframes));
        Mat m = framesArr.getMat(f);
        if (m.empty())
            CV_Error(Error::StsBadArg, cv::format("CloneBuilder::refine: frame %d is empty", f));
        if (m.size() != rec.imageSize)
            CV_Error(Error::StsBadSize, cv::format("CloneBuilder::refine: frame %d is %dx%d, the "
                     "reconstruction's image size %dx%d", f, m.cols, m.rows,
                     rec.imageSize.width, rec.imageSize.height));
        if (m.type() == CV_8UC1)
            cvtColor(m, frames[f], COLOR_GRAY2BGR);
        else if (m.type() == CV_8UC3)
            frames[f] = m;
        else
            CV_Error(Error::StsUnsupportedFormat, cv::format("CloneBuilder::refine: frame %d "
                     "must be CV_8UC3 or CV_8UC1", f));
    }
    for (const auto& o : set->objects)
        for (const auto& m : o.second.masks)
            if (m.second.size() != rec.imageSize)
                CV_Error(Error::StsBadSize, cv::format("CloneBuilder::refine: object '%s': key "
                         "frame %d's silhouette differs from the reconstruction's image size",
                         o.first.c_str(), m.first));
            else if (rec.findCamera(m.first) < 0)
                CV_Error(Error::StsBadArg, cv::format("CloneBuilder::refine: object '%s': key "
                         "frame %d has no camera", o.first.c_str(), m.first));
    PhotoCarveParams pp;
    pp.threshold = params_.photoThreshold;
    pp.minAgreement = params_.photoMinAgreement;
    pp.minViews = params_.photoMinViews;
    pp.rounds = params_.photoRounds;
    pp.patchStep = params_.photoPatchStep;
    pp.maxViews = params_.photoMaxViews;
    const std::map<String, int64> carved = photoCarve(*set, rec, frames, pp);
    int64 total = 0;
    for (const auto& c : carved)
    {
        total += c.second;
        if (c.second > 0)
            recomputePatches(set->objects, set->get(c.first), rec, params_.occlusionAware,
                             params_.raysPerPixel);
    }
    return total;
}

} // namespace

Ptr<CloneBuilder> CloneBuilder::create(const Params& params)
{
    return makePtr<CloneBuilderImpl>(params);
}

Ptr<CloneBuilder> CloneBuilder::create()
{
    return makePtr<CloneBuilderImpl>(Params());
}

} // namespace augocc
} // namespace cv
