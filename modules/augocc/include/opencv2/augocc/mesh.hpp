// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_MESH_HPP
#define OPENCV_AUGOCC_MESH_HPP

#include <vector>
#include <opencv2/core.hpp>

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

//! Surface appearance of a mesh: ambient + diffuse colour (RGB in [0, 1]) and an optional texture.
struct CV_EXPORTS Material
{
    Vec3f diffuse = Vec3f(0.8f, 0.8f, 0.8f);  //!< RGB diffuse colour, multiplied by the texture
    Vec3f ambient = Vec3f(0.2f, 0.2f, 0.2f);  //!< RGB ambient colour
    Mat texture;                              //!< optional BGR CV_8UC3 diffuse texture
};

/** @brief A triangle mesh in world (or object) coordinates: the virtual objects of the compositor
and the real objects of the SceneSynthesizer.

Optional per-vertex arrays are either empty or as long as `vertices`. Triangles are
counter-clockwise seen from outside (right-handed), normals point outwards.
*/
struct CV_EXPORTS Mesh
{
    std::vector<Vec3f> vertices;    //!< vertex positions
    std::vector<Vec3i> faces;       //!< vertex indices, three per triangle
    std::vector<Vec3f> normals;     //!< optional per-vertex normals
    std::vector<Vec2f> texcoords;   //!< optional per-vertex texture coordinates (u right, v up)
    std::vector<Vec3f> colors;      //!< optional per-vertex RGB colours in [0, 1]
    Material material;              //!< appearance of the whole mesh

    //! True when the mesh has no triangle.
    bool empty() const { return faces.empty(); }
    //! Applies a 4x4 similarity/affine transform to vertices (and normals, re-normalised).
    void transform(const Matx44d& M);
    //! Recomputes smooth per-vertex normals from the faces (area weighted).
    void computeNormals();
    //! Axis-aligned bounds; throws if the mesh has no vertex.
    void bounds(Vec3f& minCorner, Vec3f& maxCorner) const;
    //! Appends another mesh (its material is dropped; per-vertex arrays are kept only when both
    //! have them).
    void append(const Mesh& other);

    //! Axis-aligned box between two corners (flat normals, per-face texture coordinates).
    static Mesh box(const Vec3f& minCorner, const Vec3f& maxCorner);
    //! Closed cylinder around the y axis from y0 to y1 (y is up in these helpers).
    static Mesh cylinder(float radius, float y0, float y1, int segments = 32);
    //! Closed cone around the y axis, base radius at y0, apex at y1.
    static Mesh cone(float radius, float y0, float y1, int segments = 32);
    //! Sphere of a radius about the origin.
    static Mesh sphere(float radius, int segments = 32, int rings = 16);
    //! Hemisphere dome (y >= 0) closed by a disk at y = 0.
    static Mesh dome(float radius, int segments = 32, int rings = 12);
};

/** @brief Writes a mesh as binary little-endian PLY (vertices, faces, per-vertex colours and
normals when present). A mesh with no faces is written as a point cloud, an empty mesh as a valid
PLY with no element. Atomic (temporary + rename). */
CV_EXPORTS void writeMeshPly(const String& path, const Mesh& mesh);

/** @brief Loads every mesh of a file through Assimp (OBJ, PLY, glTF/GLB, and the other formats
Assimp reads), with materials (diffuse and ambient colour, diffuse texture) and node transforms
applied. Throws StsParseError naming the file when it does not parse or holds no triangle. */
CV_EXPORTS std::vector<Mesh> loadMeshes(const String& path);

//! @}

} // namespace augocc
} // namespace cv

#endif
