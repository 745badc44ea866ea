// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SHADOW_HPP
#define OPENCV_AUGOCC_SHADOW_HPP

#include <functional>
#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/lighting.hpp"

/*
Shadow maps of a Sun (lighting.hpp), one implementation for the SceneSynthesizer's truth and the
Compositor, so that both cast the same penumbra on the same texel grid:

- The light's view is a SCALED_ORTHOGRAPHIC Camera looking along -L (from the sun), its axes a
  function of L alone; texel = Sun::penumbra / Sun::kPenumbraTexels world units (grown to keep the
  map within Sun::kMaxShadowMapSide). Texel centres lie on the fixed light-space lattice
  (i * texel, j * texel) whatever the casters' bounds, so two maps of one sun sample the same
  points.
- Depth is the light camera's z of the nearest caster (+inf: none), rendered through OSMesa in
  the caller's GlContext (or by CloneSet::render for clones).
- Visibility: percentage-closer filtering, the mean over (2 r + 1)^2 taps one texel apart of the
  bilinearly weighted depth comparison, r = Sun::kPcfRadius: the penumbra is (2 r + 1) texels =
  Sun::penumbra wide. A receiver is compared at its depth minus a slope-scaled bias,
  texel * (1.5 + (r + 1) * tan(theta)), theta the angle between its normal and L (tan capped at
  4), so that the PCF taps of a plane tilted from the light do not shadow the plane itself.
*/

namespace cv {
namespace augocc {
namespace detail {

class GlContext;

struct CV_EXPORTS ShadowMap
{
    Camera cam;            //!< the sun's orthographic view (pixels = texels)
    Mat z;                 //!< CV_32F light-space depth of the nearest caster, +inf where none
    double texel = 0;      //!< world units per texel
    Vec3d L;               //!< unit, towards the sun
    Rect occupied;         //!< bounding box of the finite texels (empty: no caster)
    double zNear = 0, zFar = 1;  //!< light-camera depth range that holds the casters
    /** Extra depth bias (world units) of a receiver compared with this map: casters whose
    depth is not their surface's (the clones' voxel splats hold voxel-centre depths: one voxel). */
    double extraBias = 0;

    /** @brief Lays out the map over the casters' points (world) for the sun; z all +inf. */
    void layout(const Sun& sun, const std::vector<Vec3d>& casterPoints);
    //! Size of the map, texels.
    Size size() const { return z.size(); }
    //! Folds another rendered depth of the same layout in (per texel minimum).
    void addDepth(const Mat& depth);
    //! Recomputes `occupied` after the depth is rendered.
    void finish();
    /** @brief Fraction of the sun a world point sees, [0, 1]; 1 outside the map.
    @param X the point.
    @param n its unit normal (zero: unknown, the largest bias). */
    float visibility(const Vec3d& X, const Vec3d& n) const;
    /** @brief Visibility against two maps of the same layout at once: `this` alone and the
    texel-wise minimum of `this` and `other` (the same taps), i.e. without and with other's
    casters. */
    void visibility2(const ShadowMap& other, const Vec3d& X, const Vec3d& n, float& alone,
                     float& both) const;
    //! True when a caster of this map is within the filter's reach of X (as the sun sees it).
    bool reaches(const Vec3d& X) const;
};

/** @brief The sun's visibility of every pixel of a camera-space depth map (CV_32F, +inf: none).
@param cam the camera of the depth map.
@param depth CV_32F camera-space z.
@param a a shadow map.
@param b optional second map of the same layout (nullptr: none).
@param va output CV_32F: visibility against `a` (1 where no surface).
@param vb optional output CV_32F: against `a` and `b` together.
@param cosine optional output CV_32F: max(0, n . L) of the surface (0 where none).
@param groundMask optional CV_8U: pixels whose normal is `up` (the real ground), not estimated.
@param up the ground's unit normal for groundMask.
@param onlyNearB with `b`: 1 in both outputs where `b` has no caster near the point (only the
change `b` makes is wanted; skips the filtering there).
@param normalStep surfaceFromDepth()'s step.
Normals from surfaceFromDepth(). Rows in parallel, deterministic. */
CV_EXPORTS void depthVisibility(const Camera& cam, const Mat& depth, const ShadowMap& a,
                                const ShadowMap* b, Mat& va, Mat* vb = nullptr,
                                Mat* cosine = nullptr, const Mat& groundMask = Mat(),
                                const Vec3d& up = Vec3d(0, 1, 0), bool onlyNearB = false,
                                int normalStep = 1);

/** @brief Shadowed colour of the light model (lighting.hpp): ambient + V (lit - ambient), per
channel of 8-bit images of one size (3 or 4 channels; a 4th channel is taken from `lit`).
@param lit the colour with the sun (V = 1).
@param ambient the colour without it (V = 0).
@param vis CV_32F visibility.
@param out output, lit's type (may be `lit`). */
CV_EXPORTS void applyVisibility(const Mat& lit, const Mat& ambient, const Mat& vis, Mat& out);

/** @brief Renders the depth of casters into map.z (minimum with what it holds) in `ctx`, which is
resized to the map (resize it back before rendering a frame). `draw` issues the draw calls with
the projection and model-view matrices of map.cam loaded and the depth test on. */
CV_EXPORTS void renderShadowDepth(GlContext& ctx, ShadowMap& map,
                                  const std::function<void()>& draw);

/** @brief World point and unit normal (facing the camera; zero where unknown) of every pixel of a
camera-space depth map (+inf: none, point NaN). Normals from the smaller of the one-sided depth
differences along x and y, so that a pixel next to a depth edge takes the side of its own
surface. Rows in parallel, deterministic.
@param step the differences' baseline, pixels: 1 for rendered surfaces; more for the clones'
voxel splats, whose depth is a staircase of voxel-centre depths (a one-pixel difference there
gives the step's normal, not the surface's). */
CV_EXPORTS void surfaceFromDepth(const Camera& cam, const Mat& depth, Mat& points, Mat& normals,
                                 int step = 1);

//! The corners of an axis-aligned box, for ShadowMap::layout().
CV_EXPORTS void appendBoxCorners(const Vec3d& lo, const Vec3d& hi, std::vector<Vec3d>& out);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
