// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"

#include <filesystem>
#include <fstream>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

TEST(Augocc_Scene, read_write_roundtrip)
{
    const std::string dir = tempDir("scene_rt");
    const std::string data = std::string(AUGOCC_SOURCE_DIR) + "/test/data/";
    const std::string path = writeText(dir, "scene.yml",
        "%YAML:1.0\n---\nobjects:\n"
        "  - { name: quad, mesh: \"" + data + "quad.obj\", position: [1, 2, 3],"
        " rotation: [0, 90, 0], scale: 2 }\n"
        "  - { shape: tree, behind: building, distance: 0.5, size: 0.3,"
        " material: { diffuse: [0.1, 0.9, 0.1] } }\n"
        "  - { name: textured, mesh: \"" + data + "quad.obj\", position: [0, 0, 0],"
        " material: { ambient: [0.2, 0.3, 0.4], texture: \"" + data + "quad_tex.png\" } }\n");
    const VirtualScene s = readScene(path);
    ASSERT_EQ(s.objects.size(), 3u);
    EXPECT_EQ(s.objects[0].name, "quad");
    EXPECT_EQ(s.objects[0].placement, SceneObject::PLACE_ABSOLUTE);
    EXPECT_EQ(s.objects[0].position, Vec3d(1, 2, 3));
    EXPECT_EQ(s.objects[0].scale, Vec3d(2, 2, 2));
    EXPECT_EQ(s.objects[1].placement, SceneObject::PLACE_BEHIND);
    EXPECT_EQ(s.objects[1].anchor, "building");
    EXPECT_EQ(s.objects[1].meshes.size(), 2u);  // trunk and foliage
    EXPECT_EQ(s.objects[1].meshes[0].material.diffuse, Vec3f(0.1f, 0.9f, 0.1f));
    // Absolute placement: T * R * S; the quad's (1, 0, 0) corner -> R_y(90) * 2 -> (0, 0, -2).
    EXPECT_EQ(s.objects[2].meshes[0].material.ambient, Vec3f(0.2f, 0.3f, 0.4f));
    EXPECT_FALSE(s.objects[2].meshes[0].material.texture.empty());
    VirtualScene first = s;
    first.objects.resize(1);
    const std::vector<Matx44d> poses = scenePoses(first, Reconstruction(), nullptr);
    // The helper needs clones.
    EXPECT_THROW(scenePoses(s, Reconstruction(), nullptr), cv::Exception);
    const Vec4d p = poses[0] * Vec4d(1, 0, 0, 1);
    const double kTol = 1e-9;
    EXPECT_NEAR(p[0], 1, kTol);
    EXPECT_NEAR(p[1], 2, kTol);
    EXPECT_NEAR(p[2], 1, kTol);
    const std::string out = dir + "/again.yml";
    writeScene(out, s);
    const VirtualScene s2 = readScene(out);
    ASSERT_EQ(s2.objects.size(), 3u);
    EXPECT_EQ(s2.objects[0].position, Vec3d(1, 2, 3));
    EXPECT_EQ(s2.objects[1].distance, 0.5);
    EXPECT_EQ(s2.objects[1].shape, "tree");
    // The material overrides survive the round trip (a float written by FileStorage reads back
    // exactly), for every mesh of the object, and a mesh without overrides gets none.
    EXPECT_TRUE(s2.objects[0].material.empty());
    for (const Mesh& m : s2.objects[1].meshes)
        EXPECT_EQ(m.material.diffuse, Vec3f(0.1f, 0.9f, 0.1f));
    EXPECT_TRUE(s2.objects[1].material.hasDiffuse);
    EXPECT_FALSE(s2.objects[1].material.hasAmbient);
    EXPECT_EQ(s2.objects[2].meshes[0].material.ambient, Vec3f(0.2f, 0.3f, 0.4f));
    EXPECT_TRUE(std::filesystem::equivalent(s2.objects[2].material.texture,
                                            s.objects[2].material.texture));
    ASSERT_FALSE(s2.objects[2].meshes[0].material.texture.empty());
    EXPECT_EQ(cv::norm(s2.objects[2].meshes[0].material.texture,
                           s.objects[2].meshes[0].material.texture, NORM_INF), 0);
}

TEST(Augocc_Scene, bad_arg)
{
    const std::string dir = tempDir("scene_bad");
    const char* bad[] = {
        "objects:\n  - { shape: dome, colour: [1, 0, 0] }\n",           // unknown key
        "objects:\n  - { shape: pyramid }\n",                            // unknown shape
        "objects:\n  - { position: [0, 0, 0] }\n",                       // no mesh or shape
        "objects:\n  - { shape: dome, position: [0, 0] }\n",             // wrong vector
        "objects:\n  - { shape: dome, behind: a, in_front_of: b }\n",   // two helpers
        "objects:\n  - { shape: dome, scale: -1 }\n",                    // bad scale
        "objects:\n  - { mesh: corrupt_missing.obj }\n",                 // missing mesh
        "things: []\n",                                                  // unknown top key
    };
    int i = 0;
    for (const char* text : bad)
    {
        const std::string path = writeText(dir, cv::format("bad%d.yml", i++),
                                           std::string("%YAML:1.0\n---\n") + text);
        try
        {
            readScene(path);
            ADD_FAILURE() << "accepted: " << text;
        }
        catch (const cv::Exception& e)
        {
            // The scene file, or for a missing mesh the mesh file, is named.
            EXPECT_TRUE(e.err.find(".yml") != std::string::npos ||
                        e.err.find(".obj") != std::string::npos) << e.err;
        }
    }
    // The unknown key is named.
    try
    {
        readScene(dir + "/bad0.yml");
    }
    catch (const cv::Exception& e)
    {
        EXPECT_NE(e.err.find("colour"), std::string::npos) << e.err;
        EXPECT_EQ(e.code, Error::StsParseError);
    }
}

// Ground and placement helpers on a synthetic scene (true cameras, y up, ground y = 0).
TEST(Augocc_Scene, accuracy_ground_and_helpers)
{
    SceneSynthesizer::Params sp;
    sp.frames = 12;
    sp.numKeyFrames = 4;
    sp.imageSize = Size(320, 240);
    SyntheticScene scene;
    SceneSynthesizer::create(sp)->synthesize(scene);
    const GroundFrame g = estimateGround(scene.groundTruth);
    // Up within 2 degrees of +y and the ground height near 0 (ground points are noise-free).
    const double kUpTolDeg = 2.0, kHeightTol = 0.05;
    EXPECT_LT(std::acos(std::min(1.0, g.up.dot(Vec3d(0, 1, 0)))) * 180 / CV_PI, kUpTolDeg);
    EXPECT_NEAR(g.height, 0.0, kHeightTol);
    EXPECT_TRUE(g.fromPlane);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(scene.groundTruth, scene.keyFrameMasks);
    VirtualScene vs;
    for (int placement : {SceneObject::PLACE_BEHIND, SceneObject::PLACE_IN_FRONT})
    {
        SceneObject o;
        o.name = placement == SceneObject::PLACE_BEHIND ? "behind" : "front";
        o.shape = "box";
        o.meshes = proceduralShape("box");
        o.placement = placement;
        o.anchor = "building";
        o.size = 0.2;
        vs.objects.push_back(o);
    }
    const std::vector<Mesh> placed = placeScene(vs, scene.groundTruth, clones.get());
    ASSERT_EQ(placed.size(), 2u);
    // The building spans z in [1.5, 3.5] (the camera looks from +z): "behind" is at smaller z,
    // "in front" at larger z; both stand on the ground.
    Vec3f lo, hi;
    placed[0].bounds(lo, hi);
    EXPECT_LT(hi[2], 1.5f);
    EXPECT_NEAR(lo[1], 0.f, 0.15f);
    placed[1].bounds(lo, hi);
    EXPECT_GT(lo[2], 3.5f);
    EXPECT_NEAR(lo[1], 0.f, 0.15f);
    // A helper naming an unknown clone is an error.
    vs.objects[0].anchor = "castle";
    EXPECT_THROW(placeScene(vs, scene.groundTruth, clones.get()), cv::Exception);
}

} // namespace
} // namespace opencv_test
