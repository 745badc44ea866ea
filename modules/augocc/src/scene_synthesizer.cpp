// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// SceneSynthesizer: a textured static scene rendered headless through OSMesa, with its ground
// truth (cameras, 3D points, tracks, masks, depth). See scene_synthesizer.hpp for the scene and
// doc/synthesizer.md for the outputs of `augocc synth`.
//
// Over 800 lines in one file: the scene's geometry and textures, the camera path, the renderer
// and the ground truth derived from them share one private scene description (sections below).

#include "precomp.hpp"
#include <cstring>
#include "gl_context.hpp"
#include "shading.hpp"
#include "shadow.hpp"
#include "synthetic_scene_io.hpp"

#include <cfloat>
#include <memory>
#include <mutex>
#include <numeric>

#include <GL/gl.h>

namespace cv {
namespace augocc {

namespace {

const double kPi = 3.14159265358979323846;

// Framing: the footprint diameter of the objects spans this fraction of the frame width (of a
// 4:3 frame; the height of wider frames). The brief asks for "about 60% of the frame".
const double kFrameFill = 0.6;
// Ground square half side (world units): wide enough that the ground fills every frame of the
// default orbit at any distance ratio >= 1 (the frame spans about 17 units at the scene).
const float kGroundHalfSide = 60.f;
// World units covered by one repetition of the ground texture.
const float kGroundTexturePeriod = 16.f;
// Hand-held jitter of the camera, degrees (peak): smooth, a sum of two sinusoids.
const double kJitterElevationDeg = 1.0;
const double kJitterRollDeg = 0.8;
// Texture atlas of an object: kTiles x kTiles tiles of kTileSize texels, one per face group.
const int kTiles = 4;
const int kTileSize = 256;
// Tracks: fraction of inlier tracks sampled on the objects (the rest on the ground).
const double kObjectTrackFraction = 0.6;
// Tracks stay this many pixels inside every frame.
const double kTrackMarginPx = 2.0;
// A sampled surface point counts as visible in the middle frame when the rendered depth at its
// pixel is within this many world units of its own depth (depth slope over half a pixel on
// steep faces, plus the depth buffer resolution).
const double kVisibleDepthTol = 0.05;
// Partial tracks span at least this fraction of the sequence.
const double kPartialMinFraction = 0.2;
// Outlier random walks: initial speed (px per frame, uniform per axis) and step noise (px).
const double kOutlierSpeedPx = 2.0;
const double kOutlierStepSigmaPx = 1.5;
// Sky colour (RGB) where nothing is drawn.
const Vec3f kSkyRgb(0.62f, 0.75f, 0.90f);

// splitmix64: independent, reproducible random streams from one seed.
uint64 mixSeed(uint64 seed, uint64 stream)
{
    uint64 z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z = z ^ (z >> 31);
    return z ? z : 0x2545F4914F6CDD1DULL;
}

// ---------------------------------------------------------------------------------------------
// Procedural textures (deterministic from an RNG)

// Multi-octave value noise in [0, 1], CV_32F, periodic (tileable) over the image: each octave's
// random grid is wrapped around before the cubic upsampling.
Mat valueNoise(RNG& rng, Size size, double cellPx, int octaves)
{
    Mat acc = Mat::zeros(size, CV_32F);
    double amp = 1.0, total = 0.0, cell = cellPx;
    const int pad = 2;  // cells of wrap-around: covers the 4x4 cubic kernel
    for (int o = 0; o < octaves && cell >= 2; o++)
    {
        const int gw = std::max(1, cvRound(size.width / cell));
        const int gh = std::max(1, cvRound(size.height / cell));
        const double sx = (double)size.width / gw, sy = (double)size.height / gh;
        Mat grid(gh, gw, CV_32F), padded, up;
        rng.fill(grid, RNG::UNIFORM, 0.0, 1.0);
        cv::copyMakeBorder(grid, padded, pad, pad, pad, pad, BORDER_WRAP);
        const Size upSize(cvRound(padded.cols * sx), cvRound(padded.rows * sy));
        cv::resize(padded, up, upSize, 0, 0, INTER_CUBIC);
        const Rect roi(cvRound(pad * sx), cvRound(pad * sy), size.width, size.height);
        cv::scaleAdd(up(roi), amp, acc, acc);
        total += amp;
        amp *= 0.55;
        cell *= 0.5;
    }
    acc *= 1.0 / total;
    return acc;
}

// Draws with wrap-around (so that a texture drawn this way tiles seamlessly) when `wrap`.
template <typename DrawFn>
void drawWrapped(Size size, bool wrap, DrawFn draw)
{
    if (!wrap)
    {
        draw(Point(0, 0));
        return;
    }
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++)
            draw(Point(dx * size.width, dy * size.height));
}

Scalar randomColorNear(RNG& rng, const Vec3f& rgb, double spread)
{
    Vec3d c;
    for (int k = 0; k < 3; k++)
        c[k] = std::min(1.0, std::max(0.0, rgb[k] + rng.uniform(-spread, spread)));
    return Scalar(255 * c[2], 255 * c[1], 255 * c[0]);  // BGR
}

enum TextureStyle
{
    TEX_FACADE,   // windows in a grid
    TEX_WALL,     // blotches and cracks
    TEX_ROOF,     // tiles / gravel
    TEX_GROUND    // grass, stones, paths
};

/* A texture rich in corners at several scales for a KLT tracker: value noise for low-frequency
variation, random blobs, lines, small high-contrast speckles, and windows on facades.
BGR CV_8UC3. */
Mat makeTexture(RNG& rng, Size size, const Vec3f& baseRgb, TextureStyle style)
{
    const Mat noise = valueNoise(rng, size, size.width / 4.0, 5);
    std::vector<Mat> ch(3);
    const double amp = style == TEX_GROUND ? 0.55 : 0.45;
    for (int k = 0; k < 3; k++)
    {
        const double tint = rng.uniform(0.9, 1.1);
        noise.convertTo(ch[2 - k], CV_8U, 255.0 * baseRgb[k] * tint * amp * 2,
                        255.0 * baseRgb[k] * tint * (1 - amp));
    }
    Mat tex;
    cv::merge(ch, tex);
    const double scale = size.width / 256.0;
    const bool wrap = style == TEX_GROUND;  // the ground texture repeats: make it seamless
    // Blobs of a nearby colour.
    const int blobs = style == TEX_GROUND ? 60 : 25;
    for (int i = 0; i < blobs; i++)
    {
        const Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
        const int r = (int)(scale * rng.uniform(3, 18));
        const float shade = (float)rng.uniform(0.7, 1.25);
        const Scalar col = randomColorNear(rng, baseRgb * shade, 0.08);
        drawWrapped(size, wrap, [&](Point o) { cv::circle(tex, c + o, r, col, FILLED, LINE_AA); });
    }
    // Lines: cracks, joints, paths.
    const int lines = style == TEX_GROUND ? 30 : 14;
    for (int i = 0; i < lines; i++)
    {
        const Point a(rng.uniform(0, size.width), rng.uniform(0, size.height));
        const Point b = a + Point(rng.uniform(-size.width / 3, size.width / 3),
                                  rng.uniform(-size.height / 3, size.height / 3));
        const Scalar col = randomColorNear(rng, baseRgb * 0.5f, 0.1);
        const int thick = rng.uniform(1, 4);
        drawWrapped(size, wrap, [&](Point o) { cv::line(tex, a + o, b + o, col, thick, LINE_AA); });
    }
    if (style == TEX_FACADE)
    {
        // Windows: a grid with random lit / dark panes and frames.
        const int cols = rng.uniform(3, 6), rows = rng.uniform(3, 6);
        const double cw = (double)size.width / cols, chh = (double)size.height / rows;
        for (int r = 0; r < rows; r++)
            for (int c = 0; c < cols; c++)
            {
                const Rect w((int)(c * cw + 0.22 * cw), (int)(r * chh + 0.2 * chh),
                             (int)(0.56 * cw), (int)(0.55 * chh));
                const bool lit = rng.uniform(0.0, 1.0) < 0.3;
                const Scalar pane = lit ? Scalar(rng.uniform(90, 140), rng.uniform(190, 230),
                                                 rng.uniform(220, 255))
                                        : Scalar(rng.uniform(60, 110), rng.uniform(40, 70),
                                                 rng.uniform(20, 50));
                cv::rectangle(tex, w, pane, FILLED);
                cv::rectangle(tex, w, Scalar(235, 235, 235), std::max(1, (int)(2 * scale)));
                cv::line(tex, Point(w.x + w.width / 2, w.y),
                         Point(w.x + w.width / 2, w.y + w.height), Scalar(200, 200, 200),
                         std::max(1, (int)scale));
            }
    }
    else if (style == TEX_ROOF)
    {
        const int step = std::max(4, (int)(16 * scale));
        for (int y = 0; y < size.height; y += step)
            cv::line(tex, Point(0, y), Point(size.width, y),
                     randomColorNear(rng, baseRgb * 0.6f, 0.1), 1, LINE_AA);
    }
    // Speckles: small, high-contrast marks (the corners a tracker latches on to).
    const int speckles = (int)((style == TEX_GROUND ? 500 : 220) * scale * scale);
    for (int i = 0; i < speckles; i++)
    {
        const Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
        const bool dark = rng.uniform(0, 2) == 0;
        const Scalar col = dark ? randomColorNear(rng, baseRgb * 0.35f, 0.1)
                                : randomColorNear(rng, Vec3f(0.95f, 0.93f, 0.88f), 0.05);
        const int r = rng.uniform(1, 4);
        const bool round = rng.uniform(0, 2) == 0;
        drawWrapped(size, wrap, [&](Point o) {
            if (round)
                cv::circle(tex, c + o, r, col, FILLED, LINE_AA);
            else
                cv::rectangle(tex, Rect(c.x + o.x, c.y + o.y, r + 1, r + 1), col, FILLED);
        });
    }
    return tex;
}

// Atlas of kTiles x kTiles textures; tile k at row k / kTiles (from the top), column k % kTiles.
Mat makeAtlas(RNG& rng, const std::vector<std::pair<Vec3f, TextureStyle>>& tiles)
{
    CV_Assert((int)tiles.size() <= kTiles * kTiles);
    Mat atlas(kTiles * kTileSize, kTiles * kTileSize, CV_8UC3, Scalar(128, 128, 128));
    for (size_t k = 0; k < tiles.size(); k++)
    {
        const Rect roi((int)(k % kTiles) * kTileSize, (int)(k / kTiles) * kTileSize, kTileSize,
                       kTileSize);
        makeTexture(rng, roi.size(), tiles[k].first, tiles[k].second).copyTo(atlas(roi));
    }
    return atlas;
}

// Maps the texture coordinates of vertices [begin, end) from [0, 1]^2 into atlas tile `tile`
// (v up: tile row 0 is the top of the atlas image, i.e. v near 1).
void mapToTile(Mesh& m, size_t begin, size_t end, int tile)
{
    const float inset = 2.f / kTileSize;  // keeps bilinear / mipmap taps inside the tile
    const int col = tile % kTiles, row = tile / kTiles;
    for (size_t i = begin; i < end; i++)
    {
        Vec2f& uv = m.texcoords[i];
        const float u = std::min(1.f, std::max(0.f, uv[0]));
        const float v = std::min(1.f, std::max(0.f, uv[1]));
        uv[0] = (col + inset + u * (1 - 2 * inset)) / kTiles;
        uv[1] = (kTiles - 1 - row + inset + v * (1 - 2 * inset)) / kTiles;
    }
}

// Appends `part` to `m` with all its vertices in atlas tile `tile`.
void appendInTile(Mesh& m, Mesh part, int tile)
{
    mapToTile(part, 0, part.vertices.size(), tile);
    m.append(part);
}

// A vertical prism over a simple polygon footprint (x, z), from y = 0 to `height`. Each side is
// its own quad (flat normals, its own atlas tile starting at `firstTile`); the caps are fanned
// from footprint vertex `fanFrom`, which must see every other vertex (the reflex corner of an L).
Mesh prism(const std::vector<Point2f>& fp, float height, int fanFrom, int firstTile)
{
    const int n = (int)fp.size();
    CV_Assert(n >= 3 && fanFrom >= 0 && fanFrom < n);
    double area2 = 0;
    for (int i = 0; i < n; i++)
    {
        const Point2f a = fp[i], b = fp[(i + 1) % n];
        area2 += (double)a.x * b.y - (double)b.x * a.y;
    }
    const float orient = area2 > 0 ? 1.f : -1.f;
    Mesh m;
    int tile = firstTile;
    for (int i = 0; i < n; i++)
    {
        const Point2f a = fp[i], b = fp[(i + 1) % n];
        const Vec3f nrm = orient * Vec3f(b.y - a.y, 0, -(b.x - a.x)) *
                          (1.f / (float)cv::norm(b - a));
        Mesh q;
        // Seen from outside, walking a -> b goes right when the outward normal is right-handed.
        const Vec3f A(a.x, 0, a.y), B(b.x, 0, b.y), C(b.x, height, b.y), D(a.x, height, a.y);
        // Order so that (p1 - p0) x (p2 - p0) points along nrm.
        const Vec3f cr = (B - A).cross(C - A);
        const bool ccw = cr.dot(nrm) > 0;
        const Vec3f p[4] = {ccw ? A : B, ccw ? B : A, ccw ? C : D, ccw ? D : C};
        const Vec2f uv[4] = {Vec2f(0, 0), Vec2f(1, 0), Vec2f(1, 1), Vec2f(0, 1)};
        for (int k = 0; k < 4; k++)
        {
            q.vertices.push_back(p[k]);
            q.normals.push_back(nrm);
            q.texcoords.push_back(uv[k]);
        }
        q.faces.push_back(Vec3i(0, 1, 2));
        q.faces.push_back(Vec3i(0, 2, 3));
        appendInTile(m, q, tile++);
    }
    Point2f lo = fp[0], hi = fp[0];
    for (const Point2f& q : fp)
    {
        lo = Point2f(std::min(lo.x, q.x), std::min(lo.y, q.y));
        hi = Point2f(std::max(hi.x, q.x), std::max(hi.y, q.y));
    }
    const Rect2f box(lo, hi);
    for (int cap = 0; cap < 2; cap++)
    {
        const float y = cap == 0 ? height : 0.f;
        const Vec3f nrm(0, cap == 0 ? 1.f : -1.f, 0);
        Mesh c;
        for (int i = 0; i < n; i++)
        {
            c.vertices.push_back(Vec3f(fp[i].x, y, fp[i].y));
            c.normals.push_back(nrm);
            c.texcoords.push_back(Vec2f((fp[i].x - box.x) / box.width,
                                        1.f - (fp[i].y - box.y) / box.height));
        }
        for (int k = 1; k + 1 < n; k++)
        {
            Vec3i f(fanFrom, (fanFrom + k) % n, (fanFrom + k + 1) % n);
            const Vec3f cr = (c.vertices[f[1]] - c.vertices[f[0]])
                                 .cross(c.vertices[f[2]] - c.vertices[f[0]]);
            if (cr.dot(nrm) < 0)
                std::swap(f[1], f[2]);
            c.faces.push_back(f);
        }
        appendInTile(m, c, tile++);
    }
    return m;
}

Matx44d translation(double x, double y, double z)
{
    return Matx44d(1, 0, 0, x, 0, 1, 0, y, 0, 0, 1, z, 0, 0, 0, 1);
}

// ---------------------------------------------------------------------------------------------
// The scene (CPU side)

struct SceneModel
{
    std::vector<String> names;
    std::vector<Mesh> objects;  // world coordinates, textured (atlas), flat / smooth normals
    Mesh ground;
    Vec3d centre;               // the point the camera looks at
    double size = 10;           // footprint diameter of the objects (world units)
    double distance = 100;      // camera distance from the centre
    double scale = 1;           // SCALED_ORTHOGRAPHIC s (pixels per world unit); f = s * D
    double handHeight = 1;      // PATH_HANDHELD: camera height above the ground
    std::vector<Camera> cameras;
    std::vector<Vec3f> boundCorners;  // corners of the objects' boxes and of the ground
};

Material objectMaterial()
{
    Material m;
    m.ambient = Vec3f(0.45f, 0.45f, 0.45f);
    m.diffuse = Vec3f(0.65f, 0.65f, 0.65f);
    return m;
}

Mesh makeBuilding(RNG& rng)
{
    Mesh m = Mesh::box(Vec3f(-0.8f, 0.f, 1.5f), Vec3f(2.2f, 3.2f, 3.5f));
    for (int face = 0; face < 6; face++)
        mapToTile(m, 4 * face, 4 * face + 4, face);
    const Vec3f wall(0.75f, 0.55f, 0.42f);  // brick
    std::vector<std::pair<Vec3f, TextureStyle>> tiles;
    for (int face = 0; face < 4; face++)
        tiles.push_back({wall, TEX_FACADE});
    tiles.push_back({Vec3f(0.45f, 0.45f, 0.48f), TEX_ROOF});
    tiles.push_back({Vec3f(0.3f, 0.3f, 0.3f), TEX_WALL});
    m.material = objectMaterial();
    m.material.texture = makeAtlas(rng, tiles);
    return m;
}

Mesh makeLBlock(RNG& rng)
{
    // Footprint (x, z): a back arm along x and a left arm towards the camera; the inner corner
    // (the reflex vertex 3) faces the default camera.
    const std::vector<Point2f> fp = {Point2f(-5.0f, -3.0f), Point2f(-0.5f, -3.0f),
                                     Point2f(-0.5f, -1.0f), Point2f(-3.0f, -1.0f),
                                     Point2f(-3.0f, 1.0f),  Point2f(-5.0f, 1.0f)};
    Mesh m = prism(fp, 2.4f, 3, 0);
    std::vector<std::pair<Vec3f, TextureStyle>> tiles;
    for (int i = 0; i < 6; i++)
        tiles.push_back({Vec3f(0.62f, 0.66f, 0.72f), i % 2 ? TEX_WALL : TEX_FACADE});
    tiles.push_back({Vec3f(0.5f, 0.35f, 0.3f), TEX_ROOF});
    tiles.push_back({Vec3f(0.3f, 0.3f, 0.3f), TEX_WALL});
    m.material = objectMaterial();
    m.material.texture = makeAtlas(rng, tiles);
    return m;
}

Mesh makeTower(RNG& rng)
{
    // The paper's hotel: a narrow shaft under a wider cap (here a round "mushroom").
    Mesh m;
    appendInTile(m, Mesh::cylinder(0.55f, 0.f, 4.4f, 24), 0);
    appendInTile(m, Mesh::cylinder(1.7f, 4.4f, 5.5f, 40), 1);
    appendInTile(m, Mesh::cone(1.7f, 5.5f, 6.3f, 40), 2);
    m.transform(translation(2.8, 0, -1.8));
    std::vector<std::pair<Vec3f, TextureStyle>> tiles = {
        {Vec3f(0.85f, 0.82f, 0.7f), TEX_WALL},
        {Vec3f(0.55f, 0.7f, 0.6f), TEX_WALL},
        {Vec3f(0.7f, 0.3f, 0.25f), TEX_ROOF}};
    m.material = objectMaterial();
    m.material.texture = makeAtlas(rng, tiles);
    return m;
}

Mesh makeGround(RNG& rng)
{
    Mesh m;
    const float h = kGroundHalfSide;
    const Vec3f p[4] = {Vec3f(-h, 0, h), Vec3f(h, 0, h), Vec3f(h, 0, -h), Vec3f(-h, 0, -h)};
    for (int k = 0; k < 4; k++)
    {
        m.vertices.push_back(p[k]);
        m.normals.push_back(Vec3f(0, 1, 0));
        // u along +x, v along -z: seen from above with +z towards the viewer, v is up.
        m.texcoords.push_back(Vec2f(p[k][0] / kGroundTexturePeriod,
                                    -p[k][2] / kGroundTexturePeriod));
    }
    m.faces.push_back(Vec3i(0, 1, 2));
    m.faces.push_back(Vec3i(0, 2, 3));
    m.material.ambient = Vec3f(0.45f, 0.45f, 0.45f);
    m.material.diffuse = Vec3f(0.6f, 0.6f, 0.6f);
    m.material.texture = makeTexture(rng, Size(1024, 1024), Vec3f(0.5f, 0.56f, 0.4f),
                                     TEX_GROUND);
    return m;
}

double smoothJitter(double t, const Vec4d& phase)
{
    return 0.6 * std::sin(2 * kPi * 1.3 * t + phase[0]) +
           0.4 * std::sin(2 * kPi * 3.7 * t + phase[1]);
}

// Intrinsics of every path: the principal point at the image centre, f = s * D (the framing of
// the scaled orthographic camera at the scene centre), the lens of Params::distortion.
Camera finishCamera(const SceneSynthesizer::Params& p, const SceneModel& m, const Matx33d& R,
                    const Vec3d& C, int f)
{
    const Vec3d tv = -(R * C);
    const Point2d pp((p.imageSize.width - 1) * 0.5, (p.imageSize.height - 1) * 0.5);
    if (p.model == SCALED_ORTHOGRAPHIC)
        return Camera::orthographic(R, tv, m.scale, pp, f);
    const double fl = m.scale * m.distance;
    return Camera::perspective(R, tv, Matx33d(fl, 0, pp.x, 0, fl, pp.y, 0, 0, 1), f,
                               p.distortion);
}

// World-to-camera rotation of a camera looking along `forward` (world), image y towards the
// ground, rolled by `roll` radians about its axis.
Matx33d lookRotation(const Vec3d& forward, double roll)
{
    const Vec3d z = cv::normalize(forward);
    const Vec3d x = cv::normalize(z.cross(Vec3d(0, 1, 0)));
    const Vec3d y = z.cross(x);
    const Matx33d R0(x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]);
    const double c = std::cos(roll), s = std::sin(roll);
    return Matx33d(c, -s, 0, s, c, 0, 0, 0, 1) * R0;
}

// PATH_HANDHELD: the smooth motions of a hand, each a sum of three sinusoids (cycles per shot,
// weights summing to 1, so |value| <= 1 and the peak is the stated amplitude), phases from the
// seed. The frequencies are low (a walker's sway, not the 2 Hz step: the phone's stabiliser
// removes that) and incommensurate, so no two motions repeat together.
const double kHandFreq[3] = {0.6, 1.45, 3.2};
const double kHandWeight[3] = {0.55, 0.3, 0.15};
enum HandMotion { HAND_SWAY_X, HAND_SWAY_Y, HAND_SWAY_Z, HAND_YAW, HAND_PITCH, HAND_ROLL,
                  HAND_MOTIONS };

double handMotion(double t, const Vec3d& phase)
{
    double v = 0;
    for (int k = 0; k < 3; k++)
        v += kHandWeight[k] * std::sin(2 * kPi * kHandFreq[k] * t + phase[k]);
    return v;
}

Camera makeHandheldCamera(const SceneSynthesizer::Params& p, const SceneModel& m,
                          const std::vector<Vec3d>& phases, int f)
{
    typedef SceneSynthesizer S;
    const double t = (double)f / (p.frames - 1);
    const double az = (p.orbitDegrees * (t - 0.5)) * kPi / 180;
    const Vec3d sway(S::kHandheldSwayUnits * handMotion(t, phases[HAND_SWAY_X]),
                     S::kHandheldSwayUnits * handMotion(t, phases[HAND_SWAY_Y]),
                     S::kHandheldSwayUnits * handMotion(t, phases[HAND_SWAY_Z]));
    // The walker's arc around the scene centre at the horizontal distance D, at hand height.
    const Vec3d C = Vec3d(m.centre[0] + m.distance * std::sin(az), m.handHeight,
                          m.centre[2] + m.distance * std::cos(az)) + sway;
    const double yaw = S::kHandheldWobbleDeg * handMotion(t, phases[HAND_YAW]) * kPi / 180;
    const double pitch = S::kHandheldWobbleDeg * handMotion(t, phases[HAND_PITCH]) * kPi / 180;
    const double roll = S::kHandheldRollDeg * handMotion(t, phases[HAND_ROLL]) * kPi / 180;
    // Aimed at the scene centre, then wobbled: yaw about the world's up, pitch about the
    // camera's x axis.
    const Vec3d toCentre = cv::normalize(m.centre - C);
    const Matx33d Ryaw(std::cos(yaw), 0, std::sin(yaw), 0, 1, 0, -std::sin(yaw), 0,
                       std::cos(yaw));
    const Matx33d R0 = lookRotation(Ryaw * toCentre, 0.0);
    const Matx33d Rpitch(1, 0, 0, 0, std::cos(pitch), -std::sin(pitch), 0, std::sin(pitch),
                         std::cos(pitch));
    const Matx33d Rroll(std::cos(roll), -std::sin(roll), 0, std::sin(roll), std::cos(roll), 0,
                        0, 0, 1);
    return finishCamera(p, m, Rroll * Rpitch * R0, C, f);
}

Camera makeCamera(const SceneSynthesizer::Params& p, const SceneModel& m, const Vec4d& phE,
                  const Vec4d& phR, int f)
{
    const double t = p.frames > 1 ? (double)f / (p.frames - 1) : 0.0;
    const double az = (p.orbitDegrees * (t - 0.5)) * kPi / 180;
    double elDeg = p.elevationDegrees + kJitterElevationDeg * smoothJitter(t, phE);
    elDeg = std::min(89.5, std::max(0.5, elDeg));
    const double el = elDeg * kPi / 180;
    const double roll = kJitterRollDeg * smoothJitter(t, phR) * kPi / 180;
    const Vec3d dir(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
    const Vec3d C = m.centre + m.distance * dir;
    return finishCamera(p, m, lookRotation(-dir, roll), C, f);
}

std::shared_ptr<SceneModel> buildScene(const SceneSynthesizer::Params& p)
{
    auto m = std::make_shared<SceneModel>();
    RNG texRng(mixSeed(p.seed, 1));
    m->names = {"building", "lblock", "tower"};
    m->objects.push_back(makeBuilding(texRng));
    m->objects.push_back(makeLBlock(texRng));
    m->objects.push_back(makeTower(texRng));
    m->ground = makeGround(texRng);

    Vec3f lo(FLT_MAX, FLT_MAX, FLT_MAX), hi(-FLT_MAX, -FLT_MAX, -FLT_MAX);
    for (const Mesh& o : m->objects)
    {
        Vec3f a, b;
        o.bounds(a, b);
        for (int k = 0; k < 3; k++)
        {
            lo[k] = std::min(lo[k], a[k]);
            hi[k] = std::max(hi[k], b[k]);
        }
        for (int c = 0; c < 8; c++)
            m->boundCorners.push_back(Vec3f(c & 1 ? b[0] : a[0], c & 2 ? b[1] : a[1],
                                            c & 4 ? b[2] : a[2]));
    }
    for (const Vec3f& v : m->ground.vertices)
        m->boundCorners.push_back(v);
    m->size = std::sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) +
                        (double)(hi[2] - lo[2]) * (hi[2] - lo[2]));
    // Look at the middle of the footprint, at about a third of the tallest object's height.
    m->centre = Vec3d(0.5 * (lo[0] + hi[0]), 0.3 * hi[1], 0.5 * (lo[2] + hi[2]));
    m->distance = p.distanceRatio * m->size;
    const double frameWidth = std::min((double)p.imageSize.width, p.imageSize.height * 4.0 / 3);
    m->scale = kFrameFill * frameWidth / m->size;

    m->handHeight = SceneSynthesizer::kHandheldHeightFraction * hi[1];
    if (p.path == SceneSynthesizer::PATH_HANDHELD)
    {
        // Its own stream: the orbit's jitter (stream 2) stays as it was.
        RNG handRng(mixSeed(p.seed, 4));
        std::vector<Vec3d> phases(HAND_MOTIONS);
        for (Vec3d& ph : phases)
            for (int k = 0; k < 3; k++)
                ph[k] = handRng.uniform(0.0, 2 * kPi);
        for (int f = 0; f < p.frames; f++)
            m->cameras.push_back(makeHandheldCamera(p, *m, phases, f));
        return m;
    }
    RNG camRng(mixSeed(p.seed, 2));
    Vec4d phE, phR;
    for (int k = 0; k < 4; k++)
    {
        phE[k] = camRng.uniform(0.0, 2 * kPi);
        phR[k] = camRng.uniform(0.0, 2 * kPi);
    }
    for (int f = 0; f < p.frames; f++)
        m->cameras.push_back(makeCamera(p, *m, phE, phR, f));
    return m;
}

// Near and far planes (camera-space z) that hold every drawn thing, tight for depth precision.
void depthRange(const Camera& cam, Size size, const std::vector<Vec3f>& corners,
                const std::vector<Vec3f>& extra, double distance, double& zNear, double& zFar)
{
    double lo = DBL_MAX, hi = -DBL_MAX;
    auto add = [&](const Vec3f& v) {
        const double z = cam.depth(Vec3d(v));
        lo = std::min(lo, z);
        hi = std::max(hi, z);
    };
    for (const Vec3f& v : corners)
        add(v);
    for (const Vec3f& v : extra)
        add(v);
    if (cam.model == SCALED_ORTHOGRAPHIC)
    {
        zNear = lo - 1;
        zFar = hi + 1;
        return;
    }
    // Perspective: the ground may reach behind the camera; the nearest visible ground is seen at
    // an image corner (depth over a plane is monotone along image lines).
    double nearest = DBL_MAX;
    for (const Vec3f& v : extra)
        nearest = std::min(nearest, cam.depth(Vec3d(v)));
    for (size_t i = 0; i < corners.size(); i++)
    {
        const Vec3d X(corners[i]);
        if (X[1] > 0)  // object box corners (ground corners have y = 0)
            nearest = std::min(nearest, cam.depth(X));
    }
    const Point2d pc[4] = {Point2d(-0.5, -0.5), Point2d(size.width - 0.5, -0.5),
                           Point2d(-0.5, size.height - 0.5),
                           Point2d(size.width - 0.5, size.height - 0.5)};
    for (const Point2d& px : pc)
    {
        const Ray r = cam.backproject(px);
        if (r.direction[1] < -1e-9)
        {
            const double lambda = -r.origin[1] / r.direction[1];
            if (lambda > 0)
                nearest = std::min(nearest, cam.depth(r.at(lambda)));
        }
    }
    zNear = std::max(0.01 * distance, 0.9 * nearest);
    zFar = std::max(hi + 1, zNear * 2);
}

// ---------------------------------------------------------------------------------------------
// OpenGL side

struct GlScene
{
    detail::GlContext ctx;
    std::unique_ptr<detail::GlMesh> ground;
    std::vector<std::unique_ptr<detail::GlMesh>> objects;
    // Lens distortion: the frame-to-fine-ideal map of the label / depth / mask pass, for the
    // view and factor it was made for (the intrinsics are the same in every frame).
    Ptr<const LensView> maskView;
    int maskFactor = 0;
    Mat maskMap;
    // Params::sun: its direction as the meshes' light, and the shadow map of the real objects
    // (laid out and rendered on first use).
    Sun sun;
    Vec3f light = detail::kLightDirection;
    detail::ShadowMap realShadow;
    bool realShadowReady = false;

    GlScene(Size size, const SceneModel& m, const Sun& sunIn) : ctx(size), sun(sunIn)
    {
        if (sun.enabled())
        {
            light = Vec3f(sun.direction / cv::norm(sun.direction));
            Mesh g = m.ground;
            g.material = detail::sunSplitMaterial(g.material, sun.sky);
            ground.reset(new detail::GlMesh(g, 0.f, light));
            for (size_t i = 0; i < m.objects.size(); i++)
            {
                Mesh o = m.objects[i];
                o.material = detail::sunSplitMaterial(o.material, sun.sky);
                objects.emplace_back(new detail::GlMesh(o, (float)(i + 1) / 255.f, light));
            }
            return;
        }
        ground.reset(new detail::GlMesh(m.ground, 0.f));
        for (size_t i = 0; i < m.objects.size(); i++)
            objects.emplace_back(new detail::GlMesh(m.objects[i], (float)(i + 1) / 255.f));
    }
    ~GlScene()
    {
        // Textures belong to this context: make it current before they are deleted.
        try
        {
            ctx.makeCurrent();
        }
        catch (...)
        {
        }
        objects.clear();
        ground.reset();
    }
};

struct PassOutputs
{
    Mat* bgr = nullptr;
    Mat* labels = nullptr;
    Mat* depth = nullptr;
    std::vector<Mat>* whole = nullptr;
    //! CV_32F, the colour's size: the fraction of each pixel the extra (virtual) meshes cover
    Mat* virtualCover = nullptr;
    //! Params::sun: the casters' shadow map (the colour is shadowed), else null
    const detail::ShadowMap* shadow = nullptr;
};

// The shadow map of the sun over the real objects and the extra meshes (GlScene::sun enabled).
void renderSunShadow(GlScene& gl, const SceneModel& m,
                     const std::vector<const detail::GlMesh*>& extra,
                     const std::vector<Vec3f>& extraCorners, detail::ShadowMap& map)
{
    std::vector<Vec3d> pts;
    for (const Mesh& o : m.objects)
    {
        Vec3f lo, hi;
        o.bounds(lo, hi);
        detail::appendBoxCorners(Vec3d(lo), Vec3d(hi), pts);
    }
    for (const Vec3f& v : extraCorners)
        pts.push_back(Vec3d(v));
    map.layout(gl.sun, pts);
    detail::renderShadowDepth(gl.ctx, map, [&]() {
        for (const auto& o : gl.objects)
            o->drawFlat();
        for (const detail::GlMesh* e : extra)
            e->drawFlat();
    });
    map.finish();
}

void loadMatrices(const Camera& cam, Size size, double zNear, double zFar)
{
    const Matx44d P = detail::glProjection(cam, size, zNear, zFar).t();
    const Matx44d MV = detail::glModelView(cam).t();
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(P.val);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(MV.val);
}

/* Renders the passes of one frame on the calling thread:
   - the shaded pass (ground, objects, extra meshes) with depth test -> colour, labels (alpha
     channel: objects write (i + 1) / 255) and depth;
   - the silhouette pass: every object drawn without depth test into the red channel with a
     logical OR of its bit (1 << i), so one pass gives every object's whole silhouette. */
void renderPasses(GlScene& gl, const SceneModel& m, const Camera& cam, Size size,
                  const std::vector<const detail::GlMesh*>& extra,
                  const std::vector<Vec3f>& extraCorners, const PassOutputs& out)
{
    if (gl.ctx.size() != size)
        gl.ctx.resize(size);
    else
        gl.ctx.makeCurrent();
    double zNear, zFar;
    depthRange(cam, size, m.boundCorners, extraCorners, m.distance, zNear, zFar);
    loadMatrices(cam, size, zNear, zFar);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_DITHER);
    glDisable(GL_COLOR_LOGIC_OP);
    if (out.bgr || out.labels || out.depth || out.virtualCover)
    {
        glClearColor(kSkyRgb[0], kSkyRgb[1], kSkyRgb[2], 0.f);
        glClearDepth(1.0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        gl.ground->draw();
        for (const auto& o : gl.objects)
            o->draw();
        for (const detail::GlMesh* e : extra)
            e->draw();
        Mat camZ;
        if (out.depth || (out.bgr && out.shadow))
        {
            Mat d01;
            gl.ctx.readDepth(d01);
            detail::windowDepthToCameraZ(cam, d01, zNear, zFar, camZ);
        }
        if (out.bgr || out.labels || out.virtualCover)
        {
            Mat bgra;
            gl.ctx.readColorAlpha(bgra);
            if (out.bgr && out.shadow)
            {
                // The ambient-only pass over the same depth (the same fragments pass GL_LEQUAL),
                // then lit and shadowed colours mixed by the sun's visibility (lighting.hpp).
                glClear(GL_COLOR_BUFFER_BIT);
                glDepthFunc(GL_LEQUAL);
                glDepthMask(GL_FALSE);
                gl.ground->draw(true);
                for (const auto& o : gl.objects)
                    o->draw(true);
                for (const detail::GlMesh* e : extra)
                    e->draw(true);
                glDepthMask(GL_TRUE);
                glDepthFunc(GL_LESS);
                Mat amb, z32, vis;
                gl.ctx.readColorAlpha(amb);
                camZ.convertTo(z32, CV_32F);
                detail::depthVisibility(cam, z32, *out.shadow, nullptr, vis);
                detail::applyVisibility(bgra, amb, vis, bgra);
            }
            if (out.bgr)
                cv::cvtColor(bgra, *out.bgr, COLOR_BGRA2BGR);
            if (out.virtualCover)
            {
                // Extra meshes write alpha 255 (GlMesh id 1), the scene's objects (i + 1) / 255.
                Mat alpha;
                cv::extractChannel(bgra, alpha, 3);
                cv::compare(alpha, 255, alpha, CMP_EQ);
                alpha.convertTo(*out.virtualCover, CV_32F, 1.0 / 255);
            }
            if (out.labels)
                cv::extractChannel(bgra, *out.labels, 3);
        }
        if (out.depth)
            camZ.copyTo(*out.depth);
    }
    if (out.whole)
    {
        CV_Assert(gl.objects.size() <= 8);
        glClearColor(0.f, 0.f, 0.f, 0.f);
        glClear(GL_COLOR_BUFFER_BIT);
        glDisable(GL_DEPTH_TEST);
        glEnable(GL_COLOR_LOGIC_OP);
        glLogicOp(GL_OR);
        for (size_t i = 0; i < gl.objects.size(); i++)
        {
            glColor4ub((GLubyte)(1u << i), 0, 0, 0);
            gl.objects[i]->drawFlat();
        }
        glDisable(GL_COLOR_LOGIC_OP);
        glFinish();
        Mat bits(size, CV_8U);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, size.width, size.height, GL_RED, GL_UNSIGNED_BYTE, bits.data);
        cv::flip(bits, bits, 0);
        out.whole->resize(gl.objects.size());
        for (size_t i = 0; i < gl.objects.size(); i++)
        {
            Mat one;
            cv::bitwise_and(bits, Scalar(1u << i), one);
            cv::compare(one, 0, (*out.whole)[i], CMP_GT);
        }
    }
}

// renderPasses() with the colour rendered `supersample` times finer (supersampledCamera(), from
// compositor.hpp) and averaged down; labels, depth and silhouettes stay sampled at pixel centres.
void renderSupersampled(GlScene& gl, const SceneModel& m, const Camera& cam, Size size,
                        int supersample, const std::vector<const detail::GlMesh*>& extra,
                        const std::vector<Vec3f>& extraCorners, const PassOutputs& out)
{
    if (supersample <= 1 || !out.bgr)
    {
        renderPasses(gl, m, cam, size, extra, extraCorners, out);
        return;
    }
    PassOutputs rest = out;
    rest.bgr = nullptr;
    rest.virtualCover = nullptr;
    if (rest.labels || rest.depth || rest.whole)
        renderPasses(gl, m, cam, size, extra, extraCorners, rest);
    Mat fine, fineCover;
    PassOutputs colour;
    colour.bgr = &fine;
    colour.shadow = out.shadow;
    if (out.virtualCover)
        colour.virtualCover = &fineCover;
    renderPasses(gl, m, supersampledCamera(cam, supersample),
                 Size(size.width * supersample, size.height * supersample), extra, extraCorners,
                 colour);
    cv::resize(fine, *out.bgr, size, 0, 0, INTER_AREA);
    if (out.virtualCover)
        cv::resize(fineCover, *out.virtualCover, size, 0, 0, INTER_AREA);
}

// Lens distortion: how much finer than the ideal view labels, depth and masks are rendered.
int lensMaskFactor(Size idealSize)
{
    int k = SceneSynthesizer::kLensMaskSupersample;
    while (k > 1 && (double)idealSize.area() * k * k > SceneSynthesizer::kLensMaskPixels)
        k--;
    return k;
}

// Offset (fine pixels) of the finer view's grid: with an even factor no fine sample would sit on
// an ideal pixel's centre, and the ideal pixels' centres are the frame's (LensView, at scale 1),
// so every pixel's nearest sample would be a quarter ideal pixel off in the same direction (a
// 0.25 px shift of every mask edge); half a fine pixel puts a sample on each centre.
double lensMaskPhase(int factor)
{
    return factor % 2 == 0 ? 0.5 : 0.0;
}

// The map (frame size, CV_32FC2) from each frame pixel to the pixel of the ideal view rendered
// `factor` times finer that sees its ray; cached in `gl` for the view.
const Mat& lensMaskMap(GlScene& gl, const Ptr<const LensView>& view, int factor)
{
    if (gl.maskView == view && gl.maskFactor == factor)
        return gl.maskMap;
    const Size fs = view->frameSize();
    const double phase = lensMaskPhase(factor);
    Mat map(fs, CV_32FC2);
    parallel_for_(Range(0, fs.height), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            Point2f* row = map.ptr<Point2f>(y);
            for (int x = 0; x < fs.width; x++)
            {
                const Point2d q = view->frameToIdeal(Point2d(x, y));
                row[x] = Point2f((float)(factor * (q.x + 0.5) - 0.5 + phase),
                                 (float)(factor * (q.y + 0.5) - 0.5 + phase));
            }
        }
    });
    gl.maskView = view;
    gl.maskFactor = factor;
    gl.maskMap = map;
    return gl.maskMap;
}

/* The passes of one frame through the camera's lens. Without distortion: renderSupersampled().
With it, in the ideal pinhole view of LensView (the pose, f' >= f, a margin around the frame),
warped into the frame as Blender's Movie Distortion node does: the colour (and the virtual
coverage) bilinearly, as a lens blurs; labels, depth and silhouettes by nearest sample from a
view lensMaskFactor() times finer, so that they stay binary / one surface's depth and agree with
each other pixel for pixel (a pixel's sample is within 0.5 / factor ideal pixels of its ray). */
void renderView(GlScene& gl, const SceneModel& m, const Camera& cam, Size size, int supersample,
                const std::vector<const detail::GlMesh*>& extra,
                const std::vector<Vec3f>& extraCorners, const PassOutputs& out)
{
    if (!cam.hasDistortion())
    {
        renderSupersampled(gl, m, cam, size, supersample, extra, extraCorners, out);
        return;
    }
    const Ptr<const LensView> view = LensView::get(cam, size);
    const Camera ideal = view->idealCamera(cam);
    const Size idealSize = view->idealSize();
    if (out.bgr)
    {
        Mat bgr, cover;
        PassOutputs colour;
        colour.bgr = &bgr;
        colour.shadow = out.shadow;
        if (out.virtualCover)
            colour.virtualCover = &cover;
        renderSupersampled(gl, m, ideal, idealSize, supersample, extra, extraCorners, colour);
        view->toFrame(bgr, *out.bgr, INTER_LINEAR);
        if (out.virtualCover)
            view->toFrame(cover, *out.virtualCover, INTER_LINEAR);
    }
    if (!out.labels && !out.depth && !out.whole)
        return;
    const int factor = lensMaskFactor(idealSize);
    Mat labels, depth;
    std::vector<Mat> whole;
    PassOutputs rest;
    rest.labels = out.labels ? &labels : nullptr;
    rest.depth = out.depth ? &depth : nullptr;
    rest.whole = out.whole ? &whole : nullptr;
    Camera fine = supersampledCamera(ideal, factor);
    fine.K(0, 2) += lensMaskPhase(factor);
    fine.K(1, 2) += lensMaskPhase(factor);
    renderPasses(gl, m, fine,
                 Size(idealSize.width * factor, idealSize.height * factor), extra, extraCorners,
                 rest);
    const Mat& map = lensMaskMap(gl, view, factor);
    if (out.labels)
        cv::remap(labels, *out.labels, map, noArray(), INTER_NEAREST, BORDER_CONSTANT, Scalar());
    if (out.depth)
        cv::remap(depth, *out.depth, map, noArray(), INTER_NEAREST, BORDER_CONSTANT,
                  Scalar::all(std::numeric_limits<double>::infinity()));
    if (out.whole)
    {
        out.whole->resize(whole.size());
        for (size_t i = 0; i < whole.size(); i++)
            cv::remap(whole[i], (*out.whole)[i], map, noArray(), INTER_NEAREST, BORDER_CONSTANT,
                      Scalar());
    }
}

// Params::exposureDrift / whiteBalanceDrift on a rendered frame: BGR times `gains`, except for
// the fraction `virtualCover` (optional) of each pixel, which keeps the nominal exposure.
void applyGains(Mat& bgr, const Vec3d& gains, const Mat& virtualCover = Mat())
{
    if (gains == Vec3d(1, 1, 1))
        return;  // no drift: the frame as rendered, bit for bit
    parallel_for_(Range(0, bgr.rows), [&](const Range& r) {
        for (int y = r.start; y < r.end; y++)
        {
            Vec3b* row = bgr.ptr<Vec3b>(y);
            const float* cov = virtualCover.empty() ? nullptr : virtualCover.ptr<float>(y);
            for (int x = 0; x < bgr.cols; x++)
            {
                const double c = cov ? cov[x] : 0.0;
                for (int k = 0; k < 3; k++)
                    row[x][k] = saturate_cast<uchar>(row[x][k] * (c + (1 - c) * gains[k]));
            }
        }
    });
}

// ---------------------------------------------------------------------------------------------
// Tracks

bool insideAll(const std::vector<Camera>& cams, const Vec3d& X, Size size)
{
    for (const Camera& c : cams)
    {
        if (c.depth(X) <= 0)
            return false;
        const Point2d px = c.project(X);
        if (px.x < kTrackMarginPx || px.y < kTrackMarginPx ||
            px.x > size.width - 1 - kTrackMarginPx || px.y > size.height - 1 - kTrackMarginPx)
            return false;
    }
    return true;
}

// Whether X (on object `label` - 1, or the ground for label 0) is what the middle frame shows at
// its pixel.
bool visibleIn(const Camera& cam, const Mat& labels, const Mat& depth, const Vec3d& X, int label)
{
    const Point2d px = cam.project(X);
    const int u = cvRound(px.x), v = cvRound(px.y);
    if (u < 0 || v < 0 || u >= labels.cols || v >= labels.rows)
        return false;
    if (labels.at<uchar>(v, u) != label)
        return false;
    const float d = depth.at<float>(v, u);
    return std::isfinite(d) && std::abs(d - cam.depth(X)) < kVisibleDepthTol;
}

void makeTracks(const SceneSynthesizer::Params& p, const SceneModel& m, const Mat& midLabels,
                const Mat& midDepth, SyntheticScene& scene)
{
    const int F = p.frames, P = p.numTracks;
    const Size size = p.imageSize;
    const Camera& mid = m.cameras[F / 2];
    RNG rng(mixSeed(p.seed, 3));

    const int nOut = std::min(P, cvRound(p.outlierFraction * P));
    const int nPartial = std::min(P, cvRound(p.partialFraction * P));
    const int nIn = P - nOut;
    const int nObj = cvRound(kObjectTrackFraction * nIn);

    // Candidate triangles: object faces that do not face down (bottoms and undersides are never
    // seen from above), weighted by area.
    struct Tri { int obj; Vec3d a, b, c, n; };
    std::vector<Tri> tris;
    std::vector<double> cumArea;
    double total = 0;
    for (size_t o = 0; o < m.objects.size(); o++)
        for (const Vec3i& f : m.objects[o].faces)
        {
            Tri t;
            t.obj = (int)o;
            t.a = Vec3d(m.objects[o].vertices[f[0]]);
            t.b = Vec3d(m.objects[o].vertices[f[1]]);
            t.c = Vec3d(m.objects[o].vertices[f[2]]);
            const Vec3d cr = (t.b - t.a).cross(t.c - t.a);
            const double area = 0.5 * cv::norm(cr);
            if (area <= 1e-9)
                continue;
            t.n = cr * (0.5 / area);
            if (t.n[1] < -0.2)
                continue;
            tris.push_back(t);
            total += area;
            cumArea.push_back(total);
        }

    std::vector<Vec3d> points;
    points.reserve(nIn);
    const long maxAttempts = 2000L * std::max(1, nIn) + 100000L;
    long attempts = 0;
    while ((int)points.size() < nObj && attempts++ < maxAttempts)
    {
        const double r = rng.uniform(0.0, total);
        const size_t k = std::min(tris.size() - 1, (size_t)(std::upper_bound(cumArea.begin(),
                                  cumArea.end(), r) - cumArea.begin()));
        const Tri& t = tris[k];
        double s1 = std::sqrt(rng.uniform(0.0, 1.0)), s2 = rng.uniform(0.0, 1.0);
        const Vec3d X = (1 - s1) * t.a + s1 * (1 - s2) * t.b + s1 * s2 * t.c;
        if (!visibleIn(mid, midLabels, midDepth, X, t.obj + 1) || !insideAll(m.cameras, X, size))
            continue;
        points.push_back(X);
    }
    while ((int)points.size() < nIn && attempts++ < maxAttempts)
    {
        const Point2d px(rng.uniform(0.0, size.width - 1.0), rng.uniform(0.0, size.height - 1.0));
        const Ray ray = mid.backproject(px);
        if (ray.direction[1] > -1e-6)
            continue;
        const double lambda = -ray.origin[1] / ray.direction[1];
        Vec3d X = ray.at(lambda);
        X[1] = 0;
        if (!visibleIn(mid, midLabels, midDepth, X, 0) || !insideAll(m.cameras, X, size))
            continue;
        points.push_back(X);
    }
    if ((int)points.size() < nIn)
        CV_Error(Error::StsInternal, cv::format("SceneSynthesizer: could sample only %d of %d "
                 "visible track points", (int)points.size(), nIn));

    // Column order: a random permutation, so objects, ground and outliers are interleaved.
    std::vector<int> perm(P);
    std::iota(perm.begin(), perm.end(), 0);
    for (int i = P - 1; i > 0; i--)
        std::swap(perm[i], perm[rng.uniform(0, i + 1)]);

    scene.outlierTrack.assign(P, 0);
    scene.groundTruth.points = Mat(P, 3, CV_64F,
                                   Scalar::all(std::numeric_limits<double>::quiet_NaN()));
    Mat clean(F, P, CV_32FC2), noisy(F, P, CV_32FC2);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (int i = 0; i < P; i++)
    {
        const int col = perm[i];
        if (i < nOut)
        {
            scene.outlierTrack[col] = 1;
            // A random walk with drift, reflected at the frame border: follows no 3D point.
            Point2d pos(rng.uniform(kTrackMarginPx, size.width - 1 - kTrackMarginPx),
                        rng.uniform(kTrackMarginPx, size.height - 1 - kTrackMarginPx));
            Point2d vel(rng.uniform(-kOutlierSpeedPx, kOutlierSpeedPx),
                        rng.uniform(-kOutlierSpeedPx, kOutlierSpeedPx));
            for (int f = 0; f < F; f++)
            {
                clean.at<Point2f>(f, col) = Point2f(pos);
                noisy.at<Point2f>(f, col) = Point2f(pos);
                pos += vel + Point2d(rng.gaussian(kOutlierStepSigmaPx),
                                     rng.gaussian(kOutlierStepSigmaPx));
                const double lim[2] = {size.width - 1 - kTrackMarginPx,
                                       size.height - 1 - kTrackMarginPx};
                double* c[2] = {&pos.x, &pos.y};
                double* v[2] = {&vel.x, &vel.y};
                for (int k = 0; k < 2; k++)
                {
                    if (*c[k] < kTrackMarginPx)
                    {
                        *c[k] = 2 * kTrackMarginPx - *c[k];
                        *v[k] = -*v[k];
                    }
                    if (*c[k] > lim[k])
                    {
                        *c[k] = 2 * lim[k] - *c[k];
                        *v[k] = -*v[k];
                    }
                    *c[k] = std::min(lim[k], std::max(kTrackMarginPx, *c[k]));
                }
            }
            continue;
        }
        const Vec3d& X = points[i - nOut];
        for (int k = 0; k < 3; k++)
            scene.groundTruth.points.at<double>(col, k) = X[k];
        for (int f = 0; f < F; f++)
        {
            const Point2d px = m.cameras[f].project(X);
            clean.at<Point2f>(f, col) = Point2f(px);
            noisy.at<Point2f>(f, col) = Point2f((float)(px.x + rng.gaussian(p.noiseSigma)),
                                                (float)(px.y + rng.gaussian(p.noiseSigma)));
        }
    }
    // Partial tracks: a random subset, observed on one contiguous range of frames.
    for (int i = P - 1; i > 0; i--)
        std::swap(perm[i], perm[rng.uniform(0, i + 1)]);
    const int minLen = std::min(F, std::max(2, (int)std::ceil(kPartialMinFraction * F)));
    const int maxLen = std::max(minLen, F - 1);
    for (int i = 0; i < nPartial; i++)
    {
        const int col = perm[i];
        const int len = rng.uniform(minLen, maxLen + 1);
        const int start = rng.uniform(0, F - len + 1);
        for (int f = 0; f < F; f++)
            if (f < start || f >= start + len)
            {
                clean.at<Point2f>(f, col) = Point2f(nan, nan);
                noisy.at<Point2f>(f, col) = Point2f(nan, nan);
            }
    }
    scene.tracks = Tracks::fromDense(size, noisy, "SceneSynthesizer: tracks");
    scene.cleanTracks = Tracks::fromDense(size, clean, "SceneSynthesizer: clean tracks");
}

// ---------------------------------------------------------------------------------------------

class SceneSynthesizerImpl CV_FINAL : public SceneSynthesizer
{
public:
    explicit SceneSynthesizerImpl(const Params& p) { setParams(p); }

    ~SceneSynthesizerImpl() CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        gl_.reset();
    }

    Params getParams() const CV_OVERRIDE { return p_; }

    void setParams(const Params& p) CV_OVERRIDE
    {
        if (p.frames < 2)
            CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: frames must be >= 2 (got %d)",
                                                  p.frames));
        if (p.imageSize.width < 32 || p.imageSize.height < 32)
            CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: imageSize must be at least "
                     "32x32 (got %dx%d)", p.imageSize.width, p.imageSize.height));
        // Read as an int: a CameraModel holding another value is not one to load (UBSan's
        // enum check, the whole suite under scripts/sanitize.sh).
        int model = 0;
        static_assert(sizeof(model) == sizeof(p.model), "CameraModel is an int-sized enum");
        std::memcpy(&model, &p.model, sizeof(model));
        if (model != SCALED_ORTHOGRAPHIC && model != PERSPECTIVE)
            CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: unknown camera model %d",
                                                  model));
        if (!(p.distanceRatio >= 1.0) || !std::isfinite(p.distanceRatio))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: distanceRatio must be "
                     ">= 1 (got %g)", p.distanceRatio));
        if (!(p.orbitDegrees >= 0.0 && p.orbitDegrees <= 360.0))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: orbitDegrees must be in "
                     "[0, 360] (got %g)", p.orbitDegrees));
        if (!(p.elevationDegrees > 0.0 && p.elevationDegrees < 90.0))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: elevationDegrees must be "
                     "in (0, 90) (got %g)", p.elevationDegrees));
        if (p.numTracks < 1)
            CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: numTracks must be >= 1 "
                     "(got %d)", p.numTracks));
        if (!(p.noiseSigma >= 0.0) || !std::isfinite(p.noiseSigma))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: noiseSigma must be >= 0 "
                     "(got %g)", p.noiseSigma));
        if (!(p.partialFraction >= 0.0 && p.partialFraction <= 1.0))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: partialFraction must be "
                     "in [0, 1] (got %g)", p.partialFraction));
        if (!(p.outlierFraction >= 0.0 && p.outlierFraction <= 1.0))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: outlierFraction must be "
                     "in [0, 1] (got %g)", p.outlierFraction));
        if (p.numKeyFrames < 2 || p.numKeyFrames > p.frames)
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: numKeyFrames must be in "
                     "[2, frames = %d] (got %d)", p.frames, p.numKeyFrames));
        if (p.frameSupersample < 1 || p.frameSupersample > 8)
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: frameSupersample must be "
                     "in [1, 8] (got %d)", p.frameSupersample));
        if (p.imageSize.width > std::max(kMaxImageWidth, kMaxImageHeight) ||
            p.imageSize.height > std::max(kMaxImageWidth, kMaxImageHeight) ||
            p.imageSize.width * (double)p.imageSize.height >
                (double)kMaxImageWidth * kMaxImageHeight)
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: imageSize must be at "
                     "most %dx%d (or %dx%d) (got %dx%d)", kMaxImageWidth, kMaxImageHeight,
                     kMaxImageHeight, kMaxImageWidth, p.imageSize.width, p.imageSize.height));
        if (!p.distortion.empty())
        {
            if (p.model != PERSPECTIVE)
                CV_Error(Error::StsBadArg, "SceneSynthesizer: distortion needs model "
                         "PERSPECTIVE (a scaled orthographic camera has no lens)");
            const size_t n = p.distortion.size();
            bool finite = true;
            for (double d : p.distortion)
                finite = finite && std::isfinite(d);
            if ((n != 4 && n != 5 && n != 8 && n != 12 && n != 14) || !finite)
                CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: distortion must be 4, "
                         "5, 8, 12 or 14 finite coefficients (got %d)", (int)n));
        }
        int path = 0;  // read as an int, as the model above
        static_assert(sizeof(path) == sizeof(p.path), "CameraPath is an int-sized enum");
        std::memcpy(&path, &p.path, sizeof(path));
        if (path != PATH_ORBIT && path != PATH_HANDHELD)
            CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: path must be PATH_ORBIT or "
                     "PATH_HANDHELD (got %d)", path));
        if (p.path == PATH_HANDHELD && p.model != PERSPECTIVE)
            CV_Error(Error::StsBadArg, "SceneSynthesizer: path PATH_HANDHELD needs model "
                     "PERSPECTIVE (a hand-held camera near the scene)");
        if (!(std::abs(p.exposureDrift) < 1.0))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: exposureDrift must be "
                     "in (-1, 1) (got %g)", p.exposureDrift));
        if (!(std::abs(p.whiteBalanceDrift) < 1.0))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: whiteBalanceDrift must "
                     "be in (-1, 1) (got %g)", p.whiteBalanceDrift));
        p.sun.validate("SceneSynthesizer: sun");
        if (p.sun.enabled() && !(p.sun.direction[1] > 0))
            CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: the sun must be above the "
                     "horizon (direction y > 0, the world is y up), got (%g, %g, %g)",
                     p.sun.direction[0], p.sun.direction[1], p.sun.direction[2]));
        if (!(p.videoBitrateMbps >= 0.0 && p.videoBitrateMbps <= 200.0))
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: videoBitrateMbps must "
                     "be in [0, 200] (got %g)", p.videoBitrateMbps));
        if (p.videoBitrateMbps > 0 && (p.imageSize.width % 2 || p.imageSize.height % 2))
            CV_Error(Error::StsBadArg, cv::format("SceneSynthesizer: videoBitrateMbps needs even "
                     "imageSize sides (H.264 4:2:0; got %dx%d)", p.imageSize.width,
                     p.imageSize.height));
        std::shared_ptr<SceneModel> built;
        if (!p.distortion.empty())
        {
            // A lens that folds over inside the frame has no ideal view: say so now, naming
            // the parameter, rather than at the first render (the scene is needed for f).
            built = buildScene(p);
            try
            {
                LensView::get(built->cameras.front(), p.imageSize);
            }
            catch (const cv::Exception& e)
            {
                CV_Error(Error::StsBadArg, "SceneSynthesizer: distortion: " + e.err);
            }
        }
        std::lock_guard<std::mutex> lock(mutex_);
        p_ = p;
        model_ = built;
        gl_.reset();
    }

    void synthesize(SyntheticScene& scene) const CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        const SceneModel& m = model();
        GlScene& gl = glScene();
        const int F = p_.frames;
        const size_t nObj = m.objects.size();
        scene = SyntheticScene();
        scene.frames.resize(F);
        scene.depth.resize(F);
        scene.labels.resize(F);
        std::vector<std::vector<Mat>> whole(F);
        for (int f = 0; f < F; f++)
        {
            render(gl, m, f, &scene.frames[f], &scene.labels[f], &scene.depth[f], &whole[f]);
            detail::reportProgress(p_.progress, "synth", "render", f + 1, F, "frames");
        }
        // Visible masks from the labels (CPU, parallel over frames: each writes its own masks).
        std::vector<std::vector<Mat>> visible(F);
        parallel_for_(Range(0, F), [&](const Range& r) {
            for (int f = r.start; f < r.end; f++)
                visible[f] = visibleMasks(scene.labels[f], nObj);
        });
        for (size_t i = 0; i < nObj; i++)
        {
            FrameMasks& w = scene.wholeMasks[m.names[i]];
            FrameMasks& v = scene.visibleMasks[m.names[i]];
            for (int f = 0; f < F; f++)
            {
                w[f] = whole[f][i];
                v[f] = visible[f][i];
            }
        }
        finishScene(m, scene.labels[F / 2], scene.depth[F / 2],
                    [&](int f) { return visible[f]; }, scene);
    }

    void write(const String& dir) const CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        const SceneModel& m = model();
        GlScene& gl = glScene();
        const int F = p_.frames;
        const size_t nObj = m.objects.size();
        // Every finite depth is within the scene's bounds (depth is affine in the point).
        double maxDepth = 0;
        for (const Camera& cam : m.cameras)
            for (const Vec3f& c : m.boundCorners)
                maxDepth = std::max(maxDepth, cam.depth(Vec3d(c)));
        // What the truth that is not per frame needs is kept as the frames go by: the middle
        // frame's labels and depth (the tracks are sampled on it), the key frames' masks.
        const std::vector<int> keys = keyFrames();
        std::map<int, std::vector<Mat>> keyVisible;
        Mat midLabels, midDepth;
        SyntheticScene scene;
        detail::writeSyntheticScene(dir, m.names, p_, F, maxDepth,
                                    [&](int f, detail::SyntheticFrame& out) {
            render(gl, m, f, &out.bgr, &out.labels, &out.depth, &out.whole);
            out.visible = visibleMasks(out.labels, nObj);
            if (f == F / 2)
            {
                midLabels = out.labels;
                midDepth = out.depth;
            }
            if (std::find(keys.begin(), keys.end(), f) != keys.end())
                keyVisible[f] = out.visible;
        }, [&]() -> const SyntheticScene& {
            finishScene(m, midLabels, midDepth, [&](int f) { return keyVisible.at(f); }, scene);
            return scene;
        }, p_.progress);
    }

    void renderWithVirtual(int frame, const std::vector<Mesh>& virtualObjects, OutputArray image,
                           int supersample) const CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        checkFrame(frame);
        if (supersample < 1 || supersample > 8)
            CV_Error(Error::StsOutOfRange, cv::format("renderWithVirtual: supersample must be in "
                     "[1, 8] (got %d)", supersample));
        const SceneModel& m = model();
        GlScene& gl = glScene();
        gl.ctx.makeCurrent();  // the virtual meshes' textures are made in this context
        std::vector<std::unique_ptr<detail::GlMesh>> meshes;
        std::vector<const detail::GlMesh*> extra;
        std::vector<Vec3f> corners;
        for (const Mesh& vm : virtualObjects)
        {
            if (vm.vertices.empty())
                continue;
            meshes.emplace_back(gl.sun.enabled() ? new detail::GlMesh(vm, 1.f, gl.light)
                                                 : new detail::GlMesh(vm, 1.f));
            extra.push_back(meshes.back().get());
            Vec3f a, b;
            vm.bounds(a, b);
            for (int c = 0; c < 8; c++)
                corners.push_back(Vec3f(c & 1 ? b[0] : a[0], c & 2 ? b[1] : a[1],
                                        c & 4 ? b[2] : a[2]));
        }
        Mat bgr, cover;
        PassOutputs out;
        out.bgr = &bgr;
        const Vec3d gains = frameGains(p_, frame);
        if (gains != Vec3d(1, 1, 1) && !extra.empty())
            out.virtualCover = &cover;
        detail::ShadowMap withVirtual;
        if (gl.sun.enabled())
        {
            if (extra.empty())
                out.shadow = realShadow(gl, m);
            else
            {
                renderSunShadow(gl, m, extra, corners, withVirtual);
                out.shadow = &withVirtual;
            }
        }
        renderView(gl, m, m.cameras[frame], p_.imageSize, supersample, extra, corners, out);
        applyGains(bgr, gains, cover);
        meshes.clear();  // textures deleted while the context is current
        bgr.copyTo(image);
    }

    void renderFrame(int frame, OutputArray image, OutputArray depth, OutputArray labels,
                     OutputArrayOfArrays wholeMasks) const CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        checkFrame(frame);
        const SceneModel& m = model();
        GlScene& gl = glScene();
        Mat bgr, lab, dep;
        std::vector<Mat> whole;
        render(gl, m, frame, &bgr, labels.needed() ? &lab : nullptr,
               depth.needed() ? &dep : nullptr, wholeMasks.needed() ? &whole : nullptr);
        bgr.copyTo(image);
        if (labels.needed())
            lab.copyTo(labels);
        if (depth.needed())
            dep.copyTo(depth);
        if (wholeMasks.needed())
        {
            wholeMasks.create((int)whole.size(), 1, CV_8U);
            for (size_t i = 0; i < whole.size(); i++)
            {
                wholeMasks.create(whole[i].size(), CV_8U, (int)i);
                Mat dst = wholeMasks.getMat((int)i);
                whole[i].copyTo(dst);
            }
        }
    }

    Camera getCamera(int frame) const CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        checkFrame(frame);
        return model().cameras[frame];
    }

    std::vector<String> getObjectNames() const CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        return model().names;
    }

    std::vector<Mesh> getObjectMeshes() const CV_OVERRIDE
    {
        std::lock_guard<std::mutex> lock(mutex_);
        return model().objects;
    }

private:
    void checkFrame(int frame) const
    {
        if (frame < 0 || frame >= p_.frames)
            CV_Error(Error::StsOutOfRange, cv::format("SceneSynthesizer: frame %d out of range "
                     "[0, %d)", frame, p_.frames));
    }
    // Callers hold mutex_.
    const SceneModel& model() const
    {
        if (!model_)
            model_ = buildScene(p_);
        return *model_;
    }
    GlScene& glScene() const
    {
        if (!gl_)
            gl_.reset(new GlScene(p_.imageSize, model(), p_.sun));
        return *gl_;
    }
    // The real objects' shadow map under Params::sun (null without a sun); callers hold mutex_.
    static const detail::ShadowMap* realShadow(GlScene& gl, const SceneModel& m)
    {
        if (!gl.sun.enabled())
            return nullptr;
        if (!gl.realShadowReady)
        {
            renderSunShadow(gl, m, {}, {}, gl.realShadow);
            gl.realShadowReady = true;
        }
        return &gl.realShadow;
    }

    // One frame as synthesize() renders it (any output may be null); callers hold mutex_.
    void render(GlScene& gl, const SceneModel& m, int f, Mat* bgr, Mat* labels, Mat* depth,
                std::vector<Mat>* whole) const
    {
        Mat colour;
        PassOutputs out;
        out.bgr = bgr ? bgr : &colour;
        out.labels = labels;
        out.depth = depth;
        out.whole = whole;
        out.shadow = realShadow(gl, m);
        renderView(gl, m, m.cameras[f], p_.imageSize, p_.frameSupersample, {}, {}, out);
        if (bgr)
            applyGains(*bgr, frameGains(p_, f));
    }
    static std::vector<Mat> visibleMasks(const Mat& labels, size_t nObj)
    {
        std::vector<Mat> v(nObj);
        for (size_t i = 0; i < nObj; i++)
            cv::compare(labels, Scalar((double)(i + 1)), v[i], CMP_EQ);
        return v;
    }
    std::vector<int> keyFrames() const
    {
        std::vector<int> keys;
        for (int k = 0; k < p_.numKeyFrames; k++)
            keys.push_back(cvRound((double)k * (p_.frames - 1) / (p_.numKeyFrames - 1)));
        return keys;
    }
    // The truth that is not per frame: objects, key frames and their masks (`visibleIn(f)`:
    // the visible masks of frame f), cameras, tracks (sampled on the middle frame).
    void finishScene(const SceneModel& m, const Mat& midLabels, const Mat& midDepth,
                     const std::function<std::vector<Mat>(int)>& visibleIn,
                     SyntheticScene& scene) const
    {
        scene.objectNames = m.names;
        scene.objectMeshes = m.objects;
        scene.keyFrames = keyFrames();
        for (int f : scene.keyFrames)
        {
            const std::vector<Mat> visible = visibleIn(f);
            for (size_t i = 0; i < m.objects.size(); i++)
                scene.keyFrameMasks[m.names[i]][f] = visible[i].clone();
        }
        scene.groundTruth.model = p_.model;
        scene.groundTruth.imageSize = p_.imageSize;
        scene.groundTruth.cameras = m.cameras;
        makeTracks(p_, m, midLabels, midDepth, scene);
    }

    Params p_;
    mutable std::mutex mutex_;
    mutable std::shared_ptr<SceneModel> model_;
    mutable std::unique_ptr<GlScene> gl_;
};

} // namespace

Vec3d SceneSynthesizer::frameGains(const Params& p, int frame)
{
    if (p.exposureDrift == 0 && p.whiteBalanceDrift == 0)
        return Vec3d(1, 1, 1);
    CV_CheckGE(frame, 0, "frameGains: frame");
    CV_CheckLT(frame, p.frames, "frameGains: frame");
    // A raised-cosine ramp over the shot: auto-exposure and white balance settle smoothly, with
    // no jump in rate at the ends.
    const double t = p.frames > 1 ? (double)frame / (p.frames - 1) : 0.0;
    const double w = 0.5 * (1 - std::cos(kPi * t));
    const double gain = 1 + p.exposureDrift * w;
    const double wb = p.whiteBalanceDrift * w;
    return Vec3d(gain * (1 - wb), gain, gain * (1 + wb));
}

Ptr<SceneSynthesizer> SceneSynthesizer::create(const Params& params)
{
    return makePtr<SceneSynthesizerImpl>(params);
}

Ptr<SceneSynthesizer> SceneSynthesizer::create()
{
    return makePtr<SceneSynthesizerImpl>(Params());
}

} // namespace augocc
} // namespace cv
