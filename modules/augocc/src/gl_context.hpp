// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_GL_CONTEXT_HPP
#define OPENCV_AUGOCC_GL_CONTEXT_HPP

#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"

namespace cv {
namespace augocc {
namespace detail {

// Internal API, exported (CV_EXPORTS) only so that the tests and the perf suite can reach it.

/** @brief Offscreen OpenGL through OSMesa (Mesa llvmpipe, compatibility profile), shared by the
synthesizer and the compositor. No display is needed.

The context renders into an RGBA8 buffer with a 24-bit depth buffer. It is current on the thread
that created it or called makeCurrent() last (OSMesa contexts are per thread). gl* calls must bind
to libOSMesa: never link libGL into the library or the CLI (PITFALLS.md).
*/
class CV_EXPORTS GlContext
{
public:
    //! Creates a context of the given size; throws StsError when OSMesa fails.
    explicit GlContext(Size size);
    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    //! Makes the context current on this thread, sets the viewport to the whole buffer.
    void makeCurrent();
    //! Resizes the buffer (makes the context current).
    void resize(Size size);
    Size size() const { return size_; }

    //! Reads the colour buffer as BGR CV_8UC3, top image row first.
    void readColor(OutputArray bgr);
    //! Reads the colour buffer as BGRA CV_8UC4, top image row first.
    void readColorAlpha(OutputArray bgra);
    //! Reads the depth buffer as window depth in [0, 1], CV_32F, top image row first.
    void readDepth(OutputArray depth01);

private:
    void* ctx_ = nullptr;
    Size size_;
    std::vector<unsigned char> buffer_;
};

/** @brief OpenGL projection matrix (row-major here; transpose for glLoadMatrixd) that maps
camera-space points of `cam` to clip space so that the rasterized pixel centres match the
contract's pixel convention exactly (pixel (0,0) centre = window (0.5, H - 0.5)), with depth
increasing with camera-space z, near/far at zNear/zFar (camera-space z). The camera looks along +z
(the contract), so use glDepthFunc(GL_LESS) and no face culling, or cull with care: the y flip
reverses winding. */
CV_EXPORTS Matx44d glProjection(const Camera& cam, Size imageSize, double zNear, double zFar);

//! World-to-camera 4x4 of a camera (row-major).
CV_EXPORTS Matx44d glModelView(const Camera& cam);

/** @brief Converts window depth d in [0, 1] read back from a buffer rendered with
glProjection(cam, ..., zNear, zFar) into camera-space z. d == 1 (the cleared far plane) becomes
+infinity. */
CV_EXPORTS void windowDepthToCameraZ(const Camera& cam, InputArray depth01, double zNear, double zFar,
                          OutputArray z);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
