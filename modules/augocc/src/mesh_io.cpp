// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Mesh files through Assimp: every triangle mesh of the file's node tree, with the node
// transforms applied, and its material (diffuse and ambient colour, diffuse texture).

#include "precomp.hpp"
#include "input_limits.hpp"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

Matx44d toMatx(const aiMatrix4x4& m)
{
    return Matx44d(m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4,
                   m.d1, m.d2, m.d3, m.d4);
}

// Diffuse texture of a material: an embedded texture ("*N" or a name the scene holds) or a file
// relative to the model. A texture that cannot be read is a warning, not an error: many exported
// models reference files that did not travel with them, and the material colour still applies.
Mat loadTexture(const aiScene* scene, const aiMaterial* mat, const fs::path& modelDir,
                const String& modelPath)
{
    aiString texPath;
    bool found = false;
    for (aiTextureType type : {aiTextureType_DIFFUSE, aiTextureType_BASE_COLOR})
        if (mat->GetTextureCount(type) > 0 && mat->GetTexture(type, 0, &texPath) == AI_SUCCESS)
        {
            found = true;
            break;
        }
    if (!found || texPath.length == 0)
        return Mat();
    if (const aiTexture* emb = scene->GetEmbeddedTexture(texPath.C_Str()))
    {
        Mat img;
        if (emb->mHeight == 0)
        {
            // Compressed (png, jpg...): mWidth is the byte count.
            const uchar* b = (const uchar*)emb->pcData;
            try
            {
                img = detail::decodeImageChecked(std::vector<uchar>(b, b + emb->mWidth),
                                                 IMREAD_COLOR, modelPath + ": embedded texture " +
                                                 String(texPath.C_Str()));
            }
            catch (const cv::Exception& e)
            {
                CV_LOG_WARNING(NULL, e.err);
            }
        }
        else
        {
            // Raw aiTexel rows (b, g, r, a), top row first.
            if ((int64)emb->mWidth > detail::kMaxImageSide || (int64)emb->mHeight >
                detail::kMaxImageSide)
                CV_Error(Error::StsOutOfRange, modelPath + cv::format(": embedded texture of %u "
                         "x %u texels; augocc reads at most %d a side", emb->mWidth,
                         emb->mHeight, detail::kMaxImageSide));
            Mat bgra((int)emb->mHeight, (int)emb->mWidth, CV_8UC4, (void*)emb->pcData);
            cv::cvtColor(bgra, img, COLOR_BGRA2BGR);
        }
        if (img.empty())
            CV_LOG_WARNING(NULL, modelPath << ": embedded texture " << texPath.C_Str()
                           << " cannot be decoded; using the material colour");
        return img;
    }
    String rel = texPath.C_Str();
    std::replace(rel.begin(), rel.end(), '\\', '/');
    const fs::path file = fs::path(rel).is_absolute() ? fs::path(rel) : modelDir / rel;
    Mat img;
    try
    {
        if (fs::is_regular_file(file))
            img = detail::readImageChecked(file.string(), IMREAD_COLOR);
    }
    catch (const cv::Exception& e)
    {
        CV_LOG_WARNING(NULL, e.err);
    }
    if (img.empty())
        CV_LOG_WARNING(NULL, modelPath << ": texture " << file.string()
                       << " cannot be read; using the material colour");
    return img;
}

Material convertMaterial(const aiScene* scene, const aiMaterial* mat, const fs::path& modelDir,
                         const String& modelPath)
{
    Material out;
    aiColor4D c;
    if (mat->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
        out.diffuse = Vec3f(c.r, c.g, c.b);
    else if (mat->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS)
        out.diffuse = Vec3f(c.r, c.g, c.b);
    // Exporters often leave the ambient colour black (OBJ's Ka 0 0 0): then the surface would be
    // black where the light does not reach. As most viewers do, ambient defaults to the diffuse.
    out.ambient = out.diffuse;
    if (mat->Get(AI_MATKEY_COLOR_AMBIENT, c) == AI_SUCCESS && (c.r + c.g + c.b) > 0)
        out.ambient = Vec3f(c.r, c.g, c.b);
    out.texture = loadTexture(scene, mat, modelDir, modelPath);
    return out;
}

void collect(const aiScene* scene, const aiNode* node, const Matx44d& parent,
             const std::vector<Material>& materials, std::vector<Mesh>& out, const String& path,
             int depth = 0)
{
    if (depth > detail::kMaxStorageDepth)
        CV_Error(Error::StsOutOfRange, path + cv::format(": mesh file's node tree nests deeper "
                 "than augocc's limit of %d levels", detail::kMaxStorageDepth));
    const Matx44d M = parent * toMatx(node->mTransformation);
    const Matx33d L(M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2), M(2, 0), M(2, 1),
                    M(2, 2));
    const Matx33d N = L.inv().t();  // normals transform with the inverse transpose
    const bool mirror = cv::determinant(L) < 0;
    for (unsigned int i = 0; i < node->mNumMeshes; i++)
    {
        const aiMesh* am = scene->mMeshes[node->mMeshes[i]];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        Mesh m;
        const unsigned int nv = am->mNumVertices;
        m.vertices.resize(nv);
        for (unsigned int v = 0; v < nv; v++)
        {
            const aiVector3D& p = am->mVertices[v];
            const Vec4d q = M * Vec4d(p.x, p.y, p.z, 1.0);
            const double w = std::abs(q[3]) > 0 ? q[3] : 1.0;
            for (int k = 0; k < 3; k++)
                if (!(std::abs(q[k] / w) <= detail::kMaxSceneCoordinate))
                    CV_Error(Error::StsOutOfRange, path + cv::format(": vertex %u of mesh %u has "
                             "coordinate %g: not finite or beyond augocc's limit of %g", v,
                             node->mMeshes[i], q[k] / w, detail::kMaxSceneCoordinate));
            m.vertices[v] = Vec3f((float)(q[0] / w), (float)(q[1] / w), (float)(q[2] / w));
        }
        if (am->HasNormals())
        {
            m.normals.resize(nv);
            for (unsigned int v = 0; v < nv; v++)
            {
                const aiVector3D& n = am->mNormals[v];
                Vec3d q = N * Vec3d(n.x, n.y, n.z);
                const double len = cv::norm(q);
                m.normals[v] = len > 0 ? Vec3f(q * (1.0 / len)) : Vec3f(0, 1, 0);
            }
        }
        if (am->HasTextureCoords(0))
        {
            m.texcoords.resize(nv);
            for (unsigned int v = 0; v < nv; v++)
                m.texcoords[v] = Vec2f(am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y);
        }
        if (am->HasVertexColors(0))
        {
            m.colors.resize(nv);
            for (unsigned int v = 0; v < nv; v++)
            {
                const aiColor4D& c = am->mColors[0][v];
                m.colors[v] = Vec3f(c.r, c.g, c.b);
            }
        }
        m.faces.reserve(am->mNumFaces);
        for (unsigned int f = 0; f < am->mNumFaces; f++)
        {
            const aiFace& face = am->mFaces[f];
            if (face.mNumIndices != 3)
                continue;
            // A mirroring node transform turns the winding around: keep triangles CCW outside.
            if (mirror)
                m.faces.push_back(Vec3i((int)face.mIndices[0], (int)face.mIndices[2],
                                        (int)face.mIndices[1]));
            else
                m.faces.push_back(Vec3i((int)face.mIndices[0], (int)face.mIndices[1],
                                        (int)face.mIndices[2]));
        }
        if (m.faces.empty())
            continue;
        if (am->mMaterialIndex < materials.size())
            m.material = materials[am->mMaterialIndex];
        out.push_back(std::move(m));
    }
    for (unsigned int c = 0; c < node->mNumChildren; c++)
        collect(scene, node->mChildren[c], M, materials, out, path, depth + 1);
}

} // namespace

std::vector<Mesh> loadMeshes(const String& path)
{
    if (!fs::is_regular_file(path))
        CV_Error(Error::StsObjectNotFound, path + ": mesh file not found");
    detail::checkMeshFile(path);
    Assimp::Importer importer;
    // Points and lines are dropped (SortByPType + the flag below); normals are generated where the
    // file has none; node transforms are applied here rather than by PreTransformVertices so that
    // each mesh keeps its own material.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned int flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                               aiProcess_GenSmoothNormals | aiProcess_SortByPType |
                               aiProcess_ValidateDataStructure;
    const aiScene* scene = importer.ReadFile(path, flags);
    if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode)
        CV_Error(Error::StsParseError, path + ": cannot parse mesh file: " +
                 String(importer.GetErrorString()));
    const fs::path dir = fs::path(path).parent_path();
    std::vector<Material> materials;
    for (unsigned int i = 0; i < scene->mNumMaterials; i++)
        materials.push_back(convertMaterial(scene, scene->mMaterials[i], dir, path));
    std::vector<Mesh> meshes;
    collect(scene, scene->mRootNode, Matx44d::eye(), materials, meshes, path);
    if (meshes.empty())
        CV_Error(Error::StsParseError, path + ": mesh file holds no triangle");
    return meshes;
}

} // namespace augocc
} // namespace cv
