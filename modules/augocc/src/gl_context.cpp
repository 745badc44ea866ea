// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "gl_context.hpp"

#include <GL/osmesa.h>
#include <GL/gl.h>

namespace cv {
namespace augocc {
namespace detail {

GlContext::GlContext(Size size)
{
    CV_CheckGT(size.width, 0, "GL buffer width");
    CV_CheckGT(size.height, 0, "GL buffer height");
    const int attribs[] = {
        OSMESA_FORMAT, OSMESA_RGBA,
        OSMESA_DEPTH_BITS, 24,
        OSMESA_STENCIL_BITS, 8,
        OSMESA_ACCUM_BITS, 0,
        OSMESA_PROFILE, OSMESA_COMPAT_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION, 3,
        OSMESA_CONTEXT_MINOR_VERSION, 0,
        0
    };
    OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx)
        ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
    if (!ctx)
        CV_Error(Error::StsError, "OSMesa: cannot create an offscreen OpenGL context");
    ctx_ = ctx;
    resize(size);
}

GlContext::~GlContext()
{
    if (ctx_)
        OSMesaDestroyContext(static_cast<OSMesaContext>(ctx_));
}

void GlContext::makeCurrent()
{
    if (!OSMesaMakeCurrent(static_cast<OSMesaContext>(ctx_), buffer_.data(), GL_UNSIGNED_BYTE,
                           size_.width, size_.height))
        CV_Error(Error::StsError, "OSMesa: cannot make the context current");
    // Rows of the buffer bottom-up, as OpenGL: readColor() flips them.
    OSMesaPixelStore(OSMESA_Y_UP, 1);
    glViewport(0, 0, size_.width, size_.height);
}

void GlContext::resize(Size size)
{
    size_ = size;
    buffer_.assign((size_t)size.width * size.height * 4, 0);
    makeCurrent();
}

void GlContext::readColor(OutputArray bgr)
{
    Mat rgba;
    readColorAlpha(rgba);
    cv::cvtColor(rgba, bgr, COLOR_BGRA2BGR);
}

void GlContext::readColorAlpha(OutputArray bgra)
{
    makeCurrent();
    glFinish();
    Mat rgba(size_, CV_8UC4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
    Mat flipped;
    cv::flip(rgba, flipped, 0);
    cv::cvtColor(flipped, bgra, COLOR_RGBA2BGRA);
}

void GlContext::readDepth(OutputArray depth01)
{
    makeCurrent();
    glFinish();
    Mat d(size_, CV_32F);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, size_.width, size_.height, GL_DEPTH_COMPONENT, GL_FLOAT, d.data);
    cv::flip(d, depth01, 0);
}

Matx44d glProjection(const Camera& cam, Size imageSize, double zNear, double zFar)
{
    CV_Assert(zFar > zNear);
    const double W = imageSize.width, H = imageSize.height;
    // Window x = u + 0.5, window y = H - (v + 0.5); NDC = 2 * window / size - 1.
    if (cam.model == SCALED_ORTHOGRAPHIC)
    {
        const double s = cam.s;
        const double cx = cam.pp.x, cy = cam.pp.y;
        return Matx44d(2 * s / W, 0, 0, 2 * (cx + 0.5) / W - 1,
                       0, -2 * s / H, 0, 1 - 2 * (cy + 0.5) / H,
                       0, 0, 2 / (zFar - zNear), -(zFar + zNear) / (zFar - zNear),
                       0, 0, 0, 1);
    }
    const Matx33d& K = cam.K;
    return Matx44d(2 * K(0, 0) / W, 2 * K(0, 1) / W, 2 * (K(0, 2) + 0.5) / W - 1, 0,
                   0, -2 * K(1, 1) / H, 1 - 2 * (K(1, 2) + 0.5) / H, 0,
                   0, 0, (zFar + zNear) / (zFar - zNear), -2 * zFar * zNear / (zFar - zNear),
                   0, 0, 1, 0);
}

Matx44d glModelView(const Camera& cam)
{
    const Matx33d& R = cam.R;
    return Matx44d(R(0, 0), R(0, 1), R(0, 2), cam.t[0],
                   R(1, 0), R(1, 1), R(1, 2), cam.t[1],
                   R(2, 0), R(2, 1), R(2, 2), cam.t[2],
                   0, 0, 0, 1);
}

void windowDepthToCameraZ(const Camera& cam, InputArray depth01, double zNear, double zFar,
                          OutputArray z)
{
    Mat d = depth01.getMat();
    CV_CheckTypeEQ(d.type(), CV_32FC1, "window depth must be CV_32F");
    z.create(d.size(), CV_32F);
    Mat out = z.getMat();
    const bool ortho = cam.model == SCALED_ORTHOGRAPHIC;
    const float inf = std::numeric_limits<float>::infinity();
    for (int y = 0; y < d.rows; y++)
    {
        const float* src = d.ptr<float>(y);
        float* dst = out.ptr<float>(y);
        for (int x = 0; x < d.cols; x++)
        {
            const double w = src[x];
            if (w >= 1.0)
            {
                dst[x] = inf;
                continue;
            }
            const double ndc = 2 * w - 1;
            if (ortho)
                dst[x] = (float)(0.5 * (ndc * (zFar - zNear) + zFar + zNear));
            else
                dst[x] = (float)(2 * zFar * zNear / ((zFar + zNear) - ndc * (zFar - zNear)));
        }
    }
}

} // namespace detail
} // namespace augocc
} // namespace cv
