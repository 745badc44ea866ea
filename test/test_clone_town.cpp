// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_clone_town.hpp"

namespace opencv_test {

namespace {

double planeY(const Vec3d& p, double x, double z)
{
    return p[0] + p[1] * x + p[2] * z;
}

// Twice the signed area of the footprint (> 0: counter-clockwise in (x, z)).
double signedArea2(const std::vector<Point2d>& f)
{
    double a = 0;
    for (size_t i = 0; i < f.size(); i++)
    {
        const Point2d& p = f[i];
        const Point2d& q = f[(i + 1) % f.size()];
        a += p.x * q.y - q.x * p.y;
    }
    return a;
}

} // namespace

std::vector<Vec3d> Prism::corners() const
{
    std::vector<Vec3d> c;
    for (const Point2d& p : footprint)
    {
        c.push_back(Vec3d(p.x, planeY(bottom, p.x, p.y), p.y));
        c.push_back(Vec3d(p.x, planeY(top, p.x, p.y), p.y));
    }
    return c;
}

bool Prism::contains(const Vec3d& X) const
{
    if (X[1] < planeY(bottom, X[0], X[2]) || X[1] > planeY(top, X[0], X[2]))
        return false;
    const double s = signedArea2(footprint) > 0 ? 1 : -1;
    for (size_t i = 0; i < footprint.size(); i++)
    {
        const Point2d& p = footprint[i];
        const Point2d& q = footprint[(i + 1) % footprint.size()];
        if (s * ((q.x - p.x) * (X[2] - p.y) - (q.y - p.y) * (X[0] - p.x)) < 0)
            return false;
    }
    return true;
}

Vec3d TownObject::centre() const
{
    Vec3d lo(1e30, 1e30, 1e30), hi = -lo;
    for (const Prism& p : parts)
        for (const Vec3d& c : p.corners())
            for (int a = 0; a < 3; a++)
            {
                lo[a] = std::min(lo[a], c[a]);
                hi[a] = std::max(hi[a], c[a]);
            }
    return 0.5 * (lo + hi);
}

bool TownObject::contains(const Vec3d& X) const
{
    for (const Prism& p : parts)
        if (p.contains(X))
            return true;
    return false;
}

const TownObject& TownScene::object(const String& name) const
{
    for (const TownObject& o : objects)
        if (o.name == name)
            return o;
    CV_Error(Error::StsBadArg, "no object " + name);
}

Prism cylinderPrism(double x, double z, double r, double y0, double y1)
{
    Prism p;
    const int n = 48;
    for (int i = 0; i < n; i++)
    {
        const double a = 2 * CV_PI * i / n;
        p.footprint.push_back(Point2d(x + r * std::cos(a), z + r * std::sin(a)));
    }
    p.bottom = Vec3d(y0, 0, 0);
    p.top = Vec3d(y1, 0, 0);
    return p;
}

Prism boxPrism(const Vec3d& lo, const Vec3d& hi)
{
    Prism p;
    p.footprint = {Point2d(lo[0], lo[2]), Point2d(hi[0], lo[2]), Point2d(hi[0], hi[2]),
                   Point2d(lo[0], hi[2])};
    p.bottom = Vec3d(lo[1], 0, 0);
    p.top = Vec3d(hi[1], 0, 0);
    return p;
}

namespace {

Mat prismSilhouette(const Prism& p, const Camera& cam, Size size)
{
    std::vector<Point2f> c, hull;
    for (const Vec3d& X : p.corners())
    {
        const Point2d uv = cam.project(X);
        c.push_back(Point2f((float)uv.x, (float)uv.y));
    }
    convexHull(c, hull);
    Mat m(size, CV_8U, Scalar(0));
    const Rect r = boundingRect(hull) & Rect(Point(0, 0), size);
    for (int y = r.y; y < r.y + r.height; y++)
        for (int x = r.x; x < r.x + r.width; x++)
            if (pointPolygonTest(hull, Point2f((float)x, (float)y), false) >= 0)
                m.at<uchar>(y, x) = 255;
    return m;
}

Mat objectSilhouette(const TownObject& o, const Camera& cam, Size size)
{
    Mat m(size, CV_8U, Scalar(0));
    for (const Prism& p : o.parts)
        m |= prismSilhouette(p, cam, size);
    return m;
}

// Surface points of a prism, about `density` per unit area (its faces on the ground left out:
// no camera sees them).
void surfacePoints(const Prism& p, double density, RNG& rng, std::vector<Vec3d>& out)
{
    double xlo = 1e30, xhi = -1e30, zlo = 1e30, zhi = -1e30;
    for (const Point2d& q : p.footprint)
    {
        xlo = std::min(xlo, q.x);
        xhi = std::max(xhi, q.x);
        zlo = std::min(zlo, q.y);
        zhi = std::max(zhi, q.y);
    }
    const double area = 0.5 * std::abs(signedArea2(p.footprint));
    const int nCap = std::max(1, cvRound(area * density));
    for (int face = 0; face < 2; face++)
    {
        const Vec3d& pl = face ? p.top : p.bottom;
        if (!face && pl[0] <= 0 && pl[1] == 0 && pl[2] == 0)
            continue;
        for (int n = 0; n < nCap;)
        {
            const double x = rng.uniform(xlo, xhi), z = rng.uniform(zlo, zhi);
            Prism flat = p;
            flat.bottom = Vec3d(-1e9, 0, 0);
            flat.top = Vec3d(1e9, 0, 0);
            if (!flat.contains(Vec3d(x, 0, z)))
                continue;
            out.push_back(Vec3d(x, planeY(pl, x, z), z));
            n++;
        }
    }
    for (size_t i = 0; i < p.footprint.size(); i++)
    {
        const Point2d& a = p.footprint[i];
        const Point2d& b = p.footprint[(i + 1) % p.footprint.size()];
        const double len = cv::norm(b - a);
        const double hgt = 0.5 * (planeY(p.top, a.x, a.y) - planeY(p.bottom, a.x, a.y) +
                                  planeY(p.top, b.x, b.y) - planeY(p.bottom, b.x, b.y));
        const double expect = len * hgt * density;
        int n = (int)std::floor(expect);
        n += rng.uniform(0.0, 1.0) < expect - n;
        for (int q = 0; q < n; q++)
        {
            const double t = rng.uniform(0.0, 1.0), u = rng.uniform(0.0, 1.0);
            const Point2d s = a + t * (b - a);
            const double y0 = planeY(p.bottom, s.x, s.y), y1 = planeY(p.top, s.x, s.y);
            out.push_back(Vec3d(s.x, y0 + u * (y1 - y0), s.y));
        }
    }
}

// Surface points per unit area: Step 1's points (about 150 on the mushroom tower).
const double kPointDensity = 6.0;

} // namespace

TownScene makeTownScene(CameraModel model, const std::vector<TownObject>& objects,
                        const Vec3d& target, double dist, double ppu, double orbitDeg,
                        int keyStep, int numKeys, Size size)
{
    TownScene s;
    s.objects = objects;
    s.rec.model = model;
    s.rec.imageSize = size;
    const int frames = keyStep * (numKeys - 1) + 1;
    for (int f = 0; f < frames; f++)
    {
        const double az = -orbitDeg / 2 + orbitDeg * f / (frames - 1);
        s.rec.cameras.push_back(orbitCamera(model, az, 25, dist, target, size, ppu, f));
    }
    for (int k = 0; k < numKeys; k++)
        s.keyFrames.push_back(k * keyStep);
    for (int f = 0; f < frames; f++)
    {
        const Camera& cam = s.rec.cameras[f];
        std::vector<std::pair<double, const TownObject*> > order;
        for (const TownObject& o : objects)
            order.push_back(std::make_pair(cam.depth(o.centre()), &o));
        std::sort(order.begin(), order.end(),
                  [](const std::pair<double, const TownObject*>& a,
                     const std::pair<double, const TownObject*>& b) { return a.first < b.first; });
        Mat covered(size, CV_8U, Scalar(0));
        for (const auto& o : order)
        {
            const Mat w = objectSilhouette(*o.second, cam, size);
            s.whole[o.second->name][f] = w;
            if (s.isKey(f))
                s.keyMasks[o.second->name][f] = w & ~covered;
            covered |= w;
        }
    }
    RNG rng(18);
    std::vector<Vec3d> pts;
    for (const TownObject& o : objects)
        for (const Prism& p : o.parts)
        {
            std::vector<Vec3d> q;
            surfacePoints(p, kPointDensity, rng, q);
            // Points inside another part of the object (a stem's top under its cap) are not on
            // its surface.
            for (const Vec3d& X : q)
            {
                bool inner = false;
                for (const Prism& other : o.parts)
                    if (&other != &p && other.contains(X))
                        inner = true;
                if (!inner)
                    pts.push_back(X);
            }
        }
    for (int q = 0; q < 200; q++)
    {
        const Vec3d X(target[0] + rng.uniform(-8.0, 8.0), 0.0, target[2] + rng.uniform(-8.0, 8.0));
        bool under = false;
        for (const TownObject& o : objects)
            under |= o.contains(X + Vec3d(0, 1e-6, 0));
        if (!under)
            pts.push_back(X);
    }
    s.rec.points = Mat((int)pts.size(), 3, CV_64F);
    for (size_t q = 0; q < pts.size(); q++)
        for (int a = 0; a < 3; a++)
            s.rec.points.at<double>((int)q, a) = pts[q][a];
    return s;
}

std::vector<TownObject> mushroomObjects()
{
    // The held-out town's tower (issue 18): stem r 0.55, cap r 1.5.
    TownObject tower{"tower", {cylinderPrism(0, 0, 0.55, 0, 2.4),
                               cylinderPrism(0, 0, 1.5, 2.4, 3.0)}};
    // Between the tower and the last frames' cameras (azimuth +35: direction (0.57, 0, 0.82)).
    TownObject front{"front", {boxPrism(Vec3d(1.2, 0, 2.4), Vec3d(3.2, 1.4, 3.4))}};
    TownObject silo{"silo", {cylinderPrism(-3.8, -1.0, 0.8, 0, 2.6)}};
    return {tower, front, silo};
}

std::vector<TownObject> townObjects()
{
    // Gable roof: two half prisms over the walls, ridge along z at x = 3.5.
    Prism walls = boxPrism(Vec3d(2.5, 0, -3.5), Vec3d(4.5, 1.6, -1.5));
    Prism roofL = boxPrism(Vec3d(2.5, 1.6, -3.5), Vec3d(3.5, 1.6, -1.5));
    roofL.top = Vec3d(1.6 - 0.8 * 2.5, 0.8, 0);  // 1.6 at x 2.5, 2.4 at x 3.5
    Prism roofR = boxPrism(Vec3d(3.5, 1.6, -3.5), Vec3d(4.5, 1.6, -1.5));
    roofR.top = Vec3d(2.4 + 0.8 * 3.5, -0.8, 0);  // 2.4 at x 3.5, 1.6 at x 4.5
    TownObject house{"house", {walls, roofL, roofR}};
    // On ground sloping down to +x (the bottom plane y = -0.25 (x + 3)), roof flat at 2.2.
    Prism slope = boxPrism(Vec3d(-4.2, 0, -2.8), Vec3d(-2.4, 2.2, -1.2));
    slope.bottom = Vec3d(-0.25 * 3.0, -0.25, 0);
    TownObject hillside{"hillside", {slope}};
    // The arch faces the cameras: the hole (x in [-0.7, 0.7], y in [0, 1.5]) shows in every frame.
    TownObject arch{"arch", {boxPrism(Vec3d(-1.3, 0, 1.0), Vec3d(-0.7, 1.5, 1.8)),
                             boxPrism(Vec3d(0.7, 0, 1.0), Vec3d(1.3, 1.5, 1.8)),
                             boxPrism(Vec3d(-1.3, 1.5, 1.0), Vec3d(1.3, 2.1, 1.8))}};
    // A shed roof block at the right edge of the frames: the first frames cut it at the border.
    Prism shed = boxPrism(Vec3d(6.2, 0, 0.5), Vec3d(7.8, 1.2, 2.0));
    shed.top = Vec3d(1.2 + 0.2 * 0.5, 0, -0.2);  // 1.1 at z 0.5, 0.8 at z 2.0
    TownObject border{"border", {shed}};
    return {house, hillside, arch, border};
}

TownFigures measureTown(const CloneSet& clones, const TownScene& s, const String& object)
{
    TownFigures fig;
    int n = 0;
    for (const Camera& cam : s.rec.cameras)
    {
        Mat matte;
        clones.render(object, cam.frame, cam, s.rec.imageSize, matte);
        if (s.isKey(cam.frame))
        {
            const Mat& sil = s.keyMasks.at(object).at(cam.frame);
            Mat nearer(sil.size(), CV_8U, Scalar(0));
            for (const auto& o : s.keyMasks)
                if (o.first != object)
                    nearer |= o.second.at(cam.frame);
            fig.keyMin = std::min(fig.keyMin, maskIoU(matte & ~nearer, sil));
            continue;
        }
        const Mat& whole = s.whole.at(object).at(cam.frame);
        const double iou = maskIoU(matte, whole);
        const double recall =
            (double)countNonZero(matte & whole) / std::max(1, countNonZero(whole));
        fig.nonKeyMean += iou;
        if (iou < fig.nonKeyMin)
        {
            fig.nonKeyMin = iou;
            fig.worstFrame = cam.frame;
        }
        if (recall < fig.recallMin)
        {
            fig.recallMin = recall;
            fig.recallFrame = cam.frame;
        }
        n++;
    }
    fig.nonKeyMean /= std::max(n, 1);
    return fig;
}

} // namespace opencv_test
