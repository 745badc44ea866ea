// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "shading.hpp"

#include <GL/gl.h>

namespace cv {
namespace augocc {
namespace detail {

Vec3f shadeColor(const Material& material, const Vec3f& normal, const Vec3f& base)
{
    return shadeColor(material, normal, base, kLightDirection);
}

Vec3f ambientColor(const Material& material, const Vec3f& base)
{
    Vec3f c;
    for (int k = 0; k < 3; k++)
        c[k] = std::min(1.f, std::max(0.f, base[k] * material.ambient[k]));
    return c;
}

Material sunSplitMaterial(const Material& material, double sky)
{
    Material m = material;
    for (int k = 0; k < 3; k++)
    {
        const float total = material.ambient[k] + material.diffuse[k];
        m.ambient[k] = (float)(sky * total);
        m.diffuse[k] = (float)((1 - sky) * total);
    }
    return m;
}

Vec3f shadeColor(const Material& material, const Vec3f& normal, const Vec3f& base,
                 const Vec3f& light)
{
    const float ndotl = std::max(0.f, normal.dot(light));
    Vec3f c;
    for (int k = 0; k < 3; k++)
        c[k] = std::min(1.f, std::max(0.f, base[k] * (material.ambient[k] +
                                                      material.diffuse[k] * ndotl)));
    return c;
}

unsigned uploadTexture(const Mat& image)
{
    // RGB, bottom row first (v up), then every mipmap level down to 1x1.
    Mat rgb;
    if (image.channels() == 1)
        cv::cvtColor(image, rgb, COLOR_GRAY2RGB);
    else if (image.channels() == 4)
        cv::cvtColor(image, rgb, COLOR_BGRA2RGB);
    else
        cv::cvtColor(image, rgb, COLOR_BGR2RGB);
    if (rgb.depth() != CV_8U)
        rgb.convertTo(rgb, CV_8U, rgb.depth() == CV_16U ? 1.0 / 257 : 255.0);
    cv::flip(rgb, rgb, 0);
    GLuint id = 0;
    glGenTextures(1, &id);
    glBindTexture(GL_TEXTURE_2D, id);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    Mat cur = rgb.isContinuous() ? rgb : rgb.clone();
    for (int level = 0;; level++)
    {
        glTexImage2D(GL_TEXTURE_2D, level, GL_RGB8, cur.cols, cur.rows, 0, GL_RGB,
                     GL_UNSIGNED_BYTE, cur.data);
        if (cur.cols == 1 && cur.rows == 1)
            break;
        Mat next;
        cv::resize(cur, next, Size(std::max(1, cur.cols / 2), std::max(1, cur.rows / 2)), 0, 0,
                   INTER_AREA);
        cur = next;
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glBindTexture(GL_TEXTURE_2D, 0);
    return id;
}

GlMesh::GlMesh(const Mesh& meshIn, float alpha)
{
    init(meshIn, alpha, kLightDirection);
}

GlMesh::GlMesh(const Mesh& meshIn, float alpha, const Vec3f& light)
{
    init(meshIn, alpha, light);
}

void GlMesh::init(const Mesh& meshIn, float alpha, const Vec3f& light)
{
    const Mesh* mesh = &meshIn;
    Mesh withNormals;
    if (meshIn.normals.size() != meshIn.vertices.size())
    {
        withNormals = meshIn;
        withNormals.computeNormals();
        mesh = &withNormals;
    }
    const size_t n = mesh->vertices.size();
    const bool hasColors = mesh->colors.size() == n;
    const bool textured = !mesh->material.texture.empty() && mesh->texcoords.size() == n;
    positions_.resize(3 * n);
    colors_.resize(4 * n);
    ambient_.resize(4 * n);
    for (size_t i = 0; i < n; i++)
    {
        for (int k = 0; k < 3; k++)
            positions_[3 * i + k] = mesh->vertices[i][k];
        const Vec3f base = hasColors ? mesh->colors[i] : Vec3f(1, 1, 1);
        const Vec3f c = shadeColor(mesh->material, mesh->normals[i], base, light);
        const Vec3f a = ambientColor(mesh->material, base);
        for (int k = 0; k < 3; k++)
        {
            colors_[4 * i + k] = c[k];
            ambient_[4 * i + k] = a[k];
        }
        colors_[4 * i + 3] = alpha;
        ambient_[4 * i + 3] = alpha;
    }
    indices_.reserve(mesh->faces.size() * 3);
    for (const Vec3i& f : mesh->faces)
        for (int k = 0; k < 3; k++)
        {
            if (f[k] < 0 || (size_t)f[k] >= n)
                CV_Error(Error::StsBadArg, "GlMesh: face index out of range");
            indices_.push_back((unsigned)f[k]);
        }
    if (!textured)
        return;
    texcoords_.resize(2 * n);
    for (size_t i = 0; i < n; i++)
    {
        texcoords_[2 * i] = mesh->texcoords[i][0];
        texcoords_[2 * i + 1] = mesh->texcoords[i][1];
    }
    texture_ = uploadTexture(mesh->material.texture);
}

GlMesh::~GlMesh()
{
    if (texture_)
    {
        GLuint id = texture_;
        glDeleteTextures(1, &id);
    }
}

void GlMesh::draw(bool ambientOnly) const
{
    if (indices_.empty())
        return;
    glDisable(GL_LIGHTING);
    glShadeModel(GL_SMOOTH);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, positions_.data());
    glColorPointer(4, GL_FLOAT, 0, ambientOnly ? ambient_.data() : colors_.data());
    if (texture_)
    {
        glEnable(GL_TEXTURE_2D);
        glBindTexture(GL_TEXTURE_2D, texture_);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        glEnableClientState(GL_TEXTURE_COORD_ARRAY);
        glTexCoordPointer(2, GL_FLOAT, 0, texcoords_.data());
    }
    glDrawElements(GL_TRIANGLES, (GLsizei)indices_.size(), GL_UNSIGNED_INT, indices_.data());
    if (texture_)
    {
        glDisableClientState(GL_TEXTURE_COORD_ARRAY);
        glBindTexture(GL_TEXTURE_2D, 0);
        glDisable(GL_TEXTURE_2D);
    }
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
}

void GlMesh::drawFlat() const
{
    if (indices_.empty())
        return;
    glDisable(GL_LIGHTING);
    glDisable(GL_TEXTURE_2D);
    glEnableClientState(GL_VERTEX_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, positions_.data());
    glDrawElements(GL_TRIANGLES, (GLsizei)indices_.size(), GL_UNSIGNED_INT, indices_.data());
    glDisableClientState(GL_VERTEX_ARRAY);
}

} // namespace detail
} // namespace augocc
} // namespace cv
