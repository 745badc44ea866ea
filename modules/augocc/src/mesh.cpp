// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Mesh helpers: transforms, normals, bounds, procedural shapes and binary PLY output.
// loadMeshes() (Assimp) lives in mesh_io.cpp.

#include "precomp.hpp"

#include "atomic_write.hpp"

#include <cstdint>
#include <cstring>
#include <sstream>

namespace cv {
namespace augocc {

namespace {

const double kPi = 3.14159265358979323846;

Vec3f normalized(const Vec3f& v)
{
    const float n = (float)cv::norm(v);
    return n > 0 ? v * (1.0f / n) : v;
}

// Adds a flat, planar quad a-b-c-d (counter-clockwise seen from outside) with its own four
// vertices, normal n and texture coordinates (0,0) (1,0) (1,1) (0,1).
void addQuad(Mesh& m, const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& d,
             const Vec3f& n)
{
    const int base = (int)m.vertices.size();
    const Vec3f p[4] = {a, b, c, d};
    const Vec2f uv[4] = {Vec2f(0, 0), Vec2f(1, 0), Vec2f(1, 1), Vec2f(0, 1)};
    for (int i = 0; i < 4; i++)
    {
        m.vertices.push_back(p[i]);
        m.normals.push_back(n);
        m.texcoords.push_back(uv[i]);
    }
    m.faces.push_back(Vec3i(base, base + 1, base + 2));
    m.faces.push_back(Vec3i(base, base + 2, base + 3));
}

// A flat disk at height y around the y axis, facing up (+y) or down (-y).
void addDisk(Mesh& m, float radius, float y, bool up, int segments)
{
    const int centre = (int)m.vertices.size();
    const Vec3f n(0, up ? 1.f : -1.f, 0);
    m.vertices.push_back(Vec3f(0, y, 0));
    m.normals.push_back(n);
    m.texcoords.push_back(Vec2f(0.5f, 0.5f));
    for (int i = 0; i < segments; i++)
    {
        const double a = 2 * kPi * i / segments;
        const float c = (float)std::cos(a), s = (float)std::sin(a);
        m.vertices.push_back(Vec3f(radius * c, y, radius * s));
        m.normals.push_back(n);
        m.texcoords.push_back(Vec2f(0.5f + 0.5f * c, 0.5f + 0.5f * s));
    }
    for (int i = 0; i < segments; i++)
    {
        const int a = centre + 1 + i, b = centre + 1 + (i + 1) % segments;
        // Ring vertex angle a runs from +x towards +z: seen from above (+y) that is clockwise,
        // so the up-facing disk uses (centre, b, a).
        if (up)
            m.faces.push_back(Vec3i(centre, b, a));
        else
            m.faces.push_back(Vec3i(centre, a, b));
    }
}

} // namespace

void Mesh::transform(const Matx44d& M)
{
    const Matx33d A(M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2), M(2, 0), M(2, 1),
                    M(2, 2));
    const double det = cv::determinant(A);
    if (!(std::abs(det) > 0) || !std::isfinite(det))
        CV_Error(Error::StsBadArg, "Mesh::transform: the 3x3 part of the transform is singular");
    for (Vec3f& v : vertices)
    {
        const Vec4d h = M * Vec4d(v[0], v[1], v[2], 1.0);
        const double w = h[3] != 0 ? h[3] : 1.0;
        v = Vec3f((float)(h[0] / w), (float)(h[1] / w), (float)(h[2] / w));
    }
    // Normals transform by the inverse transpose of the linear part.
    const Matx33d N = A.inv().t();
    for (Vec3f& n : normals)
    {
        const Vec3d m = N * Vec3d(n[0], n[1], n[2]);
        n = normalized(Vec3f((float)m[0], (float)m[1], (float)m[2]));
    }
    // A mirroring transform would turn the triangles clockwise: keep them counter-clockwise.
    if (det < 0)
        for (Vec3i& f : faces)
            std::swap(f[1], f[2]);
}

void Mesh::computeNormals()
{
    std::vector<Vec3d> acc(vertices.size(), Vec3d(0, 0, 0));
    for (const Vec3i& f : faces)
    {
        for (int k = 0; k < 3; k++)
            if (f[k] < 0 || (size_t)f[k] >= vertices.size())
                CV_Error(Error::StsBadArg, "Mesh::computeNormals: face index out of range");
        const Vec3d a(vertices[f[0]]), b(vertices[f[1]]), c(vertices[f[2]]);
        const Vec3d n = (b - a).cross(c - a);  // length = twice the area: area weighting
        for (int k = 0; k < 3; k++)
            acc[f[k]] += n;
    }
    normals.resize(vertices.size());
    for (size_t i = 0; i < vertices.size(); i++)
    {
        const double len = cv::norm(acc[i]);
        normals[i] = len > 0 ? Vec3f(acc[i] * (1.0 / len)) : Vec3f(0, 0, 0);
    }
}

void Mesh::bounds(Vec3f& minCorner, Vec3f& maxCorner) const
{
    if (vertices.empty())
        CV_Error(Error::StsBadArg, "Mesh::bounds: the mesh has no vertex");
    minCorner = maxCorner = vertices[0];
    for (const Vec3f& v : vertices)
        for (int k = 0; k < 3; k++)
        {
            minCorner[k] = std::min(minCorner[k], v[k]);
            maxCorner[k] = std::max(maxCorner[k], v[k]);
        }
}

void Mesh::append(const Mesh& other)
{
    if (vertices.empty())
    {
        const Material keep = material;
        *this = other;
        material = keep;
        return;
    }
    const int offset = (int)vertices.size();
    const size_t nv = vertices.size(), no = other.vertices.size();
    auto merge = [&](auto& mine, const auto& theirs) {
        if (mine.size() == nv && theirs.size() == no)
            mine.insert(mine.end(), theirs.begin(), theirs.end());
        else
            mine.clear();
    };
    merge(normals, other.normals);
    merge(texcoords, other.texcoords);
    merge(colors, other.colors);
    vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
    faces.reserve(faces.size() + other.faces.size());
    for (const Vec3i& f : other.faces)
        faces.push_back(f + Vec3i(offset, offset, offset));
}

Mesh Mesh::box(const Vec3f& p, const Vec3f& q)
{
    const Vec3f lo(std::min(p[0], q[0]), std::min(p[1], q[1]), std::min(p[2], q[2]));
    const Vec3f hi(std::max(p[0], q[0]), std::max(p[1], q[1]), std::max(p[2], q[2]));
    Mesh m;
    const float x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0], y1 = hi[1], z1 = hi[2];
    // Each face counter-clockwise seen from outside, texture u right and v up as seen from
    // outside (for the top and bottom faces, seen with +z / -z at the bottom of the view).
    addQuad(m, Vec3f(x0, y0, z1), Vec3f(x1, y0, z1), Vec3f(x1, y1, z1), Vec3f(x0, y1, z1),
            Vec3f(0, 0, 1));   // +z
    addQuad(m, Vec3f(x1, y0, z0), Vec3f(x0, y0, z0), Vec3f(x0, y1, z0), Vec3f(x1, y1, z0),
            Vec3f(0, 0, -1));  // -z
    addQuad(m, Vec3f(x1, y0, z1), Vec3f(x1, y0, z0), Vec3f(x1, y1, z0), Vec3f(x1, y1, z1),
            Vec3f(1, 0, 0));   // +x
    addQuad(m, Vec3f(x0, y0, z0), Vec3f(x0, y0, z1), Vec3f(x0, y1, z1), Vec3f(x0, y1, z0),
            Vec3f(-1, 0, 0));  // -x
    addQuad(m, Vec3f(x0, y1, z1), Vec3f(x1, y1, z1), Vec3f(x1, y1, z0), Vec3f(x0, y1, z0),
            Vec3f(0, 1, 0));   // +y
    addQuad(m, Vec3f(x0, y0, z0), Vec3f(x1, y0, z0), Vec3f(x1, y0, z1), Vec3f(x0, y0, z1),
            Vec3f(0, -1, 0));  // -y
    return m;
}

Mesh Mesh::cylinder(float radius, float y0, float y1, int segments)
{
    CV_CheckGT(radius, 0.f, "cylinder radius");
    CV_CheckGT(y1, y0, "cylinder: y1 must be above y0");
    CV_CheckGE(segments, 3, "cylinder segments");
    Mesh m;
    // Side: segments + 1 columns (the seam is duplicated for the texture), smooth normals.
    for (int i = 0; i <= segments; i++)
    {
        const double a = 2 * kPi * i / segments;
        const float c = (float)std::cos(a), s = (float)std::sin(a);
        const float u = 1.f - (float)i / segments;  // u increases counter-clockwise seen outside
        m.vertices.push_back(Vec3f(radius * c, y0, radius * s));
        m.normals.push_back(Vec3f(c, 0, s));
        m.texcoords.push_back(Vec2f(u, 0));
        m.vertices.push_back(Vec3f(radius * c, y1, radius * s));
        m.normals.push_back(Vec3f(c, 0, s));
        m.texcoords.push_back(Vec2f(u, 1));
    }
    for (int i = 0; i < segments; i++)
    {
        const int a0 = 2 * i, a1 = 2 * i + 1, b0 = 2 * i + 2, b1 = 2 * i + 3;
        // Angle increases from +x to +z: seen from outside that runs right to left.
        m.faces.push_back(Vec3i(a0, a1, b0));
        m.faces.push_back(Vec3i(b0, a1, b1));
    }
    addDisk(m, radius, y1, true, segments);
    addDisk(m, radius, y0, false, segments);
    return m;
}

Mesh Mesh::cone(float radius, float y0, float y1, int segments)
{
    CV_CheckGT(radius, 0.f, "cone radius");
    CV_CheckGT(y1, y0, "cone: the apex y1 must be above y0");
    CV_CheckGE(segments, 3, "cone segments");
    Mesh m;
    const float h = y1 - y0;
    // One apex vertex per segment so that each gets the normal of the middle of its segment.
    for (int i = 0; i < segments; i++)
    {
        const double a = 2 * kPi * i / segments, b = 2 * kPi * (i + 1) / segments;
        const double mid = 0.5 * (a + b);
        const int base = (int)m.vertices.size();
        const double angles[2] = {a, b};
        for (int k = 0; k < 2; k++)
        {
            const float c = (float)std::cos(angles[k]), s = (float)std::sin(angles[k]);
            m.vertices.push_back(Vec3f(radius * c, y0, radius * s));
            m.normals.push_back(normalized(Vec3f(c * h, radius, s * h)));
            m.texcoords.push_back(Vec2f(1.f - (float)(i + k) / segments, 0));
        }
        const float c = (float)std::cos(mid), s = (float)std::sin(mid);
        m.vertices.push_back(Vec3f(0, y1, 0));
        m.normals.push_back(normalized(Vec3f(c * h, radius, s * h)));
        m.texcoords.push_back(Vec2f(1.f - (float)(i + 0.5) / segments, 1));
        m.faces.push_back(Vec3i(base, base + 2, base + 1));
    }
    addDisk(m, radius, y0, false, segments);
    return m;
}

Mesh Mesh::sphere(float radius, int segments, int rings)
{
    CV_CheckGT(radius, 0.f, "sphere radius");
    CV_CheckGE(segments, 3, "sphere segments");
    CV_CheckGE(rings, 2, "sphere rings");
    Mesh m;
    // Ring r at polar angle pi * r / rings from +y; the seam column is duplicated.
    for (int r = 0; r <= rings; r++)
    {
        const double theta = kPi * r / rings;
        for (int i = 0; i <= segments; i++)
        {
            const double phi = 2 * kPi * i / segments;
            const Vec3f n((float)(std::sin(theta) * std::cos(phi)), (float)std::cos(theta),
                          (float)(std::sin(theta) * std::sin(phi)));
            m.vertices.push_back(n * radius);
            m.normals.push_back(n);
            m.texcoords.push_back(Vec2f(1.f - (float)i / segments, 1.f - (float)r / rings));
        }
    }
    const int cols = segments + 1;
    for (int r = 0; r < rings; r++)
        for (int i = 0; i < segments; i++)
        {
            const int a = r * cols + i, b = a + 1, c = a + cols, d = c + 1;
            if (r > 0)
                m.faces.push_back(Vec3i(a, b, c));
            if (r < rings - 1)
                m.faces.push_back(Vec3i(b, d, c));
        }
    return m;
}

Mesh Mesh::dome(float radius, int segments, int rings)
{
    CV_CheckGT(radius, 0.f, "dome radius");
    CV_CheckGE(segments, 3, "dome segments");
    CV_CheckGE(rings, 1, "dome rings");
    Mesh m;
    for (int r = 0; r <= rings; r++)
    {
        const double theta = 0.5 * kPi * r / rings;  // 0 at the top, pi/2 at the ground
        for (int i = 0; i <= segments; i++)
        {
            const double phi = 2 * kPi * i / segments;
            const Vec3f n((float)(std::sin(theta) * std::cos(phi)), (float)std::cos(theta),
                          (float)(std::sin(theta) * std::sin(phi)));
            m.vertices.push_back(n * radius);
            m.normals.push_back(n);
            m.texcoords.push_back(Vec2f(1.f - (float)i / segments, 1.f - (float)r / rings));
        }
    }
    const int cols = segments + 1;
    for (int r = 0; r < rings; r++)
        for (int i = 0; i < segments; i++)
        {
            const int a = r * cols + i, b = a + 1, c = a + cols, d = c + 1;
            if (r > 0)
                m.faces.push_back(Vec3i(a, b, c));
            m.faces.push_back(Vec3i(b, d, c));
        }
    addDisk(m, radius, 0.f, false, segments);
    return m;
}

void writeMeshPly(const String& path, const Mesh& mesh)
{
    // An empty mesh is a valid PLY with no element (e.g. a key frame that needs no patch voxel).
    const size_t nv = mesh.vertices.size();
    for (const Vec3i& f : mesh.faces)
        for (int k = 0; k < 3; k++)
            if (f[k] < 0 || (size_t)f[k] >= nv)
                CV_Error(Error::StsBadArg, path + ": writeMeshPly: face index out of range");
    const bool hasNormals = mesh.normals.size() == nv;
    const bool hasColors = mesh.colors.size() == nv;
    {
        const uint16_t probe = 1;
        uint8_t first;
        std::memcpy(&first, &probe, 1);
        CV_Assert(first == 1 && "binary_little_endian output assumes a little-endian host");
    }
    writeAtomically(path, [&](const String& tmp) {
        std::ostringstream out;
        out << "ply\nformat binary_little_endian 1.0\ncomment written by augocc\n";
        out << "element vertex " << nv << "\n";
        out << "property float x\nproperty float y\nproperty float z\n";
        if (hasNormals)
            out << "property float nx\nproperty float ny\nproperty float nz\n";
        if (hasColors)
            out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
        if (!mesh.faces.empty())
        {
            out << "element face " << mesh.faces.size() << "\n";
            out << "property list uchar int vertex_indices\n";
        }
        out << "end_header\n";
        std::vector<char> buf;
        buf.reserve(nv * 27 + mesh.faces.size() * 13);
        auto put = [&buf](const void* p, size_t n) {
            const char* c = static_cast<const char*>(p);
            buf.insert(buf.end(), c, c + n);
        };
        for (size_t i = 0; i < nv; i++)
        {
            put(&mesh.vertices[i][0], 3 * sizeof(float));
            if (hasNormals)
                put(&mesh.normals[i][0], 3 * sizeof(float));
            if (hasColors)
            {
                uint8_t rgb[3];
                for (int k = 0; k < 3; k++)
                    rgb[k] = saturate_cast<uchar>(mesh.colors[i][k] * 255.f);
                put(rgb, 3);
            }
        }
        for (const Vec3i& f : mesh.faces)
        {
            const uint8_t three = 3;
            const int32_t idx[3] = {f[0], f[1], f[2]};
            put(&three, 1);
            put(idx, sizeof(idx));
        }
        out.write(buf.data(), (std::streamsize)buf.size());
        const String bytes = out.str();
        detail::writeFileBytes(tmp, bytes.data(), bytes.size(), path);
    });
}

} // namespace augocc
} // namespace cv
