// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"

#include <cstring>
#include <filesystem>
#include <fstream>

namespace opencv_test {
namespace {
using namespace cv;
using namespace cv::augocc;

const double kPi = 3.14159265358979323846;
// Float32 vertex positions: volumes and normals agree with the analytic values to ~1e-6
// relative; 1e-4 leaves a wide margin.
const double kVolumeRelTol = 1e-4;
const double kNormalTol = 1e-4;

// Signed volume by the divergence theorem: positive for a closed mesh whose triangles are
// counter-clockwise seen from outside.
double signedVolume(const Mesh& m)
{
    double v = 0;
    for (const Vec3i& f : m.faces)
    {
        const Vec3d a(m.vertices[f[0]]), b(m.vertices[f[1]]), c(m.vertices[f[2]]);
        v += a.dot(b.cross(c)) / 6.0;
    }
    return v;
}

// Every face's geometric normal points away from `centre` and agrees with its vertex normals.
void expectOutwardCCW(const Mesh& m, const Vec3d& centre, const std::string& what)
{
    ASSERT_EQ(m.normals.size(), m.vertices.size()) << what;
    int bad = 0, badNormals = 0;
    for (const Vec3i& f : m.faces)
    {
        const Vec3d a(m.vertices[f[0]]), b(m.vertices[f[1]]), c(m.vertices[f[2]]);
        const Vec3d n = (b - a).cross(c - a);
        if (n.dot((a + b + c) / 3.0 - centre) <= 0)
            bad++;
        for (int k = 0; k < 3; k++)
            if (n.dot(Vec3d(m.normals[f[k]])) <= 0)
                badNormals++;
    }
    EXPECT_EQ(bad, 0) << what << ": faces not counter-clockwise seen from outside";
    EXPECT_EQ(badNormals, 0) << what << ": vertex normals against the face winding";
    for (const Vec3f& n : m.normals)
        EXPECT_NEAR(cv::norm(n), 1.0, kNormalTol) << what;
    if (!m.texcoords.empty())
    {
        EXPECT_EQ(m.texcoords.size(), m.vertices.size()) << what;
    }
}

TEST(Augocc_Mesh, procedural_shapes)
{
    const Mesh box = Mesh::box(Vec3f(1, 2, 3), Vec3f(-1, 0, 0));
    EXPECT_EQ(box.faces.size(), (size_t)12);
    expectOutwardCCW(box, Vec3d(0, 1, 1.5), "box");
    EXPECT_NEAR(signedVolume(box), 2 * 2 * 3, 12 * kVolumeRelTol);

    const int n = 24;
    const double polyArea = 0.5 * n * std::sin(2 * kPi / n);  // unit-radius n-gon
    const Mesh cyl = Mesh::cylinder(2.f, -1.f, 3.f, n);
    expectOutwardCCW(cyl, Vec3d(0, 1, 0), "cylinder");
    EXPECT_NEAR(signedVolume(cyl), polyArea * 4 * 4, 16 * polyArea * kVolumeRelTol);

    const Mesh cone = Mesh::cone(1.5f, 0.f, 2.f, n);
    expectOutwardCCW(cone, Vec3d(0, 0.5, 0), "cone");
    EXPECT_NEAR(signedVolume(cone), polyArea * 2.25 * 2 / 3, polyArea * kVolumeRelTol * 10);

    const Mesh sphere = Mesh::sphere(2.f, 32, 16);
    expectOutwardCCW(sphere, Vec3d(0, 0, 0), "sphere");
    const double vs = signedVolume(sphere), exact = 4.0 / 3 * kPi * 8;
    EXPECT_GT(vs, 0.95 * exact);  // inscribed polyhedron: a little smaller
    EXPECT_LT(vs, exact);

    const Mesh dome = Mesh::dome(1.f, 32, 12);
    expectOutwardCCW(dome, Vec3d(0, 0.3, 0), "dome");
    const double vd = signedVolume(dome), hemi = 2.0 / 3 * kPi;
    EXPECT_GT(vd, 0.95 * hemi);
    EXPECT_LT(vd, hemi);
    Vec3f lo, hi;
    dome.bounds(lo, hi);
    EXPECT_NEAR(lo[1], 0.f, 1e-6);
    EXPECT_NEAR(hi[1], 1.f, 1e-6);
}

TEST(Augocc_Mesh, transform_append_bounds)
{
    Mesh m = Mesh::box(Vec3f(0, 0, 0), Vec3f(1, 2, 3));
    // Rotation about y by 90 degrees, scale 2, translation (5, 0, 0).
    const Matx44d M(0, 0, 2, 5, 0, 2, 0, 0, -2, 0, 0, 0, 0, 0, 0, 1);
    m.transform(M);
    Vec3f lo, hi;
    m.bounds(lo, hi);
    EXPECT_NEAR(lo[0], 5, 1e-5);
    EXPECT_NEAR(hi[0], 11, 1e-5);
    EXPECT_NEAR(lo[1], 0, 1e-5);
    EXPECT_NEAR(hi[1], 4, 1e-5);
    EXPECT_NEAR(lo[2], -2, 1e-5);
    EXPECT_NEAR(hi[2], 0, 1e-5);
    expectOutwardCCW(m, Vec3d(8, 2, -1), "transformed box");
    EXPECT_NEAR(signedVolume(m), 6 * 8, 48 * kVolumeRelTol);

    // A mirror keeps the triangles counter-clockwise seen from outside.
    Mesh mirrored = Mesh::box(Vec3f(0, 0, 0), Vec3f(1, 1, 1));
    mirrored.transform(Matx44d(-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1));
    expectOutwardCCW(mirrored, Vec3d(-0.5, 0.5, 0.5), "mirrored box");
    EXPECT_GT(signedVolume(mirrored), 0);

    // computeNormals on a sphere: smooth normals = radial direction.
    Mesh s = Mesh::sphere(1.f, 24, 12);
    const std::vector<Vec3f> before = s.normals;
    s.normals.clear();
    s.computeNormals();
    ASSERT_EQ(s.normals.size(), before.size());
    double worst = 0;
    for (size_t i = 0; i < before.size(); i++)
    {
        // Pole and seam vertices are not shared by all their triangles: skip them.
        const size_t column = i % 25;
        if (std::abs(s.vertices[i][1]) < 0.99f && column != 0 && column != 24)
            worst = std::max(worst, cv::norm(s.normals[i] - before[i]));
    }
    EXPECT_LT(worst, 0.05);

    // append: indices offset, per-vertex arrays kept when both have them, dropped otherwise.
    Mesh a = Mesh::box(Vec3f(0, 0, 0), Vec3f(1, 1, 1));
    a.material.diffuse = Vec3f(1, 0, 0);
    Mesh b = Mesh::cylinder(1.f, 0.f, 1.f, 8);
    b.material.diffuse = Vec3f(0, 1, 0);
    const size_t na = a.vertices.size(), fa = a.faces.size();
    Mesh ab = a;
    ab.append(b);
    EXPECT_EQ(ab.vertices.size(), na + b.vertices.size());
    EXPECT_EQ(ab.faces.size(), fa + b.faces.size());
    EXPECT_EQ(ab.faces[fa], b.faces[0] + Vec3i((int)na, (int)na, (int)na));
    EXPECT_EQ(ab.normals.size(), ab.vertices.size());
    EXPECT_EQ(ab.texcoords.size(), ab.vertices.size());
    EXPECT_EQ(ab.material.diffuse, Vec3f(1, 0, 0));
    b.texcoords.clear();
    ab = a;
    ab.append(b);
    EXPECT_TRUE(ab.texcoords.empty());
    Mesh empty;
    empty.append(a);
    EXPECT_EQ(empty.faces, a.faces);
}

TEST(Augocc_Mesh, bad_arg)
{
    Mesh empty;
    Vec3f lo, hi;
    EXPECT_THROW(empty.bounds(lo, hi), cv::Exception);
    EXPECT_THROW(Mesh::cylinder(-1.f, 0.f, 1.f), cv::Exception);
    EXPECT_THROW(Mesh::cone(1.f, 1.f, 0.f), cv::Exception);
    EXPECT_THROW(Mesh::sphere(1.f, 2, 2), cv::Exception);
    Mesh m = Mesh::box(Vec3f(0, 0, 0), Vec3f(1, 1, 1));
    EXPECT_THROW(m.transform(Matx44d::zeros()), cv::Exception);
    const std::string dir = tempDir("ply");
    // An empty mesh is a valid PLY with no element (an empty patch set of the clone builder).
    EXPECT_NO_THROW(writeMeshPly(dir + "/empty.ply", empty));
    std::ifstream in(dir + "/empty.ply", std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("element vertex 0"), std::string::npos);
    EXPECT_EQ(text.find("element face"), std::string::npos);
    EXPECT_EQ(text.substr(text.size() - 11), "end_header\n");
    Mesh broken = m;
    broken.faces.push_back(Vec3i(0, 1, 99));
    EXPECT_THROW(writeMeshPly(dir + "/broken.ply", broken), cv::Exception);
    EXPECT_FALSE(std::filesystem::exists(dir + "/broken.ply"));
}

// Minimal reader for the PLY files writeMeshPly writes (to check their bytes).
struct PlyData
{
    std::string header;
    std::vector<char> body;
};

PlyData readPly(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t end = content.find("end_header\n");
    PlyData d;
    if (end == std::string::npos)
        return d;
    d.header = content.substr(0, end + 11);
    d.body.assign(content.begin() + end + 11, content.end());
    return d;
}

TEST(Augocc_Mesh, ply_round_trip)
{
    const std::string dir = tempDir("ply");
    Mesh m = Mesh::box(Vec3f(0, 0, 0), Vec3f(1, 2, 3));
    m.colors.assign(m.vertices.size(), Vec3f(1, 0.5f, 0));
    writeMeshPly(dir + "/box.ply", m);
    PlyData d = readPly(dir + "/box.ply");
    EXPECT_NE(d.header.find("format binary_little_endian 1.0"), std::string::npos);
    EXPECT_NE(d.header.find("element vertex 24"), std::string::npos);
    EXPECT_NE(d.header.find("property float nx"), std::string::npos);
    EXPECT_NE(d.header.find("property uchar red"), std::string::npos);
    EXPECT_NE(d.header.find("element face 12"), std::string::npos);
    const size_t vsize = 6 * 4 + 3, fsize = 1 + 3 * 4;
    ASSERT_EQ(d.body.size(), 24 * vsize + 12 * fsize);
    for (size_t i = 0; i < 24; i++)
    {
        float xyz[3];
        std::memcpy(xyz, &d.body[i * vsize], sizeof(xyz));
        EXPECT_EQ(Vec3f(xyz[0], xyz[1], xyz[2]), m.vertices[i]);
        EXPECT_EQ((uchar)d.body[i * vsize + 24], 255);
        EXPECT_EQ((uchar)d.body[i * vsize + 25], 128);
    }
    for (size_t i = 0; i < 12; i++)
    {
        const char* p = &d.body[24 * vsize + i * fsize];
        EXPECT_EQ(p[0], 3);
        int idx[3];
        std::memcpy(idx, p + 1, sizeof(idx));
        EXPECT_EQ(Vec3i(idx[0], idx[1], idx[2]), m.faces[i]);
    }
    // No faces: a point cloud (no face element).
    Mesh cloud;
    cloud.vertices = {Vec3f(1, 2, 3), Vec3f(4, 5, 6)};
    writeMeshPly(dir + "/cloud.ply", cloud);
    d = readPly(dir + "/cloud.ply");
    EXPECT_NE(d.header.find("element vertex 2"), std::string::npos);
    EXPECT_EQ(d.header.find("element face"), std::string::npos);
    EXPECT_EQ(d.body.size(), (size_t)2 * 12);
}

TEST(Augocc_Visualization, contact_sheet_and_outlines)
{
    std::vector<Mat> images = {Mat(240, 320, CV_8UC3, Scalar(0, 0, 200)),
                               Mat(240, 320, CV_8UC1, Scalar(100)),
                               Mat(120, 160, CV_8UC4, Scalar(0, 255, 0, 255))};
    const Mat sheet = makeContactSheet(images, {"a", "b", "c"}, 2, 100);
    ASSERT_EQ(sheet.type(), CV_8UC3);
    EXPECT_EQ(sheet.cols, 4 + 2 * (100 + 4));
    EXPECT_EQ(sheet.rows, 4 + 2 * (75 + 22 + 4));
    EXPECT_EQ(sheet.at<Vec3b>(4 + 10, 4 + 10), Vec3b(0, 0, 200));
    EXPECT_EQ(sheet.at<Vec3b>(4 + 10, 4 + 104 + 10), Vec3b(100, 100, 100));
    EXPECT_EQ(sheet.at<Vec3b>(4 + 97 + 4 + 10, 4 + 10), Vec3b(0, 255, 0));
    EXPECT_THROW(makeContactSheet({}, {}, 2, 100), cv::Exception);
    EXPECT_THROW(makeContactSheet(images, {"a"}, 2, 100), cv::Exception);
    EXPECT_THROW(makeContactSheet(images, {}, 0, 100), cv::Exception);

    Mat img(100, 100, CV_8UC3, Scalar::all(0));
    Mat mask = Mat::zeros(100, 100, CV_8U);
    mask(Rect(20, 30, 40, 30)).setTo(255);
    drawMaskOutlines(img, mask, Scalar(0, 255, 0), 1);
    EXPECT_GT(img.at<Vec3b>(30, 40)[1], 200) << "on the top edge (anti-aliased)";
    EXPECT_EQ(img.at<Vec3b>(45, 40)[1], 0) << "inside stays";
    EXPECT_EQ(img.at<Vec3b>(5, 5)[1], 0) << "outside stays";
    EXPECT_THROW(drawMaskOutlines(img, Mat::zeros(50, 50, CV_8U), Scalar(0), 1), cv::Exception);
}

} // namespace
} // namespace opencv_test
