// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_COMPOSITOR_HPP
#define OPENCV_AUGOCC_COMPOSITOR_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/clone_builder.hpp"
#include "opencv2/augocc/lighting.hpp"
#include "opencv2/augocc/mesh.hpp"
#include "opencv2/augocc/scene.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief The camera of the same view on a pixel grid `factor` times finer.

Pixel centres follow the @ref augocc_conventions_pixels "pixel conventions" (origin at the
centre of the top-left pixel): pixel (u, v) of the original grid covers the `factor` x `factor`
block whose centres are `factor * (u + 0.5) - 0.5 +- ...`, so s (or fx, fy, skew) is multiplied
by `factor` and the principal point becomes `factor * (c + 0.5) - 0.5`. Rendering with the
returned camera at `factor` times the size and box-averaging down gives an anti-aliased image of
the original view.
*/
CV_EXPORTS Camera supersampledCamera(const Camera& camera, int factor);

/** @brief Inserts virtual objects into frames of a real scene so that real objects hide them
(the paper's Section 7), headless through OSMesa.

Per frame: the video frame is the background; the clones of the real objects go into the depth
buffer only; the virtual objects are drawn with the depth test and simple lighting (ambient plus
one directional light, per-vertex normals, material colour and diffuse texture: the convention of
the SceneSynthesizer). Depth is camera-space z in every camera model, so clones and virtual objects
compare in one metric. The virtual camera is the frame's reconstructed camera.

Soft occlusion edges: with Params::supersample = k > 1 the virtual layer is rendered against the
clone depth at k times the frame size and box-averaged down, so a pixel that a real object covers
in part gets the matching fraction of the virtual object (and the virtual objects' own outlines
are anti-aliased). k = 1 is the paper's hard per-pixel depth test.

One OpenGL context is created on first use and reused for every frame; meshes are uploaded once
into vertex buffer objects. A Compositor must be used from one thread (OSMesa contexts are per
thread); it is not itself parallel, but its CPU stages use cv::parallel_for_.
*/
class CV_EXPORTS Compositor : public Algorithm
{
public:
    //! Compositing parameters; the defaults are the initializers.
    struct CV_EXPORTS Params
    {
        /** Supersampling factor k of the depth test against the real objects, in [1, 8]: the
        occluder depth is sampled k x k per pixel. 1 is the paper's hard depth test; higher
        resolves the coverage of a pixel at an occlusion edge more finely, at k^2 the occluder
        samples (the edge error is measured in doc/compositor.md). */
        int supersample = 3;
        /** With supersample k > 1, also render the virtual objects at k x: anti-aliases their
        own outlines against the frame, at k^2 the rasterising cost. Off, the virtual layer is
        rendered at the frame's resolution and only the depth test against the real objects
        runs at k x k samples per pixel (each against the pixel's virtual depth), which is what
        makes occlusion edges soft: the same edge error for a fraction of the time
        (doc/compositor.md). */
        bool antialiasVirtual = false;
        /** Cull the back faces of meshes that are closed and outward-oriented (checked per mesh
        when uploaded; such back faces are never visible, so no pixel changes): halves the
        triangles the rasteriser sets up. */
        bool cullBackFaces = true;
        /** Optional occlusion-edge refinement: radius in frame pixels of a guided filter
        (cv::ximgproc::guidedFilter, guided by the frame) that re-estimates the visible fraction
        of the virtual objects around the occlusion boundary, so that it follows the real
        object's edge in the image; in [0, 16], 0 = off. Off by default: on richly textured
        real objects the filter follows the texture and measured worse than the supersampled
        depth test alone (doc/compositor.md); it helps on plain objects with clean edges. */
        int edgeRadius = 0;
        //! Regularisation of that guided filter, guide in [0, 1], > 0 (higher smooths more,
        //! follows the frame's edges less).
        double edgeEps = 1e-2;
        /** Rotation from the world of the reconstruction to the shading frame (y up) in which
        the light of the shading convention is fixed; identity: the world is y up, as the
        synthesizer's. For a reconstruction, use the rows (right, up, back) of its
        estimateGround() frame, so that the sun shines from above whatever the world's axes. */
        Matx33d lightRotation = Matx33d::eye();
        /** The sun (lighting.hpp; resolveSun() makes it from a scene file). Disabled (the
        default): the fixed light of the shading convention, no shadows. Set: the virtual objects
        are lit by it (lightRotation is not used) with shadows both ways, in shadow maps
        rendered in the compositor's OpenGL context: the virtual objects darken the real
        ground (`ground`) and the clones by the shadow-catcher ratio of the light model, with
        a soft edge Sun::penumbra wide (percentage-closer filtering); the clones (the
        overload with a CloneSet) and the virtual objects themselves shade the virtual
        objects. Through a lens the real ground and the clones are shaded in the frame. */
        Sun sun;
        //! The real ground (estimateGround()): receives the virtual objects' shadows.
        GroundFrame ground;
        //! Shadows of the virtual objects on the real ground and clones (with a sun).
        bool shadowCatcher = true;
    };

    /** @brief Creates a compositor (the OpenGL context is made on first use).
    @param params compositing parameters; throws as setParams() does when they are invalid.
    */
    static Ptr<Compositor> create(const Params& params);
    //! Creates a compositor with default Params.
    static Ptr<Compositor> create();
    //! The current parameters.
    virtual Params getParams() const = 0;
    /** @brief Sets the parameters.
    @param params the parameters; StsBadArg when one is outside the range its field states.
    */
    virtual void setParams(const Params& params) = 0;

    /** @brief Sets the virtual objects, in the world frame of the reconstruction. The meshes are
    copied, lit once (the light is fixed in the world: the shading convention of src/shading.hpp,
    base * (ambient + diffuse * max(0, n.L)), times the texture) and uploaded to the GPU on the
    next frame. Meshes without normals get smooth normals. An empty list composites nothing.
    Throws StsBadArg on a face index out of range. */
    virtual void setVirtualObjects(const std::vector<Mesh>& meshes) = 0;

    //! Size at which composite() wants the occluder depth: frameSize * supersample.
    virtual Size renderSize(Size frameSize) const = 0;

    /** @brief Composites one frame given the depth of the real occluders.
    @param frame the video frame, BGR CV_8UC3.
    @param camera the frame's camera (frame size grid).
    @param occluderDepth CV_32F camera-space z of the real objects (+inf where none), either at
    renderSize(frame.size()) (soft edges) or at the frame size (nearest-upsampled, hard edges).
    Empty: nothing occludes.
    @param result output BGR CV_8UC3, the frame with the virtual objects inserted.
    @param virtualLayer optional output BGRA CV_8UC4: the visible virtual objects with straight
    (not premultiplied) alpha = their coverage; result = frame * (1 - a) + layer * a.
    @param depth optional output CV_32F at the frame size: camera-space z of the nearest of the
    occluders and the virtual objects (the minimum over each pixel's samples), +inf where none.
    */
    virtual void composite(InputArray frame, const Camera& camera, InputArray occluderDepth,
                           OutputArray result, OutputArray virtualLayer = noArray(),
                           OutputArray depth = noArray()) = 0;

    /** @brief Composites one frame with the clones of the real objects as occluders: every
    clone is rendered at renderSize() with supersampledCamera(), with the patch set of `frameIndex`,
    and the nearest clone surface is the occluder depth.
    @param frame the video frame, BGR CV_8UC3.
    @param frameIndex frame index (selects the clones' patch sets).
    @param camera the frame's camera.
    @param clones the clones.
    @param result output BGR CV_8UC3.
    @param virtualLayer optional output, see the other overload.
    @param depth optional output, see the other overload.
    */
    virtual void composite(InputArray frame, int frameIndex, const Camera& camera,
                           const CloneSet& clones, OutputArray result,
                           OutputArray virtualLayer = noArray(),
                           OutputArray depth = noArray()) = 0;
};

//! @}

} // namespace augocc
} // namespace cv

#endif
