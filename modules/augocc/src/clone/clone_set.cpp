// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// CloneSet: rendering (matte + depth), file I/O, PLY export and the mattes folder.

#include "precomp.hpp"
#include <atomic>
#include "atomic_write.hpp"
#include "clone/clone_set.hpp"
#include "clone/clone_codec.hpp"
#include "input_limits.hpp"
#include "io_internal.hpp"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

namespace cv {
namespace augocc {

CloneSet::~CloneSet() {}

bool CloneSet::isPartial() const
{
    return false;
}

namespace detail {

namespace fsys = std::filesystem;

// ---------------------------------------------------------------------------------------------
// CloneSetImpl

uint64 CloneSetImpl::nextVersion()
{
    static std::atomic<uint64> counter(0);
    return ++counter;
}

const ObjectClone& CloneSetImpl::get(const String& object) const
{
    auto it = objects_.find(object);
    if (it == objects_.end())
        CV_Error(Error::StsObjectNotFound, "clones: no object '" + object + "'");
    return it->second;
}

ObjectClone& CloneSetImpl::get(const String& object)
{
    version_ = nextVersion();
    auto it = objects_.find(object);
    if (it == objects_.end())
        CV_Error(Error::StsObjectNotFound, "clones: no object '" + object + "'");
    return it->second;
}

void CloneSetImpl::insert(ObjectClone&& clone)
{
    CV_Assert(!clone.name.empty() && !objects_.count(clone.name));
    const String name = clone.name;
    version_ = nextVersion();
    objects_.emplace(name, std::move(clone));
}

void checkComplete(const CloneSet& clones, const char* who)
{
    if (clones.isPartial())
    {
        String names;
        for (const String& n : clones.objectNames())
            names += (names.empty() ? "'" : ", '") + n + "'";
        CV_Error(Error::StsBadArg, cv::format("%s: a partial clone set (objects %s, made by "
                 "CloneBuilder::buildPart): merge the parts first (CloneBuilder::mergeParts, "
                 "augocc clone --merge)", who, names.c_str()));
    }
}

ObjectClone& CloneSetImpl::add(const String& object)
{
    version_ = nextVersion();
    ObjectClone& o = objects_[object];
    o.name = object;
    return o;
}

std::vector<String> CloneSetImpl::objectNames() const
{
    std::vector<String> names;
    for (const auto& o : objects_)
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
    if (camera.hasDistortion())
    {
        // Drawn in the lens's ideal pinhole view and warped into the frame: the matte by its
        // coverage (bilinear, half a pixel), the depth by the nearest ideal pixel.
        Ptr<const LensView> view = LensView::get(camera, imageSize);
        const Camera ideal = view->idealCamera(camera);
        Mat m, d;
        render(object, frame, ideal, view->idealSize(), m, depth.needed() ? d : noArray());
        if (matte.needed())
        {
            Mat w;
            view->toFrame(m, w, INTER_LINEAR, Scalar(0));
            compare(w, 127, matte, CMP_GT);
        }
        if (depth.needed())
            view->toFrame(d, depth, INTER_NEAREST,
                          Scalar(std::numeric_limits<float>::infinity()));
        return;
    }
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
    if (!depth.needed())
    {
        // The matte alone (`augocc matte`, the mattes of a composite): coverage, no depth.
        if (matte.needed())
        {
            matte.create(imageSize, CV_8U);
            Mat m = matte.getMat();
            renderCoverage(o.grid, proj, lists, m);
        }
        return;
    }
    // Rendered straight into the caller's depth map; the matte only over the grid's bounds.
    depth.create(imageSize, CV_32F);
    Mat zmin = depth.getMat();
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
        // A partial set has a format of its own: readers of complete clones files (this one's
        // load() and older augocc's) refuse it instead of rendering unfinished clones.
        fs << "format" << (partial ? "augocc_clones_part" : "augocc_clones");
        fs << "version" << 1;
        fs << "patch_rule" << (patchRule == CloneBuilder::PATCH_BRACKETING ? "bracketing"
                                                                              : "nearest");
        if (partial)
        {
            fs << "part_all_objects" << "[";
            for (const String& n : part.allObjects)
                fs << n;
            fs << "]";
            fs << "part_params" << part.params;
            fs << "part_reconstruction" << part.reconstruction;
            fs << "part_masks" << part.masks;
            fs << "part_tracks" << part.tracks;
        }
        fs << "objects" << "[";
        for (const auto& it : objects_)
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
    for (const auto& it : objects_)
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
    return detail::loadCloneSet(path, false);
}

Ptr<CloneSet> CloneSet::loadPart(const String& path)
{
    return detail::loadCloneSet(path, true);
}

namespace detail {

namespace {

// The partial file's keys (CloneSetImpl::save) into set->part.
void readPartInfo(const FileStorage& fs, const String& path, CloneSetImpl& set)
{
    auto text = [&](const char* key) {
        const FileNode n = fs[key];
        if (!n.isString() || n.string().empty())
            CV_Error(Error::StsParseError, path + cv::format(": key '%s' (of a partial clones "
                     "file) is missing or not a string", key));
        return n.string();
    };
    const FileNode all = fs["part_all_objects"];
    if (!all.isSeq() || all.size() == 0)
        CV_Error(Error::StsParseError, path + ": key 'part_all_objects' (of a partial clones "
                 "file) must be a non-empty sequence of object names");
    for (const FileNode& n : all)
    {
        if (!n.isString() || n.string().empty())
            CV_Error(Error::StsParseError, path + ": key 'part_all_objects' holds a value that is "
                     "not an object name");
        set.part.allObjects.push_back(n.string());
    }
    set.part.params = text("part_params");
    set.part.reconstruction = text("part_reconstruction");
    set.part.masks = text("part_masks");
    set.part.tracks = text("part_tracks");
    set.part.source = path;
    set.partial = true;
}

} // namespace

Ptr<CloneSetImpl> loadCloneSet(const String& path, bool part)
{
    FileStorage fs = openFileStorageForRead(path, "clones file");
    const String format = fs["format"].isString() ? (String)fs["format"] : String();
    if (format == "augocc_clones_part" && !part)
    {
        String names;
        const FileNode objs = fs["objects"];
        if (objs.isSeq())
            for (const FileNode& n : objs)
                if (n.isMap() && n["name"].isString())
                    names += (names.empty() ? "'" : ", '") + n["name"].string() + "'";
        CV_Error(Error::StsBadArg, path + ": a partial clones file (objects " + names +
                 ", written by augocc clone --object): merge the parts into a clones file first "
                 "(augocc clone --merge)");
    }
    if (format == "augocc_clones" && part)
        CV_Error(Error::StsBadArg, path + ": a complete clones file, not a part written by "
                 "augocc clone --object (CloneBuilder::buildPart)");
    if (format != "augocc_clones" && format != "augocc_clones_part")
        CV_Error(Error::StsParseError, path + ": key 'format' is not 'augocc_clones'");
    if (!fs["version"].isInt() || (int)fs["version"] != 1)
        CV_Error(Error::StsParseError, path + ": key 'version' must be 1 (this augocc reads "
                 "version 1 clones files)");
    Ptr<CloneSetImpl> set = makePtr<CloneSetImpl>();
    if (part)
        readPartInfo(fs, path, *set);
    const String rule = fs["patch_rule"].isString() ? (String)fs["patch_rule"] : String();
    if (rule != "bracketing" && rule != "nearest")
        CV_Error(Error::StsParseError, path + ": key 'patch_rule' must be 'bracketing' or "
                 "'nearest'");
    set->patchRule = rule == "bracketing" ? CloneBuilder::PATCH_BRACKETING
                                          : CloneBuilder::PATCH_NEAREST;
    FileNode objs = fs["objects"];
    if (!objs.isSeq())
        CV_Error(Error::StsParseError, path + ": key 'objects' must be a sequence");
    Size maskSize;
    for (FileNodeIterator it = objs.begin(); it != objs.end(); ++it)
    {
        FileNode n = *it;
        if (!n.isMap())
            CV_Error(Error::StsParseError, path + ": an element of 'objects' is not a map");
        ObjectClone o;
        if (!n["name"].isString())
            CV_Error(Error::StsParseError, path + ": an object has no 'name'");
        n["name"] >> o.name;
        const String where = path + ": object '" + o.name + "'";
        if (o.name.empty())
            CV_Error(Error::StsParseError, path + ": an object has no 'name'");
        if (set->objects().count(o.name))
            CV_Error(Error::StsParseError, where + ": a second object of that name");
        const Mat dims = readStorageMat(n["dims"], where, "dims");
        Mat R = readStorageMat(n["R_box"], where, "R_box");
        Mat origin = readStorageMat(n["origin"], where, "origin");
        Mat centre = readStorageMat(n["centre"], where, "centre");
        if (!n["voxel_size"].isReal() && !n["voxel_size"].isInt())
            CV_Error(Error::StsParseError, where + ": key 'voxel_size' must be a number");
        const double h = (double)n["voxel_size"];
        if (dims.total() != 3 || dims.channels() != 1 || R.rows != 3 || R.cols != 3 ||
            R.channels() != 1 || origin.total() != 3 || origin.channels() != 1 ||
            centre.total() != 3 || centre.channels() != 1 || !(h > 0) ||
            !(h <= kMaxSceneCoordinate))
            CV_Error(Error::StsParseError, where + ": missing or malformed dims, R_box, origin, "
                     "centre or voxel_size");
        Mat dimsD;
        dims.convertTo(dimsD, CV_64F);
        for (int k = 0; k < 3; k++)
            if (!(dimsD.ptr<double>()[k] >= 1 && dimsD.ptr<double>()[k] <= kMaxGridDim))
                CV_Error(Error::StsParseError, where + ": bad grid dims");
        Mat dimsI;
        dimsD.convertTo(dimsI, CV_32S);
        R.convertTo(R, CV_64F);
        origin.convertTo(origin, CV_64F);
        centre.convertTo(centre, CV_64F);
        for (int k = 0; k < 9; k++)
            checkMagnitude(R.ptr<double>()[k], 1.0 + 1e-6, where + ": R_box");
        for (int k = 0; k < 3; k++)
        {
            checkMagnitude(origin.ptr<double>()[k], kMaxSceneCoordinate, where + ": origin");
            checkMagnitude(centre.ptr<double>()[k], kMaxSceneCoordinate, where + ": centre");
        }
        const Mat& dims_ = dimsI;
        const Vec3i d(dims_.ptr<int>()[0], dims_.ptr<int>()[1], dims_.ptr<int>()[2]);
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
            if ((*k).isMap() && (*k)["frame"].isInt())
                (*k)["frame"] >> frame;
            const String kw = where + cv::format(" key frame %d", frame);
            if (frame < 0)
                CV_Error(Error::StsParseError, kw + ": no frame index");
            if (o.masks.count(frame))
                CV_Error(Error::StsParseError, kw + ": a second key frame of that index");
            const std::vector<uchar> png = readBlob((*k)["mask_png"], kw + " mask_png");
            Mat mask = decodeImageChecked(png, IMREAD_GRAYSCALE, kw + " mask_png");
            if (mask.empty())
                CV_Error(Error::StsParseError, kw + ": no readable mask");
            // Every key-frame mask is the frames' size (the reader of the reconstruction checks
            // it against its image_size: CloneSet::checkAgainst).
            if (maskSize.empty())
                maskSize = mask.size();
            else if (mask.size() != maskSize)
                CV_Error(Error::StsBadSize, kw + cv::format(": mask is %dx%d but the file's first "
                         "key-frame mask is %dx%d", mask.cols, mask.rows, maskSize.width,
                         maskSize.height));
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
        set->add(o.name) = std::move(o);
    }
    if (part && set->objects().empty())
        CV_Error(Error::StsParseError, path + ": a partial clones file with no object");
    return set;
}

} // namespace detail

namespace {

//! What renderMattes() and writeMattes() check before any work.
void checkMatteInputs(const CloneSet& clones, const Reconstruction& rec, const char* who)
{
    detail::checkComplete(clones, who);
    if (rec.imageSize.width <= 0 || rec.imageSize.height <= 0)
        CV_Error(Error::StsBadSize, String(who) + ": reconstruction has no image size");
    // A clones file built for other frames: its key-frame silhouettes have another size.
    if (const detail::CloneSetImpl* impl = dynamic_cast<const detail::CloneSetImpl*>(&clones))
        for (const auto& o : impl->objects())
            for (const auto& km : o.second.masks)
                if (km.second.size() != rec.imageSize)
                    CV_Error(Error::StsBadSize, cv::format("clones: object '%s': key frame %d's "
                             "silhouette is %dx%d but the reconstruction's frames are %dx%d (a "
                             "clones file of another video?)", o.first.c_str(), km.first,
                             km.second.cols, km.second.rows, rec.imageSize.width,
                             rec.imageSize.height));
}

/** Renders the mattes (and depth) of cameras [b0, b1) of every object in parallel:
m[o][c - b0]. Each matte depends on its frame alone, so batching changes nothing. */
void renderMatteBatch(const CloneSet& clones, const Reconstruction& rec,
                      const std::vector<String>& names, int b0, int b1, bool withDepth,
                      std::vector<std::vector<Mat> >& m, std::vector<std::vector<Mat> >& d)
{
    m.assign(names.size(), std::vector<Mat>(b1 - b0));
    d.assign(names.size(), std::vector<Mat>(b1 - b0));
    parallel_for_(Range(b0, b1), [&](const Range& r) {
        for (int c = r.start; c < r.end; c++)
            for (size_t o = 0; o < names.size(); o++)
            {
                if (withDepth)
                    clones.render(names[o], rec.cameras[c].frame, rec.cameras[c], rec.imageSize,
                                  m[o][c - b0], d[o][c - b0]);
                else
                    clones.render(names[o], rec.cameras[c].frame, rec.cameras[c], rec.imageSize,
                                  m[o][c - b0]);
            }
    });
}

} // namespace

void renderMattes(const CloneSet& clones, const Reconstruction& rec, ObjectMasks& mattes,
                  std::map<String, std::map<int, Mat> >* depth, const ProgressCallback& progress)
{
    checkMatteInputs(clones, rec, "renderMattes");
    const std::vector<String> names = clones.objectNames();
    const int nc = (int)rec.cameras.size();
    mattes.clear();
    if (depth)
        depth->clear();
    // Batches of frames, each in parallel, progress reported between them (from this thread).
    const int batch = progress ? std::max(8, 4 * cv::getNumThreads()) : std::max(nc, 1);
    detail::reportProgress(progress, "matte", "", 0, nc, "frames");
    std::vector<std::vector<Mat> > m, d;
    for (int b0 = 0; b0 < nc; b0 += batch)
    {
        const int b1 = std::min(nc, b0 + batch);
        renderMatteBatch(clones, rec, names, b0, b1, depth != nullptr, m, d);
        for (size_t o = 0; o < names.size(); o++)
            for (int c = b0; c < b1; c++)
            {
                mattes[names[o]][rec.cameras[c].frame] = m[o][c - b0];
                if (depth)
                    (*depth)[names[o]][rec.cameras[c].frame] = d[o][c - b0];
            }
        detail::reportProgress(progress, "matte", "", b1, nc, "frames");
    }
}

void writeMattes(const String& dir, const CloneSet& clones, const Reconstruction& rec,
                 const String& depthDir, const ProgressCallback& progress)
{
    namespace fsys = std::filesystem;
    checkMatteInputs(clones, rec, "writeMattes");
    const std::vector<String> names = clones.objectNames();
    for (const String& n : names)
        if (n.empty() || n.find('/') != String::npos)
            CV_Error(Error::StsBadArg, "invalid object name '" + n + "'");
    const int nc = (int)rec.cameras.size();
    const bool withDepth = !depthDir.empty();
    const fsys::path target(dir), depthTarget(depthDir);
    if (target.has_parent_path())
        detail::createDirectories(target.parent_path().string());
    if (withDepth && depthTarget.has_parent_path())
        detail::createDirectories(depthTarget.parent_path().string());
    // Streamed: a batch of frames is rendered in parallel, written, and dropped, so memory does
    // not grow with the shot (a 300-frame 720p shot held 1 GB of mattes before). Each folder is
    // written under a temporary name and renamed when complete (the mattes first, then the depth).
    auto writeAll = [&](const String& tmp, const String& depthTmp) {
        detail::createDirectories(tmp, dir);
        for (const String& n : names)
            detail::createDirectories((fsys::path(tmp) / n).string(), (target / n).string());
        if (withDepth)
        {
            detail::createDirectories(depthTmp, depthDir);
            for (const String& n : names)
                detail::createDirectories((fsys::path(depthTmp) / n).string(),
                                          (depthTarget / n).string());
        }
        const int batch = std::max(8, 4 * cv::getNumThreads());
        detail::reportProgress(progress, "matte", "", 0, nc, "frames");
        std::vector<std::vector<Mat> > m, d;
        for (int b0 = 0; b0 < nc; b0 += batch)
        {
            const int b1 = std::min(nc, b0 + batch);
            renderMatteBatch(clones, rec, names, b0, b1, withDepth, m, d);
            for (size_t o = 0; o < names.size(); o++)
                for (int c = b0; c < b1; c++)
                {
                    const int f = rec.cameras[c].frame;
                    const String png = cv::format("%04d.png", f);
                    detail::writeImageFile((fsys::path(tmp) / names[o] / png).string(),
                                           m[o][c - b0], (target / names[o] / png).string());
                    if (withDepth)
                    {
                        const String tiff = cv::format("%04d.tiff", f);
                        detail::writeImageFile(
                            (fsys::path(depthTmp) / names[o] / tiff).string(), d[o][c - b0],
                            (depthTarget / names[o] / tiff).string());
                    }
                }
            detail::reportProgress(progress, "matte", "", b1, nc, "frames");
        }
    };
    if (withDepth)
        writeAtomically(depthDir, [&](const String& depthTmp) {
            writeAtomically(dir, [&](const String& tmp) { writeAll(tmp, depthTmp); });
        });
    else
        writeAtomically(dir, [&](const String& tmp) { writeAll(tmp, String()); });
}

} // namespace augocc
} // namespace cv
