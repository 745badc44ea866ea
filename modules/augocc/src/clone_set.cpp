// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// CloneSet: rendering (matte + depth), patch voxels (the paper's Step 5), file I/O, PLY export and
// the mattes folder.

#include "precomp.hpp"
#include "atomic_write.hpp"
#include "clone_internal.hpp"
#include "clone_codec.hpp"

#include <filesystem>
#include <unordered_map>
#include <opencv2/imgcodecs.hpp>

namespace cv {
namespace augocc {

CloneSet::~CloneSet() {}

namespace detail {

namespace fsys = std::filesystem;

namespace {

// Step 5: extra rounds of candidate patch voxels for pixels the first round left uncovered, each
// with one more ray per pixel along each axis and the depth range widened by one voxel; in the
// last round each ray takes, over its whole span in the grid, the one voxel nearest to the
// estimated segment whose footprint fits the silhouette. (Taking every voxel of the span that
// fits, as before, put patches of rim pixels at the far end of the grid under a perspective
// camera, where voxels project smaller: streaks far behind the object in the other frames. On
// the squirrel turntable, 9 of 36 views as key frames: held-out IoU 0.939 -> see doc/clones.md.)
const int kPatchExtraRounds = 2;
// Key-frame consistency warning: more than this fraction of a key frame's silhouette lies more
// than kDeepMissingPx inside its outline yet is carved by the other key frames (patches restore
// it). Rims miss a few pixels normally (measured on exact synthesized data: at most 2% of a
// small tower's silhouette, 0.2-1.2% on Middlebury's dino and the squirrel turntable); a mask that
// marks a region the others leave out (the CMU hotel's roof in one of three masks: 14.6%) does not.
const double kInconsistentFraction = 0.05;
const float kDeepMissingPx = 3.f;
// Samples along a ray segment per voxel edge (two: no voxel the segment crosses is skipped).
const double kSamplesPerVoxel = 2.0;

// Parameters [t0, t1] of the line a + t (b - a) inside the grid's box (voxel coordinates, centres
// at integers, so the box is [-0.5, dims - 0.5]); false when the line misses it.
bool clipToGrid(const VoxelGrid& g, const Vec3d& a, const Vec3d& b, double& t0, double& t1)
{
    t0 = -std::numeric_limits<double>::infinity();
    t1 = std::numeric_limits<double>::infinity();
    const Vec3d d = b - a;
    for (int ax = 0; ax < 3; ax++)
    {
        const double lo = -0.5, hi = g.dims[ax] - 0.5;
        if (std::abs(d[ax]) < 1e-12)
        {
            if (a[ax] < lo || a[ax] > hi)
                return false;
            continue;
        }
        double ta = (lo - a[ax]) / d[ax], tb = (hi - a[ax]) / d[ax];
        if (ta > tb)
            std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1 && std::isfinite(t0) && std::isfinite(t1);
}

const uint32_t kNoVoxel = ~0u;

// The last patch round for one ray a + t (b - a) (voxel coordinates; the estimated segment is
// t in [0, 1], the grid's span [t0, t1]): the empty voxel nearest to the segment, not yet a
// patch voxel, whose footprint fits `view`'s silhouette; kNoVoxel when none does.
uint32_t nearestFittingVoxel(const VoxelGrid& g, const CarveView& view, const Vec3d& a,
                             const Vec3d& b, double t0, double t1,
                             const std::vector<uint32_t>& accepted,
                             std::unordered_map<uint32_t, bool>& fits)
{
    const Vec3d d = b - a;
    const double len = std::max(std::abs(d[0]), std::max(std::abs(d[1]), std::abs(d[2])));
    if (!(len > 0))
        return kNoVoxel;
    const double dt = 1.0 / (len * kSamplesPerVoxel);  // parameter step: half a voxel
    const double mid = std::min(std::max(0.5, t0), t1);
    // Outwards from the segment's middle (clamped to the span), alternating both ways.
    const int nUp = (int)std::floor((t1 - mid) / dt), nDown = (int)std::floor((mid - t0) / dt);
    uint32_t last[2] = {kNoVoxel, kNoVoxel};  // per direction: samples repeat voxels
    for (int s = 0; s <= std::max(nUp, nDown); s++)
        for (int side = 0; side < (s == 0 ? 1 : 2); side++)
        {
            if ((side == 0 && s > nUp) || (side == 1 && s > nDown))
                continue;
            const double t = side == 0 ? mid + s * dt : mid - s * dt;
            const Vec3d v = a + t * d;
            const int i = cvRound(v[0]), j = cvRound(v[1]), k = cvRound(v[2]);
            if (!g.inside(i, j, k) || g.data[g.index(i, j, k)])
                continue;
            const uint32_t p = packVoxel(i, j, k);
            if (p == last[side])
                continue;
            last[side] = p;
            if (std::binary_search(accepted.begin(), accepted.end(), p))
                continue;
            // Neighbouring rays cross the same voxels: each footprint is tested once a round.
            auto it = fits.find(p);
            if (it == fits.end())
                it = fits.emplace(p, g.footprintKept(view, i, j, k)).first;
            if (it->second)
                return p;
        }
    return kNoVoxel;
}

Mat paddedKeep(const Mat& keep, int pad)
{
    Mat k01 = keep != 0, out;
    copyMakeBorder(k01, out, pad, pad, pad, pad, BORDER_CONSTANT, Scalar(255));
    return out;
}

} // namespace

std::vector<uint32_t> computePatches(const ObjectClone& obj, const Camera& camera,
                                     const Mat& silhouette, const Mat& keep, int raysPerPixel)
{
    const VoxelGrid& g = obj.grid;
    const VoxelProjector proj = g.projector(camera, silhouette.size());
    // Per-pixel work only over the silhouette's bounding box and the ring of neighbours the
    // second pass reads: buffers (and the page faults of allocating them) scale with the object,
    // not the frame. Pixel coordinates below are in the box; `origin` maps them to the image.
    Rect roi = boundingRect(silhouette);
    if (roi.empty())
        return std::vector<uint32_t>();
    roi = Rect(roi.x - 1, roi.y - 1, roi.width + 2, roi.height + 2) &
          Rect(Point(), silhouette.size());
    const Point origin = roi.tl();
    const Size size = roi.size();
    const Mat sil = silhouette(roi);
    Mat zmin(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
    splatVoxels(proj, obj.surface.ijk.data(), obj.surface.faces.data(), obj.surface.size(), true,
                zmin, nullptr, origin);
    Mat zfar(size, CV_32F, Scalar(-std::numeric_limits<float>::infinity()));
    Mat zdummy(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
    splatVoxels(proj, obj.surface.ijk.data(), nullptr, obj.surface.size(), false, zdummy, &zfar,
                origin);

    // First pass: d1 / d2 where the clone is hit; the missing pixels are the rest of the silhouette.
    const int W = size.width, H = size.height;
    Mat d1(size, CV_32F, Scalar(0)), d2(size, CV_32F, Scalar(0));
    Mat state(size, CV_8U, Scalar(0));  // 0 not in play, 1 known, 2 missing
    std::vector<Point> missing;
    double sum1 = 0, sum2 = 0;
    int nknown = 0;
    for (int y = 0; y < H; y++)
    {
        const float* zr = zmin.ptr<float>(y);
        const float* zf = zfar.ptr<float>(y);
        const uchar* s = sil.ptr<uchar>(y);
        for (int x = 0; x < W; x++)
        {
            if (zr[x] < std::numeric_limits<float>::infinity())
            {
                state.at<uchar>(y, x) = 1;
                d1.at<float>(y, x) = zr[x];
                d2.at<float>(y, x) = std::max(zf[x], zr[x]);
                sum1 += zr[x];
                sum2 += std::max(zf[x], zr[x]);
                nknown++;
            }
            else if (s[x])
            {
                state.at<uchar>(y, x) = 2;
                missing.push_back(Point(x, y));
            }
        }
    }
    if (missing.empty())
        return std::vector<uint32_t>();
    const int area = countNonZero(sil);
    if ((double)missing.size() > kInconsistentFraction * area)
    {
        Mat inside;
        distanceTransform(sil, inside, DIST_L2, 3);
        int deep = 0;
        for (const Point& p : missing)
            deep += inside.at<float>(p) > kDeepMissingPx;
        if ((double)deep > kInconsistentFraction * area)
            CV_LOG_WARNING(NULL, cv::format("augocc: object '%s', key frame %d: %.1f%% of the "
                           "silhouette (more than %.0f px inside its outline) is carved away by "
                           "the other key frames and kept by patch voxels only: the key-frame "
                           "silhouettes or the cameras disagree (check this frame's mask)",
                           obj.name.c_str(), camera.frame, 100.0 * deep / area,
                           kDeepMissingPx));
    }

    // Second pass: d1 / d2 of missing pixels from their eight neighbours, in order of distance from
    // the known pixels (one ring at a time, each ring from the rings before it only).
    std::vector<Point> ring;
    for (const Point& p : missing)
    {
        bool near = false;
        for (int dy = -1; dy <= 1 && !near; dy++)
            for (int dx = -1; dx <= 1; dx++)
            {
                const int x = p.x + dx, y = p.y + dy;
                if (x >= 0 && y >= 0 && x < W && y < H && state.at<uchar>(y, x) == 1)
                {
                    near = true;
                    break;
                }
            }
        if (near)
            ring.push_back(p);
    }
    std::vector<float> v1, v2;
    while (!ring.empty())
    {
        v1.assign(ring.size(), 0.f);
        v2.assign(ring.size(), 0.f);
        for (size_t q = 0; q < ring.size(); q++)
        {
            double a = 0, b = 0;
            int n = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                {
                    const int x = ring[q].x + dx, y = ring[q].y + dy;
                    if (x >= 0 && y >= 0 && x < W && y < H && state.at<uchar>(y, x) == 1)
                    {
                        a += d1.at<float>(y, x);
                        b += d2.at<float>(y, x);
                        n++;
                    }
                }
            v1[q] = (float)(a / n);
            v2[q] = (float)(b / n);
        }
        for (size_t q = 0; q < ring.size(); q++)
        {
            d1.at<float>(ring[q]) = v1[q];
            d2.at<float>(ring[q]) = v2[q];
            state.at<uchar>(ring[q]) = 3;  // assigned in this ring
        }
        std::vector<Point> next;
        for (const Point& p : ring)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                {
                    const int x = p.x + dx, y = p.y + dy;
                    if (x >= 0 && y >= 0 && x < W && y < H && state.at<uchar>(y, x) == 2)
                    {
                        state.at<uchar>(y, x) = 4;  // queued
                        next.push_back(Point(x, y));
                    }
                }
        for (const Point& p : ring)
            state.at<uchar>(p) = 1;
        ring.swap(next);
    }
    // Missing islands with no known pixel around: the clone's mean depth range, or the grid's.
    float f1, f2;
    if (nknown > 0)
    {
        f1 = (float)(sum1 / nknown);
        f2 = (float)(sum2 / nknown);
    }
    else
    {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (int c = 0; c < 8; c++)
        {
            const Vec3d X = g.centre(c & 1 ? g.dims[0] - 0.5 : -0.5, c & 2 ? g.dims[1] - 0.5 : -0.5,
                                     c & 4 ? g.dims[2] - 0.5 : -0.5);
            lo = std::min(lo, camera.depth(X));
            hi = std::max(hi, camera.depth(X));
        }
        f1 = (float)lo;
        f2 = (float)hi;
    }
    for (const Point& p : missing)
        if (state.at<uchar>(p) == 2)
        {
            d1.at<float>(p) = f1;
            d2.at<float>(p) = f2;
        }

    // Patch voxels: several rays per pixel, each segment [d1, d2] sampled finely enough that no
    // voxel it crosses is skipped; a candidate is kept only when its footprint stays in `keep`
    // (the carving rule), so patches never cover a pixel outside the silhouette.
    CarveView view;
    view.proj = proj;
    view.pad = 4;
    view.keep = paddedKeep(keep, view.pad);
    Mat covered = zmin.clone();
    std::vector<Point> todo = missing;
    std::vector<uint32_t> accepted;
    for (int round = 0; round <= kPatchExtraRounds && !todo.empty(); round++)
    {
        const int n = raysPerPixel + round;
        const double widen = g.h * round;
        std::vector<uint32_t> cand;
        std::unordered_map<uint32_t, bool> fits;
        for (const Point& p : todo)
        {
            const double z1 = d1.at<float>(p) - widen, z2 = d2.at<float>(p) + widen;
            for (int sy = 0; sy < n; sy++)
                for (int sx = 0; sx < n; sx++)
                {
                    const Point2d px(origin.x + p.x + (sx + 0.5) / n - 0.5,
                                     origin.y + p.y + (sy + 0.5) / n - 0.5);
                    Vec3d a = g.toVoxel(camera.unproject(px, z1));
                    Vec3d b = g.toVoxel(camera.unproject(px, z2));
                    // The segment, clipped to the grid; when the estimated depths miss the grid,
                    // and in the last round, the ray's whole span in the grid.
                    double t0, t1;
                    if (!clipToGrid(g, a, b, t0, t1))
                        continue;
                    if (round == kPatchExtraRounds)
                    {
                        const uint32_t v = nearestFittingVoxel(g, view, a, b, t0, t1, accepted,
                                                               fits);
                        if (v != kNoVoxel)
                            cand.push_back(v);
                        continue;
                    }
                    if (t1 < 0 || t0 > 1)
                    {
                        const Vec3d a0 = a;
                        a = a0 + t0 * (b - a0);
                        b = a0 + t1 * (b - a0);
                    }
                    else
                    {
                        const Vec3d a0 = a;
                        a = a0 + std::max(t0, 0.0) * (b - a0);
                        b = a0 + std::min(t1, 1.0) * (b - a0);
                    }
                    const double len = std::max(std::abs(b[0] - a[0]),
                                                std::max(std::abs(b[1] - a[1]), std::abs(b[2] - a[2])));
                    const int steps = (int)std::ceil(len * kSamplesPerVoxel);
                    for (int s = 0; s <= steps; s++)
                    {
                        const double t = steps > 0 ? (double)s / steps : 0.0;
                        const Vec3d v = a + t * (b - a);
                        const int i = cvRound(v[0]), j = cvRound(v[1]), k = cvRound(v[2]);
                        if (g.inside(i, j, k) && !g.data[g.index(i, j, k)])
                            cand.push_back(packVoxel(i, j, k));
                    }
                }
        }
        std::sort(cand.begin(), cand.end());
        cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
        std::vector<uint32_t> ok;
        for (uint32_t c : cand)
        {
            if (std::binary_search(accepted.begin(), accepted.end(), c))
                continue;
            int i, j, k;
            unpackVoxel(c, i, j, k);
            if (g.footprintKept(view, i, j, k))
                ok.push_back(c);
        }
        splatVoxels(proj, ok.data(), nullptr, ok.size(), false, covered, nullptr, origin);
        std::vector<uint32_t> merged(accepted.size() + ok.size());
        std::merge(accepted.begin(), accepted.end(), ok.begin(), ok.end(), merged.begin());
        accepted.swap(merged);
        std::vector<Point> left;
        for (const Point& p : todo)
            if (!(covered.at<float>(p) < std::numeric_limits<float>::infinity()))
                left.push_back(p);
        todo.swap(left);
    }
    if (!todo.empty())
    {
        CV_LOG_DEBUG(NULL, cv::format("augocc: %s: %d silhouette pixels left uncovered by patches",
                                      obj.name.c_str(), (int)todo.size()));
    }
    return accepted;
}

// ---------------------------------------------------------------------------------------------
// CloneSetImpl

const ObjectClone& CloneSetImpl::get(const String& object) const
{
    auto it = objects.find(object);
    if (it == objects.end())
        CV_Error(Error::StsObjectNotFound, "clones: no object '" + object + "'");
    return it->second;
}

ObjectClone& CloneSetImpl::get(const String& object)
{
    auto it = objects.find(object);
    if (it == objects.end())
        CV_Error(Error::StsObjectNotFound, "clones: no object '" + object + "'");
    return it->second;
}

std::vector<String> CloneSetImpl::objectNames() const
{
    std::vector<String> names;
    for (const auto& o : objects)
        names.push_back(o.first);
    return names;
}

std::vector<int> CloneSetImpl::keyFrames(const String& object) const
{
    std::vector<int> k;
    for (const auto& m : get(object).masks)
        k.push_back(m.first);
    return k;
}

std::vector<int> CloneSetImpl::patchFrames(const String& object, int frame) const
{
    const std::vector<int> keys = keyFrames(object);
    if (keys.empty())
        return keys;
    auto it = std::lower_bound(keys.begin(), keys.end(), frame);
    if (it != keys.end() && *it == frame)
        return std::vector<int>(1, frame);
    if (it == keys.begin())
        return std::vector<int>(1, keys.front());
    if (it == keys.end())
        return std::vector<int>(1, keys.back());
    const int before = *(it - 1), after = *it;
    if (patchRule == CloneBuilder::PATCH_BRACKETING)
        return std::vector<int>{before, after};
    return std::vector<int>(1, frame - before <= after - frame ? before : after);
}

int CloneSetImpl::voxelCount(const String& object) const
{
    return (int)get(object).grid.count();
}

int CloneSetImpl::patchVoxelCount(const String& object, int keyFrame) const
{
    const ObjectClone& o = get(object);
    auto it = o.patches.find(keyFrame);
    return it == o.patches.end() ? 0 : (int)it->second.size();
}

Vec3i CloneSetImpl::gridSize(const String& object) const
{
    return get(object).grid.dims;
}

double CloneSetImpl::voxelSize(const String& object) const
{
    return get(object).grid.h;
}

void CloneSetImpl::gridPose(const String& object, Matx33d& Rbox, Vec3d& origin) const
{
    const ObjectClone& o = get(object);
    Rbox = o.grid.Rbox;
    origin = o.grid.origin;
}

void CloneSetImpl::render(const String& object, int frame, const Camera& camera, Size imageSize,
                          OutputArray matte, OutputArray depth) const
{
    const ObjectClone& o = get(object);
    if (imageSize.width <= 0 || imageSize.height <= 0)
        CV_Error(Error::StsBadSize, cv::format("clones: render: bad image size %dx%d",
                                               imageSize.width, imageSize.height));
    const VoxelProjector proj = o.grid.projector(camera, imageSize);
    std::vector<VoxelList> lists(1);
    lists[0].ijk = o.surface.ijk.data();
    lists[0].faces = o.surface.faces.data();
    lists[0].n = o.surface.size();
    lists[0].frontOnly = true;
    for (int kf : patchFrames(object, frame))
    {
        auto it = o.patches.find(kf);
        if (it == o.patches.end() || it->second.empty())
            continue;
        VoxelList l;
        l.ijk = it->second.data();
        l.n = it->second.size();
        lists.push_back(l);
    }
    // Rendered straight into the caller's depth map; the matte only over the grid's bounds.
    Mat zmin;
    if (depth.needed())
    {
        depth.create(imageSize, CV_32F);
        zmin = depth.getMat();
    }
    renderDepth(o.grid, proj, lists, zmin);
    if (matte.needed())
    {
        matte.create(imageSize, CV_8U);
        Mat m = matte.getMat();
        const Rect roi = o.grid.imageBounds(proj);
        m.setTo(Scalar(0));
        if (!roi.empty())
            compare(zmin(roi), std::numeric_limits<float>::infinity(), m(roi), CMP_LT);
    }
}

void CloneSetImpl::save(const String& path) const
{
    detail::writeStorageAtomically(path, [&](FileStorage& fs) {
        fs << "format" << "augocc_clones";
        fs << "version" << 1;
        fs << "patch_rule" << (patchRule == CloneBuilder::PATCH_BRACKETING ? "bracketing"
                                                                              : "nearest");
        fs << "objects" << "[";
        for (const auto& it : objects)
        {
            const ObjectClone& o = it.second;
            fs << "{";
            fs << "name" << o.name;
            fs << "dims" << Mat(o.grid.dims).reshape(1, 1);
            fs << "R_box" << Mat(o.grid.Rbox);
            fs << "origin" << Mat(o.grid.origin);
            fs << "voxel_size" << o.grid.h;
            fs << "centre" << Mat(o.centre);
            writeBlob(fs, "voxels", encodeGrid(o.grid.data, o.grid.dims[0],
                                               o.grid.dims[1] * o.grid.dims[2]));
            fs << "key_frames" << "[";
            for (const auto& m : o.masks)
            {
                fs << "{";
                fs << "frame" << m.first;
                std::vector<uchar> png;
                cv::imencode(".png", m.second, png);
                writeBlob(fs, "mask_png", png);
                std::vector<uchar> pv;
                auto p = o.patches.find(m.first);
                if (p != o.patches.end())
                {
                    putVarint(pv, p->second.size());
                    uint32_t last = 0;
                    for (uint32_t v : p->second)
                    {
                        putVarint(pv, v - last);  // sorted: deltas are small
                        last = v;
                    }
                }
                else
                    putVarint(pv, 0);
                writeBlob(fs, "patches", pv);
                fs << "}";
            }
            fs << "]";
            fs << "}";
        }
        fs << "]";
    });
}

void CloneSetImpl::exportPly(const String& dir) const
{
    std::error_code ec;
    fsys::create_directories(dir, ec);
    if (!fsys::is_directory(dir))
        CV_Error(Error::StsError, dir + ": cannot create folder");
    for (const auto& it : objects)
    {
        const ObjectClone& o = it.second;
        writeMeshPly((fsys::path(dir) / (o.name + "_clone.ply")).string(),
                     o.grid.surfaceMesh(o.surface));
        for (const auto& p : o.patches)
            writeMeshPly((fsys::path(dir) / cv::format("%s_patches_%04d.ply", o.name.c_str(),
                                                       p.first)).string(),
                         o.grid.cubesMesh(p.second));
    }
}

} // namespace detail

Ptr<CloneSet> CloneSet::load(const String& path)
{
    using namespace detail;
    FileStorage fs;
    try
    {
        fs.open(path, FileStorage::READ);
    }
    catch (const cv::Exception& e)
    {
        CV_Error(Error::StsParseError, path + ": cannot parse: " + e.msg);
    }
    if (!fs.isOpened())
        CV_Error(Error::StsObjectNotFound, path + ": cannot open clones file");
    if ((String)fs["format"] != "augocc_clones")
        CV_Error(Error::StsParseError, path + ": key 'format' is not 'augocc_clones'");
    Ptr<CloneSetImpl> set = makePtr<CloneSetImpl>();
    const String rule = (String)fs["patch_rule"];
    set->patchRule = rule == "bracketing" ? CloneBuilder::PATCH_BRACKETING
                                          : CloneBuilder::PATCH_NEAREST;
    FileNode objs = fs["objects"];
    if (!objs.isSeq())
        CV_Error(Error::StsParseError, path + ": key 'objects' must be a sequence");
    for (FileNodeIterator it = objs.begin(); it != objs.end(); ++it)
    {
        FileNode n = *it;
        ObjectClone o;
        n["name"] >> o.name;
        const String where = path + ": object '" + o.name + "'";
        if (o.name.empty())
            CV_Error(Error::StsParseError, path + ": an object has no 'name'");
        Mat dims, R, origin, centre;
        n["dims"] >> dims;
        n["R_box"] >> R;
        n["origin"] >> origin;
        n["centre"] >> centre;
        double h = 0;
        n["voxel_size"] >> h;
        if (dims.total() != 3 || R.rows != 3 || R.cols != 3 || origin.total() != 3 ||
            centre.total() != 3 || !(h > 0))
            CV_Error(Error::StsParseError, where + ": missing or malformed dims, R_box, origin, "
                     "centre or voxel_size");
        dims.convertTo(dims, CV_32S);
        R.convertTo(R, CV_64F);
        origin.convertTo(origin, CV_64F);
        centre.convertTo(centre, CV_64F);
        const Vec3i d(dims.ptr<int>()[0], dims.ptr<int>()[1], dims.ptr<int>()[2]);
        if (d[0] <= 0 || d[1] <= 0 || d[2] <= 0 || std::max(d[0], std::max(d[1], d[2])) > kMaxGridDim)
            CV_Error(Error::StsParseError, where + ": bad grid dims");
        o.grid.dims = d;
        o.grid.Rbox = Matx33d((double*)R.ptr<double>());
        o.grid.origin = Vec3d(origin.ptr<double>());
        o.grid.h = h;
        o.centre = Vec3d(centre.ptr<double>());
        decodeGrid(readBlob(n["voxels"], where + " voxels"), d[0], d[1] * d[2], o.grid.data,
                   where + " voxels");
        FileNode kfs = n["key_frames"];
        for (FileNodeIterator k = kfs.begin(); k != kfs.end(); ++k)
        {
            int frame = -1;
            (*k)["frame"] >> frame;
            const String kw = where + cv::format(" key frame %d", frame);
            const std::vector<uchar> png = readBlob((*k)["mask_png"], kw + " mask_png");
            Mat mask = png.empty() ? Mat() : cv::imdecode(png, IMREAD_GRAYSCALE);
            if (frame < 0 || mask.empty())
                CV_Error(Error::StsParseError, kw + ": no frame index or no readable mask");
            o.masks[frame] = mask > 127;
            const std::vector<uchar> pv = readBlob((*k)["patches"], kw + " patches");
            size_t pos = 0;
            const uint64_t count = getVarint(pv, pos, kw + " patches");
            if (count > (uint64_t)o.grid.total())
                CV_Error(Error::StsParseError, kw + ": corrupt patches");
            std::vector<uint32_t> p((size_t)count);
            uint64_t last = 0;
            for (size_t q = 0; q < p.size(); q++)
            {
                last += getVarint(pv, pos, kw + " patches");
                int i, j, kk;
                unpackVoxel((uint32_t)last, i, j, kk);
                if (last > 0xffffffffULL || !o.grid.inside(i, j, kk))
                    CV_Error(Error::StsParseError, kw + ": a patch voxel is off the grid");
                p[q] = (uint32_t)last;
            }
            o.patches[frame] = p;
        }
        o.surface = o.grid.surface();
        set->objects[o.name] = std::move(o);
    }
    return set;
}

void renderMattes(const CloneSet& clones, const Reconstruction& rec, ObjectMasks& mattes,
                  std::map<String, std::map<int, Mat> >* depth)
{
    const std::vector<String> names = clones.objectNames();
    const int nc = (int)rec.cameras.size();
    if (rec.imageSize.width <= 0 || rec.imageSize.height <= 0)
        CV_Error(Error::StsBadSize, "renderMattes: reconstruction has no image size");
    std::vector<std::vector<Mat> > m(names.size(), std::vector<Mat>(nc)), d = m;
    parallel_for_(Range(0, nc), [&](const Range& r) {
        for (int c = r.start; c < r.end; c++)
            for (size_t o = 0; o < names.size(); o++)
            {
                if (depth)
                    clones.render(names[o], rec.cameras[c].frame, rec.cameras[c], rec.imageSize,
                                  m[o][c], d[o][c]);
                else
                    clones.render(names[o], rec.cameras[c].frame, rec.cameras[c], rec.imageSize,
                                  m[o][c]);
            }
    });
    mattes.clear();
    if (depth)
        depth->clear();
    for (size_t o = 0; o < names.size(); o++)
        for (int c = 0; c < nc; c++)
        {
            mattes[names[o]][rec.cameras[c].frame] = m[o][c];
            if (depth)
                (*depth)[names[o]][rec.cameras[c].frame] = d[o][c];
        }
}

void writeMattes(const String& dir, const CloneSet& clones, const Reconstruction& rec,
                 const String& depthDir)
{
    ObjectMasks mattes;
    std::map<String, std::map<int, Mat> > depth;
    renderMattes(clones, rec, mattes, depthDir.empty() ? nullptr : &depth);
    if (!depthDir.empty())
    {
        namespace fsys = std::filesystem;
        fsys::path target(depthDir);
        if (target.has_parent_path())
            detail::createDirectories(target.parent_path().string());
        writeAtomically(depthDir, [&](const String& tmp) {
            detail::createDirectories(tmp, depthDir);
            for (const auto& o : depth)
            {
                const fsys::path od = fsys::path(tmp) / o.first;
                detail::createDirectories(od.string(), (target / o.first).string());
                for (const auto& f : o.second)
                {
                    const String name = cv::format("%04d.tiff", f.first);
                    detail::writeImageFile((od / name).string(), f.second,
                                           (target / o.first / name).string());
                }
            }
        });
    }
    writeMasks(dir, mattes);
}

} // namespace augocc
} // namespace cv
