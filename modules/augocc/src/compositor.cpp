// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The compositor (the paper's Section 7): frame as background, clones into the depth buffer only,
// virtual objects with the depth test. Beyond the paper: one depth metric (camera-space z) for
// every camera model, and soft occlusion edges by supersampling the virtual layer against the
// clone depth rendered at the same finer grid.
//
// Over 800 lines in one file: one class's render path (context, shaders, the clones' depth pass,
// the virtual pass, the supersampled resolve) sharing its GL state; the scene file, the GL context
// and the shading it uses are in their own files.

#include "precomp.hpp"
#include "clone/clone_set.hpp"
#include "gl_context.hpp"
#include "pinhole.hpp"
#include "shading.hpp"
#include "shadow.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <tuple>
#include <unordered_map>
#include <opencv2/ximgproc.hpp>
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

namespace {

// GL >= 1.5 entry points come from OSMesaGetProcAddress, so that they are OSMesa's whatever
// other libGL highgui pulls into the process (PITFALLS.md).
typedef void (*PfnGenBuffers)(GLsizei, GLuint*);
typedef void (*PfnDeleteBuffers)(GLsizei, const GLuint*);
typedef void (*PfnBindBuffer)(GLenum, GLuint);
typedef void (*PfnBufferData)(GLenum, ptrdiff_t, const void*, GLenum);
typedef void (*PfnWindowPos2i)(GLint, GLint);
typedef void (*PfnDrawRangeElements)(GLenum, GLuint, GLuint, GLsizei, GLenum, const void*);
const GLenum kArrayBuffer = 0x8892;         // GL_ARRAY_BUFFER
const GLenum kElementArrayBuffer = 0x8893;  // GL_ELEMENT_ARRAY_BUFFER
const GLenum kStaticDraw = 0x88E4;          // GL_STATIC_DRAW
const GLenum kStreamDraw = 0x88E0;          // GL_STREAM_DRAW

struct GlBufferApi
{
    PfnGenBuffers genBuffers = nullptr;
    PfnDeleteBuffers deleteBuffers = nullptr;
    PfnBindBuffer bindBuffer = nullptr;
    PfnBufferData bufferData = nullptr;
    PfnWindowPos2i windowPos2i = nullptr;
    PfnDrawRangeElements drawRangeElements = nullptr;

    void load()
    {
        if (genBuffers)
            return;
        genBuffers = (PfnGenBuffers)OSMesaGetProcAddress("glGenBuffers");
        deleteBuffers = (PfnDeleteBuffers)OSMesaGetProcAddress("glDeleteBuffers");
        bindBuffer = (PfnBindBuffer)OSMesaGetProcAddress("glBindBuffer");
        bufferData = (PfnBufferData)OSMesaGetProcAddress("glBufferData");
        windowPos2i = (PfnWindowPos2i)OSMesaGetProcAddress("glWindowPos2i");
        drawRangeElements = (PfnDrawRangeElements)OSMesaGetProcAddress("glDrawRangeElements");
        if (!genBuffers || !deleteBuffers || !bindBuffer || !bufferData || !windowPos2i ||
            !drawRangeElements)
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
    float ar, ag, ab;  // ambient only: the colour in the sun's shadow (Params::sun)
};

bool sameSun(const Sun& a, const Sun& b)
{
    return a.direction == b.direction && a.sky == b.sky && a.penumbra == b.penumbra;
}

// A mesh on the GPU: interleaved vertices, triangle indices, optional texture.
struct GpuMesh
{
    GLuint vbo = 0, ibo = 0, texture = 0;
    GLsizei indexCount = 0;
    GLuint vertexCount = 0;
    bool cull = false;  // closed and outward: back faces are never seen
    // Culled meshes only: per face, its first vertex and unit normal (zero when degenerate),
    // for the back-face test on the CPU; the faces that pass it are streamed into `keptIbo`.
    std::vector<Vec3f> faceOrigin, faceNormal;
    GLuint keptIbo = 0;
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
    // Each grid coordinate is in [0, 1e6] (an axis' extent is at most the diagonal): three of
    // them pack into 63 bits, and welding is a sort of those keys.
    const size_t nv = m.vertices.size();
    const int64_t kMaxCell = (int64_t(1) << 21) - 1;
    std::vector<std::pair<uint64_t, int>> keyed(nv);
    for (size_t i = 0; i < nv; i++)
    {
        uint64_t key = 0;
        for (int k = 0; k < 3; k++)
        {
            const double c = std::round((m.vertices[i][k] - lo[k]) / cell);
            if (!(c >= 0 && c <= (double)kMaxCell))
                return false;  // not finite: no culling (always safe)
            key |= (uint64_t)c << (21 * k);
        }
        keyed[i] = std::make_pair(key, (int)i);
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<int> id(nv);
    int nid = 0;
    for (size_t k = 0; k < nv; k++)
    {
        if (k > 0 && keyed[k].first != keyed[k - 1].first)
            nid++;
        id[keyed[k].second] = nid;
    }
    nid++;
    // Directed edges as adjacency lists (CSR) of the welded vertices: no hashing, so that the
    // check costs little next to the upload (`augocc place` re-uploads a dragged object on every
    // step; a std::map weld and a hash of the edges took 5x longer on a 100k-triangle sphere).
    auto degenerate = [&](const Vec3i& f) {
        return id[f[0]] == id[f[1]] || id[f[1]] == id[f[2]] || id[f[2]] == id[f[0]];
    };
    std::vector<int> first(nid + 1, 0);
    for (const Vec3i& f : m.faces)
        if (!degenerate(f))
            for (int e = 0; e < 3; e++)
                first[id[f[e]] + 1]++;
    for (int v = 0; v < nid; v++)
        first[v + 1] += first[v];
    std::vector<int> to(first[nid]), fill(first.begin(), first.end() - 1);
    double volume6 = 0;
    for (const Vec3i& f : m.faces)
    {
        // Degenerate triangles (a sphere's poles) cover no pixel: they do not count.
        if (degenerate(f))
            continue;
        for (int e = 0; e < 3; e++)
            to[fill[id[f[e]]]++] = id[f[(e + 1) % 3]];
        const Vec3d p0(m.vertices[f[0]]), p1(m.vertices[f[1]]), p2(m.vertices[f[2]]);
        volume6 += p0.dot(p1.cross(p2));
    }
    for (int a = 0; a < nid; a++)
        for (int i = first[a]; i < first[a + 1]; i++)
        {
            const int b = to[i];
            for (int j = first[a]; j < i; j++)
                if (to[j] == b)
                    return false;  // an edge used twice in one direction: inconsistent
            bool back = false;
            for (int j = first[b]; j < first[b + 1] && !back; j++)
                back = to[j] == a;
            if (!back)
                return false;  // a border edge: the mesh is open
        }
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
        p.sun.validate("Compositor: sun");
        if (p.cullBackFaces != params_.cullBackFaces || p.lightRotation != params_.lightRotation ||
            !sameSun(p.sun, params_.sun))
            dirty_ = true;
        if (p.supersample < 1 || p.supersample > 8)
            CV_Error(Error::StsBadArg, cv::format("Compositor: supersample must be in [1, 8], "
                     "got %d", p.supersample));
        if (p.edgeRadius < 0 || p.edgeRadius > 16)
            CV_Error(Error::StsBadArg, cv::format("Compositor: edgeRadius must be in [0, 16], "
                     "got %d", p.edgeRadius));
        if (!(p.edgeEps > 0))
            CV_Error(Error::StsBadArg, "Compositor: edgeEps must be positive");
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

    void composite(InputArray frameArr0, int frameIndex, const Camera& camera,
                   const CloneSet& clones, OutputArray result, OutputArray virtualLayer,
                   OutputArray depthOut) CV_OVERRIDE
    {
        Mat frameArr = frameArr0.getMat();
        if (!insideLens_ && sunShadows())
        {
            // Params::sun: the shadow maps of this frame, the real surfaces' shadow catcher on
            // the frame itself (through the lens too: the clones render through it).
            const Mat f0 = checkedFrame(frameArr, camera);
            prepareShadows(frameIndex, &clones);
            frameArr = catchShadows(f0, camera, frameIndex, &clones, Mat());
        }
        if (camera.hasDistortion())
        {
            // The depth test in the lens's ideal view, clones drawn there directly.
            LensScope scope(insideLens_);
            compositeThroughLens(frameArr, camera, [&](const Mat& black, const Camera& ideal,
                                                       Mat& layer, Mat* depth) {
                composite(black, frameIndex, ideal, clones, lensResult_, layer,
                          depth ? _OutputArray(*depth) : _OutputArray(noArray()));
            }, result, virtualLayer, depthOut);
            return;
        }
        const Mat frame = checkedFrame(frameArr, camera);
        const Size rsz = renderSize(frame.size());
        const FramePlan pl = plan(camera, rsz);
        // The clones are rendered only where the occluder depth is used: the whole render grid
        // for the depth output; else only the bounding box of the samples the virtual objects
        // cover (known once they are drawn: tighter than the ROI, which bounds their 3D box),
        // with the camera shifted by its corner (an integer shift of the principal point: the
        // same pixels). The depth test reads the occluder at covered samples only.
        const bool needZ = depthOut.needed();
        const float inf = std::numeric_limits<float>::infinity();
        auto renderClones = [&](const Rect& area, Mat& occ) {
            const Camera ac = shiftedCamera(pl.rc, area.tl());
            for (const String& name : clones.objectNames())
            {
                // The matte is not an optional output of CloneSet::render(): a reused buffer.
                clones.render(name, frameIndex, ac, area.size(), cloneMatte_, cloneDepth_);
                CV_CheckTypeEQ(cloneDepth_.type(), CV_32FC1, "clone depth must be CV_32F");
                CV_CheckEQ(cloneDepth_.size(), area.size(), "clone depth size");
                cv::min(occ, cloneDepth_, occ);
            }
        };
        if (needZ)
        {
            cloneOcc_.create(rsz, CV_32F);
            cloneOcc_.setTo(Scalar::all(inf));
            renderClones(Rect(Point(), rsz), cloneOcc_);
            const Mat occRoi = pl.roi.area() > 0 ? cloneOcc_(pl.roi) : Mat();
            compositeCore(frame, camera, pl, [&](const Rect&) { return occRoi; }, cloneOcc_,
                          result, virtualLayer, depthOut);
            return;
        }
        auto occluderOf = [&](const Rect& cov) {
            if (cov.area() == 0)
                return Mat();
            cloneOcc_.create(pl.roi.size(), CV_32F);
            cloneOcc_.setTo(Scalar::all(inf));
            Mat sub = cloneOcc_(cov);
            renderClones(cov + pl.roi.tl(), sub);
            return cloneOcc_;
        };
        compositeCore(frame, camera, pl, occluderOf, Mat(), result, virtualLayer, depthOut);
    }

    void composite(InputArray frameArr0, const Camera& camera, InputArray occluderArr,
                   OutputArray result, OutputArray virtualLayer, OutputArray depthOut) CV_OVERRIDE
    {
        Mat frameArr = frameArr0.getMat();
        if (!insideLens_ && sunShadows())
        {
            // Params::sun: no clones, so the virtual objects alone cast; the occluder depth and
            // the ground receive.
            const Mat f0 = checkedFrame(frameArr, camera);
            prepareShadows(-1, nullptr);
            const Mat occ0 = occluderArr.getMat();
            if (!occ0.empty())
                CV_CheckTypeEQ(occ0.type(), CV_32FC1, "Compositor: occluder depth must be CV_32F");
            frameArr = catchShadows(f0, camera, -1, nullptr, occ0);
        }
        if (camera.hasDistortion())
        {
            LensScope scope(insideLens_);
            // The occluder depth (frame pixels) is resampled into the ideal view's render grid
            // (nearest: depth is not interpolated across edges), the test runs there.
            const Mat frame0 = checkedFrame(frameArr, camera);
            Mat occ = occluderArr.getMat();
            const int k = params_.supersample;
            const Size fsz = frame0.size(), rsz = renderSize(fsz);
            if (!occ.empty())
            {
                CV_CheckTypeEQ(occ.type(), CV_32FC1, "Compositor: occluder depth must be CV_32F");
                if (occ.size() != fsz && occ.size() != rsz)
                    CV_Error(Error::StsBadSize, cv::format("Compositor: occluder depth is %dx%d, "
                             "expected %dx%d or %dx%d", occ.cols, occ.rows, rsz.width,
                             rsz.height, fsz.width, fsz.height));
            }
            compositeThroughLens(frameArr, camera, [&](const Mat& black, const Camera& ideal,
                                                       Mat& layer, Mat* depth) {
                Mat idealOcc;
                if (!occ.empty())
                {
                    const int f = occ.size() == rsz ? k : 1;
                    const Camera occCam = supersampledCamera(camera, f);
                    const Camera gridCam = supersampledCamera(ideal, k);
                    const Size gsz(black.cols * k, black.rows * k);
                    if (occMap_.size() != gsz || occMapK_ != occCam.K ||
                        occMapGridK_ != gridCam.K || occMapD_ != camera.distortion)
                    {
                        // Render grid of the ideal view -> occluder pixel (cached per lens).
                        const Matx33d Hi = gridCam.K.inv();
                        occMap_.create(gsz, CV_32FC2);
                        parallel_for_(Range(0, gsz.height), [&](const Range& r) {
                            for (int y = r.start; y < r.end; y++)
                            {
                                Vec2f* row = occMap_.ptr<Vec2f>(y);
                                for (int x = 0; x < gsz.width; x++)
                                {
                                    const Vec3d n = Hi * Vec3d(x, y, 1);
                                    const Point2d p = detail::pixelOf(occCam.K,
                                        occCam.distortNormalized(Point2d(n[0], n[1])));
                                    row[x] = Vec2f((float)p.x, (float)p.y);
                                }
                            }
                        });
                        occMapK_ = occCam.K;
                        occMapGridK_ = gridCam.K;
                        occMapD_ = camera.distortion;
                    }
                    cv::remap(occ, idealOcc, occMap_, noArray(), INTER_NEAREST,
                              BORDER_CONSTANT, Scalar(std::numeric_limits<float>::infinity()));
                }
                composite(black, ideal, idealOcc, lensResult_, layer,
                          depth ? _OutputArray(*depth) : _OutputArray(noArray()));
            }, result, virtualLayer, depthOut);
            return;
        }
        const Mat frame = checkedFrame(frameArr, camera);
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
        const FramePlan pl = plan(camera, rsz);
        const Mat occRoi = (occ.empty() || pl.roi.area() == 0) ? Mat() : occ(pl.roi);
        compositeCore(frame, camera, pl, [&](const Rect&) { return occRoi; }, occ, result,
                      virtualLayer, depthOut);
    }

private:
    // Marks the inner (ideal view) composite of a lens frame: the shadow maps and the shadow
    // catcher are the outer call's.
    struct LensScope
    {
        bool& flag;
        explicit LensScope(bool& f) : flag(f) { flag = true; }
        ~LensScope() { flag = false; }
    };

    bool sunShadows() const { return params_.sun.enabled() && !meshes_.empty(); }

    // Params::sun, before a frame: the two shadow maps on one lattice over the boxes of the
    // virtual objects and of the clones' grids; the virtual objects' map rendered again only
    // when they, the sun or the lattice changed; the clones' for this frame (its patch set),
    // all +inf without clones. Both in the compositor's context (resized to the map).
    void prepareShadows(int frameIndex, const CloneSet* clones)
    {
        if (!gl_)
        {
            gl_.reset(new detail::GlContext(Size(64, 64)));
            glApi_.load();
        }
        else
            gl_->makeCurrent();
        uploadIfDirty();
        std::vector<Vec3d> pts;
        for (int c = 0; c < 8; c++)
            pts.push_back(boundsCorner(c));
        double voxel = 0;
        if (clones)
            for (const String& name : clones->objectNames())
            {
                Matx33d Rb;
                Vec3d o;
                clones->gridPose(name, Rb, o);
                const Vec3i n = clones->gridSize(name);
                const double v = clones->voxelSize(name);
                voxel = std::max(voxel, v);
                for (int c = 0; c < 8; c++)
                    pts.push_back(o + Rb * Vec3d((c & 1) ? n[0] * v : 0, (c & 2) ? n[1] * v : 0,
                                                 (c & 4) ? n[2] * v : 0));
            }
        detail::ShadowMap lay;
        lay.layout(params_.sun, pts);
        const bool same = virtualVersion_ == meshVersion_ && virtualMap_.size() == lay.size() &&
                          virtualMap_.cam.pp == lay.cam.pp && virtualMap_.cam.s == lay.cam.s &&
                          virtualMap_.cam.R == lay.cam.R && virtualMap_.cam.t == lay.cam.t &&
                          virtualMap_.zNear == lay.zNear && virtualMap_.zFar == lay.zFar;
        if (!same)
        {
            virtualMap_ = lay;
            virtualMap_.z = lay.z.clone();
            detail::renderShadowDepth(*gl_, virtualMap_, [&]() { drawDepthOnly(); });
            virtualMap_.finish();
            virtualVersion_ = meshVersion_;
        }
        // The clones' map depends on the frame only through the patch sets it shows (the
        // nearest key frame's, or the bracketing ones): consecutive frames between two key
        // frames share it, and it is rendered again only when that set, the clones (their
        // voxel counts, key frames and grids: what building, refining and adding key frames
        // change) or the lattice change. Splatting it was 58% of a 1080p composite's time.
        const String key = cloneMapKey(clones, frameIndex, voxel);
        const bool sameClones = cloneMapKey_ == key && cloneMap_.size() == lay.size() &&
                                cloneMap_.cam.pp == lay.cam.pp && cloneMap_.cam.s == lay.cam.s &&
                                cloneMap_.cam.R == lay.cam.R && cloneMap_.cam.t == lay.cam.t &&
                                cloneMap_.zNear == lay.zNear && cloneMap_.zFar == lay.zFar;
        if (sameClones)
            return;
        cloneMapKey_.clear();  // until the map is complete (an exception leaves no stale key)
        cloneMap_ = lay;
        cloneMap_.z = lay.z.clone();
        // Voxel splats hold voxel-centre depths: a receiver on a clone sits up to about a
        // voxel behind its own splat as the sun sees it.
        cloneMap_.extraBias = 1.5 * voxel;
        if (clones)
            for (const String& name : clones->objectNames())
            {
                clones->render(name, frameIndex, cloneMap_.cam, cloneMap_.size(), cloneMatte_,
                               shadowDepth_);
                cloneMap_.addDepth(shadowDepth_);
            }
        cloneMap_.finish();
        cloneMapKey_ = key;
    }

    //! What the clones' shadow map of a frame depends on besides the lattice (see above).
    static String cloneMapKey(const CloneSet* clones, int frameIndex, double voxel)
    {
        if (!clones)
            return "none";
        String k = cv::format("%p %.17g", (const void*)clones, voxel);
        // augocc's own sets count their changes; another implementation is fingerprinted by
        // what building, refining and adding key frames change (counting its voxels per frame).
        const detail::CloneSetImpl* impl = dynamic_cast<const detail::CloneSetImpl*>(clones);
        if (impl)
            k += cv::format(" v%llu", (unsigned long long)impl->version());
        for (const String& name : clones->objectNames())
        {
            if (impl)
            {
                for (int f : clones->patchFrames(name, frameIndex))
                    k += cv::format("|%s p%d", name.c_str(), f);
                continue;
            }
            const Vec3i n = clones->gridSize(name);
            Matx33d R;
            Vec3d o;
            clones->gridPose(name, R, o);
            k += cv::format("|%s %d %d %d %d %.17g %.17g %.17g %.17g", name.c_str(),
                            clones->voxelCount(name), n[0], n[1], n[2], clones->voxelSize(name),
                            o[0], o[1], o[2]);
            for (int f : clones->keyFrames(name))
                k += cv::format(" k%d", f);
            for (int f : clones->patchFrames(name, frameIndex))
                k += cv::format(" p%d", f);
        }
        return k;
    }

    /* The shadow catcher (lighting.hpp): the frame darkened where the virtual objects take the
    sun from the real surfaces, by ratio = (s + (1 - s) c V_all) / (s + (1 - s) c V_real), c =
    max(0, n . L): the nearest of the ground plane (Params::ground, normal `up`) and the clones
    (or the occluder depth), normals of the clones from their depth. Only where the virtual
    objects' shadow map can reach. */
    const Mat& catchShadows(const Mat& frame, const Camera& camera, int frameIndex,
                            const CloneSet* clones, const Mat& occ)
    {
        if (!params_.shadowCatcher || virtualMap_.occupied.area() == 0)
        {
            shadowFrame_ = frame;
            return shadowFrame_;
        }
        const Size fsz = frame.size();
        const float inf = std::numeric_limits<float>::infinity();
        const GroundFrame& gr = params_.ground;
        const Vec3d up = gr.up / cv::norm(gr.up);
        const Rect roi = catcherRoi(camera, fsz, up, gr.height);
        if (roi.area() == 0)
        {
            shadowFrame_ = frame;
            return shadowFrame_;
        }
        realZ_.create(fsz, CV_32F);
        realZ_.setTo(Scalar::all(inf));
        // Only realZ_(roi) is read below: the clones are drawn over the ROI alone, with the
        // camera shifted by its corner (the same pixels; a whole 1920x1080 frame per object
        // before). Through a lens the render's ideal view depends on the image's size: there
        // the whole frame.
        const Rect drawn = camera.hasDistortion() ? Rect(Point(), fsz) : roi;
        if (clones)
            for (const String& name : clones->objectNames())
            {
                clones->render(name, frameIndex, shiftedCamera(camera, drawn.tl()), drawn.size(),
                               cloneMatte_, cloneDepth_);
                Mat z = realZ_(drawn);
                cv::min(z, cloneDepth_, z);
            }
        else if (!occ.empty() && occ.size() == fsz)
            occ.copyTo(realZ_);
        else if (!occ.empty())
        {
            // The occluder at the render grid: the nearest of each pixel's samples.
            const int k = occ.cols / fsz.width;
            CV_CheckEQ(occ.size(), Size(fsz.width * k, fsz.height * k),
                       "Compositor: occluder depth size");
            parallel_for_(Range(0, fsz.height), [&](const Range& r) {
                for (int y = r.start; y < r.end; y++)
                    for (int x = 0; x < fsz.width; x++)
                    {
                        float m = inf;
                        for (int j = 0; j < k; j++)
                            for (int i = 0; i < k; i++)
                                m = std::min(m, occ.at<float>(y * k + j, x * k + i));
                        realZ_.at<float>(y, x) = m;
                    }
            });
        }
        groundMask_.create(fsz, CV_8U);
        groundMask_.setTo(Scalar(0));
        parallel_for_(Range(roi.y, roi.y + roi.height), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
            {
                float* z = realZ_.ptr<float>(y);
                uchar* g = groundMask_.ptr<uchar>(y);
                for (int x = roi.x; x < roi.x + roi.width; x++)
                {
                    g[x] = 0;
                    const Ray ray = camera.backproject(Point2d(x, y));
                    const double dn = up.dot(ray.direction);
                    if (std::abs(dn) < 1e-12)
                        continue;
                    const double lambda = (gr.height - up.dot(ray.origin)) / dn;
                    const double zg = camera.depth(ray.at(lambda));
                    if (zg > 0 && zg < z[x])
                    {
                        z[x] = (float)zg;
                        g[x] = 255;
                    }
                }
            }
        });
        Mat vReal, vAll, cosine;
        // Normals of the clones from one-pixel differences: a longer baseline over their
        // voxel-centre staircase (3 px) measured no better (doc/lighting.md).
        detail::depthVisibility(shiftedCamera(camera, roi.tl()), realZ_(roi), cloneMap_,
                                &virtualMap_, vReal, &vAll, &cosine, groundMask_(roi), up, true);
        frame.copyTo(shadowFrameBuf_);
        const float sky = (float)params_.sun.sky;
        parallel_for_(Range(0, roi.height), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
            {
                const float* va = vReal.ptr<float>(y);
                const float* vb = vAll.ptr<float>(y);
                const float* c = cosine.ptr<float>(y);
                uchar* o = shadowFrameBuf_.ptr<uchar>(roi.y + y) + 3 * roi.x;
                for (int x = 0; x < roi.width; x++)
                {
                    if (!(vb[x] < va[x]) || c[x] <= 0.f)
                        continue;
                    const float ratio = (sky + (1 - sky) * c[x] * vb[x]) /
                                        (sky + (1 - sky) * c[x] * va[x]);
                    for (int ch = 0; ch < 3; ch++)
                        o[3 * x + ch] = saturate_cast<uchar>(o[3 * x + ch] * ratio);
                }
            }
        });
        shadowFrame_ = shadowFrameBuf_;
        return shadowFrame_;
    }

    /* The frame rectangle where the virtual objects' shadow can fall on a real surface above
    the ground: the projections of their box's corners and of those corners carried down along
    the sun's rays to the ground plane (receivers lie between a caster and the ground), with the
    penumbra's reach; the whole frame when a point is behind a perspective camera. */
    Rect catcherRoi(const Camera& camera, Size fsz, const Vec3d& up, double height) const
    {
        const Vec3d L = params_.sun.direction / cv::norm(params_.sun.direction);
        const double lu = L.dot(up);
        if (!(lu > 1e-6))
            return Rect(Point(), fsz);
        double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
        double ppu = 0;
        for (int c = 0; c < 8; c++)
        {
            const Vec3d X = boundsCorner(c);
            const Vec3d pts[2] = {X, X - L * ((up.dot(X) - height) / lu)};
            for (const Vec3d& P : pts)
            {
                const double z = camera.depth(P);
                if (camera.model == PERSPECTIVE && !(z > 0))
                    return Rect(Point(), fsz);
                ppu = std::max(ppu, camera.pixelsPerUnit(z));
                const Point2d u = camera.project(P);
                x0 = std::min(x0, u.x);
                x1 = std::max(x1, u.x);
                y0 = std::min(y0, u.y);
                y1 = std::max(y1, u.y);
            }
        }
        // The penumbra's reach (the filter's taps, spread along the ground), and 2 px.
        const double m = 2 + (Sun::kPcfRadius + 2) * virtualMap_.texel * ppu / std::max(lu, 0.1);
        const Rect r(Point(std::max(0, cvFloor(x0 - m)), std::max(0, cvFloor(y0 - m))),
                     Point(std::min(fsz.width, cvCeil(x1 + m) + 1),
                           std::min(fsz.height, cvCeil(y1 + m) + 1)));
        return r.width > 0 && r.height > 0 ? r : Rect();
    }

    // The virtual samples read back (rgbaUp_, bottom-up, window depth depthUp_) shaded by the
    // sun's visibility against the clones and the virtual objects: ambient + V (lit - ambient).
    void shadeVirtual(const Camera& roiCam, double zNear, double zFar)
    {
        Mat z, zTop, vNone, vis, visUp;
        detail::windowDepthToCameraZ(roiCam, depthUp_, zNear, zFar, z);
        cv::flip(z, zTop, 0);
        detail::depthVisibility(roiCam, zTop, cloneMap_, &virtualMap_, vNone, &vis);
        cv::flip(vis, visUp, 0);
        detail::applyVisibility(rgbaUp_, ambUp_, visUp, rgbaUp_);
    }

    // A frame through a distorted lens: `pinhole` composites a black image of the ideal view
    // with the ideal camera (virtual layer: straight alpha, BGRA; depth when asked), the layer is
    // premultiplied, warped into the frame bilinearly (LensView::toFrame) over the rectangle it
    // covers, and blended over the frame; the depth is warped by the nearest ideal pixel.
    void compositeThroughLens(InputArray frameArr, const Camera& camera,
                              const std::function<void(const Mat&, const Camera&, Mat&, Mat*)>&
                                  pinhole,
                              OutputArray resultArr, OutputArray layerArr, OutputArray depthOut)
    {
        const Mat frame = checkedFrame(frameArr, camera);
        Ptr<const LensView> view = LensView::get(camera, frame.size());
        const Size isz = view->idealSize();
        if (lensBlack_.size() != isz)
            lensBlack_ = Mat(isz, CV_8UC3, Scalar::all(0));
        Mat layer, depth;
        pinhole(lensBlack_, view->idealCamera(camera), layer, depthOut.needed() ? &depth : nullptr);
        resultArr.create(frame.size(), CV_8UC3);
        Mat result = resultArr.getMat();
        frame.copyTo(result);
        Mat outLayer;
        if (layerArr.needed())
        {
            layerArr.create(frame.size(), CV_8UC4);
            outLayer = layerArr.getMat();
            outLayer.setTo(Scalar::all(0));
        }
        if (depthOut.needed())
            view->toFrame(depth, depthOut, INTER_NEAREST,
                          Scalar(std::numeric_limits<float>::infinity()));
        Mat alpha;
        cv::extractChannel(layer, alpha, 3);
        const Rect ar = cv::boundingRect(alpha);
        if (ar.area() == 0)
            return;
        // The frame rectangle that sees the covered ideal rectangle (its border, sampled).
        double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
        const int steps = 32;
        for (int i = 0; i <= steps; i++)
            for (int side = 0; side < 4; side++)
            {
                const double t = (double)i / steps;
                Point2d q;
                switch (side)
                {
                case 0: q = Point2d(ar.x - 1 + t * (ar.width + 1), ar.y - 1); break;
                case 1: q = Point2d(ar.x - 1 + t * (ar.width + 1), ar.y + ar.height); break;
                case 2: q = Point2d(ar.x - 1, ar.y - 1 + t * (ar.height + 1)); break;
                default: q = Point2d(ar.x + ar.width, ar.y - 1 + t * (ar.height + 1)); break;
                }
                const Point2d p = view->idealToFrame(q);
                x0 = std::min(x0, p.x);
                y0 = std::min(y0, p.y);
                x1 = std::max(x1, p.x);
                y1 = std::max(y1, p.y);
            }
        const Rect fr = Rect(Point(cvFloor(x0) - 2, cvFloor(y0) - 2),
                             Point(cvCeil(x1) + 3, cvCeil(y1) + 3)) &
                        Rect(Point(), frame.size());
        if (fr.area() == 0)
            return;
        // Premultiplied float layer over the covered rectangle (with a 1-pixel ring of zeros
        // for the bilinear taps), and the frame map shifted into it.
        const Rect pr = Rect(ar.x - 1, ar.y - 1, ar.width + 2, ar.height + 2) & Rect(Point(), isz);
        Mat pre(pr.size(), CV_32FC4);
        for (int y = 0; y < pr.height; y++)
        {
            const uchar* s = layer.ptr<uchar>(pr.y + y) + 4 * pr.x;
            Vec4f* d = pre.ptr<Vec4f>(y);
            for (int x = 0; x < pr.width; x++, s += 4)
            {
                const float a = s[3] * (1.f / 255.f);
                d[x] = Vec4f(s[0] * a, s[1] * a, s[2] * a, a);
            }
        }
        Mat map;
        view->frameMap()(fr).copyTo(map);
        map -= Scalar((float)pr.x, (float)pr.y);
        Mat warped;
        cv::remap(pre, warped, map, noArray(), INTER_LINEAR, BORDER_CONSTANT, Scalar::all(0));
        parallel_for_(Range(0, fr.height), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
            {
                const Vec4f* w = warped.ptr<Vec4f>(y);
                uchar* o = result.ptr<uchar>(fr.y + y) + 3 * fr.x;
                const uchar* f = frame.ptr<uchar>(fr.y + y) + 3 * fr.x;
                uchar* l = outLayer.empty() ? nullptr : outLayer.ptr<uchar>(fr.y + y) + 4 * fr.x;
                for (int x = 0; x < fr.width; x++, o += 3, f += 3)
                {
                    const Vec4f& v = w[x];
                    if (v[3] <= 0.f)
                        continue;
                    const float ia = 1.f - v[3];
                    for (int ch = 0; ch < 3; ch++)
                        o[ch] = saturate_cast<uchar>(v[ch] + f[ch] * ia);
                    if (l)
                    {
                        uchar* lp = l + 4 * x;
                        for (int ch = 0; ch < 3; ch++)
                            lp[ch] = saturate_cast<uchar>(v[ch] / v[3]);
                        lp[3] = saturate_cast<uchar>(255.f * v[3]);
                    }
                }
            }
        });
    }

    // What a frame needs before drawing: the depth range that holds the virtual objects, the
    // camera of the render grid and the part of that grid where the virtual objects can appear.
    struct FramePlan
    {
        double zNear = 0, zFar = 1;
        Camera rc;
        Rect roi;  // render grid, a multiple of k, so that it maps onto whole frame pixels
    };

    static Mat checkedFrame(InputArray frameArr, const Camera& camera)
    {
        Mat frame = frameArr.getMat();
        if (frame.empty())
            CV_Error(Error::StsBadArg, "Compositor: empty frame");
        CV_CheckTypeEQ(frame.type(), CV_8UC3, "Compositor: frame must be BGR CV_8UC3");
        camera.validate("Compositor camera");
        return frame;
    }

    FramePlan plan(const Camera& camera, Size rsz) const
    {
        FramePlan pl;
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
        chooseDepthRange(camera, zmin, zmax, pl.zNear, pl.zFar);
        pl.rc = supersampledCamera(camera, params_.supersample);
        // Only the part of the render grid where the virtual objects can appear is drawn, read
        // back and blended.
        pl.roi = meshes_.empty() ? Rect() : screenRoi(pl.rc, rsz, params_.supersample, pl.zNear);
        return pl;
    }

    // The camera of the sub-image whose top-left pixel is `corner` of the camera's image.
    static Camera shiftedCamera(const Camera& camera, Point corner)
    {
        Camera c = camera;
        if (camera.model == SCALED_ORTHOGRAPHIC)
            c.pp = Point2d(camera.pp.x - corner.x, camera.pp.y - corner.y);
        else
        {
            c.K(0, 2) = camera.K(0, 2) - corner.x;
            c.K(1, 2) = camera.K(1, 2) - corner.y;
            c.pp = Point2d(c.K(0, 2), c.K(1, 2));
        }
        return c;
    }

    // Bounding box, top-down in the ROI, of the samples the virtual objects cover in the
    // read-back colour (GL rows bottom-up).
    static Rect coveredRect(const Mat& rgbaUp)
    {
        Mat alpha;
        cv::extractChannel(rgbaUp, alpha, 3);
        const Rect r = cv::boundingRect(alpha);  // non-zero pixels of a CV_8U image
        if (r.area() == 0)
            return Rect();
        return Rect(r.x, rgbaUp.rows - r.y - r.height, r.width, r.height);
    }

    // Draws, reads back, resolves against the occluder and blends. occluderOf(cov): the
    // occluder depth over pl.roi (render grid), right at least in `cov`, the rectangle of pl.roi
    // the virtual objects cover (empty: nothing occludes); occFull: over the render grid, for
    // the depth output only (empty: nothing). The virtual objects are drawn at the render grid
    // (antialiasVirtual) or at the frame grid, each pixel's depth then tested against its k x k
    // occluder samples.
    void compositeCore(const Mat& frame, const Camera& camera, const FramePlan& pl,
                       const std::function<Mat(const Rect&)>& occluderOf, const Mat& occFull,
                       OutputArray result, OutputArray virtualLayer, OutputArray depthOut)
    {
        const int k = params_.supersample;
        const Size fsz = frame.size();
        const Size rsz = renderSize(fsz);
        // g: the grid the virtual objects are drawn at, in samples per frame pixel.
        const int g = params_.antialiasVirtual ? k : 1;
        const Size gsz(fsz.width * g, fsz.height * g);
        ensureContext(gsz);
        uploadIfDirty();
        const Rect roi(pl.roi.x / k * g, pl.roi.y / k * g, pl.roi.width / k * g,
                       pl.roi.height / k * g);
        const double zNear = pl.zNear, zFar = pl.zFar;

        // layerRoi_: frame grid, ROI only: premultiplied RGB + alpha, CV_32FC4, top-down.
        // zRoi_: render grid, ROI only: camera z of the virtual surface (+inf: none).
        // Buffers are members, reused from frame to frame.
        const bool needZ = depthOut.needed();
        if (roi.area() > 0)
        {
            const int winY = gsz.height - roi.y - roi.height;
            // A clear of the whole buffer (colour, depth and stencil together) is a fast clear in
            // llvmpipe; a scissored one draws a quad through the fragment shader. Only the ROI is
            // read, so either is right: the fast one while the ROI is a good part of the buffer.
            glClearColor(0, 0, 0, 0);
            glClearDepth(1.0);
            glClearStencil(0);
            const bool wholeClear = 4 * (double)roi.area() >= (double)gsz.area();
            if (wholeClear)
                glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
            glEnable(GL_SCISSOR_TEST);
            glScissor(roi.x, winY, roi.width, roi.height);
            if (!wholeClear)
                glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            glDisable(GL_LIGHTING);
            glDisable(GL_BLEND);
            glDisable(GL_DITHER);
            glEnable(GL_DEPTH_TEST);
            drawMeshes(g == k ? pl.rc : camera, gsz, zNear, zFar);
            // glReadPixels waits for the rasteriser itself: no glFinish. RGBA bytes are the
            // buffer's own format (a plain copy in Mesa); the channel order is handled in
            // resolve().
            rgbaUp_.create(roi.size(), CV_8UC4);
            depthUp_.create(roi.size(), CV_32F);
            glPixelStorei(GL_PACK_ALIGNMENT, 4);
            glReadPixels(roi.x, winY, roi.width, roi.height, GL_RGBA, GL_UNSIGNED_BYTE,
                         rgbaUp_.data);
            glReadPixels(roi.x, winY, roi.width, roi.height, GL_DEPTH_COMPONENT, GL_FLOAT,
                         depthUp_.data);
            if (sunShadows())
            {
                // The ambient-only pass over the same depth (the same fragments pass GL_LEQUAL),
                // mixed with the lit one by the sun's visibility of each virtual sample.
                glClear(GL_COLOR_BUFFER_BIT);
                glDepthMask(GL_FALSE);
                glDepthFunc(GL_LEQUAL);
                drawMeshes(g == k ? pl.rc : camera, gsz, zNear, zFar, true);
                glDepthMask(GL_TRUE);
                glDepthFunc(GL_LESS);
                ambUp_.create(roi.size(), CV_8UC4);
                glReadPixels(roi.x, winY, roi.width, roi.height, GL_RGBA, GL_UNSIGNED_BYTE,
                             ambUp_.data);
                shadeVirtual(shiftedCamera(g == k ? pl.rc : camera, roi.tl()), zNear, zFar);
            }
            glDisable(GL_SCISSOR_TEST);
            frameRoi_ = frame(Rect(roi.x / g, roi.y / g, roi.width / g, roi.height / g));
            const Rect cov = coveredRect(rgbaUp_);
            const Mat occRoi = occluderOf(g == k ? cov : Rect(cov.x * k, cov.y * k,
                                                              cov.width * k, cov.height * k));
            if (g == k)
                resolve(camera, rgbaUp_, depthUp_, occRoi, zNear, zFar, k, needZ, layerRoi_,
                        zRoi_);
            else
                resolveEdges(camera, rgbaUp_, depthUp_, occRoi, zNear, zFar, k, needZ,
                             layerRoi_, zRoi_);
        }
        const Rect froi(pl.roi.x / k, pl.roi.y / k, pl.roi.width / k, pl.roi.height / k);
        blend(frame, layerRoi_, froi, result, virtualLayer);
        frameRoi_ = Mat();
        if (needZ)
            writeDepth(occFull, zRoi_, pl.roi, rsz, fsz, k, depthOut);
    }

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
            if (g.keptIbo)
                glApi_.deleteBuffers(1, &g.keptIbo);
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
        const bool sunLit = params_.sun.enabled();
        const Vec3f sunL = sunLit ? Vec3f(params_.sun.direction / cv::norm(params_.sun.direction))
                                  : Vec3f();
        meshVersion_++;
        for (const Mesh& m : meshes_)
        {
            const size_t nv = m.vertices.size();
            std::vector<GpuVertex> verts(nv);
            const bool hasTex = !m.material.texture.empty() && m.texcoords.size() == nv;
            const bool hasColors = m.colors.size() == nv;
            cv::parallel_for_(Range(0, (int)nv), [&](const Range& r) {
                for (int i = r.start; i < r.end; i++)
                {
                    const Vec3f base = hasColors ? m.colors[i] : Vec3f(1, 1, 1);
                    const Vec3f c = sunLit ? detail::shadeColor(m.material, m.normals[i], base,
                                                                sunL)
                                           : detail::shadeColor(m.material, Vec3f(
                                                 params_.lightRotation * Vec3d(m.normals[i])),
                                                 base);
                    const Vec3f a = detail::ambientColor(m.material, base);
                    GpuVertex& g = verts[i];
                    g.x = m.vertices[i][0];
                    g.y = m.vertices[i][1];
                    g.z = m.vertices[i][2];
                    g.r = c[0];
                    g.g = c[1];
                    g.b = c[2];
                    g.u = hasTex ? m.texcoords[i][0] : 0.f;
                    g.v = hasTex ? m.texcoords[i][1] : 0.f;
                    g.ar = a[0];
                    g.ag = a[1];
                    g.ab = a[2];
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
            g.vertexCount = (GLuint)nv;
            g.cull = params_.cullBackFaces && closedOutward(m);
            if (g.cull)
            {
                const int nf = (int)m.faces.size();
                g.faceOrigin.resize(nf);
                g.faceNormal.resize(nf);
                cv::parallel_for_(Range(0, nf), [&](const Range& r) {
                    for (int i = r.start; i < r.end; i++)
                    {
                        const Vec3i& f = m.faces[i];
                        const Vec3d p0(m.vertices[f[0]]), p1(m.vertices[f[1]]),
                            p2(m.vertices[f[2]]);
                        const Vec3d n = (p1 - p0).cross(p2 - p0);
                        const double len = cv::norm(n);
                        g.faceOrigin[i] = m.vertices[f[0]];
                        g.faceNormal[i] = len > 0 ? Vec3f(n / len) : Vec3f(0, 0, 0);
                    }
                });
                glApi_.genBuffers(1, &g.keptIbo);
            }
            if (hasTex)
                g.texture = detail::uploadTexture(m.material.texture);
            gpu_.push_back(g);
        }
        glApi_.bindBuffer(kArrayBuffer, 0);
        glApi_.bindBuffer(kElementArrayBuffer, 0);
        dirty_ = false;
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
        return Vec3d((c & 1) ? boundsMax_[0] : boundsMin_[0],
                     (c & 2) ? boundsMax_[1] : boundsMin_[1],
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

    // The depth test against the real objects, per sample of the render grid, and the box
    // average to the frame grid: camera z of each virtual sample (from its window depth) against
    // the occluder's camera z, so that both compare in one metric whatever the camera model.
    // Output per frame pixel: the visible virtual colour (premultiplied) and coverage; with soft
    // edges and edgeRadius > 0, the visible fraction refined on the frame by a guided filter near
    // the occlusion boundary. zVirtual (render grid) is filled only when `needZ`.
    void resolve(const Camera& cam, const Mat& rgbaUp, const Mat& depthUp, const Mat& occ,
                 double zNear, double zFar, int k, bool needZ, Mat& layer, Mat& zVirtual)
    {
        const Size up = rgbaUp.size(), sz(up.width / k, up.height / k);
        const bool ortho = cam.model == SCALED_ORTHOGRAPHIC;
        const float inf = std::numeric_limits<float>::infinity();
        const bool refine = !occ.empty() && params_.edgeRadius > 0 && frameRoi_.data;
        if (needZ)
            zVirtual.create(up, CV_32F);
        layer.create(sz, CV_32FC4);
        // Visible fraction of the virtual coverage and the unoccluded premultiplied colour,
        // for the refinement only.
        if (refine)
        {
            visFrac_.create(sz, CV_32F);
            allColor_.create(sz, CV_32FC4);
        }
        const float inv = 1.f / (255.f * k * k);
        // Window depth d to camera z (the inverse of glProjection's depth row).
        const double zSum = zFar + zNear, zDiff = zFar - zNear, zProd2 = 2 * zFar * zNear;
        cv::parallel_for_(Range(0, sz.height), [&](const Range& r) {
            // Per frame-grid row: sums over the k x k samples of every pixel (integers, exact in
            // float whatever the order). vis: visible samples, tot: all covered samples.
            std::vector<float> sums(8 * (size_t)sz.width), zRow(up.width);
            for (int y = r.start; y < r.end; y++)
            {
                std::fill(sums.begin(), sums.end(), 0.f);
                for (int j = 0; j < k; j++)
                {
                    const int yu = y * k + j;  // top-down row of the render grid
                    const float* d = depthUp.ptr<float>(up.height - 1 - yu);
                    const uchar* c = rgbaUp.ptr<uchar>(up.height - 1 - yu);
                    const float* zo = occ.empty() ? nullptr : occ.ptr<float>(yu);
                    float* zv = needZ ? zVirtual.ptr<float>(yu) : zRow.data();
                    for (int x = 0; x < up.width; x++)
                    {
                        const uchar* cx = c + 4 * x;
                        if (cx[3] == 0)
                        {
                            zv[x] = inf;
                            continue;
                        }
                        const double ndc = 2.0 * d[x] - 1.0;
                        zv[x] = ortho ? (float)(0.5 * (ndc * zDiff + zSum))
                                      : (float)(zProd2 / (zSum - ndc * zDiff));
                        float* t = &sums[8 * (size_t)(x / k)];
                        t[4] += cx[2];
                        t[5] += cx[1];
                        t[6] += cx[0];
                        t[7] += 255.f;
                        if (zo && !(zv[x] < zo[x]))
                            continue;  // a real object is in front
                        t[0] += cx[2];
                        t[1] += cx[1];
                        t[2] += cx[0];
                        t[3] += 255.f;
                    }
                }
                Vec4f* out = layer.ptr<Vec4f>(y);
                for (int x = 0; x < sz.width; x++)
                {
                    const float* t = &sums[8 * (size_t)x];
                    // BGR premultiplied, in [0, 1].
                    out[x] = Vec4f(t[0] * inv, t[1] * inv, t[2] * inv, t[3] * inv);
                }
                if (refine)
                {
                    Vec4f* all = allColor_.ptr<Vec4f>(y);
                    float* vf = visFrac_.ptr<float>(y);
                    for (int x = 0; x < sz.width; x++)
                    {
                        const float* t = &sums[8 * (size_t)x];
                        all[x] = Vec4f(t[4] * inv, t[5] * inv, t[6] * inv, t[7] * inv);
                        vf[x] = t[7] > 0 ? t[3] / t[7] : 1.f;
                    }
                }
            }
        });
        if (refine)
            refineOcclusion(visFrac_, allColor_, layer);
    }

    // resolve() for virtual objects drawn at the frame grid (rgbaUp, depthUp: frame grid, GL rows
    // bottom-up) and the occluder at k x: a covered pixel's camera z is tested against its k x k
    // occluder samples, and its colour weighted by the fraction in front. zVirtual (render grid)
    // repeats the pixel's z over its samples.
    void resolveEdges(const Camera& cam, const Mat& rgbaUp, const Mat& depthUp, const Mat& occ,
                      double zNear, double zFar, int k, bool needZ, Mat& layer, Mat& zVirtual)
    {
        const Size sz = rgbaUp.size();
        const bool ortho = cam.model == SCALED_ORTHOGRAPHIC;
        const float inf = std::numeric_limits<float>::infinity();
        const bool refine = !occ.empty() && params_.edgeRadius > 0 && frameRoi_.data;
        if (needZ)
            zVirtual.create(sz.height * k, sz.width * k, CV_32F);
        layer.create(sz, CV_32FC4);
        if (refine)
        {
            visFrac_.create(sz, CV_32F);
            allColor_.create(sz, CV_32FC4);
        }
        const float inv255 = 1.f / 255.f, invSamples = 1.f / (float)(k * k);
        const double zSum = zFar + zNear, zDiff = zFar - zNear, zProd2 = 2 * zFar * zNear;
        cv::parallel_for_(Range(0, sz.height), [&](const Range& r) {
            for (int y = r.start; y < r.end; y++)
            {
                const float* d = depthUp.ptr<float>(sz.height - 1 - y);
                const uchar* c = rgbaUp.ptr<uchar>(sz.height - 1 - y);
                Vec4f* out = layer.ptr<Vec4f>(y);
                for (int x = 0; x < sz.width; x++)
                {
                    const uchar* cx = c + 4 * x;
                    float z = inf, frac = 0.f;
                    if (cx[3] != 0)
                    {
                        const double ndc = 2.0 * d[x] - 1.0;
                        z = ortho ? (float)(0.5 * (ndc * zDiff + zSum))
                                  : (float)(zProd2 / (zSum - ndc * zDiff));
                        int visible = k * k;
                        if (!occ.empty())
                            for (int j = 0; j < k; j++)
                            {
                                const float* zo = occ.ptr<float>(y * k + j) + x * k;
                                for (int i = 0; i < k; i++)
                                    visible -= zo[i] < z;  // a real object is in front
                            }
                        frac = visible * invSamples;
                    }
                    const Vec4f all(cx[2] * inv255, cx[1] * inv255, cx[0] * inv255,
                                    cx[3] != 0 ? 1.f : 0.f);
                    out[x] = all * frac;
                    if (refine)
                    {
                        allColor_.at<Vec4f>(y, x) = all;
                        visFrac_.at<float>(y, x) = cx[3] != 0 ? frac : 1.f;
                    }
                    if (needZ)
                        for (int j = 0; j < k; j++)
                        {
                            float* zv = zVirtual.ptr<float>(y * k + j) + x * k;
                            for (int i = 0; i < k; i++)
                                zv[i] = z;
                        }
                }
            }
        });
        if (refine)
            refineOcclusion(visFrac_, allColor_, layer);
    }

    // Soft occlusion edges beyond the supersampling: where a clone hides part of a virtual
    // object, the visible fraction m is re-estimated by a guided filter on the frame, in a band
    // of edgeRadius pixels around the occlusion boundary, so that the boundary follows the real
    // object's edge in the image (clones are only as exact as their voxels) and is as soft as
    // that edge. The refined colour is the visible colour plus (m' - m) times the unoccluded one.
    void refineOcclusion(const Mat& visFrac, const Mat& allColor, Mat& layer) const
    {
        const Size sz = visFrac.size();
        Mat alphaAll;
        cv::extractChannel(allColor, alphaAll, 3);
        Mat covered = alphaAll > 0;
        Mat hidden = (visFrac < 0.5f) & covered;
        if (cv::countNonZero(hidden) == 0)
            return;
        const int r = params_.edgeRadius;
        const Mat se = getStructuringElement(MORPH_ELLIPSE, Size(2 * r + 1, 2 * r + 1));
        Mat grown, shrunk;
        cv::dilate(hidden, grown, se);
        cv::erode(hidden, shrunk, se, Point(-1, -1), 1, BORDER_CONSTANT, Scalar(0));
        const Mat band = grown & ~shrunk & covered;
        if (cv::countNonZero(band) == 0)
            return;
        Mat guide, refined;
        frameRoi_.convertTo(guide, CV_32F, 1.0 / 255);
        cv::ximgproc::guidedFilter(guide, visFrac, refined, r, params_.edgeEps);
        cv::parallel_for_(Range(0, sz.height), [&](const Range& rr) {
            for (int y = rr.start; y < rr.end; y++)
            {
                const uchar* b = band.ptr<uchar>(y);
                const float* m = visFrac.ptr<float>(y);
                const float* q = refined.ptr<float>(y);
                const Vec4f* all = allColor.ptr<Vec4f>(y);
                Vec4f* out = layer.ptr<Vec4f>(y);
                for (int x = 0; x < sz.width; x++)
                {
                    if (!b[x])
                        continue;
                    const float mq = std::min(1.f, std::max(0.f, q[x]));
                    out[x] += (mq - m[x]) * all[x];
                    for (int c = 0; c < 4; c++)
                        out[x][c] = std::min(1.f, std::max(0.f, out[x][c]));
                }
            }
        });
    }

    // Every virtual triangle, geometry only (no culling: the sun sees other faces than the
    // camera), with the caller's matrices: the casters of the virtual objects' shadow map.
    void drawDepthOnly()
    {
        glDisable(GL_TEXTURE_2D);
        glEnableClientState(GL_VERTEX_ARRAY);
        for (const GpuMesh& g : gpu_)
        {
            glApi_.bindBuffer(kElementArrayBuffer, g.ibo);
            glApi_.bindBuffer(kArrayBuffer, g.vbo);
            glVertexPointer(3, GL_FLOAT, sizeof(GpuVertex), (const void*)offsetof(GpuVertex, x));
            glApi_.drawRangeElements(GL_TRIANGLES, 0, g.vertexCount - 1, g.indexCount,
                                     GL_UNSIGNED_INT, nullptr);
        }
        glDisableClientState(GL_VERTEX_ARRAY);
        glApi_.bindBuffer(kArrayBuffer, 0);
        glApi_.bindBuffer(kElementArrayBuffer, 0);
    }

    void drawMeshes(const Camera& cam, Size rsz, double zNear, double zFar, bool ambient = false)
    {
        const Matx44d P = detail::glProjection(cam, rsz, zNear, zFar).t();
        const Matx44d MV = detail::glModelView(cam).t();
        glMatrixMode(GL_PROJECTION);
        glLoadMatrixd(P.val);
        glMatrixMode(GL_MODELVIEW);
        glLoadMatrixd(MV.val);
        glDepthFunc(ambient ? GL_LEQUAL : GL_LESS);
        glDepthMask(ambient ? GL_FALSE : GL_TRUE);
        glEnableClientState(GL_VERTEX_ARRAY);
        glEnableClientState(GL_COLOR_ARRAY);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        // Window y points up like the viewer's up (glProjection), so a triangle that is
        // counter-clockwise seen from outside is counter-clockwise in the window when it faces
        // the camera.
        glFrontFace(GL_CCW);
        glCullFace(GL_BACK);
        for (size_t mi = 0; mi < gpu_.size(); mi++)
        {
            const GpuMesh& g = gpu_[mi];
            GLsizei indexCount = g.indexCount;
            if (g.cull)
            {
                glEnable(GL_CULL_FACE);
                frontFaces(g, cam, meshes_[mi].faces, keptFaces_);
                indexCount = (GLsizei)(3 * keptFaces_.size());
                if (indexCount == 0)
                    continue;
                glApi_.bindBuffer(kElementArrayBuffer, g.keptIbo);
                glApi_.bufferData(kElementArrayBuffer,
                                  (ptrdiff_t)(keptFaces_.size() * sizeof(Vec3i)),
                                  keptFaces_.data(), kStreamDraw);
            }
            else
            {
                glDisable(GL_CULL_FACE);
                glApi_.bindBuffer(kElementArrayBuffer, g.ibo);
            }
            glApi_.bindBuffer(kArrayBuffer, g.vbo);
            glVertexPointer(3, GL_FLOAT, sizeof(GpuVertex), (const void*)offsetof(GpuVertex, x));
            glColorPointer(3, GL_FLOAT, sizeof(GpuVertex),
                           ambient ? (const void*)offsetof(GpuVertex, ar)
                                   : (const void*)offsetof(GpuVertex, r));
            if (g.texture)
            {
                glEnable(GL_TEXTURE_2D);
                glBindTexture(GL_TEXTURE_2D, g.texture);
                glEnableClientState(GL_TEXTURE_COORD_ARRAY);
                glTexCoordPointer(2, GL_FLOAT, sizeof(GpuVertex),
                                  (const void*)offsetof(GpuVertex, u));
            }
            // The index range is known: Mesa need not scan the indices for it.
            glApi_.drawRangeElements(GL_TRIANGLES, 0, g.vertexCount - 1, indexCount,
                                     GL_UNSIGNED_INT, nullptr);
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

    // The faces of a culled mesh that may face the camera, in their order. The rasteriser would
    // cull the others anyway, but only after fetching and transforming their vertices and
    // assembling them: a plane test per face on the CPU costs far less. A face is dropped only
    // when it faces away by more than kEdgeOnCos (the cosine between its normal and the viewing
    // ray), so that the rasteriser still decides the nearly edge-on ones from its own window
    // coordinates and the pixels are exactly those of GL culling alone (tested). camera.validate()
    // guarantees det R = 1 and positive focal lengths, so no mirroring flips the facing.
    static void frontFaces(const GpuMesh& g, const Camera& cam, const std::vector<Vec3i>& faces,
                           std::vector<Vec3i>& kept)
    {
        const float kEdgeOnCos = 1e-2f;  // 0.6 deg: far above float rounding of the window area
        const int nf = (int)faces.size();
        const bool ortho = cam.model == SCALED_ORTHOGRAPHIC;
        const Vec3f c(cam.center());
        const Vec3f dir((float)cam.R(2, 0), (float)cam.R(2, 1), (float)cam.R(2, 2));
        // Fixed blocks (not thread chunks): the output does not depend on the thread count.
        const int kBlock = 8192;
        const int nb = (nf + kBlock - 1) / kBlock;
        std::vector<int> offset(nb + 1, 0);
        std::vector<uchar> keep(nf);
        cv::parallel_for_(Range(0, nb), [&](const Range& r) {
            for (int b = r.start; b < r.end; b++)
            {
                int count = 0;
                for (int i = b * kBlock, e = std::min(nf, i + kBlock); i < e; i++)
                {
                    const Vec3f& n = g.faceNormal[i];
                    bool back;
                    if (ortho)
                        back = n.dot(dir) > kEdgeOnCos;
                    else
                    {
                        const Vec3f d = g.faceOrigin[i] - c;  // viewing ray to the face
                        const float dn = d.dot(n);
                        back = dn > 0 && dn * dn > kEdgeOnCos * kEdgeOnCos * d.dot(d);
                    }
                    keep[i] = back ? 0 : 1;
                    count += keep[i];
                }
                offset[b + 1] = count;
            }
        });
        for (int b = 0; b < nb; b++)
            offset[b + 1] += offset[b];
        kept.resize(offset[nb]);
        cv::parallel_for_(Range(0, nb), [&](const Range& r) {
            for (int b = r.start; b < r.end; b++)
            {
                Vec3i* out = kept.data() + offset[b];
                for (int i = b * kBlock, e = std::min(nf, i + kBlock); i < e; i++)
                    if (keep[i])
                        *out++ = faces[i];
            }
        });
    }

    // result = frame * (1 - a) + premultiplied colour inside `roi` (frame grid); the frame
    // elsewhere. The output layer has straight alpha.
    static void blend(const Mat& frame, const Mat& layerRoi, const Rect& roi,
                      OutputArray resultArr, OutputArray layerArr)
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
                const Vec4f* c = layerRoi.ptr<Vec4f>(j);
                uchar* o = result.ptr<uchar>(y) + 3 * roi.x;
                uchar* l = layer.empty() ? nullptr : layer.ptr<uchar>(y) + 4 * roi.x;
                for (int x = 0; x < roi.width; x++, f += 3, o += 3)
                {
                    const Vec4f& v = c[x];
                    if (v[3] <= 0.f)
                        continue;
                    const float ia = 1.f - v[3];
                    for (int ch = 0; ch < 3; ch++)
                        o[ch] = saturate_cast<uchar>(255.f * v[ch] + f[ch] * ia);
                    if (l)
                    {
                        uchar* lp = l + 4 * x;
                        for (int ch = 0; ch < 3; ch++)
                            lp[ch] = saturate_cast<uchar>(255.f * v[ch] / v[3]);
                        lp[3] = saturate_cast<uchar>(255.f * v[3]);
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
    // Params::sun: the shadow maps (one lattice), the version of the uploaded meshes the
    // virtual one holds, and the catcher's buffers.
    detail::ShadowMap virtualMap_, cloneMap_;
    String cloneMapKey_;  // what cloneMap_ was rendered for (cloneMapKey()); empty: nothing
    int meshVersion_ = 0, virtualVersion_ = -1;
    bool insideLens_ = false;
    Mat ambUp_, realZ_, groundMask_, shadowFrame_, shadowFrameBuf_, shadowDepth_;
    Vec3d boundsMin_, boundsMax_;
    bool dirty_ = true;
    std::unique_ptr<detail::GlContext> gl_;
    GlBufferApi glApi_;
    std::vector<GpuMesh> gpu_;
    std::vector<Vec3i> keptFaces_;  // frontFaces() of the mesh being drawn (reused)
    Mat frameRoi_;  // the frame under the ROI, guide of the refinement (during composite())
    Mat rgbaUp_, depthUp_, zRoi_, layerRoi_, visFrac_, allColor_;  // per-frame buffers, reused
    Mat cloneOcc_, cloneDepth_, cloneMatte_;  // composite(..., clones, ...), reused
    // Through a lens: the ideal view's black background and discarded result; the occluder
    // overload's map from the ideal render grid to the occluder's pixels, and its lens.
    Mat lensBlack_, lensResult_, occMap_;
    Matx33d occMapK_, occMapGridK_;
    std::vector<double> occMapD_;
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
