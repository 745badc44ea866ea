// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_LIGHTING_HPP
#define OPENCV_AUGOCC_LIGHTING_HPP

#include <opencv2/core.hpp>

/*
The sun of a shot (issue 19): a directional light with cast shadows and a sky (ambient) share,
shared by the SceneSynthesizer (its ground truth) and the Compositor (shadows both ways).

Light model, the shading convention of src/shading.hpp extended by a visibility:
  colour = base * (ambient + diffuse * V * max(0, n . L))
where L = Sun::direction, V in [0, 1] the fraction of the sun the point sees (shadow map with
percentage-closer filtering). A real surface of the footage is Lambertian with albedo rho under
sky irradiance s and sun irradiance (1 - s) (s = Sun::sky), so its pixel is
  I = rho * (s + (1 - s) * V * max(0, n . L)),
and a virtual caster that takes the sun from it changes the visibility from V_real (the clones'
shadows, already in the frame) to V_all (the clones' and the virtual objects'): the frame is
multiplied there by the shadow-catcher ratio
  ratio = (s + (1 - s) * c * V_all) / (s + (1 - s) * c * V_real),  c = max(0, n . L)
(1 where c == 0: a face turned away from the sun has no shadow to receive). The synthesizer's
real materials follow the same split (ambient = s (a + d), diffuse = (1 - s) (a + d)), so that
the ratio is exact for its footage.
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief A sun: directional light, shadows, sky share. Disabled (the default, zero direction):
the fixed light of the shading convention, no shadows. */
struct CV_EXPORTS Sun
{
    //! Unit vector from a surface point towards the sun, world frame of the scene. Zero: no sun.
    Vec3d direction = Vec3d(0, 0, 0);
    //! Sky (ambient) share of the irradiance of a surface facing the sun, in [0, 1).
    double sky = 0.4;
    /** Width of the soft shadow edge (penumbra), world units, > 0. The shadow map's texel is
    penumbra / kPenumbraTexels, so the penumbra and the map's resolution are one setting. */
    double penumbra = 0.1;
    //! Percentage-closer filtering: (2 r + 1)^2 bilinear taps, r = kPcfRadius; the penumbra
    //! spans kPenumbraTexels = 2 r + 1 shadow-map texels.
    static constexpr int kPcfRadius = 2;
    //! Texels across the penumbra (see penumbra).
    static constexpr int kPenumbraTexels = 2 * kPcfRadius + 1;
    //! Largest shadow map side, texels; beyond it the texel grows (the penumbra with it).
    static constexpr int kMaxShadowMapSide = 4096;

    //! True when direction is set (non-zero).
    bool enabled() const { return direction.dot(direction) > 0; }
    //! Throws StsBadArg naming `what` when direction is neither zero nor finite, sky is outside
    //! [0, 1) or penumbra is not positive.
    void validate(const String& what = "Sun") const;
};

/** @brief Solar position after NOAA's "General Solar Position Calculations" (NOAA Global
Monitoring Division; the fractional-year series of Spencer 1971 for the equation of time and
the declination): accurate to about 0.2 degrees between latitudes 60 S and 60 N, no refraction.
@param year calendar year (UTC).
@param month 1-12.
@param day 1-31.
@param hourUtc hours since midnight UTC, [0, 24).
@param latitudeDeg degrees, north positive, [-90, 90].
@param longitudeDeg degrees, east positive, [-180, 180].
@param azimuthDeg output: degrees clockwise from north (east = 90), [0, 360).
@param elevationDeg output: degrees above the horizon (negative: below).
Throws StsOutOfRange naming the argument out of range. */
CV_EXPORTS void solarPosition(int year, int month, int day, double hourUtc, double latitudeDeg,
                              double longitudeDeg, double& azimuthDeg, double& elevationDeg);

//! @}

} // namespace augocc
} // namespace cv

#endif
