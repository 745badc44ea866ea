// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Shadow maps of the sun (shadow.hpp): layout on a fixed light-space lattice, OSMesa depth
// render, percentage-closer filtered visibility, and surface points / normals from a depth map.

#include "precomp.hpp"
#include "shadow.hpp"
#include "gl_context.hpp"

#include <opencv2/core/utils/logger.hpp>
#include <GL/gl.h>

namespace cv {
namespace augocc {
namespace detail {

namespace {

const int kPad = Sun::kPcfRadius + 2;  // texels around the casters' bounds

// Slope-scaled depth bias in texels (shadow.hpp).
double biasTexels(const Vec3d& n, const Vec3d& L)
{
    double tanT = 4;
    const double c = std::abs(n.dot(L));
    if (n.dot(n) > 0 && c > 0)
        tanT = std::min(4.0, std::sqrt(std::max(0.0, 1 - c * c)) / c);
    return 1.5 + (Sun::kPcfRadius + 1) * tanT;
}

// The (2r + 2)^2 texels the PCF taps of (u, v) read, compared with depth zr, weighted
// separably: the taps at offsets -r..r read texels x0 - r .. x0 + r + 1 with weights
// (1 - fx), 1, ..., 1, fx (and the same in y). `b` (optional) is a second map of the same layout.
void pcf(const Mat& a, const Mat* b, double u, double v, float zra, float zrb, float& va,
         float& vb)
{
    const int r = Sun::kPcfRadius, n = 2 * r + 2;
    const int x0 = cvFloor(u), y0 = cvFloor(v);
    const float fx = (float)(u - x0), fy = (float)(v - y0);
    float wx[2 * Sun::kPcfRadius + 2], wy[2 * Sun::kPcfRadius + 2];
    for (int k = 0; k < n; k++)
    {
        wx[k] = k == 0 ? 1 - fx : k == n - 1 ? fx : 1.f;
        wy[k] = k == 0 ? 1 - fy : k == n - 1 ? fy : 1.f;
    }
    float sa = 0, sb = 0;
    for (int j = 0; j < n; j++)
    {
        const int y = y0 - r + j;
        float ra = 0, rb = 0;
        if (y < 0 || y >= a.rows)
        {
            for (int i = 0; i < n; i++)
                ra += wx[i];
            rb = ra;
        }
        else
        {
            const float* za = a.ptr<float>(y);
            const float* zb = b ? b->ptr<float>(y) : nullptr;
            for (int i = 0; i < n; i++)
            {
                const int x = x0 - r + i;
                if (x < 0 || x >= a.cols)
                {
                    ra += wx[i];
                    rb += wx[i];
                    continue;
                }
                const bool litA = za[x] >= zra;
                ra += litA ? wx[i] : 0.f;
                if (zb)
                    rb += litA && zb[x] >= zrb ? wx[i] : 0.f;
            }
        }
        sa += wy[j] * ra;
        sb += wy[j] * rb;
    }
    const float inv = 1.f / (float)((2 * r + 1) * (2 * r + 1));
    va = std::min(1.f, sa * inv);
    vb = std::min(1.f, sb * inv);
}

} // namespace

void appendBoxCorners(const Vec3d& lo, const Vec3d& hi, std::vector<Vec3d>& out)
{
    for (int c = 0; c < 8; c++)
        out.push_back(Vec3d(c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]));
}

void ShadowMap::layout(const Sun& sun, const std::vector<Vec3d>& pts)
{
    sun.validate("shadow map");
    CV_Assert(sun.enabled());
    L = sun.direction / cv::norm(sun.direction);
    z.release();
    occupied = Rect();
    // Axes from L alone: z along the light's travel, x from the world axis least aligned with L.
    const Vec3d za = -L;
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (std::abs(L[i]) < std::abs(L[k]))
            k = i;
    Vec3d a(0, 0, 0);
    a[k] = 1;
    Vec3d xa = a - za * za.dot(a);
    xa /= cv::norm(xa);
    const Vec3d ya = za.cross(xa);
    const Matx33d R(xa[0], xa[1], xa[2], ya[0], ya[1], ya[2], za[0], za[1], za[2]);
    texel = sun.penumbra / Sun::kPenumbraTexels;
    if (pts.empty())
        return;
    Vec3d lo = Vec3d::all(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Vec3d& p : pts)
    {
        const Vec3d q = R * p;
        for (int c = 0; c < 3; c++)
        {
            lo[c] = std::min(lo[c], q[c]);
            hi[c] = std::max(hi[c], q[c]);
        }
    }
    int i0, j0, w, h;
    for (;;)
    {
        i0 = cvFloor(lo[0] / texel) - kPad;
        j0 = cvFloor(lo[1] / texel) - kPad;
        w = cvCeil(hi[0] / texel) + kPad - i0 + 1;
        h = cvCeil(hi[1] / texel) + kPad - j0 + 1;
        if (w <= Sun::kMaxShadowMapSide && h <= Sun::kMaxShadowMapSide)
            break;
        // Doubling keeps the lattice nested in the finer one.
        texel *= 2;
        CV_LOG_WARNING(NULL, cv::format("shadow map: casters span %dx%d texels, texel doubled "
                                        "to %g (penumbra %g)", w, h, texel,
                                        texel * Sun::kPenumbraTexels));
    }
    const double extent = cv::norm(hi - lo);
    const double margin = 0.05 * extent + 10 * texel;
    zNear = 0.5 * margin;
    zFar = hi[2] - lo[2] + 2 * margin;
    cam = Camera::orthographic(R, Vec3d(0, 0, margin - lo[2]), 1.0 / texel,
                               Point2d(-i0, -j0));
    z = Mat(h, w, CV_32F, Scalar::all(std::numeric_limits<float>::infinity()));
}

void ShadowMap::addDepth(const Mat& depth)
{
    CV_CheckTypeEQ(depth.type(), CV_32FC1, "shadow map depth");
    CV_CheckEQ(depth.size(), z.size(), "shadow map depth size");
    cv::min(z, depth, z);
}

void ShadowMap::finish()
{
    if (z.empty())
    {
        occupied = Rect();
        return;
    }
    const Mat finite = z < std::numeric_limits<float>::infinity();
    occupied = cv::boundingRect(finite);
}

float ShadowMap::visibility(const Vec3d& X, const Vec3d& n) const
{
    float a, b;
    visibility2(ShadowMap(), X, n, a, b);
    return a;
}

void ShadowMap::visibility2(const ShadowMap& other, const Vec3d& X, const Vec3d& n, float& alone,
                            float& both) const
{
    alone = both = 1.f;
    const bool useOther = !other.z.empty() && other.occupied.area() > 0;
    if (z.empty() || (occupied.area() == 0 && !useOther))
        return;
    const Vec3d Xc = cam.toCamera(X);
    const double u = Xc[0] * cam.s + cam.pp.x, v = Xc[1] * cam.s + cam.pp.y;
    const double reach = Sun::kPcfRadius + 2;
    auto near = [&](const Rect& r) {
        return r.area() > 0 && u > r.x - reach && u < r.x + r.width - 1 + reach &&
               v > r.y - reach && v < r.y + r.height - 1 + reach;
    };
    const bool inThis = near(occupied), inOther = useOther && near(other.occupied);
    if (!inThis && !inOther)
        return;
    const double zr = Xc[2] - biasTexels(n, L) * texel;
    pcf(z, inOther ? &other.z : nullptr, u, v, (float)(zr - extraBias),
        (float)(zr - other.extraBias), alone, both);
    if (!inOther)
        both = alone;
}

bool ShadowMap::reaches(const Vec3d& X) const
{
    if (z.empty() || occupied.area() == 0)
        return false;
    const Vec3d Xc = cam.toCamera(X);
    const double u = Xc[0] * cam.s + cam.pp.x, v = Xc[1] * cam.s + cam.pp.y;
    const double reach = Sun::kPcfRadius + 2;
    return u > occupied.x - reach && u < occupied.x + occupied.width - 1 + reach &&
           v > occupied.y - reach && v < occupied.y + occupied.height - 1 + reach;
}

void depthVisibility(const Camera& cam, const Mat& depth, const ShadowMap& a, const ShadowMap* b,
                     Mat& va, Mat* vb, Mat* cosine, const Mat& groundMask, const Vec3d& up,
                     bool onlyNearB, int normalStep)
{
    CV_CheckTypeEQ(depth.type(), CV_32FC1, "depthVisibility: depth");
    Mat points, normals;
    surfaceFromDepth(cam, depth, points, normals, normalStep);
    const Size sz = depth.size();
    va.create(sz, CV_32F);
    if (vb)
        vb->create(sz, CV_32F);
    if (cosine)
        cosine->create(sz, CV_32F);
    const ShadowMap none;
    const ShadowMap& other = b ? *b : none;
    const Vec3d L = a.L;
    parallel_for_(Range(0, sz.height), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            const Vec3f* p = points.ptr<Vec3f>(y);
            const Vec3f* nn = normals.ptr<Vec3f>(y);
            const uchar* g = groundMask.empty() ? nullptr : groundMask.ptr<uchar>(y);
            float* oa = va.ptr<float>(y);
            float* ob = vb ? vb->ptr<float>(y) : nullptr;
            float* oc = cosine ? cosine->ptr<float>(y) : nullptr;
            for (int x = 0; x < sz.width; x++)
            {
                float al = 1.f, bo = 1.f, c = 0.f;
                if (std::isfinite(p[x][0]))
                {
                    const Vec3d n = g && g[x] ? up : Vec3d(nn[x]);
                    c = (float)std::max(0.0, n.dot(L));
                    if (!(onlyNearB && b && !b->reaches(Vec3d(p[x]))))
                        a.visibility2(other, Vec3d(p[x]), n, al, bo);
                }
                oa[x] = al;
                if (ob)
                    ob[x] = bo;
                if (oc)
                    oc[x] = c;
            }
        }
    });
}

void applyVisibility(const Mat& lit, const Mat& ambient, const Mat& vis, Mat& out)
{
    CV_CheckDepthEQ(lit.depth(), CV_8U, "applyVisibility: lit");
    CV_CheckTypeEQ(lit.type(), ambient.type(), "applyVisibility: ambient");
    CV_CheckEQ(lit.size(), ambient.size(), "applyVisibility: ambient size");
    CV_CheckEQ(lit.size(), vis.size(), "applyVisibility: visibility size");
    CV_CheckTypeEQ(vis.type(), CV_32FC1, "applyVisibility: visibility");
    const int cn = lit.channels();
    if (out.data != lit.data)
        lit.copyTo(out);
    parallel_for_(Range(0, lit.rows), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            uchar* o = out.ptr<uchar>(y);
            const uchar* am = ambient.ptr<uchar>(y);
            const float* v = vis.ptr<float>(y);
            for (int x = 0; x < lit.cols; x++)
            {
                if (v[x] >= 1.f)
                    continue;
                for (int k = 0; k < std::min(cn, 3); k++)
                {
                    const float l = o[cn * x + k], a = am[cn * x + k];
                    o[cn * x + k] = saturate_cast<uchar>(a + v[x] * (l - a));
                }
            }
        }
    });
}

void renderShadowDepth(GlContext& ctx, ShadowMap& map, const std::function<void()>& draw)
{
    if (map.z.empty())
        return;
    const Size sz = map.size();
    if (ctx.size() != sz)
        ctx.resize(sz);
    else
        ctx.makeCurrent();
    const Matx44d P = glProjection(map.cam, sz, map.zNear, map.zFar).t();
    const Matx44d MV = glModelView(map.cam).t();
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(P.val);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(MV.val);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    draw();
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    Mat d01, zc;
    ctx.readDepth(d01);
    windowDepthToCameraZ(map.cam, d01, map.zNear, map.zFar, zc);
    zc.convertTo(zc, CV_32F);
    map.addDepth(zc);
}

void surfaceFromDepth(const Camera& cam, const Mat& depth, Mat& points, Mat& normals, int step)
{
    CV_CheckGE(step, 1, "surfaceFromDepth: step");
    CV_CheckTypeEQ(depth.type(), CV_32FC1, "surfaceFromDepth: depth");
    const Size sz = depth.size();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    points.create(sz, CV_32FC3);
    normals.create(sz, CV_32FC3);
    parallel_for_(Range(0, sz.height), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            const float* d = depth.ptr<float>(y);
            Vec3f* p = points.ptr<Vec3f>(y);
            for (int x = 0; x < sz.width; x++)
                p[x] = std::isfinite(d[x]) ? Vec3f(cam.unproject(Point2d(x, y), d[x]))
                                           : Vec3f(nan, nan, nan);
        }
    });
    const bool ortho = cam.model == SCALED_ORTHOGRAPHIC;
    const Vec3d view = cam.viewDirection(), centre = cam.center();
    parallel_for_(Range(0, sz.height), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            const float* d = depth.ptr<float>(y);
            Vec3f* n = normals.ptr<Vec3f>(y);
            for (int x = 0; x < sz.width; x++)
            {
                n[x] = Vec3f(0, 0, 0);
                if (!std::isfinite(d[x]))
                    continue;
                // One-sided difference with the smaller depth step (x, then y).
                auto side = [&](int dx, int dy, Vec3d& out) {
                    double best = std::numeric_limits<double>::infinity();
                    for (int sgn = -1; sgn <= 1; sgn += 2)
                    {
                        const int xx = x + sgn * dx, yy = y + sgn * dy;
                        if (xx < 0 || yy < 0 || xx >= sz.width || yy >= sz.height)
                            continue;
                        const float dz = depth.at<float>(yy, xx);
                        if (!std::isfinite(dz) || std::abs(dz - d[x]) >= best)
                            continue;
                        best = std::abs(dz - d[x]);
                        out = sgn * (Vec3d(points.at<Vec3f>(yy, xx)) -
                                     Vec3d(points.at<Vec3f>(y, x)));
                    }
                    return std::isfinite(best);
                };
                Vec3d tx, ty;
                if (!side(step, 0, tx) || !side(0, step, ty))
                    continue;
                Vec3d nn = tx.cross(ty);
                const double len = cv::norm(nn);
                if (!(len > 0))
                    continue;
                nn /= len;
                const Vec3d ray = ortho ? view : Vec3d(points.at<Vec3f>(y, x)) - centre;
                if (nn.dot(ray) > 0)
                    nn = -nn;
                n[x] = Vec3f(nn);
            }
        }
    });
}

} // namespace detail
} // namespace augocc
} // namespace cv
