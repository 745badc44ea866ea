// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SHADING_HPP
#define OPENCV_AUGOCC_SHADING_HPP

#include <opencv2/core.hpp>
#include "opencv2/augocc/mesh.hpp"

/*
The one lighting convention of augocc, shared by the SceneSynthesizer (frames and the
renderWithVirtual() ground truth) and the Compositor, so that a virtual object composited into a
synthesized frame can be compared with the synthesizer's ground truth pixel for pixel.

- One directional light fixed in the WORLD (a sun), direction kLightDirection = the unit vector
  from a surface point TOWARDS the light (y is up: the light is above, in front of the default
  camera (+z) and to its right (+x)). Light colour white, intensity 1.
- Ambient term: the material's ambient colour (no separate ambient light; ambient intensity 1).
- Lambertian diffuse, one-sided: colour = base * (ambient + diffuse * max(0, n . L)), each channel
  clamped to [0, 1], where base = vertex colour (white without colours) and n the unit normal.
- The result is multiplied by the diffuse texture (GL_MODULATE) when the material has one.
- Shading is per vertex (Gouraud), evaluated once on the CPU since the light is fixed in the
  world; flat faces (separate vertices per face) therefore shade exactly flat.
- Texture coordinates: u right, v up (v = 0 is the bottom row of the texture image).
*/

namespace cv {
namespace augocc {
namespace detail {

//! Unit vector towards the light, world coordinates (y up). normalize(0.35, 0.8, 0.5).
const Vec3f kLightDirection(0.347833f, 0.795046f, 0.496904f);

/** @brief Lit colour (RGB in [0, 1]) of a surface point, per the convention above, before the
texture: base * (ambient + diffuse * max(0, n . L)), clamped.
@param material ambient and diffuse colours.
@param normal unit surface normal (world).
@param base vertex colour (white when the mesh has none).
*/
Vec3f shadeColor(const Material& material, const Vec3f& normal,
                 const Vec3f& base = Vec3f(1, 1, 1));
//! shadeColor() under another light (a Sun of lighting.hpp): unit vector towards it, world.
Vec3f shadeColor(const Material& material, const Vec3f& normal, const Vec3f& base,
                 const Vec3f& light);
/** @brief The ambient part alone, base * ambient clamped: the colour of a point the light does
not reach (the shadowed colour of lighting.hpp's model, V = 0). */
Vec3f ambientColor(const Material& material, const Vec3f& base = Vec3f(1, 1, 1));
/** @brief The material of a real surface of the footage under a sun with sky share `sky`
(lighting.hpp): ambient = sky (a + d), diffuse = (1 - sky) (a + d), so that the ambient-only
colour over the lit colour is the shadow-catcher ratio of the light model. */
Material sunSplitMaterial(const Material& material, double sky);

/** @brief Uploads `image` as a GL_TEXTURE_2D of the current OpenGL context and returns its name
(the caller deletes it with glDeleteTextures, in that context).

The one texture upload of the compositor and the synthesizer, so that both sample a texture
identically: RGB8 from a grey, BGR or BGRA image (16-bit scaled by 1/257, floating point by 255),
bottom row first (texture coordinates have v up), and every mipmap level down to 1x1 made on the
CPU by INTER_AREA halving (deterministic, rather than whatever the driver's generator does);
trilinear minification, linear magnification, GL_REPEAT in s and t. Leaves GL_UNPACK_ALIGNMENT at 1
and no texture bound.
@param image the texture image, as Material::texture holds it.
*/
unsigned uploadTexture(const Mat& image);

/** @brief A mesh ready to draw in the current OpenGL context (fixed pipeline, vertex arrays):
per-vertex lit colours computed once (shadeColor), texture uploaded by uploadTexture().

Make the owning context current before creating, drawing or destroying it (the texture belongs
to that context). Normals are computed (smooth) when the mesh has none.
*/
class GlMesh
{
public:
    /** @param mesh the mesh (copied).
    @param alpha alpha written with every fragment (the synthesizer encodes object labels in it).
    */
    explicit GlMesh(const Mesh& mesh, float alpha = 1.f);
    /** @param mesh the mesh (copied).
    @param alpha as above.
    @param light unit vector towards the light (a Sun's direction), world. */
    GlMesh(const Mesh& mesh, float alpha, const Vec3f& light);
    ~GlMesh();
    GlMesh(const GlMesh&) = delete;
    GlMesh& operator=(const GlMesh&) = delete;

    //! Draws lit and textured (ambientOnly: the ambient colours, ambientColor(): in shadow).
    //! Expects depth test and matrices set by the caller.
    void draw(bool ambientOnly = false) const;
    //! Draws geometry only, with the current glColor (no texture, no lighting): masks, IDs.
    void drawFlat() const;
    size_t triangleCount() const { return indices_.size() / 3; }

private:
    std::vector<float> positions_;  // xyz
    void init(const Mesh& mesh, float alpha, const Vec3f& light);
    std::vector<float> colors_;     // rgba
    std::vector<float> ambient_;    // rgba, ambient only
    std::vector<float> texcoords_;  // uv (empty without texture)
    std::vector<unsigned> indices_;
    unsigned texture_ = 0;
};

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
