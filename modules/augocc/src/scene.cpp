// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Scene files (virtual objects and where they go), the ground frame of a reconstruction and the
// placement helpers that put objects relative to the clones of what the user sees.

#include "precomp.hpp"
#include "ground_plane.hpp"
#include "input_limits.hpp"
#include "io_internal.hpp"
#include "scene_detail.hpp"

#include "atomic_write.hpp"

#include <filesystem>
#include <set>
#include <opencv2/imgcodecs.hpp>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

const char* const kObjectKeys[] = {"name", "mesh", "shape", "position", "rotation", "scale",
                                   "size", "material", "on_ground_beside", "behind",
                                   "in_front_of", "distance", "side", "offset"};
const char* const kMaterialKeys[] = {"diffuse", "ambient", "texture"};
const char* const kSunKeys[] = {"direction", "azimuth", "elevation", "date", "time", "latitude",
                                "longitude", "north", "sky", "penumbra"};

[[noreturn]] void sceneError(const String& file, const String& where, const String& what)
{
    CV_Error(Error::StsParseError, file + ": " + where + ": " + what);
}

bool isNumber(const FileNode& n)
{
    return n.isReal() || n.isInt();
}

double readNumber(const FileNode& n, const String& file, const String& where)
{
    if (!isNumber(n))
        sceneError(file, where, "expected a number");
    const double v = (double)n;
    if (!std::isfinite(v))
        sceneError(file, where, "value is not finite");
    if (std::abs(v) > detail::kMaxSceneCoordinate)
        sceneError(file, where, cv::format("%g is beyond augocc's limit of %g", v,
                                           detail::kMaxSceneCoordinate));
    return v;
}

Vec3d readVec3(const FileNode& n, const String& file, const String& where)
{
    if (!n.isSeq() || n.size() != 3)
        sceneError(file, where, "expected a sequence of three numbers, e.g. [1, 2, 3]");
    Vec3d v;
    for (int k = 0; k < 3; k++)
        v[k] = readNumber(n[k], file, where);
    return v;
}

String readString(const FileNode& n, const String& file, const String& where)
{
    if (!n.isString())
        sceneError(file, where, "expected a string");
    const String s = (String)n;
    if (s.empty())
        sceneError(file, where, "empty string");
    return s;
}

void checkKeys(const FileNode& map, const char* const* keys, size_t nkeys, const String& file,
               const String& where)
{
    if (!map.isMap())
        sceneError(file, where, "expected a map of keys");
    const std::set<String> allowed(keys, keys + nkeys);
    for (const String& k : map.keys())
        if (!allowed.count(k))
            sceneError(file, where, "unknown key '" + k + "'");
}

Vec3f readColor(const FileNode& n, const String& file, const String& where)
{
    const Vec3d c = readVec3(n, file, where);
    for (int k = 0; k < 3; k++)
        if (c[k] < 0 || c[k] > 1)
            sceneError(file, where, "colour components must be in [0, 1]");
    return Vec3f(c);
}

Matx44d affine(const Matx33d& A, const Vec3d& t)
{
    return Matx44d(A(0, 0), A(0, 1), A(0, 2), t[0], A(1, 0), A(1, 1), A(1, 2), t[1],
                   A(2, 0), A(2, 1), A(2, 2), t[2], 0, 0, 0, 1);
}

Mesh colored(Mesh m, const Vec3f& rgb)
{
    m.material.diffuse = rgb;
    m.material.ambient = rgb * 0.35f;
    return m;
}

// "YYYY-MM-DD" and "HH:MM[:SS]" (UTC) to the date and the hour; throws naming the key.
void parseDateTime(const SceneSun& sun, const String& file, int& y, int& mo, int& d, double& h)
{
    char tail = 0;
    if (std::sscanf(sun.date.c_str(), "%4d-%2d-%2d%c", &y, &mo, &d, &tail) != 3 || mo < 1 ||
        mo > 12 || d < 1 || d > 31)
        sceneError(file, "sun.date", "expected \"YYYY-MM-DD\", got '" + sun.date + "'");
    int hh = 0, mm = 0;
    double ss = 0;
    const int n = std::sscanf(sun.time.c_str(), "%2d:%2d:%lf%c", &hh, &mm, &ss, &tail);
    if ((n != 2 && n != 3) || hh < 0 || hh > 23 || mm < 0 || mm > 59 || ss < 0 || ss >= 60)
        sceneError(file, "sun.time", "expected \"HH:MM\" or \"HH:MM:SS\" (UTC), got '" +
                   sun.time + "'");
    h = hh + mm / 60.0 + ss / 3600.0;
}

SceneSun readSun(const FileNode& n, const String& file)
{
    checkKeys(n, kSunKeys, sizeof(kSunKeys) / sizeof(kSunKeys[0]), file, "sun");
    SceneSun sun;
    const bool dir = !n["direction"].empty();
    const bool azel = !n["azimuth"].empty() || !n["elevation"].empty();
    const bool when = !n["date"].empty() || !n["time"].empty() || !n["latitude"].empty() ||
                      !n["longitude"].empty();
    if ((int)dir + (int)azel + (int)when != 1)
        sceneError(file, "sun", "give exactly one of 'direction', 'azimuth' + 'elevation', or "
                   "'date' + 'time' + 'latitude' + 'longitude'");
    if (dir)
    {
        sun.form = SceneSun::SUN_DIRECTION;
        sun.direction = readVec3(n["direction"], file, "sun.direction");
        if (!(cv::norm(sun.direction) > 0))
            sceneError(file, "sun.direction", "must not be zero");
        sun.direction /= cv::norm(sun.direction);
    }
    else if (azel)
    {
        sun.form = SceneSun::SUN_AZIMUTH_ELEVATION;
        for (const char* k : {"azimuth", "elevation"})
            if (n[k].empty())
                sceneError(file, String("sun.") + k, "missing (azimuth and elevation go together)");
        sun.azimuthDeg = readNumber(n["azimuth"], file, "sun.azimuth");
        sun.elevationDeg = readNumber(n["elevation"], file, "sun.elevation");
    }
    else
    {
        sun.form = SceneSun::SUN_DATE_TIME;
        for (const char* k : {"date", "time", "latitude", "longitude"})
            if (n[k].empty())
                sceneError(file, String("sun.") + k, "missing (date, time, latitude and "
                           "longitude go together)");
        sun.date = readString(n["date"], file, "sun.date");
        sun.time = readString(n["time"], file, "sun.time");
        sun.latitudeDeg = readNumber(n["latitude"], file, "sun.latitude");
        sun.longitudeDeg = readNumber(n["longitude"], file, "sun.longitude");
        if (std::abs(sun.latitudeDeg) > 90)
            sceneError(file, "sun.latitude", "must be in [-90, 90]");
        if (std::abs(sun.longitudeDeg) > 180)
            sceneError(file, "sun.longitude", "must be in [-180, 180]");
        int y, mo, d;
        double h;
        parseDateTime(sun, file, y, mo, d, h);
        solarPosition(y, mo, d, h, sun.latitudeDeg, sun.longitudeDeg, sun.azimuthDeg,
                      sun.elevationDeg);
    }
    if (sun.form != SceneSun::SUN_DIRECTION && !(sun.elevationDeg > 0 && sun.elevationDeg < 90))
        sceneError(file, sun.form == SceneSun::SUN_DATE_TIME ? "sun.date" : "sun.elevation",
                   cv::format("the sun is %.2f degrees above the horizon: expected (0, 90)",
                              sun.elevationDeg));
    if (!n["north"].empty())
    {
        if (dir)
            sceneError(file, "sun.north", "only valid with azimuth/elevation or date/time");
        sun.north = readVec3(n["north"], file, "sun.north");
        if (!(cv::norm(sun.north) > 0))
            sceneError(file, "sun.north", "must not be zero");
    }
    if (!n["sky"].empty())
    {
        sun.sky = readNumber(n["sky"], file, "sun.sky");
        if (!(sun.sky >= 0 && sun.sky < 1))
            sceneError(file, "sun.sky", "must be in [0, 1)");
    }
    if (!n["penumbra"].empty())
    {
        sun.penumbraPx = readNumber(n["penumbra"], file, "sun.penumbra");
        if (!(sun.penumbraPx > 0 && sun.penumbraPx <= 100))
            sceneError(file, "sun.penumbra", "must be in (0, 100] pixels");
    }
    return sun;
}

} // namespace

std::vector<Mesh> proceduralShape(const String& shape)
{
    // Unit size, base on y = 0. Colours after the paper's Fig. 3 (a pale dome, a green tree).
    const Vec3f grey(0.75f, 0.75f, 0.75f);
    if (shape == "dome")
        return {colored(Mesh::dome(1.f, 48, 16), Vec3f(0.92f, 0.86f, 0.72f))};
    if (shape == "tree")
        return {colored(Mesh::cylinder(0.07f, 0.f, 0.35f, 16), Vec3f(0.45f, 0.30f, 0.15f)),
                colored(Mesh::cone(0.3f, 0.25f, 1.f, 32), Vec3f(0.18f, 0.55f, 0.20f))};
    if (shape == "box")
        return {colored(Mesh::box(Vec3f(-0.5f, 0.f, -0.5f), Vec3f(0.5f, 1.f, 0.5f)), grey)};
    if (shape == "sphere")
    {
        Mesh m = Mesh::sphere(0.5f, 32, 16);
        m.transform(affine(Matx33d::eye(), Vec3d(0, 0.5, 0)));
        return {colored(m, grey)};
    }
    if (shape == "cylinder")
        return {colored(Mesh::cylinder(0.5f, 0.f, 1.f, 32), grey)};
    if (shape == "cone")
        return {colored(Mesh::cone(0.5f, 0.f, 1.f, 32), grey)};
    CV_Error(Error::StsBadArg, "unknown shape '" + shape + "' (dome, tree, box, sphere, "
             "cylinder, cone)");
}

VirtualScene readScene(const String& path)
{
    const FileStorage fsIn = detail::openFileStorageForRead(path, "scene file");
    const FileNode root = fsIn.root();
    const char* const rootKeys[] = {"objects", "sun"};
    checkKeys(root, rootKeys, 2, path, "top level");
    const FileNode objs = root["objects"];
    if (objs.empty() || !objs.isSeq() || objs.size() == 0)
        sceneError(path, "objects", "missing or empty: expected a sequence of objects");

    VirtualScene scene;
    scene.path = path;
    if (!root["sun"].empty())
        scene.sun = readSun(root["sun"], path);
    const fs::path dir = fs::path(path).parent_path();
    std::set<String> names;
    for (int i = 0; i < (int)objs.size(); i++)
    {
        const FileNode o = objs[i];
        const String where = cv::format("objects[%d]", i);
        checkKeys(o, kObjectKeys, sizeof(kObjectKeys) / sizeof(kObjectKeys[0]), path, where);
        SceneObject so;
        so.name = o["name"].empty() ? cv::format("object_%d", i)
                                    : readString(o["name"], path, where + ".name");
        if (!names.insert(so.name).second)
            sceneError(path, where + ".name", "duplicate object name '" + so.name + "'");
        const bool hasMesh = !o["mesh"].empty(), hasShape = !o["shape"].empty();
        if (hasMesh == hasShape)
            sceneError(path, where, "give exactly one of 'mesh' (a file) or 'shape' (dome, tree, "
                       "box, sphere, cylinder, cone)");
        if (hasShape)
        {
            so.shape = readString(o["shape"], path, where + ".shape");
            try
            {
                so.meshes = proceduralShape(so.shape);
            }
            catch (const cv::Exception& e)
            {
                sceneError(path, where + ".shape", e.err);
            }
        }
        else
        {
            const String rel = readString(o["mesh"], path, where + ".mesh");
            so.meshFile = fs::path(rel).is_absolute() ? rel : (dir / rel).string();
            so.meshes = loadMeshes(so.meshFile);
        }
        if (!o["rotation"].empty())
            so.rotationDeg = readVec3(o["rotation"], path, where + ".rotation");
        if (!o["scale"].empty())
        {
            const FileNode s = o["scale"];
            so.scale = s.isSeq() ? readVec3(s, path, where + ".scale")
                                 : Vec3d::all(readNumber(s, path, where + ".scale"));
            for (int k = 0; k < 3; k++)
                if (!(so.scale[k] > 0))
                    sceneError(path, where + ".scale", "scale must be positive");
        }
        int helpers = 0;
        const std::pair<const char*, int> helperKeys[] = {
            {"on_ground_beside", SceneObject::PLACE_BESIDE},
            {"behind", SceneObject::PLACE_BEHIND},
            {"in_front_of", SceneObject::PLACE_IN_FRONT}};
        for (const auto& hk : helperKeys)
            if (!o[hk.first].empty())
            {
                so.anchor = readString(o[hk.first], path, where + "." + hk.first);
                so.placement = hk.second;
                helpers++;
            }
        if (helpers > 1)
            sceneError(path, where, "give at most one of on_ground_beside, behind, in_front_of");
        const bool hasPosition = !o["position"].empty();
        if (hasPosition && helpers)
            sceneError(path, where, "'position' and a placement helper exclude each other");
        if (hasPosition)
            so.position = readVec3(o["position"], path, where + ".position");
        if (!helpers)
        {
            for (const char* k : {"distance", "side", "offset", "size"})
                if (!o[k].empty())
                    sceneError(path, where + "." + k, "only valid with on_ground_beside, behind "
                               "or in_front_of");
        }
        else
        {
            if (!o["distance"].empty())
                so.distance = readNumber(o["distance"], path, where + ".distance");
            if (!o["offset"].empty())
                so.offset = readVec3(o["offset"], path, where + ".offset");
            if (!o["size"].empty())
            {
                so.size = readNumber(o["size"], path, where + ".size");
                if (!(so.size > 0))
                    sceneError(path, where + ".size", "size must be positive");
            }
            if (!o["side"].empty())
            {
                if (so.placement != SceneObject::PLACE_BESIDE)
                    sceneError(path, where + ".side", "only valid with on_ground_beside");
                const String side = readString(o["side"], path, where + ".side");
                if (side != "left" && side != "right")
                    sceneError(path, where + ".side", "expected 'left' or 'right'");
                so.side = side == "left" ? -1 : 1;
            }
        }
        if (!o["material"].empty())
        {
            const FileNode m = o["material"];
            checkKeys(m, kMaterialKeys, 3, path, where + ".material");
            SceneObject::MaterialOverride& mo = so.material;
            if ((mo.hasDiffuse = !m["diffuse"].empty()))
                mo.diffuse = readColor(m["diffuse"], path, where + ".material.diffuse");
            if ((mo.hasAmbient = !m["ambient"].empty()))
                mo.ambient = readColor(m["ambient"], path, where + ".material.ambient");
            Mat tex;
            if (!m["texture"].empty())
            {
                const String rel = readString(m["texture"], path, where + ".material.texture");
                mo.texture = fs::path(rel).is_absolute() ? rel : (dir / rel).string();
                if (!fs::is_regular_file(mo.texture))
                    sceneError(path, where + ".material.texture",
                               mo.texture + ": cannot read image");
                try
                {
                    tex = detail::readImageChecked(mo.texture, IMREAD_COLOR);
                }
                catch (const cv::Exception& e)
                {
                    sceneError(path, where + ".material.texture", e.err);
                }
            }
            for (Mesh& mesh : so.meshes)
            {
                if (mo.hasDiffuse)
                {
                    mesh.material.diffuse = mo.diffuse;
                    mesh.colors.clear();
                }
                if (mo.hasAmbient)
                    mesh.material.ambient = mo.ambient;
                if (!tex.empty())
                    mesh.material.texture = tex;
            }
        }
        scene.objects.push_back(std::move(so));
    }
    return scene;
}

namespace {

//! A file named relative to a scene file's folder when it can be (else as it is).
String relativeTo(const String& file, const fs::path& dir)
{
    std::error_code ec;
    const fs::path rel = fs::relative(file, dir.empty() ? "." : dir, ec);
    return ec || rel.empty() ? file : rel.string();
}

} // namespace

void writeScene(const String& path, const VirtualScene& scene)
{
    detail::writeStorageAtomically(path, [&](FileStorage& out) {
        const fs::path dir = fs::path(path).parent_path();
        out << "objects" << "[";
        for (const SceneObject& o : scene.objects)
        {
            out << "{";
            out << "name" << o.name;
            if (!o.shape.empty())
                out << "shape" << o.shape;
            else
                out << "mesh" << relativeTo(o.meshFile, dir);
            const char* helper = o.placement == SceneObject::PLACE_BESIDE ? "on_ground_beside"
                                 : o.placement == SceneObject::PLACE_BEHIND ? "behind"
                                 : o.placement == SceneObject::PLACE_IN_FRONT ? "in_front_of"
                                                                            : nullptr;
            if (helper)
            {
                out << helper << o.anchor << "distance" << o.distance;
                if (o.placement == SceneObject::PLACE_BESIDE)
                    out << "side" << (o.side < 0 ? "left" : "right");
                if (o.size > 0)
                    out << "size" << o.size;
                out << "offset" << "[:" << o.offset[0] << o.offset[1] << o.offset[2] << "]";
            }
            else
                out << "position" << "[:" << o.position[0] << o.position[1] << o.position[2]
                    << "]";
            out << "rotation" << "[:" << o.rotationDeg[0] << o.rotationDeg[1]
                << o.rotationDeg[2] << "]";
            out << "scale" << "[:" << o.scale[0] << o.scale[1] << o.scale[2] << "]";
            if (!o.material.empty())
            {
                const SceneObject::MaterialOverride& mo = o.material;
                out << "material" << "{:";
                if (mo.hasDiffuse)
                    out << "diffuse" << "[:" << mo.diffuse[0] << mo.diffuse[1] << mo.diffuse[2]
                        << "]";
                if (mo.hasAmbient)
                    out << "ambient" << "[:" << mo.ambient[0] << mo.ambient[1] << mo.ambient[2]
                        << "]";
                if (!mo.texture.empty())
                    out << "texture" << relativeTo(mo.texture, dir);
                out << "}";
            }
            out << "}";
        }
        out << "]";
        const SceneSun& sun = scene.sun;
        if (sun.form == SceneSun::SUN_NONE)
            return;
        out << "sun" << "{";
        if (sun.form == SceneSun::SUN_DIRECTION)
            out << "direction" << "[:" << sun.direction[0] << sun.direction[1]
                << sun.direction[2] << "]";
        else if (sun.form == SceneSun::SUN_AZIMUTH_ELEVATION)
            out << "azimuth" << sun.azimuthDeg << "elevation" << sun.elevationDeg;
        else
            out << "date" << sun.date << "time" << sun.time << "latitude" << sun.latitudeDeg
                << "longitude" << sun.longitudeDeg;
        if (sun.form != SceneSun::SUN_DIRECTION && sun.north != Vec3d(0, 0, 0))
            out << "north" << "[:" << sun.north[0] << sun.north[1] << sun.north[2] << "]";
        out << "sky" << sun.sky << "penumbra" << sun.penumbraPx;
        out << "}";
    });
}

Vec3d sunDirection(const GroundFrame& ground, double azimuthDeg, double elevationDeg,
                   const Vec3d& northIn)
{
    const Vec3d north0 = northIn == Vec3d(0, 0, 0) ? -ground.back : northIn;
    Vec3d north = north0 - ground.up * ground.up.dot(north0);
    if (!(cv::norm(north) > 1e-9 * std::max(1.0, cv::norm(north0))))
        CV_Error(Error::StsBadArg, "sunDirection: north is vertical (no horizontal part)");
    north /= cv::norm(north);
    const Vec3d east = north.cross(ground.up);
    const double az = azimuthDeg * CV_PI / 180, el = elevationDeg * CV_PI / 180;
    const Vec3d d = std::cos(el) * (std::cos(az) * north + std::sin(az) * east) +
                    std::sin(el) * ground.up;
    return d / cv::norm(d);
}

Sun resolveSun(const VirtualScene& scene, const Reconstruction& rec)
{
    Sun sun;
    const SceneSun& s = scene.sun;
    if (s.form == SceneSun::SUN_NONE)
        return sun;
    if (rec.cameras.empty())
        CV_Error(Error::StsBadArg, scene.path + ": sun: the reconstruction has no camera");
    const GroundFrame ground = estimateGround(rec);
    if (s.form == SceneSun::SUN_DIRECTION)
        sun.direction = s.direction / cv::norm(s.direction);
    else
    {
        try
        {
            sun.direction = sunDirection(ground, s.azimuthDeg, s.elevationDeg, s.north);
        }
        catch (const cv::Exception& e)
        {
            CV_Error(Error::StsBadArg, scene.path + ": sun.north: " + e.err);
        }
    }
    sun.sky = s.sky;
    // Pixels of the first camera at the ground origin to world units.
    const Camera& cam = rec.cameras.front();
    const double ppu = cam.pixelsPerUnit(cam.depth(ground.fromGround(Vec3d(0, 0, 0))));
    if (!(ppu > 0) || !std::isfinite(ppu))
        CV_Error(Error::StsBadArg, scene.path + ": sun.penumbra: the first camera sees no scale "
                 "at the ground origin");
    sun.penumbra = s.penumbraPx / ppu;
    sun.validate(scene.path + ": sun");
    return sun;
}

// ---------------------------------------------------------------------------------------------
// Rotations of scene files

namespace detail {

Matx33d eulerDegToRotation(const Vec3d& deg)
{
    const double d2r = CV_PI / 180.0;
    const double ax = deg[0] * d2r, ay = deg[1] * d2r, az = deg[2] * d2r;
    const Matx33d Rx(1, 0, 0, 0, std::cos(ax), -std::sin(ax), 0, std::sin(ax), std::cos(ax));
    const Matx33d Ry(std::cos(ay), 0, std::sin(ay), 0, 1, 0, -std::sin(ay), 0, std::cos(ay));
    const Matx33d Rz(std::cos(az), -std::sin(az), 0, std::sin(az), std::cos(az), 0, 0, 0, 1);
    return Rz * Ry * Rx;
}

Vec3d rotationToEulerDeg(const Matx33d& R)
{
    // R = Rz Ry Rx: R(2,0) = -sin y, R(2,1) = cos y sin x, R(2,2) = cos y cos x,
    // R(1,0) = sin z cos y, R(0,0) = cos z cos y.
    const double r2d = 180.0 / CV_PI;
    const double cy = std::sqrt(R(0, 0) * R(0, 0) + R(1, 0) * R(1, 0));
    const double ay = std::atan2(-R(2, 0), cy);
    if (cy > 1e-9)
        return Vec3d(std::atan2(R(2, 1), R(2, 2)) * r2d, ay * r2d,
                     std::atan2(R(1, 0), R(0, 0)) * r2d);
    // Gimbal lock (y = +-90): only x -+ z is defined; z = 0, x from R(0,1), R(1,1).
    return Vec3d(std::atan2(-R(1, 2), R(1, 1)) * r2d, ay * r2d, 0.0);
}

} // namespace detail

// ---------------------------------------------------------------------------------------------
// Ground frame

Vec3d GroundFrame::toGround(const Vec3d& X) const
{
    return Vec3d(right.dot(X), up.dot(X) - height, back.dot(X));
}

Vec3d GroundFrame::fromGround(const Vec3d& g) const
{
    return right * g[0] + up * (g[1] + height) + back * g[2];
}

Matx33d GroundFrame::rotation() const
{
    return Matx33d(right[0], right[1], right[2], up[0], up[1], up[2], back[0], back[1], back[2]);
}

GroundFrame estimateGround(const Reconstruction& rec)
{
    if (rec.cameras.empty())
        CV_Error(Error::StsBadArg, "estimateGround: the reconstruction has no camera");
    // Up from the cameras: image x axes are horizontal (no roll), image up (-y) roughly up.
    Matx33d S = Matx33d::zeros();
    Vec3d meanUp(0, 0, 0), meanView(0, 0, 0);
    for (const Camera& c : rec.cameras)
    {
        const Vec3d x(c.R(0, 0), c.R(0, 1), c.R(0, 2));
        S += x * x.t();
        meanUp -= Vec3d(c.R(1, 0), c.R(1, 1), c.R(1, 2));
        meanView += c.viewDirection();
    }
    meanUp = cv::normalize(meanUp);
    // The x axes must span a plane (the camera turned about the vertical): the middle eigenvalue
    // of sum x x^T is then well above the smallest. 1e-3 of the largest is a turn of about 6
    // degrees over the shot; 20x the smallest keeps noisy axes (0.3 deg ~ 3e-5) from deciding.
    const double kMinSpanRatio = 1e-3, kMinSeparation = 20.0;
    Mat evals, evecs;
    cv::eigen(Mat(S), evals, evecs);  // descending
    Vec3d up(evecs.at<double>(2, 0), evecs.at<double>(2, 1), evecs.at<double>(2, 2));
    const double l0 = evals.at<double>(0), l1 = evals.at<double>(1), l2 = evals.at<double>(2);
    if (!(l1 > kMinSpanRatio * l0 && l1 > kMinSeparation * std::max(l2, 0.0)))
        up = meanUp;
    if (up.dot(meanUp) < 0)
        up = -up;

    GroundFrame g;
    // Ground plane from the points (detail::fitGroundPlane, ground_plane.cpp).
    std::vector<Vec3d> pts;
    for (int i = 0; i < rec.points.rows; i++)
        if (rec.hasPoint(i))
            pts.push_back(rec.point(i));
    g.fromPlane = detail::fitGroundPlane(pts, up, g.height);
    g.up = up;
    // Horizontal mean view direction: "behind" is away from the viewer.
    Vec3d f = meanView - up * up.dot(meanView);
    if (cv::norm(f) < 1e-6)
    {
        // Looking straight down: "forward" is image up.
        f = meanUp - up * up.dot(meanUp);
    }
    f = cv::normalize(f);
    g.right = cv::normalize(f.cross(up));
    g.back = -f;
    return g;
}

void estimateCloneBounds(const CloneSet& clones, const String& object, const Reconstruction& rec,
                         const GroundFrame& ground, Vec3d& minCorner, Vec3d& maxCorner)
{
    const std::vector<String> names = clones.objectNames();
    if (std::find(names.begin(), names.end(), object) == names.end())
        CV_Error(Error::StsObjectNotFound, "no clone named '" + object + "'");
    CV_Assert(!rec.cameras.empty());
    const int n = (int)rec.cameras.size();
    std::set<int> which = {0, n / 2, n - 1};
    minCorner = Vec3d::all(std::numeric_limits<double>::infinity());
    maxCorner = -minCorner;
    int seen = 0;
    for (int idx : which)
    {
        const Camera& cam = rec.cameras[idx];
        Mat matte, depth;
        clones.render(object, cam.frame, cam, rec.imageSize, matte, depth);
        for (int y = 0; y < depth.rows; y++)
        {
            const float* d = depth.ptr<float>(y);
            for (int x = 0; x < depth.cols; x++)
            {
                if (!std::isfinite(d[x]))
                    continue;
                const Vec3d g = ground.toGround(cam.unproject(Point2d(x, y), d[x]));
                for (int k = 0; k < 3; k++)
                {
                    minCorner[k] = std::min(minCorner[k], g[k]);
                    maxCorner[k] = std::max(maxCorner[k], g[k]);
                }
                seen++;
            }
        }
    }
    if (!seen)
        CV_Error(Error::StsObjectNotFound, "the clone of '" + object + "' is seen in no frame");
}

std::vector<Matx44d> scenePoses(const VirtualScene& scene, const Reconstruction& rec,
                                const CloneSet* clones)
{
    std::vector<Matx44d> poses;
    GroundFrame ground;
    bool groundReady = false;
    for (const SceneObject& o : scene.objects)
    {
        const Matx33d Rs = detail::eulerDegToRotation(o.rotationDeg) *
                           Matx33d(o.scale[0], 0, 0, 0, o.scale[1], 0, 0, 0, o.scale[2]);
        if (o.placement == SceneObject::PLACE_ABSOLUTE)
        {
            poses.push_back(affine(Rs, o.position));
            continue;
        }
        const String where = scene.path + ": object '" + o.name + "'";
        if (!clones)
            CV_Error(Error::StsBadArg, where + " is placed relative to clone '" + o.anchor +
                     "' but no clones are given");
        const std::vector<String> names = clones->objectNames();
        if (std::find(names.begin(), names.end(), o.anchor) == names.end())
            CV_Error(Error::StsBadArg, where + ": no clone named '" + o.anchor + "'");
        if (!groundReady)
        {
            ground = estimateGround(rec);
            groundReady = true;
        }
        Vec3d cmin, cmax;
        estimateCloneBounds(*clones, o.anchor, rec, ground, cmin, cmax);
        const Vec3d cext = cmax - cmin;
        const double cloneSize = std::max(cext[0], std::max(cext[1], cext[2]));
        // Object bounds after rotation and scale (object coordinates, y up).
        Vec3d omin = Vec3d::all(std::numeric_limits<double>::infinity()), omax = -omin;
        for (const Mesh& m : o.meshes)
            for (const Vec3f& v : m.vertices)
            {
                const Vec3d p = Rs * Vec3d(v);
                for (int k = 0; k < 3; k++)
                {
                    omin[k] = std::min(omin[k], p[k]);
                    omax[k] = std::max(omax[k], p[k]);
                }
            }
        double k = 1.0;
        if (o.size > 0)
        {
            const Vec3d oext = omax - omin;
            const double osize = std::max(oext[0], std::max(oext[1], oext[2]));
            k = o.size * cloneSize / std::max(osize, 1e-12);
        }
        omin *= k;
        omax *= k;
        // Ground coordinates of the object origin: base on the ground (y = 0).
        const double gap = o.distance * cloneSize;
        const Vec3d ccenter = 0.5 * (cmin + cmax);
        Vec3d g(ccenter[0] - 0.5 * (omin[0] + omax[0]), -omin[1],
                ccenter[2] - 0.5 * (omin[2] + omax[2]));
        if (o.placement == SceneObject::PLACE_BEHIND)
            g[2] = cmin[2] - gap - omax[2];  // back axis points to the viewer
        else if (o.placement == SceneObject::PLACE_IN_FRONT)
            g[2] = cmax[2] + gap - omin[2];
        else if (o.side > 0)
            g[0] = cmax[0] + gap - omin[0];
        else
            g[0] = cmin[0] - gap - omax[0];
        g += o.offset * cloneSize;
        // Object axes (x, y, z) -> ground axes (right, up, back), scaled by k.
        const Matx33d B(ground.right[0], ground.up[0], ground.back[0],
                        ground.right[1], ground.up[1], ground.back[1],
                        ground.right[2], ground.up[2], ground.back[2]);
        poses.push_back(affine(B * Rs * k, ground.fromGround(g)));
    }
    return poses;
}

std::vector<Mesh> placeScene(const VirtualScene& scene, const Reconstruction& rec,
                             const CloneSet* clones)
{
    const std::vector<Matx44d> poses = scenePoses(scene, rec, clones);
    std::vector<Mesh> out;
    for (size_t i = 0; i < scene.objects.size(); i++)
        for (const Mesh& m : scene.objects[i].meshes)
        {
            Mesh w = m;
            w.transform(poses[i]);
            out.push_back(std::move(w));
        }
    return out;
}

} // namespace augocc
} // namespace cv
