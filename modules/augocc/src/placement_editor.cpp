// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Interactive placement of virtual objects (`augocc place`), headless: the paper's users placed
// the virtual objects "interactively through a GUI" (Ong, Teh & Tan 1998, Section 7). Every edit
// is stored in the scene file's own fields and the pose recomputed from them by scenePoses(),
// so what the preview shows is what the saved scene.yml composites to.

#include "precomp.hpp"
#include "opencv2/augocc/placement_editor.hpp"
#include "scene_detail.hpp"

#include <deque>
#include <filesystem>
#include <memory>
#include <set>
#include <opencv2/imgproc.hpp>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

typedef std::shared_ptr<const std::vector<Mesh>> MeshList;

// One object of the scene being edited: its scene-file fields (meshes held apart, shared between
// undo states) and what they place.
struct Item
{
    SceneObject so;      // meshes empty
    MeshList meshes;     // object coordinates
    MeshList placed;     // world coordinates (scenePoses() applied)
    Matx44d pose;
    Vec3d gmin, gmax;    // ground-aligned bounds of the placed vertices (in double)
};

struct State
{
    std::vector<Item> items;
    int selected = -1;
    int id = 0;          // identifies the state for isModified()
    SceneSun sun;        // the scene's sun (an edit like the objects': undoable)
};

bool sameSun(const SceneSun& a, const SceneSun& b)
{
    return a.form == b.form && a.direction == b.direction && a.azimuthDeg == b.azimuthDeg &&
           a.elevationDeg == b.elevationDeg && a.date == b.date && a.time == b.time &&
           a.latitudeDeg == b.latitudeDeg && a.longitudeDeg == b.longitudeDeg &&
           a.north == b.north && a.sky == b.sky && a.penumbraPx == b.penumbraPx;
}

// Azimuth (clockwise from north seen from above, [0, 360)) and elevation of a direction in a
// ground frame: the inverse of sunDirection() (scene.hpp), north's horizontal part (zero: -back).
void directionAngles(const GroundFrame& g, const Vec3d& d, const Vec3d& north, double& azimuthDeg,
                     double& elevationDeg)
{
    Vec3d n = north == Vec3d(0, 0, 0) ? -g.back : north;
    n -= g.up * n.dot(g.up);
    n = normalize(n);
    const Vec3d e = n.cross(g.up);
    const Vec3d u = normalize(d);
    elevationDeg = std::asin(std::max(-1.0, std::min(1.0, u.dot(g.up)))) * 180 / CV_PI;
    azimuthDeg = std::atan2(u.dot(e), u.dot(n)) * 180 / CV_PI;
    if (azimuthDeg < 0)
        azimuthDeg += 360;
    if (azimuthDeg >= 360)
        azimuthDeg -= 360;
}

const double kMinSunElevationDeg = 1, kMaxSunElevationDeg = 89, kMaxSky = 0.95;

//! `base` (its north, sky and penumbra) in the azimuth / elevation form at these angles, the
//! elevation held in [kMinSunElevationDeg, kMaxSunElevationDeg], the azimuth in [0, 360).
SceneSun azimuthElevationSun(SceneSun s, double azimuthDeg, double elevationDeg)
{
    s.form = SceneSun::SUN_AZIMUTH_ELEVATION;
    s.azimuthDeg = std::fmod(azimuthDeg, 360.0);
    if (s.azimuthDeg < 0)
        s.azimuthDeg += 360;
    s.elevationDeg = std::max(kMinSunElevationDeg, std::min(kMaxSunElevationDeg, elevationDeg));
    s.direction = Vec3d(0, 0, 0);
    s.date.clear();
    s.time.clear();
    return s;
}

Matx44d affine(const Matx33d& A, const Vec3d& t)
{
    return Matx44d(A(0, 0), A(0, 1), A(0, 2), t[0], A(1, 0), A(1, 1), A(1, 2), t[1],
                   A(2, 0), A(2, 1), A(2, 2), t[2], 0, 0, 0, 1);
}

Matx33d linearPart(const Matx44d& M)
{
    return Matx33d(M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2), M(2, 0), M(2, 1),
                   M(2, 2));
}

Vec3d translationPart(const Matx44d& M)
{
    return Vec3d(M(0, 3), M(1, 3), M(2, 3));
}

// A = R * diag(s) with R a rotation (every pose the editor makes has this form: the scene file's
// rotation times its per-axis scale, then rotations and uniform scales): s = the column norms.
void splitRotationScale(const Matx33d& A, Matx33d& R, Vec3d& s)
{
    for (int c = 0; c < 3; c++)
    {
        s[c] = std::sqrt(A(0, c) * A(0, c) + A(1, c) * A(1, c) + A(2, c) * A(2, c));
        CV_Assert(s[c] > 0);
        for (int r = 0; r < 3; r++)
            R(r, c) = A(r, c) / s[c];
    }
}

// The eight corners of a ground-aligned box, world coordinates.
std::vector<Vec3d> boxCorners(const GroundFrame& g, const Vec3d& lo, const Vec3d& hi)
{
    std::vector<Vec3d> c;
    for (int k = 0; k < 8; k++)
        c.push_back(g.fromGround(Vec3d(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1],
                                       k & 4 ? hi[2] : lo[2])));
    return c;
}

class PlacementEditorImpl CV_FINAL : public PlacementEditor
{
public:
    PlacementEditorImpl(const Reconstruction& rec, const Ptr<CloneSet>& clones,
                        const VirtualScene& scene, const Params& params)
        : rec_(rec), clones_(clones), scene_(scene)
    {
        if (!clones_)
            CV_Error(Error::StsBadArg, "PlacementEditor: no clones given");
        rec_.validate("reconstruction");
        setParams(params);
        ground_ = estimateGround(rec_);
        cur_.sun = scene.sun;
        resolvedSun(cur_.sun);  // a bad sun is reported now
        scene_.objects.clear();
        for (const SceneObject& o : scene.objects)
        {
            Item it;
            it.so = o;
            it.so.meshes.clear();
            it.meshes = std::make_shared<const std::vector<Mesh>>(o.meshes);
            refresh(it);
            cur_.items.push_back(std::move(it));
        }
        cur_.id = savedId_ = nextId_++;
    }

    Params getParams() const CV_OVERRIDE { return params_; }

    void setParams(const Params& p) CV_OVERRIDE
    {
        if (p.supersample < 1 || p.supersample > 8)
            CV_Error(Error::StsBadArg, cv::format("PlacementEditor: supersample %d is outside "
                                                  "[1, 8]", p.supersample));
        if (!(p.addedSize > 0) || !std::isfinite(p.addedSize))
            CV_Error(Error::StsBadArg, "PlacementEditor: addedSize must be positive");
        if (p.maxUndo < 1)
            CV_Error(Error::StsBadArg, "PlacementEditor: maxUndo must be >= 1");
        if (p.supersample != params_.supersample || p.antialiasVirtual != params_.antialiasVirtual)
            comp_.release();
        params_ = p;
    }

    GroundFrame getGround() const CV_OVERRIDE { return ground_; }

    double getSceneSize() const CV_OVERRIDE
    {
        if (sceneSize_ > 0)
            return sceneSize_;
        double lo0 = DBL_MAX, lo2 = DBL_MAX, hi0 = -DBL_MAX, hi2 = -DBL_MAX;
        for (const String& name : clones_->objectNames())
        {
            Vec3d lo, hi;
            try
            {
                getCloneBounds(name, lo, hi);
            }
            catch (const cv::Exception&)
            {
                continue;  // a clone seen in no frame has no footprint
            }
            lo0 = std::min(lo0, lo[0]);
            lo2 = std::min(lo2, lo[2]);
            hi0 = std::max(hi0, hi[0]);
            hi2 = std::max(hi2, hi[2]);
        }
        if (hi0 >= lo0)
            sceneSize_ = std::hypot(hi0 - lo0, hi2 - lo2);
        else
        {
            // No clone to measure: the reconstructed points' footprint (2nd-98th percentiles).
            std::vector<double> xs, zs;
            for (int i = 0; i < rec_.points.rows; i++)
                if (rec_.hasPoint(i))
                {
                    const Vec3d g = ground_.toGround(rec_.point(i));
                    xs.push_back(g[0]);
                    zs.push_back(g[2]);
                }
            if (xs.size() >= 2)
            {
                auto spread = [](std::vector<double>& v) {
                    std::sort(v.begin(), v.end());
                    const size_t a = v.size() / 50, b = v.size() - 1 - v.size() / 50;
                    return v[b] - v[a];
                };
                sceneSize_ = std::hypot(spread(xs), spread(zs));
            }
        }
        if (!(sceneSize_ > 0))
            sceneSize_ = 1.0;
        return sceneSize_;
    }

    void getCloneBounds(const String& clone, Vec3d& lo, Vec3d& hi) const CV_OVERRIDE
    {
        auto it = cloneBounds_.find(clone);
        if (it == cloneBounds_.end())
        {
            Vec3d a, b;
            estimateCloneBounds(*clones_, clone, rec_, ground_, a, b);
            it = cloneBounds_.insert(std::make_pair(clone, std::make_pair(a, b))).first;
        }
        lo = it->second.first;
        hi = it->second.second;
    }

    void setFrame(int frameIndex, InputArray image) CV_OVERRIDE
    {
        const int idx = rec_.findCamera(frameIndex);
        if (idx < 0)
            CV_Error(Error::StsBadArg, cv::format("PlacementEditor: the reconstruction has no "
                                                  "camera for frame %d", frameIndex));
        const Mat img = image.getMat();
        CV_CheckTypeEQ(img.type(), CV_8UC3, "PlacementEditor: the frame must be BGR CV_8UC3");
        if (img.size() != rec_.imageSize)
            CV_Error(Error::StsBadSize, cv::format("PlacementEditor: frame %d is %dx%d, the "
                     "reconstruction's image size %dx%d", frameIndex, img.cols, img.rows,
                     rec_.imageSize.width, rec_.imageSize.height));
        img.copyTo(image_);
        frame_ = frameIndex;
        camera_ = rec_.cameras[idx];
    }

    int getFrame() const CV_OVERRIDE { return frame_; }

    Camera getCamera() const CV_OVERRIDE
    {
        requireFrame();
        return camera_;
    }

    bool groundPoint(Point2d px, Vec3d& world) const CV_OVERRIDE
    {
        requireFrame();
        const Ray ray = camera_.backproject(px);
        const double denom = ground_.up.dot(ray.direction);
        if (std::abs(denom) < 1e-9)
            return false;  // the ray runs along the ground
        const double lambda = (ground_.height - ground_.up.dot(ray.origin)) / denom;
        // A perspective ray starts at the camera centre: the ground behind it is not seen.
        // A scaled-orthographic ray is a whole line (its origin is only the plane Xc.z = 0).
        if (camera_.model == PERSPECTIVE && lambda <= 0)
            return false;
        world = ray.at(lambda);
        return true;
    }

    int pickObject(Point2d px) const CV_OVERRIDE
    {
        requireFrame();
        int best = -1;
        double bestDepth = DBL_MAX;
        for (size_t i = 0; i < cur_.items.size(); i++)
        {
            const Item& it = cur_.items[i];
            std::vector<Point2f> pts;
            bool ok = true;
            for (const Vec3d& c : boxCorners(ground_, it.gmin, it.gmax))
            {
                if (camera_.model == PERSPECTIVE && camera_.depth(c) <= 0)
                    ok = false;
                pts.push_back(Point2f(camera_.project(c)));
            }
            if (!ok)
                continue;
            std::vector<Point2f> hull;
            convexHull(pts, hull);
            if (pointPolygonTest(hull, Point2f(px), false) < 0)
                continue;
            const double d = camera_.depth(ground_.fromGround(0.5 * (it.gmin + it.gmax)));
            if (d < bestDepth)
            {
                bestDepth = d;
                best = (int)i;
            }
        }
        return best;
    }

    int getObjectCount() const CV_OVERRIDE { return (int)cur_.items.size(); }

    void selectObject(int index) CV_OVERRIDE
    {
        if (index < -1 || index >= getObjectCount())
            CV_Error(Error::StsOutOfRange, cv::format("PlacementEditor: no object %d (the scene "
                                                      "has %d)", index, getObjectCount()));
        cur_.selected = index;
    }

    int getSelected() const CV_OVERRIDE { return cur_.selected; }

    VirtualScene getScene() const CV_OVERRIDE
    {
        VirtualScene s = scene_;
        s.sun = cur_.sun;
        for (const Item& it : cur_.items)
            s.objects.push_back(withMeshes(it));
        return s;
    }

    SceneObject getObject(int index) const CV_OVERRIDE { return item(index).so; }

    Matx44d getPose(int index) const CV_OVERRIDE { return item(index).pose; }

    Vec3d getBasePoint(int index) const CV_OVERRIDE { return basePoint(item(index)); }

    void getObjectBounds(int index, Vec3d& lo, Vec3d& hi) const CV_OVERRIDE
    {
        lo = item(index).gmin;
        hi = item(index).gmax;
    }

    bool beginDrag(Point2d px) CV_OVERRIDE
    {
        endDrag();
        const int o = pickObject(px);
        Vec3d g;
        if (o < 0 || !groundPoint(px, g))
            return false;
        cur_.selected = o;
        const Vec3d off = basePoint(cur_.items[o]) - g;
        dragOffset_ = off - ground_.up * ground_.up.dot(off);
        pushUndo();
        dragging_ = true;
        dragMoved_ = false;
        return true;
    }

    bool dragTo(Point2d px) CV_OVERRIDE
    {
        Vec3d g;
        if (!dragging_ || !groundPoint(px, g))
            return false;
        moveBase(cur_.items[cur_.selected], g + dragOffset_);
        dragMoved_ = true;
        return true;
    }

    bool endDrag() CV_OVERRIDE
    {
        if (!dragging_)
            return false;
        dragging_ = false;
        if (!dragMoved_)
        {
            // A click without a move selects; it is no edit.
            const int sel = cur_.selected;
            cur_ = undo_.back();
            cur_.selected = sel;
            undo_.pop_back();
        }
        return true;
    }

    bool isDragging() const CV_OVERRIDE { return dragging_; }

    bool moveTo(Point2d px) CV_OVERRIDE
    {
        Vec3d g;
        if (cur_.selected < 0 || !groundPoint(px, g))
            return false;
        moveBase(*beginEdit(), g);
        return true;
    }

    bool rotate(double degrees) CV_OVERRIDE
    {
        if (!std::isfinite(degrees))
            CV_Error(Error::StsBadArg, "PlacementEditor::rotate: the angle is not finite");
        Item* edited = beginEdit();
        if (!edited)
            return false;
        Item& it = *edited;
        const Vec3d c = basePoint(it);
        const Matx33d Ru = rotationFromRodrigues(ground_.up * (degrees * CV_PI / 180.0));
        setAbsolute(it, affine(Ru * linearPart(it.pose), c + Ru * (translationPart(it.pose) - c)));
        // The footprint's box turns with the object: its centre moves unless the object is
        // symmetric about that axis. Put the base point back where it was.
        moveBase(it, c);
        return true;
    }

    bool scale(double factor) CV_OVERRIDE
    {
        if (!(factor > 0) || !std::isfinite(factor))
            CV_Error(Error::StsBadArg, cv::format("PlacementEditor::scale: factor %g must be "
                                                  "positive", factor));
        Item* edited = beginEdit();
        if (!edited)
            return false;
        Item& it = *edited;
        const Vec3d c = basePoint(it);
        setAbsolute(it, affine(linearPart(it.pose) * factor,
                               c + factor * (translationPart(it.pose) - c)));
        return true;
    }

    bool raise(double height) CV_OVERRIDE
    {
        if (!std::isfinite(height))
            CV_Error(Error::StsBadArg, "PlacementEditor::raise: the height is not finite");
        Item* edited = beginEdit();
        if (!edited)
            return false;
        Item& it = *edited;
        setAbsolute(it, affine(linearPart(it.pose),
                               translationPart(it.pose) + ground_.up * height));
        return true;
    }

    bool snapToClone(const String& clone, int side, double gap) CV_OVERRIDE
    {
        if (side < SNAP_BEHIND || side > SNAP_RIGHT)
            CV_Error(Error::StsBadArg, cv::format("PlacementEditor::snapToClone: side %d is not "
                                                  "a SnapSide", side));
        if (!(gap >= 0) || !std::isfinite(gap))
            CV_Error(Error::StsBadArg, cv::format("PlacementEditor::snapToClone: gap %g must be "
                                                  ">= 0", gap));
        Vec3d lo, hi;
        getCloneBounds(clone, lo, hi);  // StsObjectNotFound for an unknown clone
        Item* edited = beginEdit();
        if (!edited)
            return false;
        Item& it = *edited;
        // scenePoses(): pose = B * eulerDeg(rotation) * diag(scale) * k, B the ground axes as
        // columns; k = 1 without `size`. Keep the object's turn and scale: B^T R, s.
        Matx33d R;
        Vec3d s;
        splitRotationScale(linearPart(it.pose), R, s);
        const Vec3d ext = hi - lo;
        const double cloneSize = std::max(ext[0], std::max(ext[1], ext[2]));
        SceneObject& so = it.so;
        so.placement = side == SNAP_BEHIND     ? SceneObject::PLACE_BEHIND
                       : side == SNAP_IN_FRONT ? SceneObject::PLACE_IN_FRONT
                                               : SceneObject::PLACE_BESIDE;
        so.side = side == SNAP_LEFT ? -1 : 1;
        so.anchor = clone;
        so.distance = gap / std::max(cloneSize, 1e-12);
        so.offset = Vec3d(0, 0, 0);
        so.size = 0;
        so.position = Vec3d(0, 0, 0);
        so.rotationDeg = detail::rotationToEulerDeg(ground_.rotation() * R);
        so.scale = s;
        refresh(it);
        return true;
    }

    String snapToNearestClone(int side, double gap) CV_OVERRIDE
    {
        if (cur_.selected < 0)
            return String();
        const Vec3d b = ground_.toGround(basePoint(cur_.items[cur_.selected]));
        String best;
        double bestD = DBL_MAX;
        for (const String& name : clones_->objectNames())
        {
            Vec3d lo, hi;
            try
            {
                getCloneBounds(name, lo, hi);
            }
            catch (const cv::Exception&)
            {
                continue;  // seen in no frame
            }
            const Vec3d c = 0.5 * (lo + hi);
            const double d = std::hypot(c[0] - b[0], c[2] - b[2]);
            if (d < bestD)
            {
                bestD = d;
                best = name;
            }
        }
        if (best.empty())
            CV_Error(Error::StsObjectNotFound, "PlacementEditor: no clone is seen in any frame");
        snapToClone(best, side, gap);
        return best;
    }

    int addObject(const String& meshFile, Point2d px) CV_OVERRIDE
    {
        SceneObject so;
        so.meshFile = fs::absolute(fs::path(meshFile)).lexically_normal().string();
        so.meshes = loadMeshes(meshFile);
        so.name = uniqueName(fs::path(meshFile).stem().string());
        return insertObject(so, px);
    }

    int addShape(const String& shape, Point2d px) CV_OVERRIDE
    {
        SceneObject so;
        so.shape = shape;
        so.meshes = proceduralShape(shape);
        so.name = uniqueName(shape);
        return insertObject(so, px);
    }

    void removeObject(int index) CV_OVERRIDE
    {
        item(index);
        endDrag();
        pushUndo();
        cur_.items.erase(cur_.items.begin() + index);
        if (cur_.selected == index)
            cur_.selected = -1;
        else if (cur_.selected > index)
            cur_.selected--;
        meshesDirty_ = true;
    }

    SceneSun getSun() const CV_OVERRIDE { return cur_.sun; }

    void setSun(const SceneSun& sun) CV_OVERRIDE
    {
        resolvedSun(sun);  // throws before anything changes
        endDrag();
        pushUndo();
        cur_.sun = sun;
    }

    bool getSunAngles(double& azimuthDeg, double& elevationDeg) const CV_OVERRIDE
    {
        if (cur_.sun.form == SceneSun::SUN_NONE)
            return false;
        if (cur_.sun.form == SceneSun::SUN_AZIMUTH_ELEVATION)
        {
            azimuthDeg = cur_.sun.azimuthDeg;
            elevationDeg = cur_.sun.elevationDeg;
            return true;
        }
        directionAngles(ground_, resolvedSun(cur_.sun).direction, cur_.sun.north, azimuthDeg,
                        elevationDeg);
        return true;
    }

    bool turnSun(double dAzimuthDeg, double dElevationDeg) CV_OVERRIDE
    {
        if (!std::isfinite(dAzimuthDeg) || !std::isfinite(dElevationDeg))
            CV_Error(Error::StsBadArg, "PlacementEditor::turnSun: the angles must be finite");
        double az, el;
        if (!getSunAngles(az, el))
            return false;
        setSun(azimuthElevationSun(cur_.sun, az + dAzimuthDeg, el + dElevationDeg));
        return true;
    }

    bool changeSky(double delta) CV_OVERRIDE
    {
        if (!std::isfinite(delta))
            CV_Error(Error::StsBadArg, "PlacementEditor::changeSky: delta must be finite");
        if (cur_.sun.form == SceneSun::SUN_NONE)
            return false;
        SceneSun s = cur_.sun;
        s.sky = std::max(0.0, std::min(kMaxSky, s.sky + delta));
        setSun(s);
        return true;
    }

    SunEstimate estimateSunFromFrames(const std::vector<Mat>& frames,
                                      const std::vector<int>& frameNumbers,
                                      const SunEstimationParams& params) CV_OVERRIDE
    {
        const SunEstimate e = cv::augocc::estimateSun(frames, frameNumbers, rec_, *clones_,
                                                      ground_, params);
        const SceneSun base = cur_.sun.form == SceneSun::SUN_NONE ? SceneSun() : cur_.sun;
        double az = 0, el = 0;
        directionAngles(ground_, e.direction, base.north, az, el);
        SceneSun s = azimuthElevationSun(base, az, el);
        s.sky = std::max(0.0, std::min(kMaxSky, e.sky));
        setSun(s);
        estimate_ = e;
        return e;
    }

    SunEstimate getSunEstimate() const CV_OVERRIDE { return estimate_; }

    bool undo() CV_OVERRIDE
    {
        endDrag();
        if (undo_.empty())
            return false;
        redo_.push_back(std::move(cur_));
        cur_ = std::move(undo_.back());
        undo_.pop_back();
        meshesDirty_ = true;
        return true;
    }

    bool redo() CV_OVERRIDE
    {
        endDrag();
        if (redo_.empty())
            return false;
        undo_.push_back(std::move(cur_));
        cur_ = std::move(redo_.back());
        redo_.pop_back();
        meshesDirty_ = true;
        return true;
    }

    bool canUndo() const CV_OVERRIDE { return !undo_.empty(); }
    bool canRedo() const CV_OVERRIDE { return !redo_.empty(); }
    bool isModified() const CV_OVERRIDE { return cur_.id != savedId_; }

    void save(const String& path) CV_OVERRIDE
    {
        if (cur_.items.empty())
            CV_Error(Error::StsBadArg, path + ": the scene has no object to save (readScene() "
                     "needs at least one)");
        // writeScene() references the meshes by file; it does not need them.
        VirtualScene s = scene_;
        s.sun = cur_.sun;
        for (const Item& it : cur_.items)
            s.objects.push_back(it.so);
        s.path = path;
        writeScene(path, s);
        savedId_ = cur_.id;
    }

    void render(OutputArray preview, OutputArray virtualLayer) CV_OVERRIDE
    {
        requireFrame();
        if (!comp_)
        {
            // compositeSequence()'s compositor: the same parameters, lit in the ground frame.
            Compositor::Params cp;
            cp.supersample = params_.supersample;
            cp.antialiasVirtual = params_.antialiasVirtual;
            cp.lightRotation = ground_.rotation();
            // Under the scene's sun, shadows both ways as composite draws them (issue 19).
            cp.ground = ground_;
            cp.sun = resolvedSun(cur_.sun);
            comp_ = Compositor::create(cp);
            compSun_ = cur_.sun;
            meshesDirty_ = true;
        }
        else if (!sameSun(compSun_, cur_.sun))
        {
            Compositor::Params cp = comp_->getParams();
            cp.sun = resolvedSun(cur_.sun);
            comp_->setParams(cp);
            compSun_ = cur_.sun;
        }
        if (meshesDirty_)
        {
            std::vector<Mesh> all;
            for (const Item& it : cur_.items)
                all.insert(all.end(), it.placed->begin(), it.placed->end());
            comp_->setVirtualObjects(all);
            meshesDirty_ = false;
        }
        comp_->composite(image_, frame_, camera_, *clones_, preview, virtualLayer);
    }

    void drawOverlay(InputOutputArray canvasArr) const CV_OVERRIDE
    {
        requireFrame();
        Mat canvas = canvasArr.getMat();
        CV_CheckTypeEQ(canvas.type(), CV_8UC3, "PlacementEditor::drawOverlay: BGR canvas");
        for (size_t i = 0; i < cur_.items.size(); i++)
        {
            const Item& it = cur_.items[i];
            const bool sel = (int)i == cur_.selected;
            const Vec3d b = basePoint(it);
            if (camera_.model == PERSPECTIVE && camera_.depth(b) <= 0)
                continue;
            const Point2d pb = camera_.project(b);
            if (!sel)
            {
                circle(canvas, pb, 4, Scalar(0, 200, 255), 1, LINE_AA);
                continue;
            }
            const std::vector<Vec3d> c = boxCorners(ground_, it.gmin, it.gmax);
            bool front = true;
            for (const Vec3d& p : c)
                front = front && (camera_.model != PERSPECTIVE || camera_.depth(p) > 0);
            if (front)
                for (int a = 0; a < 8; a++)
                    for (int bit = 1; bit < 8; bit <<= 1)
                        if (!(a & bit))
                            line(canvas, camera_.project(c[a]), camera_.project(c[a | bit]),
                                 Scalar(0, 255, 255), 1, LINE_AA);
            drawMarker(canvas, pb, Scalar(0, 0, 255), MARKER_CROSS, 14, 2, LINE_AA);
        }
    }

private:
    //! The sun of the scene with `sun` in the reconstruction's world (resolveSun()), validated.
    Sun resolvedSun(const SceneSun& sun) const
    {
        VirtualScene s;
        s.path = scene_.path;
        s.sun = sun;
        const Sun r = resolveSun(s, rec_);
        if (r.enabled())
            r.validate("PlacementEditor: sun");
        return r;
    }

    void requireFrame() const
    {
        if (frame_ < 0)
            CV_Error(Error::StsError, "PlacementEditor: no frame set (setFrame())");
    }

    const Item& item(int index) const
    {
        if (index < 0 || index >= getObjectCount())
            CV_Error(Error::StsOutOfRange, cv::format("PlacementEditor: no object %d (the scene "
                                                      "has %d)", index, getObjectCount()));
        return cur_.items[index];
    }

    static SceneObject withMeshes(const Item& it)
    {
        SceneObject o = it.so;
        o.meshes = *it.meshes;
        return o;
    }

    static Vec3d basePointGround(const Item& it)
    {
        return Vec3d(0.5 * (it.gmin[0] + it.gmax[0]), it.gmin[1], 0.5 * (it.gmin[2] + it.gmax[2]));
    }

    Vec3d basePoint(const Item& it) const { return ground_.fromGround(basePointGround(it)); }

    // Pose, placed meshes and bounds from the scene-file fields: scenePoses() (one place for the
    // placement rules), then the vertices placed as placeScene() places them.
    void refresh(Item& it)
    {
        VirtualScene one;
        one.path = scene_.path;
        one.objects.push_back(it.so);
        if (it.so.placement != SceneObject::PLACE_ABSOLUTE)
            one.objects[0].meshes = *it.meshes;  // the helpers size the object by its bounds
        it.pose = scenePoses(one, rec_, clones_.get())[0];
        auto placed = std::make_shared<std::vector<Mesh>>();
        it.gmin = Vec3d::all(DBL_MAX);
        it.gmax = Vec3d::all(-DBL_MAX);
        const Matx33d A = linearPart(it.pose);
        const Vec3d t = translationPart(it.pose);
        for (const Mesh& m : *it.meshes)
        {
            Mesh w = m;
            w.transform(it.pose);
            // Bounds in double from the object's vertices (not the placed floats): the base
            // point then moves exactly with the pose, whatever path a drag took.
            for (const Vec3f& v : m.vertices)
            {
                const Vec3d g = ground_.toGround(A * Vec3d(v) + t);
                for (int k = 0; k < 3; k++)
                {
                    it.gmin[k] = std::min(it.gmin[k], g[k]);
                    it.gmax[k] = std::max(it.gmax[k], g[k]);
                }
            }
            placed->push_back(std::move(w));
        }
        if (it.gmin[0] > it.gmax[0])
            it.gmin = it.gmax = ground_.toGround(translationPart(it.pose));  // no vertex
        it.placed = placed;
        meshesDirty_ = true;
    }

    // The object becomes `position` / `rotation` / `scale` in the world frame (the helper no
    // longer holds once the user moves it).
    void setAbsolute(Item& it, const Matx44d& pose)
    {
        Matx33d R;
        Vec3d s;
        splitRotationScale(linearPart(pose), R, s);
        SceneObject& so = it.so;
        so.placement = SceneObject::PLACE_ABSOLUTE;
        so.anchor.clear();
        so.size = 0;
        so.distance = SceneObject().distance;
        so.side = SceneObject().side;
        so.offset = Vec3d(0, 0, 0);
        so.position = translationPart(pose);
        so.rotationDeg = detail::rotationToEulerDeg(R);
        so.scale = s;
        refresh(it);
    }

    // Horizontal move of the base point to above `target`.
    void moveBase(Item& it, const Vec3d& target)
    {
        Vec3d d = target - basePoint(it);
        d -= ground_.up * ground_.up.dot(d);
        setAbsolute(it, affine(linearPart(it.pose), translationPart(it.pose) + d));
    }

    String uniqueName(const String& stem) const
    {
        std::set<String> names;
        for (const Item& it : cur_.items)
            names.insert(it.so.name);
        const String base = stem.empty() ? String("object") : stem;
        String name = base;
        for (int n = 2; names.count(name); n++)
            name = base + cv::format("_%d", n);
        return name;
    }

    int insertObject(SceneObject so, Point2d px)
    {
        Vec3d g;
        if (frame_ < 0 || !groundPoint(px, g))
        {
            if (frame_ < 0 || !groundPoint(Point2d((rec_.imageSize.width - 1) * 0.5,
                                                   (rec_.imageSize.height - 1) * 0.5), g))
                g = ground_.fromGround(Vec3d(0, 0, 0));
        }
        // Object coordinates are y up (the helpers' convention): object (x, y, z) -> ground
        // (right, up, back), scaled to Params::addedSize of the scene, base on the ground at g.
        Vec3d lo = Vec3d::all(DBL_MAX), hi = Vec3d::all(-DBL_MAX);
        for (const Mesh& m : so.meshes)
            for (const Vec3f& v : m.vertices)
                for (int k = 0; k < 3; k++)
                {
                    lo[k] = std::min(lo[k], (double)v[k]);
                    hi[k] = std::max(hi[k], (double)v[k]);
                }
        const Vec3d ext = hi - lo;
        const double dim = std::max(ext[0], std::max(ext[1], ext[2]));
        const double k = params_.addedSize * getSceneSize() / std::max(dim, 1e-12);
        const Matx33d B = ground_.rotation().t() * k;
        const Vec3d baseObj(0.5 * (lo[0] + hi[0]), lo[1], 0.5 * (lo[2] + hi[2]));
        Item it;
        it.meshes = std::make_shared<const std::vector<Mesh>>(std::move(so.meshes));
        so.meshes.clear();
        it.so = so;
        endDrag();
        pushUndo();
        setAbsolute(it, affine(B, g - B * baseObj));
        cur_.items.push_back(std::move(it));
        cur_.selected = (int)cur_.items.size() - 1;
        return cur_.selected;
    }

    //! The selected item, ready for an edit: a drag ended, the state before it on the undo
    //! stack. Null without a selection (nothing pushed).
    Item* beginEdit()
    {
        if (cur_.selected < 0)
            return nullptr;
        endDrag();
        pushUndo();
        return &cur_.items[cur_.selected];
    }

    void pushUndo()
    {
        undo_.push_back(cur_);
        while ((int)undo_.size() > params_.maxUndo)
            undo_.pop_front();
        redo_.clear();
        cur_.id = nextId_++;
    }

    Params params_;
    Reconstruction rec_;
    Ptr<CloneSet> clones_;
    VirtualScene scene_;   // everything but the objects (kept as the file had it)
    GroundFrame ground_;
    State cur_;
    std::deque<State> undo_, redo_;
    int nextId_ = 1, savedId_ = 0;
    mutable std::map<String, std::pair<Vec3d, Vec3d>> cloneBounds_;
    mutable double sceneSize_ = 0;
    int frame_ = -1;
    Mat image_;
    Camera camera_;
    Vec3d dragOffset_;
    bool dragging_ = false, dragMoved_ = false, meshesDirty_ = true;
    Ptr<Compositor> comp_;
    SceneSun compSun_;     // the sun comp_ is lit by
    SunEstimate estimate_;
};

} // namespace

Ptr<PlacementEditor> PlacementEditor::create(const Reconstruction& rec,
                                             const Ptr<CloneSet>& clones,
                                             const VirtualScene& scene, const Params& params)
{
    return makePtr<PlacementEditorImpl>(rec, clones, scene, params);
}

Ptr<PlacementEditor> PlacementEditor::create(const Reconstruction& rec,
                                             const Ptr<CloneSet>& clones,
                                             const VirtualScene& scene)
{
    return create(rec, clones, scene, Params());
}

} // namespace augocc
} // namespace cv
