// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_COMPOSITOR_SHADING_HPP
#define OPENCV_AUGOCC_COMPOSITOR_SHADING_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

// Lighting of virtual objects: ambient plus one directional light fixed in the world, Lambertian,
// evaluated per vertex (Gouraud), colour multiplied by the diffuse texture.
const Vec3f kLightDirection(0.3f, 1.0f, 0.5f);  // towards the light, world frame (y up)
const float kAmbientLight = 0.35f;
const float kDiffuseLight = 0.75f;

inline Vec3f normalizedLight(const Vec3f& d)
{
    const float n = (float)cv::norm(d);
    return n > 0 ? d * (1.f / n) : Vec3f(0, 1, 0);
}

//! Lit colour of a vertex: ambientLight * ambientColor + diffuseLight * max(0, n.L) * diffuseColor.
inline Vec3f shadeVertex(const Vec3f& diffuseColor, const Vec3f& ambientColor, const Vec3f& normal,
                         const Vec3f& lightDir, float ambientLight, float diffuseLight)
{
    const float nl = std::max(0.f, normal.dot(lightDir));
    Vec3f c;
    for (int k = 0; k < 3; k++)
        c[k] = std::min(1.f, ambientLight * ambientColor[k] + diffuseLight * nl * diffuseColor[k]);
    return c;
}

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
