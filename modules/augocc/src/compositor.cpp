// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The compositor (the paper's Section 7): frame as background, clones into the depth buffer only,
// virtual objects with the depth test. Beyond the paper: one depth metric (camera-space z) for
// every camera model, and soft occlusion edges by supersampling the virtual layer against the
// clone depth rendered at the same finer grid.

#include "precomp.hpp"
#include "gl_context.hpp"
#include "shading.hpp"

#include <map>
#include <tuple>
#include <unordered_map>
#include <GL/osmesa.h>
#include <GL/gl.h>

namespace cv {
namespace augocc {

Camera supersampledCamera(const Camera& camera, int factor)
{
    CV_CheckGE(factor, 1, "supersampling factor");
    Camera c = camera;
    const double k = factor;
    if (camera.model == SCALED_ORTHOGRAPHIC)
    {
        c.s = k * camera.s;
        c.pp = Point2d(k * (camera.pp.x + 0.5) - 0.5, k * (camera.pp.y + 0.5) - 0.5);
    }
    else
    {
        c.K(0, 0) = k * camera.K(0, 0);
        c.K(0, 1) = k * camera.K(0, 1);
        c.K(1, 1) = k * camera.K(1, 1);
        c.K(0, 2) = k * (camera.K(0, 2) + 0.5) - 0.5;
        c.K(1, 2) = k * (camera.K(1, 2) + 0.5) - 0.5;
        c.pp = Point2d(c.K(0, 2), c.K(1, 2));
    }
    return c;
}

Compositor::Params::Params()
    : supersample(3), cullBackFaces(true)
{
}

namespace {

// GL >= 1.5 entry points come from OSMesaGetProcAddress, so that they are OSMesa's whatever
// other libGL highgui pulls into the process (PITFALLS.md).
typedef void (*PfnGenBuffers)(GLsizei, GLuint*);
typedef void (*PfnDeleteBuffers)(GLsizei, const GLuint*);
typedef void (*PfnBindBuffer)(GLenum, GLuint);
typedef void (*PfnBufferData)(GLenum, ptrdiff_t, const void*, GLenum);
typedef void (*PfnWindowPos2i)(GLint, GLint);
const GLenum kArrayBuffer = 0x8892;         // GL_ARRAY_BUFFER
const GLenum kElementArrayBuffer = 0x8893;  // GL_ELEMENT_ARRAY_BUFFER
const GLenum kStaticDraw = 0x88E4;          // GL_STATIC_DRAW

struct GlBufferApi
{
    PfnGenBuffers genBuffers = nullptr;
    PfnDeleteBuffers deleteBuffers = nullptr;
    PfnBindBuffer bindBuffer = nullptr;
    PfnBufferData bufferData = nullptr;
    PfnWindowPos2i windowPos2i = nullptr;

    void load()
    {
        if (genBuffers)
            return;
        genBuffers = (PfnGenBuffers)OSMesaGetProcAddress("glGenBuffers");
        deleteBuffers = (PfnDeleteBuffers)OSMesaGetProcAddress("glDeleteBuffers");
        bindBuffer = (PfnBindBuffer)OSMesaGetProcAddress("glBindBuffer");
        bufferData = (PfnBufferData)OSMesaGetProcAddress("glBufferData");
        windowPos2i = (PfnWindowPos2i)OSMesaGetProcAddress("glWindowPos2i");
        if (!genBuffers || !deleteBuffers || !bindBuffer || !bufferData || !windowPos2i)
            CV_Error(Error::StsError, "OSMesa: OpenGL 1.5 entry points are not available");
    }
};

// One vertex of the uploaded meshes: position, lit colour (RGB, the light is fixed in the world),
// texture coordinates.
struct GpuVertex
{
    float x, y, z;
    float r, g, b;
    float u, v;
};

// A mesh on the GPU: interleaved vertices, triangle indices, optional texture.
struct GpuMesh
{
    GLuint vbo = 0, ibo = 0, texture = 0;
    GLsizei indexCount = 0;
    bool cull = false;  // closed and outward: back faces are never seen
};

// True when the mesh is closed and consistently oriented with outward normals (vertices welded by
// position, so that per-face copies of a vertex count as one): then its back faces are always
// hidden by its front faces and culling them changes no pixel.
bool closedOutward(const Mesh& m)
{
    if (m.faces.empty())
        return false;
    // Weld on a grid of 1e-6 of the mesh's size: seams computed as sin(2 pi) land together.
    Vec3f lo, hi;
    m.bounds(lo, hi);
    const double cell = std::max(1e-30, 1e-6 * cv::norm(hi - lo));
    std::map<std::tuple<int64_t, int64_t, int64_t>, int> weld;
    std::vector<int> id(m.vertices.size());
    for (size_t i = 0; i < m.vertices.size(); i++)
    {
        const Vec3f& v = m.vertices[i];
        const auto key = std::make_tuple((int64_t)std::llround((v[0] - lo[0]) / cell),
                                         (int64_t)std::llround((v[1] - lo[1]) / cell),
                                         (int64_t)std::llround((v[2] - lo[2]) / cell));
        id[i] = weld.emplace(key, (int)weld.size()).first->second;
    }
    std::unordered_map<uint64_t, int> directed;
    directed.reserve(m.faces.size() * 3);
    double volume6 = 0;
    for (const Vec3i& f : m.faces)
    {
        // Degenerate triangles (a sphere's poles) cover no pixel: they do not count.
        if (id[f[0]] == id[f[1]] || id[f[1]] == id[f[2]] || id[f[2]] == id[f[0]])
            continue;
        for (int e = 0; e < 3; e++)
        {
            const uint64_t a = (uint64_t)id[f[e]], b = (uint64_t)id[f[(e + 1) % 3]];
            if (++directed[(a << 32) | b] > 1)
                return false;  // an edge used twice in one direction: not consistently oriented
        }
        const Vec3d p0(m.vertices[f[0]]), p1(m.vertices[f[1]]), p2(m.vertices[f[2]]);
        volume6 += p0.dot(p1.cross(p2));
    }
    for (const auto& e : directed)
        if (!directed.count(((e.first & 0xffffffffu) << 32) | (e.first >> 32)))
            return false;  // a border edge: the mesh is open
    return volume6 > 0;
}

class CompositorImpl CV_FINAL : public Compositor
{
public:
    explicit CompositorImpl(const Params& p) { setParams(p); }
    ~CompositorImpl() CV_OVERRIDE { releaseGpu(); }

    Params getParams() const CV_OVERRIDE { return params_; }
    void setParams(const Params& p) CV_OVERRIDE
    {
        if (p.cullBackFaces != params_.cullBackFaces)
            dirty_ = true;
        if (p.supersample < 1 || p.supersample > 8)
            CV_Error(Error::StsBadArg, cv::format("Compositor: supersample must be in [1, 8], "
                     "got %d", p.supersample));
        params_ = p;
    }

    void setVirtualObjects(const std::vector<Mesh>& meshes) CV_OVERRIDE
    {
        meshes_.clear();
        boundsMin_ = Vec3d::all(std::numeric_limits<double>::infinity());
        boundsMax_ = -boundsMin_;
        for (const Mesh& m : meshes)
        {
            if (m.empty())
                continue;
            const int nv = (int)m.vertices.size();
            for (const Vec3i& f : m.faces)
                for (int k = 0; k < 3; k++)
                    if (f[k] < 0 || f[k] >= nv)
                        CV_Error(Error::StsBadArg, cv::format("Compositor: face index %d out of "
                                 "range (%d vertices)", f[k], nv));
            Mesh copy = m;
            if (copy.normals.size() != copy.vertices.size())
                copy.computeNormals();
            for (const Vec3f& v : copy.vertices)
                for (int k = 0; k < 3; k++)
                {
                    boundsMin_[k] = std::min(boundsMin_[k], (double)v[k]);
                    boundsMax_[k] = std::max(boundsMax_[k], (double)v[k]);
                }
            meshes_.push_back(std::move(copy));
        }
        dirty_ = true;
    }

    Size renderSize(Size frameSize) const CV_OVERRIDE
    {
        return Size(frameSize.width * params_.supersample, frameSize.height * params_.supersample);
    }

    void composite(InputArray frame, int frameIndex, const Camera& camera, const CloneSet& clones,
                   OutputArray result, OutputArray virtualLayer, OutputArray depth) CV_OVERRIDE
    {
        const Size fsz = frame.size();
        const Size rsz = renderSize(fsz);
        const Camera rc = supersampledCamera(camera, params_.supersample);
        Mat occ(rsz, CV_32F, Scalar::all(std::numeric_limits<float>::infinity()));
        Mat matte, d;
        for (const String& name : clones.objectNames())
        {
            clones.render(name, frameIndex, rc, rsz, matte, d);
            CV_CheckTypeEQ(d.type(), CV_32FC1, "clone depth must be CV_32F");
            CV_CheckEQ(d.size(), rsz, "clone depth size");
            cv::min(occ, d, occ);
        }
        composite(frame, camera, occ, result, virtualLayer, depth);
    }

    void composite(InputArray frameArr, const Camera& camera, InputArray occluderArr,
                   OutputArray result, OutputArray virtualLayer, OutputArray depthOut) CV_OVERRIDE
    {
        Mat frame = frameArr.getMat();
        if (frame.empty())
            CV_Error(Error::StsBadArg, "Compositor: empty frame");
        CV_CheckTypeEQ(frame.type(), CV_8UC3, "Compositor: frame must be BGR CV_8UC3");
        camera.validate("Compositor camera");
        const int k = params_.supersample;
        const Size fsz = frame.size();
        const Size rsz = renderSize(fsz);

        // Occluder depth at the render grid.
        Mat occ = occluderArr.getMat();
        if (!occ.empty())
        {
            CV_CheckTypeEQ(occ.type(), CV_32FC1, "Compositor: occluder depth must be CV_32F");
            if (occ.size() == fsz && k > 1)
            {
                Mat up;
                cv::resize(occ, up, rsz, 0, 0, INTER_NEAREST);
                occ = up;
            }
            else if (occ.size() != rsz)
                CV_Error(Error::StsBadSize, cv::format("Compositor: occluder depth is %dx%d, "
                         "expected %dx%d or %dx%d", occ.cols, occ.rows, rsz.width, rsz.height,
                         fsz.width, fsz.height));
        }

        ensureContext(rsz);
        uploadIfDirty();

        // Depth range that holds the virtual objects. Occluders nearer than the near plane clamp
        // to window depth 0 (they hide everything), farther than the far plane to 1 (nothing).
        double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
        if (!meshes_.empty())
            for (int c = 0; c < 8; c++)
            {
                const double z = camera.depth(boundsCorner(c));
                zmin = std::min(zmin, z);
                zmax = std::max(zmax, z);
            }
        double zNear = 0, zFar = 1;
        chooseDepthRange(camera, zmin, zmax, zNear, zFar);
        const Camera rc = supersampledCamera(camera, k);
        // Only the part of the render grid where the virtual objects can appear is drawn, read
        // back and blended (a multiple of k, so that it maps onto whole frame pixels).
        const Rect roi = meshes_.empty() ? Rect() : screenRoi(rc, rsz, k, zNear);

        Mat rgba;  // frame grid, ROI only, rows bottom-up
        Mat zRoi;  // render grid, ROI only, camera z of the nearest surface (depth output)
        if (roi.area() > 0)
        {
            const int winY = rsz.height - roi.y - roi.height;
            glEnable(GL_SCISSOR_TEST);
            glScissor(roi.x, winY, roi.width, roi.height);
            glClearColor(0, 0, 0, 0);
            glClearDepth(1.0);
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            glDisable(GL_LIGHTING);
            glDisable(GL_BLEND);
            glDisable(GL_DITHER);
            glEnable(GL_DEPTH_TEST);

            if (!occ.empty())
                drawOccluderDepth(camera, occ(roi), zNear, zFar, roi.tl(), winY);
            drawMeshes(rc, rsz, zNear, zFar);

            glFinish();
            Mat rgbaUp(roi.size(), CV_8UC4);
            glPixelStorei(GL_PACK_ALIGNMENT, 4);
            glReadPixels(roi.x, winY, roi.width, roi.height, GL_RGBA, GL_UNSIGNED_BYTE,
                         rgbaUp.data);
            if (k > 1)
                cv::resize(rgbaUp, rgba, Size(roi.width / k, roi.height / k), 0, 0, INTER_AREA);
            else
                rgba = rgbaUp;
            if (depthOut.needed())
            {
                Mat d(roi.size(), CV_32F), flipped;
                glPixelStorei(GL_PACK_ALIGNMENT, 4);
                glReadPixels(roi.x, winY, roi.width, roi.height, GL_DEPTH_COMPONENT, GL_FLOAT,
                             d.data);
                cv::flip(d, flipped, 0);
                detail::windowDepthToCameraZ(camera, flipped, zNear, zFar, zRoi);
            }
            glDisable(GL_SCISSOR_TEST);
        }
        const Rect froi(roi.x / k, roi.y / k, roi.width / k, roi.height / k);
        blend(frame, rgba, froi, result, virtualLayer);
        if (depthOut.needed())
            writeDepth(occ, zRoi, roi, rsz, fsz, k, depthOut);
    }

private:
    void ensureContext(Size rsz)
    {
        if (!gl_)
        {
            gl_.reset(new detail::GlContext(rsz));
            glApi_.load();
        }
        else if (gl_->size() != rsz)
            gl_->resize(rsz);
        else
            gl_->makeCurrent();
    }

    void releaseGpu()
    {
        if (!gl_)
            return;
        gl_->makeCurrent();
        for (GpuMesh& g : gpu_)
        {
            if (g.vbo)
                glApi_.deleteBuffers(1, &g.vbo);
            if (g.ibo)
                glApi_.deleteBuffers(1, &g.ibo);
            if (g.texture)
                glDeleteTextures(1, &g.texture);
        }
        gpu_.clear();
    }

    void uploadIfDirty()
    {
        if (!dirty_)
            return;
        releaseGpu();
        for (const Mesh& m : meshes_)
        {
            const size_t nv = m.vertices.size();
            std::vector<GpuVertex> verts(nv);
            const bool hasTex = !m.material.texture.empty() && m.texcoords.size() == nv;
            const bool hasColors = m.colors.size() == nv;
            cv::parallel_for_(Range(0, (int)nv), [&](const Range& r) {
                for (int i = r.start; i < r.end; i++)
                {
                    const Vec3f c = detail::shadeColor(m.material, m.normals[i],
                                                       hasColors ? m.colors[i] : Vec3f(1, 1, 1));
                    GpuVertex& g = verts[i];
                    g.x = m.vertices[i][0];
                    g.y = m.vertices[i][1];
                    g.z = m.vertices[i][2];
                    g.r = c[0];
                    g.g = c[1];
                    g.b = c[2];
                    g.u = hasTex ? m.texcoords[i][0] : 0.f;
                    g.v = hasTex ? m.texcoords[i][1] : 0.f;
                }
            });
            GpuMesh g;
            glApi_.genBuffers(1, &g.vbo);
            glApi_.bindBuffer(kArrayBuffer, g.vbo);
            glApi_.bufferData(kArrayBuffer, (ptrdiff_t)(verts.size() * sizeof(GpuVertex)),
                                verts.data(), kStaticDraw);
            glApi_.genBuffers(1, &g.ibo);
            glApi_.bindBuffer(kElementArrayBuffer, g.ibo);
            glApi_.bufferData(kElementArrayBuffer, (ptrdiff_t)(m.faces.size() * sizeof(Vec3i)),
                                m.faces.data(), kStaticDraw);
            g.indexCount = (GLsizei)(m.faces.size() * 3);
            g.cull = params_.cullBackFaces && closedOutward(m);
            if (hasTex)
                g.texture = uploadTexture(m.material.texture);
            gpu_.push_back(g);
        }
        glApi_.bindBuffer(kArrayBuffer, 0);
        glApi_.bindBuffer(kElementArrayBuffer, 0);
        dirty_ = false;
    }

    static GLuint uploadTexture(const Mat& bgr)
    {
        // Texture coordinates have v up (mesh.hpp): GL's first row is t = 0, the image's bottom.
        Mat rgb, flipped;
        if (bgr.channels() == 1)
            cv::cvtColor(bgr, rgb, COLOR_GRAY2RGB);
        else if (bgr.channels() == 4)
            cv::cvtColor(bgr, rgb, COLOR_BGRA2RGB);
        else
            cv::cvtColor(bgr, rgb, COLOR_BGR2RGB);
        if (rgb.depth() != CV_8U)
            rgb.convertTo(rgb, CV_8U, rgb.depth() == CV_16U ? 1.0 / 257 : 255.0);
        cv::flip(rgb, flipped, 0);
        GLuint tex = 0;
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        // Every mipmap level made on the CPU by INTER_AREA halving, as the synthesizer does, so
        // that both sample a texture identically.
        Mat cur = flipped;
        for (int level = 0;; level++)
        {
            glTexImage2D(GL_TEXTURE_2D, level, GL_RGB8, cur.cols, cur.rows, 0, GL_RGB,
                         GL_UNSIGNED_BYTE, cur.data);
            if (cur.cols == 1 && cur.rows == 1)
                break;
            Mat next;
            cv::resize(cur, next, Size(std::max(1, cur.cols / 2), std::max(1, cur.rows / 2)), 0,
                       0, INTER_AREA);
            cur = next;
        }
        glBindTexture(GL_TEXTURE_2D, 0);
        return tex;
    }

    // Near/far planes in camera z around the virtual objects, with a 5% margin. The depth
    // buffer is 24-bit; a tight range keeps the comparison of clone and virtual depth exact to
    // far below a clone voxel.
    static void chooseDepthRange(const Camera& cam, double zmin, double zmax, double& zNear,
                                 double& zFar)
    {
        if (!(zmax >= zmin))
        {
            zmin = 0;
            zmax = 1;
        }
        const double range = std::max(zmax - zmin, 1e-6 * std::max(1.0, std::abs(zmax)));
        if (cam.model == SCALED_ORTHOGRAPHIC)
        {
            zNear = zmin - 0.05 * range;
            zFar = zmax + 0.05 * range;
        }
        else
        {
            zFar = zmax + 0.05 * range;
            // Objects behind the camera are clipped by the near plane.
            zNear = std::max(zmin - 0.05 * range, 1e-4 * zFar);
            if (zNear >= zFar)
                zNear = 0.5 * zFar;
        }
    }

    Vec3d boundsCorner(int c) const
    {
        return Vec3d((c & 1) ? boundsMax_[0] : boundsMin_[0], (c & 2) ? boundsMax_[1] : boundsMin_[1],
                     (c & 4) ? boundsMax_[2] : boundsMin_[2]);
    }

    // Render-grid rectangle that holds the projection of the virtual objects' bounding box
    // (2 pixels of margin for the rasteriser's edge rule), aligned to k. The whole grid when a
    // corner lies behind the near plane of a perspective camera.
    Rect screenRoi(const Camera& rc, Size rsz, int k, double zNear) const
    {
        double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
        for (int c = 0; c < 8; c++)
        {
            const Vec3d X = boundsCorner(c);
            if (rc.model == PERSPECTIVE && rc.depth(X) <= zNear)
                return Rect(0, 0, rsz.width, rsz.height);
            const Point2d u = rc.project(X);
            x0 = std::min(x0, u.x);
            x1 = std::max(x1, u.x);
            y0 = std::min(y0, u.y);
            y1 = std::max(y1, u.y);
        }
        const double kMargin = 2.0;
        const double W = rsz.width, H = rsz.height;
        x0 = std::max(0.0, std::floor(x0 - kMargin));
        y0 = std::max(0.0, std::floor(y0 - kMargin));
        x1 = std::min(W, std::ceil(x1 + kMargin) + 1);
        y1 = std::min(H, std::ceil(y1 + kMargin) + 1);
        if (!(x1 > x0 && y1 > y0))
            return Rect();
        const int ix0 = ((int)x0 / k) * k, iy0 = ((int)y0 / k) * k;
        const int ix1 = std::min(rsz.width, (((int)x1 + k - 1) / k) * k);
        const int iy1 = std::min(rsz.height, (((int)y1 + k - 1) / k) * k);
        return Rect(ix0, iy0, ix1 - ix0, iy1 - iy0);
    }

    // Window depth of camera z for glProjection(cam, ..., zNear, zFar): (ndc + 1) / 2.
    static inline float windowDepth(bool ortho, double z, double zNear, double zFar)
    {
        if (!(z < std::numeric_limits<double>::infinity()))
            return 1.f;
        double w;
        if (ortho)
            w = (z - zNear) / (zFar - zNear);
        else
            w = z <= zNear ? 0.0 : zFar * (z - zNear) / ((zFar - zNear) * z);
        return (float)std::min(1.0, std::max(0.0, w));
    }

    // The clones go into the depth buffer only (colour writes off), as window depth of the same
    // projection the virtual objects use; rows bottom-up as GL expects.
    void drawOccluderDepth(const Camera& cam, const Mat& occ, double zNear, double zFar,
                           Point origin, int winY)
    {
        const bool ortho = cam.model == SCALED_ORTHOGRAPHIC;
        const Size sz = occ.size();
        windowBuf_.create(sz, CV_32F);
        cv::parallel_for_(Range(0, sz.height), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
            {
                const float* src = occ.ptr<float>(y);
                float* dst = windowBuf_.ptr<float>(sz.height - 1 - y);
                for (int x = 0; x < sz.width; x++)
                    dst[x] = windowDepth(ortho, src[x], zNear, zFar);
            }
        });
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glDepthMask(GL_TRUE);
        glDepthFunc(GL_ALWAYS);
        glApi_.windowPos2i(origin.x, winY);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glDrawPixels(sz.width, sz.height, GL_DEPTH_COMPONENT, GL_FLOAT, windowBuf_.data);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }

    void drawMeshes(const Camera& cam, Size rsz, double zNear, double zFar)
    {
        const Matx44d P = detail::glProjection(cam, rsz, zNear, zFar).t();
        const Matx44d MV = detail::glModelView(cam).t();
        glMatrixMode(GL_PROJECTION);
        glLoadMatrixd(P.val);
        glMatrixMode(GL_MODELVIEW);
        glLoadMatrixd(MV.val);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glEnableClientState(GL_VERTEX_ARRAY);
        glEnableClientState(GL_COLOR_ARRAY);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        // Window y points up like the viewer's up (glProjection), so a triangle that is
        // counter-clockwise seen from outside is counter-clockwise in the window when it faces
        // the camera.
        glFrontFace(GL_CCW);
        glCullFace(GL_BACK);
        for (const GpuMesh& g : gpu_)
        {
            if (g.cull)
                glEnable(GL_CULL_FACE);
            else
                glDisable(GL_CULL_FACE);
            glApi_.bindBuffer(kArrayBuffer, g.vbo);
            glApi_.bindBuffer(kElementArrayBuffer, g.ibo);
            glVertexPointer(3, GL_FLOAT, sizeof(GpuVertex), (const void*)offsetof(GpuVertex, x));
            glColorPointer(3, GL_FLOAT, sizeof(GpuVertex), (const void*)offsetof(GpuVertex, r));
            if (g.texture)
            {
                glEnable(GL_TEXTURE_2D);
                glBindTexture(GL_TEXTURE_2D, g.texture);
                glEnableClientState(GL_TEXTURE_COORD_ARRAY);
                glTexCoordPointer(2, GL_FLOAT, sizeof(GpuVertex),
                                  (const void*)offsetof(GpuVertex, u));
            }
            glDrawElements(GL_TRIANGLES, g.indexCount, GL_UNSIGNED_INT, nullptr);
            if (g.texture)
            {
                glDisableClientState(GL_TEXTURE_COORD_ARRAY);
                glBindTexture(GL_TEXTURE_2D, 0);
                glDisable(GL_TEXTURE_2D);
            }
        }
        glDisable(GL_CULL_FACE);
        glDisableClientState(GL_VERTEX_ARRAY);
        glDisableClientState(GL_COLOR_ARRAY);
        glApi_.bindBuffer(kArrayBuffer, 0);
        glApi_.bindBuffer(kElementArrayBuffer, 0);
    }

    // result = frame * (1 - a) + premultiplied colour, inside `roi` (frame grid); the frame
    // elsewhere. The layer has straight alpha. `rgba` rows are bottom-up (GL), RGB order.
    static void blend(const Mat& frame, const Mat& rgba, const Rect& roi, OutputArray resultArr,
                      OutputArray layerArr)
    {
        const Size sz = frame.size();
        resultArr.create(sz, CV_8UC3);
        Mat result = resultArr.getMat();
        frame.copyTo(result);
        Mat layer;
        if (layerArr.needed())
        {
            layerArr.create(sz, CV_8UC4);
            layer = layerArr.getMat();
            layer.setTo(Scalar::all(0));
        }
        if (roi.area() == 0)
            return;
        cv::parallel_for_(Range(0, roi.height), [&](const Range& r) {
            for (int j = r.start; j < r.end; j++)
            {
                const int y = roi.y + j;
                const uchar* f = frame.ptr<uchar>(y) + 3 * roi.x;
                const uchar* c = rgba.ptr<uchar>(roi.height - 1 - j);
                uchar* o = result.ptr<uchar>(y) + 3 * roi.x;
                uchar* l = layer.empty() ? nullptr : layer.ptr<uchar>(y) + 4 * roi.x;
                for (int x = 0; x < roi.width; x++, f += 3, c += 4, o += 3)
                {
                    const int a = c[3];
                    if (a == 0)
                    {
                        if (l)
                            l += 4;
                        continue;
                    }
                    const int ia = 255 - a;
                    o[0] = saturate_cast<uchar>((c[2] * 255 + f[0] * ia + 127) / 255);
                    o[1] = saturate_cast<uchar>((c[1] * 255 + f[1] * ia + 127) / 255);
                    o[2] = saturate_cast<uchar>((c[0] * 255 + f[2] * ia + 127) / 255);
                    if (l)
                    {
                        l[0] = saturate_cast<uchar>((c[2] * 255 + a / 2) / a);
                        l[1] = saturate_cast<uchar>((c[1] * 255 + a / 2) / a);
                        l[2] = saturate_cast<uchar>((c[0] * 255 + a / 2) / a);
                        l[3] = (uchar)a;
                        l += 4;
                    }
                }
            }
        });
    }

    // Depth output at the frame grid: per pixel the minimum over its k x k samples of the
    // occluder depth and (inside the ROI) the depth buffer read back.
    static void writeDepth(const Mat& occ, const Mat& zRoi, const Rect& roi, Size rsz, Size fsz,
                           int k, OutputArray depthOut)
    {
        const float inf = std::numeric_limits<float>::infinity();
        Mat zUp;
        if (!occ.empty())
            occ.copyTo(zUp);
        else
            zUp = Mat(rsz, CV_32F, Scalar::all(inf));
        if (roi.area() > 0)
        {
            Mat sub = zUp(roi);
            cv::min(sub, zRoi, sub);
        }
        depthOut.create(fsz, CV_32F);
        Mat out = depthOut.getMat();
        cv::parallel_for_(Range(0, fsz.height), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
                for (int x = 0; x < fsz.width; x++)
                {
                    float m = inf;
                    for (int j = 0; j < k; j++)
                    {
                        const float* row = zUp.ptr<float>(y * k + j) + x * k;
                        for (int i = 0; i < k; i++)
                            m = std::min(m, row[i]);
                    }
                    out.at<float>(y, x) = m;
                }
        });
    }

    Params params_;
    std::vector<Mesh> meshes_;
    Vec3d boundsMin_, boundsMax_;
    bool dirty_ = true;
    std::unique_ptr<detail::GlContext> gl_;
    GlBufferApi glApi_;
    std::vector<GpuMesh> gpu_;
    Mat windowBuf_;
};

} // namespace

Ptr<Compositor> Compositor::create(const Params& params)
{
    return makePtr<CompositorImpl>(params);
}

Ptr<Compositor> Compositor::create()
{
    return create(Params());
}

} // namespace augocc
} // namespace cv
