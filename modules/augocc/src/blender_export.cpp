// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The shot handed to Blender: a Python script (the static body, blender_shot.py, embedded at
// build time, after a JSON block of this shot's data) and its assets. The camera conversion is
// done here, once, in double precision; the script only applies it.

#include "precomp.hpp"
#include "atomic_write.hpp"
#include "shading.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <opencv2/core/utils/logger.hpp>

#include "blender_shot_py.hpp"  // kBlenderShotPy, generated from src/blender_shot.py

namespace cv {
namespace augocc {

namespace {

namespace fs = std::filesystem;

// Blender's default sensor width (mm); with sensor fit HORIZONTAL only lens / sensor matters.
const double kSensorWidthMm = 36.0;
// Ground plane (shadow catcher) half-size, in horizontal radii of the shot's assets.
const double kGroundRadii = 3.0;

String num(double v)
{
    CV_Assert(std::isfinite(v));
    return format("%.17g", v);
}

String quoted(const String& s)
{
    String out = "\"";
    for (char c : s)
    {
        if (c == '"' || c == '\\')
            out += '\\';
        if ((unsigned char)c < 0x20)
            out += format("\\u%04x", (unsigned char)c);
        else
            out += c;
    }
    return out + "\"";
}

String vec(const double* v, int n)
{
    String s = "[";
    for (int i = 0; i < n; i++)
        s += (i ? ", " : "") + num(v[i]);
    return s + "]";
}

// A 4x4 row-major matrix [A | b; 0 0 0 1].
String matrix(const Matx33d& A, const Vec3d& b)
{
    const Matx44d M(A(0, 0), A(0, 1), A(0, 2), b[0], A(1, 0), A(1, 1), A(1, 2), b[1], A(2, 0),
                    A(2, 1), A(2, 2), b[2], 0, 0, 0, 1);
    return vec(M.val, 16);
}

// Path of `target` relative to the folder `base` (both made absolute), '/' separators.
String relativeTo(const String& target, const fs::path& base)
{
    const fs::path rel = fs::absolute(target).lexically_normal().lexically_relative(
        fs::absolute(base).lexically_normal());
    return (rel.empty() ? fs::absolute(target) : rel).generic_string();
}

// The file Blender opens for the footage: the video itself, or the first image of a folder or
// pattern (Blender finds the rest of a numbered sequence itself).
String footageFile(const String& input)
{
    if (fs::is_regular_file(input))
        return input;
    if (fs::is_directory(input))
    {
        std::vector<fs::path> files;
        for (const auto& e : fs::directory_iterator(input))
            if (e.is_regular_file())
                files.push_back(e.path());
        std::sort(files.begin(), files.end());
        CV_Assert(!files.empty());  // FrameSource::open() accepted it
        return files.front().string();
    }
    // A printf pattern (FrameSource's rules): its first existing file, index 0 or 1.
    for (int i = 0; i < 2; i++)
    {
        const String f = format(input.c_str(), i);
        if (fs::is_regular_file(f))
            return f;
    }
    CV_Error(Error::StsObjectNotFound, input + ": no first frame (index 0 or 1) of the pattern");
}

// Lens distortion for Blender's movie clip (its tracking camera), as the compositor's Movie
// Distortion node and the undistorted camera background apply it (checked by a render,
// doc/blender.md). They work in the clip's pixels with pixel centres at integers (OpenCV's rule)
// and rows counted from the bottom, so the principal point is (cx, H - 1 - cy) and the
// normalised y is OpenCV's -y: the tangential terms keep their form with p1 -> -p1. The models:
// POLYNOMIAL (k1, k2, k3) without tangential terms, else BROWN, whose tangential terms are
// OpenCV's with p1 and p2 swapped (libmv's ApplyBrownDistortionModel: x gets p1 (r^2 + 2 x^2),
// OpenCV's x gets p2 (r^2 + 2 x^2)): brown_p1 = p2, brown_p2 = -p1. OpenCV's k4..k6 (rational),
// s1..s4 (thin prism) and tau (tilt) have no Blender model: an error.
String distortionJson(const Camera& c, int height, const String& what)
{
    if (!c.hasDistortion())
        return "null";
    double d[14] = {0};
    for (size_t i = 0; i < c.distortion.size(); i++)
        d[i] = c.distortion[i];
    static const char* const names[14] = {"k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6",
                                          "s1", "s2", "s3", "s4", "tau_x", "tau_y"};
    for (int i = 5; i < 14; i++)
        if (d[i] != 0)
            CV_Error(Error::StsNotImplemented, what + format(": frame %d: distortion "
                     "coefficient %s = %g is not 0; Blender's lens models have only OpenCV's k1, "
                     "k2, p1, p2, k3 (rational, thin prism and tilt terms cannot be exported)",
                     c.frame, names[i], d[i]));
    const bool tangential = d[2] != 0 || d[3] != 0;
    const Point2d pp = c.principalPoint();
    std::ostringstream s;
    s << "{\"model\": " << (tangential ? "\"BROWN\"" : "\"POLYNOMIAL\"")
      << ", \"k1\": " << num(d[0]) << ", \"k2\": " << num(d[1]) << ", \"k3\": " << num(d[4])
      << ", \"brown_p1\": " << num(d[3]) << ", \"brown_p2\": " << num(-d[2])
      << ", \"focal_px\": " << num(c.K(0, 0))
      << ", \"principal_px\": [" << num(pp.x) << ", " << num(height - 1 - pp.y) << "]}";
    return s.str();
}

// World corners of an object's voxel grid.
void gridCorners(const CloneSet& clones, const String& object, std::vector<Vec3d>& out)
{
    Matx33d Rbox;
    Vec3d origin;
    clones.gridPose(object, Rbox, origin);
    const Vec3i n = clones.gridSize(object);
    const double h = clones.voxelSize(object);
    for (int k = 0; k < 8; k++)
        out.push_back(origin + Rbox * Vec3d((k & 1) ? n[0] * h : 0, (k & 2) ? n[1] * h : 0,
                                            (k & 4) ? n[2] * h : 0));
}

struct ShotData
{
    int first = 0, end = 0;
    double fps = 25;
    String footage;   // relative to the script's folder, or empty
};

// The checks of the inputs, before anything is written.
ShotData checkShot(const Reconstruction& rec, const BlenderShotOptions& o)
{
    const String& recName = o.reconstructionName;
    rec.validate(recName);
    if (rec.cameras.empty())
        CV_Error(Error::StsBadArg, recName + ": no camera");
    if (o.samples < 1)
        CV_Error(Error::StsBadArg, format("samples %d: must be >= 1", o.samples));
    if (!(o.fps >= 0) || !std::isfinite(o.fps))
        CV_Error(Error::StsBadArg, format("fps %g: must be positive (0: the footage's)", o.fps));
    ShotData d;
    int count = rec.cameras.back().frame + 1;
    d.fps = 25;
    if (!o.footage.empty())
    {
        Ptr<FrameSource> src = FrameSource::open(o.footage);
        count = src->count();
        d.fps = src->fps();
        if (rec.imageSize != src->size())
            CV_Error(Error::StsBadSize, o.footage + format(": frames are %dx%d but the "
                     "image_size of ", src->size().width, src->size().height) + recName +
                     format(" is %dx%d: they do not belong together", rec.imageSize.width,
                            rec.imageSize.height));
    }
    if (rec.cameras.back().frame >= count)
        CV_Error(Error::StsBadArg, o.footage + format(": the input has %d frames but ", count) +
                 recName + format(" has a camera for frame %d: they do not belong together",
                                  rec.cameras.back().frame));
    if (o.fps > 0)
        d.fps = o.fps;
    d.first = o.firstFrame;
    d.end = o.endFrame < 0 ? count : o.endFrame;
    if (d.first < 0 || d.first >= d.end || d.end > count)
        CV_Error(Error::StsOutOfRange, (o.footage.empty() ? recName : o.footage) +
                 format(": frames %d:%d out of range, the shot has %d frames (0:%d)", d.first,
                        d.end, count, count));
    for (int f = d.first; f < d.end; f++)
        if (rec.findCamera(f) < 0)
            CV_Error(Error::StsBadArg, recName + format(": frame %d has no camera (frames %d:%d "
                     "are in the shot)", f, d.first, d.end));
    const Camera& c0 = rec.camera(d.first);
    for (int f = d.first; f < d.end; f++)
        distortionJson(rec.camera(f), rec.imageSize.height, recName);  // throws: no model
    if (rec.model == PERSPECTIVE)
        for (int f = d.first; f < d.end; f++)
        {
            const Matx33d& K = rec.camera(f).K;
            if (std::abs(K(1, 1) / K(0, 0) - 1) > 1e-9 || K(0, 1) != 0)
                CV_LOG_WARNING(NULL, recName << ": frame " << f << ": fx != fy or skew != 0; "
                               "Blender's camera has one focal length and no skew, fx is used");
            if (rec.camera(f).distortion != c0.distortion)
                CV_LOG_WARNING(NULL, recName << ": frame " << f << ": lens distortion differs "
                               "from frame " << d.first << "'s; the movie clip has one (frame "
                               << d.first << "'s)");
        }
    return d;
}

// What writeShot() has made so far, for writeBlenderShot() to remove on failure.
struct ShotFiles
{
    String assetsTmp;  // the assets' temporary folder, until it is renamed into place
    String script;     // the script, once written (before the assets are in place)
    bool writing = false;  // the inputs were checked, files are being written
};

// writeBlenderShot() without the clean-up. All or nothing: the assets go to a temporary
// folder, the script is written (atomically), and only then the folder is renamed into place.
void writeShot(const String& scriptPath, const Reconstruction& rec, const CloneSet& clones,
               const VirtualScene& scene, const BlenderShotOptions& options, ShotFiles& files)
{
    if (scriptPath.empty())
        CV_Error(Error::StsBadArg, "no script path given");
    const ShotData shot = checkShot(rec, options);
    const std::vector<Matx44d> poses = scenePoses(scene, rec, &clones);
    const GroundFrame ground = estimateGround(rec);
    const Sun sceneSun = resolveSun(scene, rec);
    const bool sunLit = sceneSun.enabled();

    const fs::path script = fs::absolute(scriptPath);
    const fs::path here = script.parent_path();
    detail::createDirectories(here.string(), scriptPath);
    const String assetsName = script.stem().string() + "_assets";
    const fs::path assets = here / assetsName;
    const int W = rec.imageSize.width, H = rec.imageSize.height;

    // Assets, as one folder: clones, then the virtual objects in the reconstruction's world.
    std::vector<Vec3d> corners;  // of everything in the shot, for the clip range and ground
    const std::vector<String> objects = clones.objectNames();
    for (const String& o : objects)
        gridCorners(clones, o, corners);
    // The assets, then the script, then the assets renamed into place (the caller removes what
    // was made if anything fails).
    files.writing = true;
    detail::sweepStaleTemporaries(assets.string());
    const String tmp = detail::tmpNameFor(assets.string());
    files.assetsTmp = tmp;
    std::ostringstream objectsJson;
    {
        detail::createDirectories(tmp, assets.string());
        clones.exportPly((fs::path(tmp) / "clones").string());
        detail::createDirectories((fs::path(tmp) / "objects").string(), assets.string());
        objectsJson << "[";
        int n = 0;
        for (size_t i = 0; i < scene.objects.size(); i++)
            for (size_t k = 0; k < scene.objects[i].meshes.size(); k++)
            {
                Mesh m = scene.objects[i].meshes[k];
                m.transform(poses[i]);
                if (!m.material.texture.empty())
                    CV_LOG_WARNING(NULL, scene.path << ": " << scene.objects[i].name
                                   << ": textures are not exported to Blender (colour only)");
                for (const Vec3f& v : m.vertices)
                    corners.push_back(Vec3d(v[0], v[1], v[2]));
                const String name = format("%s_%d", scene.objects[i].name.c_str(), (int)k);
                writeMeshPly((fs::path(tmp) / "objects" / (name + ".ply")).string(), m);
                // Under a sun the script's Lambertian albedo: ambient + diffuse (a face lit
                // head-on, base * (a + d) in shading.hpp); without one the diffuse colour.
                const Vec3f c = sunLit ? m.material.ambient + m.material.diffuse
                                       : m.material.diffuse;
                const Vec3d col(c[0], c[1], c[2]);
                objectsJson << (n++ ? ",\n  " : "\n  ") << "{\"name\": " << quoted(name)
                            << ", \"object\": " << quoted(scene.objects[i].name)
                            << ", \"file\": " << quoted(assetsName + "/objects/" + name + ".ply")
                            << ", \"color\": " << vec(col.val, 3) << "}";
            }
        objectsJson << "]";
    }

    // Clones: the trimmed model, and each key frame's patches with the frames that show them.
    std::ostringstream clonesJson;
    clonesJson << "[";
    for (size_t i = 0; i < objects.size(); i++)
    {
        const String& o = objects[i];
        clonesJson << (i ? ",\n  " : "\n  ") << "{\"name\": " << quoted(o) << ", \"file\": "
                   << quoted(assetsName + "/clones/" + o + "_clone.ply") << ", \"patches\": [";
        const std::vector<int> keys = clones.keyFrames(o);
        for (size_t k = 0; k < keys.size(); k++)
        {
            clonesJson << (k ? ", " : "") << "{\"key_frame\": " << keys[k] << ", \"file\": "
                       << quoted(assetsName + format("/clones/%s_patches_%04d.ply", o.c_str(),
                                                     keys[k]))
                       << ", \"frames\": [";
            int n = 0;
            for (int f = shot.first; f < shot.end; f++)
            {
                const std::vector<int> pf = clones.patchFrames(o, f);
                if (std::find(pf.begin(), pf.end(), keys[k]) != pf.end())
                    clonesJson << (n++ ? ", " : "") << f;
            }
            clonesJson << "]}";
        }
        clonesJson << "]}";
    }
    clonesJson << "]";

    // Extent of the shot: centre and radius of the assets' corners (points when no asset).
    if (corners.empty())
        for (int p = 0; p < rec.points.rows; p++)
            if (rec.hasPoint(p))
                corners.push_back(rec.point(p));
    if (corners.empty())
        corners.push_back(Vec3d(0, 0, 0));
    Vec3d centre(0, 0, 0);
    for (const Vec3d& c : corners)
        centre += c;
    centre *= 1.0 / corners.size();
    double radius = 0;
    for (const Vec3d& c : corners)
        radius = std::max(radius, norm(c - centre));
    radius = std::max(radius, 1e-6);

    // Cameras. OpenCV's camera looks down +z with y down (x right); Blender's looks down -z
    // with y up: camera-to-world rotation = R^T * diag(1, -1, -1). Intrinsics with sensor fit
    // HORIZONTAL (Blender's frame spans [0, W] x [0, H], OpenCV's pixel centres are integers,
    // so an OpenCV coordinate u is Blender's u + 0.5 from the left, v + 0.5 from the top):
    //   u + 0.5 = W / 2 - shift_x * W + W * x_view,  x_view = Xc.x / ortho_scale or
    //             Xc.x / Xc.z * lens / sensor_width,
    //   v + 0.5 = H / 2 + shift_y * W + W * y_view (y_view likewise with Xc.y),
    // so ortho_scale = W / s, lens = fx * sensor_width / W, shift_x = (W / 2 - cx - 0.5) / W,
    // shift_y = (cy + 0.5 - H / 2) / W (Blender's shifts are fractions of the fitted side).
    const Matx33d flip(1, 0, 0, 0, -1, 0, 0, 0, -1);
    const bool ortho = rec.model == SCALED_ORTHOGRAPHIC;
    std::ostringstream camerasJson;
    camerasJson << "[";
    double clipEnd = 0;
    for (int f = shot.first; f < shot.end; f++)
    {
        const Camera& c = rec.camera(f);
        Vec3d centreCam = c.center();
        if (ortho)
        {
            // An orthographic camera's position along its axis does not change the image, but
            // Blender clips what is behind it: place it a radius in front of the nearest corner.
            double zmin = std::numeric_limits<double>::infinity();
            for (const Vec3d& X : corners)
                zmin = std::min(zmin, c.depth(X));
            centreCam = c.R.t() * (Vec3d(0, 0, zmin - radius) - c.t);
        }
        for (const Vec3d& X : corners)
            clipEnd = std::max(clipEnd, norm(X - centreCam));
        const Point2d pp = c.principalPoint();
        const double shiftX = (0.5 * W - pp.x - 0.5) / W;
        const double shiftY = (pp.y + 0.5 - 0.5 * H) / W;
        camerasJson << (f > shot.first ? ",\n  " : "\n  ") << "{\"frame\": " << f
                    << ", \"matrix\": " << matrix(c.R.t() * flip, centreCam)
                    << (ortho ? ", \"ortho_scale\": " + num(W / c.s)
                              : ", \"lens\": " + num(c.K(0, 0) * kSensorWidthMm / W))
                    << ", \"shift_x\": " << num(shiftX) << ", \"shift_y\": " << num(shiftY)
                    << "}";
    }
    camerasJson << "]";

    // Blender's world: x right, y away from the viewer (-back), z up, ground at z = 0.
    const Matx33d Wr(ground.right[0], ground.right[1], ground.right[2], -ground.back[0],
                     -ground.back[1], -ground.back[2], ground.up[0], ground.up[1], ground.up[2]);
    const Vec3d Wt(0, 0, -ground.height);
    // Ground plane: a square on up . X = height about the shot's centre.
    const Vec3d g0 = ground.toGround(centre);
    const double half = kGroundRadii * radius;
    std::ostringstream groundJson;
    groundJson << "[";
    for (int k = 0; k < 4; k++)
    {
        const double dx = (k == 1 || k == 2) ? half : -half, dz = k >= 2 ? half : -half;
        const Vec3d X = ground.fromGround(Vec3d(g0[0] + dx, 0, g0[2] + dz));
        groundJson << (k ? ", " : "") << vec(X.val, 3);
    }
    groundJson << "]";
    // The light. Without a sun in scene.yml: the fixed light of the shading convention
    // (src/shading.hpp) in the ground frame, as before. With one: resolveSun()'s direction (the
    // reconstruction's world, as every asset), its sky share and its penumbra as the sun's
    // angular diameter: augocc's penumbra is a width on the receiver, Blender's grows with the
    // caster's height above it, so the angle is the penumbra over the mean height of the
    // virtual objects' vertices above the ground (their shadows' typical caster distance).
    Vec3d sun;
    String sunJson = "null";
    if (sunLit)
    {
        sun = sceneSun.direction / cv::norm(sceneSun.direction);
        double heightSum = 0;
        size_t count = 0;
        for (size_t i = 0; i < scene.objects.size(); i++)
            for (const Mesh& m0 : scene.objects[i].meshes)
            {
                Mesh m = m0;
                m.transform(poses[i]);
                for (const Vec3f& v : m.vertices)
                {
                    heightSum += std::max(0.0, ground.toGround(Vec3d(v[0], v[1], v[2]))[1]);
                    count++;
                }
            }
        const double meanHeight = count ? heightSum / count : 0;
        const double angle = meanHeight > 0 ? std::min(sceneSun.penumbra / meanHeight, 0.5) : 0;
        sunJson = format("{\"sky\": %s, \"angle\": %s, \"penumbra\": %s}",
                         num(sceneSun.sky).c_str(), num(angle).c_str(),
                         num(sceneSun.penumbra).c_str());
    }
    else
    {
        const Vec3d L(detail::kLightDirection[0], detail::kLightDirection[1],
                      detail::kLightDirection[2]);
        sun = ground.right * L[0] + ground.up * L[1] + ground.back * L[2];
    }

    std::ostringstream j;
    j << "{\n\"model\": " << (ortho ? "\"ORTHO\"" : "\"PERSP\"") << ",\n\"width\": " << W
      << ",\n\"height\": " << H << ",\n\"fps\": " << num(shot.fps)
      << ",\n\"first_frame\": " << shot.first << ",\n\"end_frame\": " << shot.end
      << ",\n\"sensor_width\": " << num(kSensorWidthMm)
      << ",\n\"clip_start\": " << num(1e-3 * radius)
      << ",\n\"clip_end\": " << num(2 * clipEnd + radius)
      << ",\n\"samples\": " << options.samples
      << ",\n\"script\": " << quoted(script.filename().string())
      << ",\n\"assets\": " << quoted(assetsName)
      << ",\n\"footage\": "
      << (options.footage.empty() ? String("null")
                                  : quoted(relativeTo(footageFile(options.footage), here)))
      << ",\n\"distortion\": " << distortionJson(rec.camera(shot.first), H,
                                                 options.reconstructionName)
      << ",\n\"blend\": "
      << (options.blendPath.empty() ? String("null")
                                    : quoted(relativeTo(options.blendPath, here)))
      << ",\n\"world_matrix\": " << matrix(Wr, Wt) << ",\n\"ground\": " << groundJson.str()
      << ",\n\"sun_direction\": " << vec(sun.val, 3) << ",\n\"sun\": " << sunJson << ",\n\"cameras\": " << camerasJson.str()
      << ",\n\"clones\": " << clonesJson.str() << ",\n\"objects\": " << objectsJson.str()
      << "\n}";

    std::ostringstream py;
    py << "# Shot written by `augocc export-blender` for Blender 3.4+ (doc/blender.md).\n"
       << "# Run: blender -b -P " << script.filename().string() << "  (or Blender's Scripting "
       << "tab, Run Script)\n"
       << "SHOT_JSON = r'''\n" << j.str() << "\n'''\n" << kBlenderShotPy;
    const String text = py.str();
    writeAtomically(scriptPath, [&](const String& tmpScript) {
        detail::writeFileBytes(tmpScript, text.data(), text.size(), scriptPath);
    });
    files.script = scriptPath;
    detail::commitTemporary(tmp, assets.string());
    files.assetsTmp.clear();
}

} // namespace

void writeBlenderShot(const String& scriptPath, const Reconstruction& rec,
                      const CloneSet& clones, const VirtualScene& scene,
                      const BlenderShotOptions& options)
{
    ShotFiles files;
    try
    {
        writeShot(scriptPath, rec, clones, scene, options, files);
    }
    catch (const std::exception& e)
    {
        std::error_code ec;
        if (!files.assetsTmp.empty())
            fs::remove_all(files.assetsTmp, ec);
        if (!files.script.empty())
            fs::remove(files.script, ec);
        const cv::Exception* cve = dynamic_cast<const cv::Exception*>(&e);
        const fs::filesystem_error* fse = dynamic_cast<const fs::filesystem_error*>(&e);
        const String what = cve ? cve->err
                          : fse ? fse->path1().string() + ": " + fse->code().message()
                                : String(e.what());
        // A write failure names the script (the output the user asked for) first.
        if (!files.writing || what.compare(0, scriptPath.size(), scriptPath) == 0)
            throw;
        CV_Error(cve ? cve->code : Error::StsError, scriptPath + ": " + what);
    }
}

} // namespace augocc
} // namespace cv
