// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

std::string dataFile(const std::string& name)
{
    return std::string(AUGOCC_SOURCE_DIR) + "/test/data/" + name;
}

// Material colours are stored as float in the files: exact to float precision.
const float kColorEps = 1e-5f;

TEST(Augocc_LoadMeshes, obj_with_material_and_texture)
{
    const std::vector<Mesh> meshes = loadMeshes(dataFile("quad.obj"));
    ASSERT_EQ(meshes.size(), 1u);
    const Mesh& m = meshes[0];
    EXPECT_EQ(m.faces.size(), 2u);
    EXPECT_EQ(m.vertices.size(), 4u);
    ASSERT_EQ(m.texcoords.size(), m.vertices.size());
    ASSERT_EQ(m.normals.size(), m.vertices.size());
    for (size_t i = 0; i < m.vertices.size(); i++)
    {
        // Texture coordinates equal the vertex x, y (v up, as written).
        EXPECT_NEAR(m.texcoords[i][0], m.vertices[i][0], kColorEps);
        EXPECT_NEAR(m.texcoords[i][1], m.vertices[i][1], kColorEps);
        EXPECT_NEAR(m.normals[i][2], 1.f, kColorEps);
    }
    EXPECT_NEAR(m.material.diffuse[0], 0.8f, kColorEps);
    EXPECT_NEAR(m.material.diffuse[1], 0.6f, kColorEps);
    EXPECT_NEAR(m.material.diffuse[2], 0.4f, kColorEps);
    EXPECT_NEAR(m.material.ambient[0], 0.1f, kColorEps);
    EXPECT_NEAR(m.material.ambient[2], 0.3f, kColorEps);
    ASSERT_FALSE(m.material.texture.empty());
    EXPECT_EQ(m.material.texture.size(), Size(4, 4));
    // BGR: the top row is red, the bottom row blue.
    EXPECT_EQ(m.material.texture.at<Vec3b>(0, 0), Vec3b(0, 0, 255));
    EXPECT_EQ(m.material.texture.at<Vec3b>(3, 0), Vec3b(255, 0, 0));
    // Faces counter-clockwise seen from +z (the normal's side).
    for (const Vec3i& f : m.faces)
    {
        const Vec3f n = (m.vertices[f[1]] - m.vertices[f[0]]).cross(m.vertices[f[2]] -
                                                                    m.vertices[f[0]]);
        EXPECT_GT(n[2], 0.f);
    }
}

TEST(Augocc_LoadMeshes, ply_with_vertex_colors)
{
    const std::vector<Mesh> meshes = loadMeshes(dataFile("tetra.ply"));
    ASSERT_EQ(meshes.size(), 1u);
    const Mesh& m = meshes[0];
    EXPECT_EQ(m.faces.size(), 4u);
    ASSERT_EQ(m.colors.size(), m.vertices.size());
    ASSERT_EQ(m.normals.size(), m.vertices.size());  // generated (the file has none)
    // Every vertex of the file appears with its colour.
    int found = 0;
    for (size_t i = 0; i < m.vertices.size(); i++)
        if (norm(m.vertices[i] - Vec3f(0, 0, 0)) < 1e-6)
        {
            EXPECT_NEAR(m.colors[i][0], 1.f, kColorEps);
            EXPECT_NEAR(m.colors[i][1], 0.f, kColorEps);
            found++;
        }
    EXPECT_GE(found, 1);
}

TEST(Augocc_LoadMeshes, gltf_node_transforms_and_base_color)
{
    const std::vector<Mesh> meshes = loadMeshes(dataFile("triangle_nodes.gltf"));
    ASSERT_EQ(meshes.size(), 1u);
    const Mesh& m = meshes[0];
    ASSERT_EQ(m.vertices.size(), 3u);
    // Node chain: translate (10, 0, 0) then scale 2: (0,0,0) (1,0,0) (0,1,0) -> (10,0,0)
    // (12,0,0) (10,2,0).
    Vec3f lo, hi;
    m.bounds(lo, hi);
    EXPECT_NEAR(lo[0], 10.f, 1e-5f);
    EXPECT_NEAR(hi[0], 12.f, 1e-5f);
    EXPECT_NEAR(hi[1], 2.f, 1e-5f);
    EXPECT_NEAR(m.material.diffuse[0], 0.2f, kColorEps);
    EXPECT_NEAR(m.material.diffuse[1], 0.4f, kColorEps);
    EXPECT_NEAR(m.material.diffuse[2], 0.6f, kColorEps);
}

TEST(Augocc_LoadMeshes, bad_arg)
{
    try
    {
        loadMeshes(dataFile("corrupt.ply"));
        ADD_FAILURE() << "a corrupt PLY was accepted";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_EQ(e.code, Error::StsParseError);
        EXPECT_NE(e.err.find("corrupt.ply"), std::string::npos) << e.err;
    }
    EXPECT_THROW(loadMeshes(dataFile("no_such_mesh.obj")), cv::Exception);
    // A file that is not a mesh at all.
    try
    {
        loadMeshes(dataFile("quad_tex.png"));
        ADD_FAILURE() << "a PNG was accepted as a mesh";
    }
    catch (const cv::Exception& e)
    {
        EXPECT_EQ(e.code, Error::StsParseError);
    }
}

} // namespace
} // namespace opencv_test
