// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_COMPOSITOR_SHADING_HPP
#define OPENCV_AUGOCC_COMPOSITOR_SHADING_HPP

#include <opencv2/core.hpp>
#include "opencv2/augocc/mesh.hpp"

namespace cv {
namespace augocc {
namespace detail {

// The shading convention of the synthesizer (src/shading.hpp on its branch): one directional
// light fixed in the world, ambient = the material's ambient colour, Lambertian one-sided
// diffuse, per vertex, times the texture.
const Vec3f kLightDirection(0.3526f, 0.8060f, 0.5037f);

inline Vec3f shadeColor(const Material& material, const Vec3f& normal,
                        const Vec3f& base = Vec3f(1, 1, 1))
{
    const float ndotl = std::max(0.f, normal.dot(kLightDirection));
    Vec3f c;
    for (int k = 0; k < 3; k++)
        c[k] = std::min(1.f, std::max(0.f, base[k] * (material.ambient[k] +
                                                      material.diffuse[k] * ndotl)));
    return c;
}

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
