// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Sequence compositing with all-or-nothing outputs, `augocc run` and `augocc demo`.

#include "precomp.hpp"

#include "atomic_write.hpp"
#include "video_out.hpp"
#include "run_manifest.hpp"

#include <filesystem>
#include <future>
#include <set>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

// A temporary sibling of `path` with the same extension (video writers pick the container from
// it), renamed onto `path` by commit(); removed on destruction otherwise.
class PendingOutput
{
public:
    explicit PendingOutput(const String& path) : path_(path)
    {
        fs::path p(path);
        if (p.has_parent_path() && !fs::exists(p.parent_path()))
        {
            // Folders made here go again on failure (the first one made is enough to remove).
            fs::path top = p.parent_path();
            while (top.has_parent_path() && top.parent_path() != top &&
                   !top.parent_path().empty() && !fs::exists(top.parent_path()))
                top = top.parent_path();
            madeDir_ = top.string();
            detail::createDirectories(p.parent_path().string());
        }
        detail::sweepStaleTemporaries(path);
        tmp_ = detail::tmpNameFor(path);
    }
    ~PendingOutput()
    {
        if (!committed_)
        {
            std::error_code ec;
            fs::remove_all(tmp_, ec);
            // Empty folders only, from the output's up to the outermost one made here.
            if (!madeDir_.empty())
                for (fs::path d = fs::path(path_).parent_path(); !d.empty();
                     d = d.parent_path())
                {
                    if (!fs::remove(d, ec) || d == fs::path(madeDir_))
                        break;
                }
        }
    }
    const String& tmp() const { return tmp_; }
    void commit()
    {
        // A folder replaces a folder, a file a file (rename); a file and a folder, not.
        std::error_code ec;
        if (fs::exists(path_) && fs::is_directory(path_) != fs::is_directory(tmp_))
            fs::remove_all(path_, ec);
        detail::commitTemporary(tmp_, path_);
        committed_ = true;
    }

private:
    String path_, tmp_;
    String madeDir_;  // outermost folder created for the output, if any
    bool committed_ = false;
};

// `name` in the temporary folder `tmp` of the output folder `shown` (errors name the latter).
void writeImage(const String& tmp, const String& shown, const String& name, const Mat& img)
{
    detail::writeImageFile((fs::path(tmp) / name).string(), img,
                           (fs::path(shown) / name).string());
}

// Depth range of the 16-bit depth output, fixed for the sequence (first frame, 50% margin).
struct DepthEncoding
{
    double offset = 0, scale = 1;
    bool ready = false;
};

Mat encodeDepth(const Mat& z, DepthEncoding& enc)
{
    if (!enc.ready)
    {
        Mat finite = z < std::numeric_limits<float>::infinity();
        double lo = 0, hi = 1;
        if (cv::countNonZero(finite) > 0)
            cv::minMaxLoc(z, &lo, &hi, nullptr, nullptr, finite);
        const double range = std::max(hi - lo, 1e-9);
        enc.offset = lo - 0.5 * range;
        enc.scale = 65534.0 / (2.0 * range);
        enc.ready = true;
    }
    Mat out(z.size(), CV_16U);
    for (int y = 0; y < z.rows; y++)
    {
        const float* s = z.ptr<float>(y);
        ushort* d = out.ptr<ushort>(y);
        for (int x = 0; x < z.cols; x++)
            d[x] = std::isfinite(s[x])
                       ? (ushort)std::min(65535.0, std::max(1.0, std::round((s[x] - enc.offset) *
                                                                            enc.scale) + 1))
                       : 0;
    }
    return out;
}

} // namespace

int compositeSequence(const String& input, const Reconstruction& rec, const CloneSet& clones,
                      const std::vector<Mesh>& virtualObjects, const String& output,
                      const CompositeOptions& options)
{
    if (output.empty())
        CV_Error(Error::StsBadArg, "no output given");
    // The inputs take printf patterns; an output is a video or a folder (of %04d.png): a
    // pattern here made a folder named after it.
    if (!detail::isVideoPath(output) &&
        fs::path(output).filename().string().find('%') != std::string::npos)
        CV_Error(Error::StsBadArg, output + ": a printf pattern; the composite is written as a "
                 "video (.mp4, .avi, .mkv, .mov, .m4v) or into a folder as %04d.png: give the "
                 "folder");
    Ptr<FrameSource> src = FrameSource::open(input);
    const int count = src->count();
    const int first = options.firstFrame;
    const int end = options.endFrame < 0 ? count : options.endFrame;
    if (first < 0 || first >= end || end > count)
        CV_Error(Error::StsOutOfRange, input + cv::format(": frames %d:%d out of range, the input "
                 "has %d frames (0:%d)", first, end, count, count));
    const String& recName = options.reconstructionName;
    rec.validate(recName);
    if (rec.imageSize != src->size())
        CV_Error(Error::StsBadSize, input + cv::format(": frames are %dx%d but the image_size of ",
                 src->size().width, src->size().height) + recName +
                 cv::format(" is %dx%d: they do not belong together", rec.imageSize.width,
                 rec.imageSize.height));
    if (!rec.cameras.empty() && rec.cameras.back().frame >= count)
        CV_Error(Error::StsBadArg, input + cv::format(": the input has %d frames but ", count) +
                 recName + cv::format(" has a camera for frame %d: they do not belong together",
                 rec.cameras.back().frame));
    for (int f = first; f < end; f++)
        if (rec.findCamera(f) < 0)
            CV_Error(Error::StsBadArg, recName + cv::format(": frame %d has no camera (frames "
                     "%d:%d are to be composited)", f, first, end));

    const bool video = detail::isVideoPath(output);
    PendingOutput out(output);
    std::unique_ptr<PendingOutput> mattesOut, depthOut, layerOut;
    if (!options.mattesDir.empty())
        mattesOut.reset(new PendingOutput(options.mattesDir));
    if (!options.depthDir.empty())
        depthOut.reset(new PendingOutput(options.depthDir));
    if (!options.virtualLayerDir.empty())
        layerOut.reset(new PendingOutput(options.virtualLayerDir));
    if (!video)
        detail::createDirectories(out.tmp(), output);
    const std::vector<String> objects = clones.objectNames();
    if (mattesOut)
        for (const String& o : objects)
            detail::createDirectories((fs::path(mattesOut->tmp()) / o).string(),
                                      options.mattesDir);
    if (depthOut)
        detail::createDirectories(depthOut->tmp(), options.depthDir);
    if (layerOut)
        detail::createDirectories(layerOut->tmp(), options.virtualLayerDir);

    Compositor::Params cp;
    cp.supersample = options.supersample;
    cp.antialiasVirtual = options.antialiasVirtual;
    if (options.lightFromGround || options.sun.enabled())
        cp.ground = estimateGround(rec);
    if (options.lightFromGround)
        cp.lightRotation = cp.ground.rotation();
    cp.sun = options.sun;
    Ptr<Compositor> comp = Compositor::create(cp);
    comp->setVirtualObjects(virtualObjects);
    VideoWriter writer;
    if (video)
        writer = detail::openVideo(out.tmp(), output,
                                   options.fps > 0 ? options.fps : src->fps(), src->size());
    DepthEncoding enc;
    src->seek(first);
    Mat frame, result, layer, depth, matte;
    /* Decoding the next frame and encoding the last result overlap the compositing (one task
    each beside it, on two buffers each): the compositor, whose OpenGL context belongs to this
    thread, left a core mostly idle while the codecs ran (1920x1080 under the sun: 1.23 cores
    busy on average). Same frames, same order: the same output. The tasks are declared after
    what they use, so that an exception here waits for them before that goes. */
    Mat nextFrame, writing;
    auto readInto = [&](Mat* m) { return src->read(*m); };
    std::future<bool> reading = std::async(std::launch::async, readInto, &nextFrame);
    std::future<void> written;
    for (int f = first; f < end; f++)
    {
        if (!reading.get())
            CV_Error(Error::StsParseError, input + cv::format(": cannot decode frame %d (the "
                     "input ends early or is corrupt)", f));
        std::swap(frame, nextFrame);
        if (f + 1 < end)
            reading = std::async(std::launch::async, readInto, &nextFrame);
        const Camera& cam = rec.camera(f);
        comp->composite(frame, f, cam, clones, result,
                        layerOut ? _OutputArray(layer) : _OutputArray(noArray()),
                        depthOut ? _OutputArray(depth) : _OutputArray(noArray()));
        const String name = cv::format("%04d.png", f);
        if (written.valid())
            written.get();  // the last result is written (and its buffer free)
        std::swap(result, writing);
        written = std::async(std::launch::async, [&, name]() {
            if (video)
                writer.write(writing);
            else
                writeImage(out.tmp(), output, name, writing);
        });
        if (layerOut)
            writeImage(layerOut->tmp(), options.virtualLayerDir, name, layer);
        if (depthOut)
            writeImage(depthOut->tmp(), options.depthDir, name, encodeDepth(depth, enc));
        if (mattesOut)
            for (const String& o : objects)
            {
                clones.render(o, f, cam, rec.imageSize, matte);
                writeImage((fs::path(mattesOut->tmp()) / o).string(),
                           (fs::path(options.mattesDir) / o).string(), name, matte);
            }
        detail::reportProgress(options.progress, "composite", "", f - first + 1, end - first,
                               "frames");
    }
    if (written.valid())
        written.get();
    if (video)
    {
        writer.release();
        detail::checkVideoFile(out.tmp(), end - first, output);
    }
    if (depthOut)
        detail::writeStorageFile((fs::path(depthOut->tmp()) / "depth.yml").string(),
                                 [&](FileStorage& fsd) {
                                     fsd << "description"
                                         << "z = (value - 1) / scale + offset; value 0 = nothing";
                                     fsd << "scale" << enc.scale << "offset" << enc.offset;
                                 },
                                 (fs::path(options.depthDir) / "depth.yml").string());
    src->checkUnchanged();  // a composite of two versions of the footage is not kept
    out.commit();
    if (mattesOut)
        mattesOut->commit();
    if (depthOut)
        depthOut->commit();
    if (layerOut)
        layerOut->commit();
    return end - first;
}

// ---------------------------------------------------------------------------------------------
// augocc run

namespace {

class StageTimer
{
public:
    explicit StageTimer(RunResult& r) : r_(r) {}
    void start() { t0_ = cv::getTickCount(); }
    void stop(const String& stage)
    {
        r_.stageSeconds.push_back({stage, (cv::getTickCount() - t0_) / cv::getTickFrequency()});
    }

private:
    RunResult& r_;
    int64 t0_ = 0;
};

// Frames [first, end) of a source as a source of their own (frame 0 = `first`): what the tracker
// reads for `run --frames a:b`.
class FrameRangeSource CV_FINAL : public FrameSource
{
public:
    FrameRangeSource(const Ptr<FrameSource>& src, int first, int end)
        : src_(src), first_(first), end_(end)
    {
        src_->seek(first_);
    }
    int count() const CV_OVERRIDE { return end_ - first_; }
    Size size() const CV_OVERRIDE { return src_->size(); }
    double fps() const CV_OVERRIDE { return src_->fps(); }
    bool read(OutputArray frame) CV_OVERRIDE
    {
        return src_->position() < end_ && src_->read(frame);
    }
    int position() const CV_OVERRIDE { return src_->position() - first_; }
    void seek(int index) CV_OVERRIDE { src_->seek(first_ + index); }

private:
    Ptr<FrameSource> src_;
    int first_, end_;
};

} // namespace

RunResult runPipeline(const RunOptions& o)
{
    if (o.outDir.empty())
        CV_Error(Error::StsBadArg, "no output folder given");
    RunResult r;
    StageTimer timer(r);
    // Bad inputs first, before any work or output: the options, the input, the masks, the
    // scene, the calibration.
    if (o.model != "auto" && o.model != "scaled_orthographic" && o.model != "perspective")
        CV_Error(Error::StsBadArg, "--model " + o.model + ": expected scaled_orthographic, "
                 "perspective or auto");
    if (!(o.voxelPixels > 0) || !std::isfinite(o.voxelPixels))
        CV_Error(Error::StsBadArg, cv::format("--voxel-pixels %g: must be positive",
                                              o.voxelPixels));
    CloneBuilder::Params cp;
    cp.voxelPixels = o.voxelPixels;
    if (!o.freeSpace)
        cp.freeSpace.minViews = 0;
    cp.progress = o.progress;
    Ptr<CloneBuilder> builder = CloneBuilder::create(cp);
    Ptr<FrameSource> src = FrameSource::open(o.input);
    ObjectMasks masks = readMasks(o.masksDir, src->size());
    if (masks.empty())
        CV_Error(Error::StsBadArg, o.masksDir + ": no object folder with masks");
    const int frameCount = src->count();
    // The frames processed, [first, end): input frame numbers throughout.
    const int first = o.firstFrame, end = o.endFrame < 0 ? frameCount : o.endFrame;
    const String framesFlag = cv::format("--frames %d:%d", first, end);
    if (first < 0 || end > frameCount || first >= end)
        CV_Error(Error::StsOutOfRange, framesFlag + ": outside " + o.input + cv::format(", which "
                 "has frames 0:%d (half-open: frames a..b-1)", frameCount));
    if (end - first < 3)
        CV_Error(Error::StsOutOfRange, framesFlag + cv::format(": %d frame(s); the camera "
                 "recovery needs at least 3", end - first));
    for (const auto& obj : masks)
    {
        if (obj.second.empty())
            CV_Error(Error::StsBadArg, (fs::path(o.masksDir) / obj.first).string() +
                     ": no key-frame mask");
        for (const auto& fm : obj.second)
        {
            const String file = (fs::path(o.masksDir) / obj.first /
                                 cv::format("%04d.png", fm.first)).string();
            if (fm.first >= frameCount)
                CV_Error(Error::StsBadArg, file + cv::format(": a mask for frame %d but %s has "
                         "%d frames: they do not belong together", fm.first, o.input.c_str(),
                         frameCount));
            // CloneBuilder's own checks (after track and sfm), here before them.
            const int n = countNonZero(fm.second > 127);
            if (n == 0)
                CV_Error(Error::StsBadArg, file + ": the silhouette is empty (no pixel above "
                         "127): draw the object or remove the file");
            if (n == (int)fm.second.total())
                CV_Error(Error::StsBadArg, file + ": the silhouette covers the whole frame");
        }
    }
    // Key frames outside the frames processed have no camera in this run: left out, listed in
    // the result; an object left without any is an error (it would get no clone).
    for (auto& obj : masks)
    {
        for (auto it = obj.second.begin(); it != obj.second.end();)
        {
            if (it->first >= first && it->first < end)
            {
                ++it;
                continue;
            }
            r.ignoredMasks.push_back((fs::path(o.masksDir) / obj.first /
                                      cv::format("%04d.png", it->first)).string());
            it = obj.second.erase(it);
        }
        if (obj.second.empty())
            CV_Error(Error::StsBadArg, framesFlag + ": " + (fs::path(o.masksDir) /
                     obj.first).string() + " has no key-frame mask in these frames (frames "
                     "a..b-1): widen the range or move the object's folder out of the masks");
    }
    VirtualScene scene;
    if (!o.scenePath.empty())
    {
        scene = readScene(o.scenePath);
        for (const SceneObject& so : scene.objects)
            if (so.placement != SceneObject::PLACE_ABSOLUTE && !masks.count(so.anchor))
                CV_Error(Error::StsBadArg, o.scenePath + ": object '" + so.name + "' is placed "
                         "against '" + so.anchor + "', which has no masks in " + o.masksDir);
    }
    SfmOptions sfm;
    if (!o.calibrationPath.empty())
        sfm.calibration = readCalibration(o.calibrationPath, src->size());
    sfm.model = o.model;
    sfm.focal = o.focal;
    sfm.refineIntrinsics = o.refineIntrinsics;
    sfm.selfCalibrate = o.selfCalibrate;
    sfm.progress = o.progress;
    // An output folder made here and still empty when a stage fails goes again. Intermediate
    // files already written stay: each is complete (written atomically) and re-runs by hand.
    struct EmptyDirGuard
    {
        String dir;
        ~EmptyDirGuard()
        {
            std::error_code ec;
            if (!dir.empty())
                fs::remove(dir, ec);
        }
    } guard;
    if (!fs::exists(o.outDir))
        guard.dir = o.outDir;
    detail::createDirectories(o.outDir);
    const fs::path dir(o.outDir);
    const String tracksPath = (dir / "tracks.yml").string();
    const String recPath = (dir / "reconstruction.yml").string();
    const String clonesPath = (dir / "clones.yml.gz").string();
    const String mattesPath = (dir / "mattes").string();
    const String compositePath = (dir / "composite.mp4").string();

    // Resume: each stage's manifest names what its output was made from; the next stage's
    // names that output's signature, so a stage run again invalidates the ones after it.
    detail::StageManifest mTrack, mSfm, mClone, mMatte, mComposite;
    // Every frame file: once (the quick one is taken again as each stage ends, which finds
    // frames replaced while a stage read them).
    const String inputQuick = detail::quickSignature(o.input);
    const String inputSignature = detail::pathSignature(o.input);
    mTrack.stage = "track";
    mTrack.signedInput("input", inputSignature, o.input, inputQuick);
    mTrack.option("tracker", "default");
    // The range: every stage after track depends on it through tracks.yml; sfm and clone name
    // it too (the frame shift of the cameras, the key frames left out).
    const String framesOption = cv::format("%d:%d", first, end);
    mTrack.option("frames", framesOption);
    const bool trackReused = !o.force && detail::manifestMatches(mTrack, tracksPath);
    bool tracksLoaded = false;
    auto loadTracks = [&]() {
        if (!tracksLoaded)
            r.tracks = readTracks(tracksPath);
        tracksLoaded = true;
    };

    timer.start();
    if (trackReused)
        r.reused.push_back("track");
    else
    {
        detail::removeManifest(tracksPath);
        FeatureTracker::Params tp;
        tp.progress = o.progress;
        Tracks local;
        FeatureTracker::create(tp)->track(makePtr<FrameRangeSource>(src, first, end), local);
        tracksLoaded = true;
        // A video cut short or corrupt mid-stream ends early: found here, before anything is
        // written, not later as cameras missing for the masks' frames.
        if (local.frames() != end - first)
            CV_Error(Error::StsParseError, o.input + cv::format(": %d frames decoded of the %d "
                     "the input declares (cut short or corrupt)", first + local.frames(),
                     frameCount));
        // Input frame numbers (the contract): frames before `first` are empty.
        r.tracks = first > 0 ? local.shiftedFrames(first, end) : local;
        writeTracks(tracksPath, r.tracks);
        detail::writeManifest(mTrack, tracksPath);
        r.tracks = readTracks(tracksPath);  // what a resumed run starts from (see sfm below)
    }
    timer.stop("track");

    mSfm.stage = "sfm";
    mSfm.input("tracks", tracksPath);
    mSfm.input("calibration", o.calibrationPath);
    mSfm.option("model", o.model);
    mSfm.option("focal", o.focal);
    mSfm.option("refine_intrinsics", o.refineIntrinsics ? "1" : "0");
    mSfm.option("self_calibrate", o.selfCalibrate ? "1" : "0");
    mSfm.option("frames", framesOption);
    timer.start();
    if (!o.force && detail::manifestMatches(mSfm, recPath))
    {
        r.reconstruction = readReconstruction(recPath);
        r.reused.push_back("sfm");
    }
    else
    {
        detail::removeManifest(recPath);
        loadTracks();
        r.reconstruction = recoverCameras(r.tracks, sfm, &r.sfm);
        writeReconstruction(recPath, r.reconstruction);
        detail::writeManifest(mSfm, recPath);
        // The later stages start from the file, as a resumed run does: the reconstruction in
        // memory is not the file's to the last bit (a killed and resumed run's composite under
        // a sun came out 33-38 dB PSNR from the uninterrupted run's, its clones rebuilt from
        // the file).
        r.reconstruction = readReconstruction(recPath);
    }
    timer.stop("sfm");

    mClone.stage = "clone";
    mClone.input("reconstruction", recPath);
    mClone.input("tracks", tracksPath);
    mClone.input("masks", o.masksDir);
    if (o.photoRefine)
        mClone.signedInput("input", inputSignature, o.input, inputQuick);
    else
        mClone.signedInput("input", "unused");
    mClone.option("voxel_pixels", o.voxelPixels);
    mClone.option("free_space", o.freeSpace ? "1" : "0");
    mClone.option("photo_refine", o.photoRefine ? "1" : "0");
    mClone.option("frames", framesOption);
    timer.start();
    if (!o.force && detail::manifestMatches(mClone, clonesPath))
    {
        r.clones = CloneSet::load(clonesPath);
        r.reused.push_back("clone");
    }
    else
    {
        detail::removeManifest(clonesPath);
        loadTracks();
        r.clones = builder->build(r.reconstruction, masks, &r.tracks);
        if (o.photoRefine)
        {
            // Only the frames refine() compares are held (photoFrames(): at most
            // PhotoParams::maxViews); the others stay empty, so memory does not grow with the shot.
            const std::vector<int> used = builder->photoFrames(r.reconstruction);
            std::vector<Mat> frames(end);
            src->seek(first);
            size_t next = 0;
            for (int f = first; f < end && next < used.size(); f++)
            {
                Mat img;
                if (!src->read(img))
                    CV_Error(Error::StsParseError, o.input + cv::format(": frame %d cannot be "
                             "read again for the photo-consistency carving", f));
                if (f == used[next])
                {
                    frames[f] = img;
                    next++;
                }
            }
            builder->refine(*r.clones, r.reconstruction, frames);
        }
        r.clones->save(clonesPath);
        detail::writeManifest(mClone, clonesPath);
    }
    timer.stop("clone");

    mMatte.stage = "matte";
    mMatte.input("clones", clonesPath);
    mMatte.input("reconstruction", recPath);
    timer.start();
    if (!o.force && detail::manifestMatches(mMatte, mattesPath))
        r.reused.push_back("matte");
    else
    {
        detail::removeManifest(mattesPath);
        writeMattes(mattesPath, *r.clones, r.reconstruction, String(), o.progress);
        detail::writeManifest(mMatte, mattesPath);
    }
    timer.stop("matte");

    if (!o.scenePath.empty())
    {
        mComposite.stage = "composite";
        mComposite.input("scene", o.scenePath);
        // The meshes' folders: the mesh files and what they refer to (materials, textures).
        std::set<String> meshDirs;
        for (const SceneObject& so : scene.objects)
            if (!so.meshFile.empty())
                meshDirs.insert((fs::path(o.scenePath).parent_path() / so.meshFile)
                                    .parent_path().string());
        for (const String& d : meshDirs)
        {
            // Files of the folder only (not below: it may hold this run's outputs).
            std::error_code ec;
            std::vector<String> files;
            for (const auto& e : fs::directory_iterator(d.empty() ? "." : d, ec))
                if (e.is_regular_file(ec))
                    files.push_back(e.path().string());
            std::sort(files.begin(), files.end());
            for (const String& f : files)
                mComposite.input("mesh folder file " + f, f);
        }
        mComposite.signedInput("input", inputSignature, o.input, inputQuick);
        mComposite.input("clones", clonesPath);
        mComposite.input("reconstruction", recPath);
        mComposite.option("supersample", o.supersample);
        mComposite.option("antialias_virtual", o.antialiasVirtual ? "1" : "0");
        timer.start();
        r.virtualObjects = placeScene(scene, r.reconstruction, r.clones.get());
        const Sun sun = resolveSun(scene, r.reconstruction);
        mComposite.option("sun", cv::format("%.9g %.9g %.9g %.9g %.9g", sun.direction[0],
                                            sun.direction[1], sun.direction[2], sun.sky,
                                            sun.penumbra));
        r.compositePath = compositePath;
        if (!o.force && detail::manifestMatches(mComposite, compositePath))
            r.reused.push_back("composite");
        else
        {
            detail::removeManifest(compositePath);
            CompositeOptions co;
            co.supersample = o.supersample;
            co.antialiasVirtual = o.antialiasVirtual;
            co.sun = sun;
            co.firstFrame = r.reconstruction.cameras.front().frame;
            co.endFrame = r.reconstruction.cameras.back().frame + 1;
            co.progress = o.progress;
            compositeSequence(o.input, r.reconstruction, *r.clones, r.virtualObjects,
                              r.compositePath, co);
            detail::writeManifest(mComposite, compositePath);
        }
        timer.stop("composite");
    }
    guard.dir.clear();
    return r;
}

// ---------------------------------------------------------------------------------------------
// augocc demo

namespace {

Mat alphaOf(const Mat& bgra)
{
    Mat a;
    cv::extractChannel(bgra, a, 3);
    return a;
}

} // namespace

// The demo's virtual objects after the paper's Fig. 3: a dome behind the front building
// (partly hidden by it, peeking out on its left, in the L-block's inner corner: on its right the
// tower's clone cannot be carved under its cap) and a tree in front of it.
VirtualScene demoVirtualScene(const String& path)
{
    VirtualScene s;
    s.path = path;
    SceneObject dome;
    dome.name = "dome";
    dome.shape = "dome";
    dome.meshes = proceduralShape("dome");
    dome.placement = SceneObject::PLACE_BEHIND;
    dome.anchor = "building";
    dome.distance = 0.05;
    dome.size = 0.6;
    dome.offset = Vec3d(-0.45, 0, 0);
    SceneObject tree;
    tree.name = "tree";
    tree.shape = "tree";
    tree.meshes = proceduralShape("tree");
    tree.placement = SceneObject::PLACE_IN_FRONT;
    tree.anchor = "building";
    tree.distance = 0.15;
    tree.size = 0.6;
    tree.offset = Vec3d(-0.2, 0, 0);
    s.objects = {dome, tree};
    s.sun = demoSun();
    return s;
}

SceneSun demoSun()
{
    SceneSun sun;
    sun.form = SceneSun::SUN_AZIMUTH_ELEVATION;
    sun.azimuthDeg = 150;
    sun.elevationDeg = 55;
    sun.sky = 0.5;
    sun.penumbraPx = 3;
    return sun;
}

DemoOptions handheldDemoOptions()
{
    DemoOptions o;
    o.imageSize = Size(1280, 720);
    o.frames = 90;
    o.numKeyFrames = 6;
    o.model = PERSPECTIVE;
    o.path = SceneSynthesizer::PATH_HANDHELD;
    o.distanceRatio = 1.5;
    o.orbitDegrees = 30;
    o.distortion = {-0.12, 0, 0, 0, 0};
    o.exposureDrift = 0.15;
    o.whiteBalanceDrift = 0.05;
    o.videoBitrateMbps = 8;
    return o;
}

DemoResult runDemo(const DemoOptions& o)
{
    DemoResult res;
    const fs::path dir(o.outDir);
    detail::createDirectories((dir / "input").string());
    SceneSynthesizer::Params sp;
    sp.frames = o.frames;
    sp.imageSize = o.imageSize;
    sp.model = o.model;
    sp.distanceRatio = o.distanceRatio;
    sp.path = o.path;
    sp.orbitDegrees = o.orbitDegrees;
    sp.numKeyFrames = o.numKeyFrames;
    sp.distortion = o.distortion;
    sp.exposureDrift = o.exposureDrift;
    sp.whiteBalanceDrift = o.whiteBalanceDrift;
    sp.videoBitrateMbps = o.videoBitrateMbps;
    sp.progress = o.progress;
    Ptr<SceneSynthesizer> synth = SceneSynthesizer::create(sp);
    VirtualScene demoScene = demoVirtualScene((dir / "scene.yml").string());
    if (o.sun)
    {
        // The sun of the scene file in the true world: its ground (y up, the plane y = 0) with
        // north the true cameras' mean view direction, as resolveSun() takes it from the
        // reconstruction's estimated ground; penumbra pixels of the first camera at the origin.
        Reconstruction gt;
        gt.model = sp.model;
        gt.imageSize = sp.imageSize;
        for (int f = 0; f < sp.frames; f++)
            gt.cameras.push_back(synth->getCamera(f));
        GroundFrame g = estimateGround(gt);
        g.up = Vec3d(0, 1, 0);
        g.height = 0;
        Vec3d fwd = -g.back - g.up * g.up.dot(-g.back);
        fwd = cv::normalize(fwd);
        g.right = cv::normalize(fwd.cross(g.up));
        g.back = -fwd;
        const SceneSun& ds = demoScene.sun;
        sp.sun.direction = sunDirection(g, ds.azimuthDeg, ds.elevationDeg, ds.north);
        sp.sun.sky = ds.sky;
        const Camera& c0 = gt.cameras.front();
        sp.sun.penumbra = ds.penumbraPx / c0.pixelsPerUnit(c0.depth(Vec3d(0, 0, 0)));
        synth->setParams(sp);
    }
    else
        demoScene.sun = SceneSun();
    SyntheticScene scene;
    synth->synthesize(scene);
    // The input: frames as PNG (lossless) or, at a set bit rate, the synthesized data set with
    // its H.264 video (a user's footage) and calibration.yml; key-frame masks, the scene file.
    String framesDir = (dir / "input" / "frames").string();
    String masksDir = (dir / "input" / "masks").string();
    if (o.videoBitrateMbps > 0)
    {
        const String synthDir = (dir / "synth").string();
        writeSyntheticScene(synthDir, scene, sp, o.progress);
        framesDir = (dir / "synth" / "video.mp4").string();
        masksDir = (dir / "synth" / "input" / "masks").string();
    }
    else
    {
        writeAtomically(framesDir, [&](const String& tmp) {
            detail::createDirectories(tmp, framesDir);
            for (size_t f = 0; f < scene.frames.size(); f++)
                writeImage(tmp, framesDir, cv::format("%04d.png", (int)f), scene.frames[f]);
        });
        writeMasks(masksDir, scene.keyFrameMasks);
    }
    if (sp.model == PERSPECTIVE && o.videoBitrateMbps > 0)
        res.calibrationPath = (dir / "synth" / "calibration.yml").string();
    res.scenePath = (dir / "scene.yml").string();
    writeScene(res.scenePath, demoScene);

    RunOptions ro;
    ro.input = framesDir;
    ro.masksDir = masksDir;
    ro.scenePath = res.scenePath;
    ro.outDir = o.outDir;
    ro.progress = o.progress;
    ro.photoRefine = o.photoRefine;
    ro.force = true;  // the demo measures a whole run, not a resumed one
    if (o.lens == DEMO_LENS_CALIBRATION)
    {
        if (res.calibrationPath.empty())
            CV_Error(Error::StsBadArg, "runDemo: DEMO_LENS_CALIBRATION needs perspective footage "
                     "written as a data set (videoBitrateMbps > 0)");
        ro.calibrationPath = res.calibrationPath;
    }
    ro.selfCalibrate = o.lens != DEMO_LENS_IGNORED;
    res.run = runPipeline(ro);
    res.compositePath = res.run.compositePath;

    // Score against the ground truth: the placed objects mapped into the true world.
    const Reconstruction& rec = res.run.reconstruction;
    const Matx44d M = alignReconstructions(rec, scene.groundTruth);
    std::vector<Mesh> truthMeshes = res.run.virtualObjects;
    for (Mesh& m : truthMeshes)
        m.transform(M);
    const Matx33d Ma(M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2), M(2, 0), M(2, 1),
                     M(2, 2));
    const double sigma = std::cbrt(cv::determinant(Ma));
    Compositor::Params soft, hard;
    soft.ground = estimateGround(rec);
    soft.lightRotation = soft.ground.rotation();
    soft.sun = resolveSun(demoScene, rec);
    hard.supersample = 1;
    // The truth is lit in the true world (y up) by the synthesizer: light it the same way here.
    Ptr<Compositor> ours = Compositor::create(soft), ref = Compositor::create(hard);
    ours->setVirtualObjects(res.run.virtualObjects);
    ref->setVirtualObjects(truthMeshes);
    // The virtual objects under the true sun without the real objects' shadows (no clones,
    // the true depth as occluder): the reference of the shadows on the virtual objects.
    Compositor::Params litP = hard;
    litP.sun = sp.sun;
    Ptr<Compositor> lit = Compositor::create(litP);
    lit->setVirtualObjects(truthMeshes);
    double sumReal = 0, sumVirtual = 0, sumBoundReal = 0, sumBoundVirtual = 0;
    int boundFramesReal = 0, boundFramesVirtual = 0;
    std::vector<Mat> before, after;
    std::vector<String> captions;
    const int n = (int)scene.frames.size();
    const int kSheetFrames = 4;
    int scored = 0;
    for (int f = 0; f < n; f++)
    {
        if (rec.findCamera(f) < 0)
            continue;
        const Camera& cam = rec.camera(f);
        const Camera& gtCam = scene.groundTruth.camera(f);
        res.rotationErrorDeg += rotationAngleDeg(cam.R * (Ma.t() * (1.0 / sigma)), gtCam.R);
        Mat result, layer, truth, refImg, refLayer, silImg, silLayer;
        ours->composite(scene.frames[f], f, cam, *res.run.clones, result, layer);
        // Pixel agreement against the plain (1x) ground truth: the frames themselves are
        // rendered at 1x, so a supersampled truth differs from them everywhere in the texture.
        synth->renderWithVirtual(f, truthMeshes, truth, 1);
        Mat real = scene.depth[f].clone();
        real.setTo(std::numeric_limits<float>::infinity(), scene.labels[f] == 0);
        ref->composite(scene.frames[f], gtCam, real, refImg, refLayer);
        ref->composite(scene.frames[f], gtCam, noArray(), silImg, silLayer);
        const CompositeScore s = scoreComposite(result, truth, alphaOf(layer),
                                                alphaOf(refLayer) > 0, alphaOf(silLayer) > 0);
        res.fractionWithin += s.fractionWithin;
        if (o.sun)
        {
            Mat litImg, litLayer;
            lit->composite(scene.frames[f], gtCam, real, litImg, litLayer);
            const Mat a = alphaOf(layer), at = alphaOf(refLayer);
            Mat anyV = (a > 0) | (at > 0), realMask, bothV, virtualMask;
            cv::dilate(anyV, anyV, getStructuringElement(MORPH_RECT, Size(3, 3)));
            cv::bitwise_not(anyV, realMask);
            bothV = (a == 255) & (at == 255);
            cv::erode(bothV, virtualMask, getStructuringElement(MORPH_RECT, Size(3, 3)));
            const ShadowScore sr = scoreShadows(scene.frames[f], result, truth, realMask);
            const ShadowScore sv = scoreShadows(litImg, result, truth, virtualMask);
            sumReal += sr.fractionWithin * sr.bandPixels;
            res.shadowReal.bandPixels += sr.bandPixels;
            sumVirtual += sv.fractionWithin * sv.bandPixels;
            res.shadowVirtual.bandPixels += sv.bandPixels;
            if (sr.boundaryPixels > 0)
            {
                sumBoundReal += sr.boundaryDistance;
                boundFramesReal++;
            }
            if (sv.boundaryPixels > 0)
            {
                sumBoundVirtual += sv.boundaryDistance;
                boundFramesVirtual++;
            }
        }
        if (s.boundaryPixels > 0 || s.boundaryDistance > 0)
        {
            res.boundaryDistance += s.boundaryDistance;
            res.boundaryFrames++;
        }
        scored++;
        if (f % std::max(1, (n - 1) / (kSheetFrames - 1)) == 0 &&
            (int)before.size() < kSheetFrames)
        {
            before.push_back(scene.frames[f]);
            after.push_back(result);
        }
    }
    CV_Assert(scored > 0);
    res.slide = measureSlide(rec, scene.groundTruth);
    if (rec.model == PERSPECTIVE && !rec.cameras.empty())
        res.focalErrorPercent = 100 * std::abs(rec.cameras[0].K(0, 0) /
                                               scene.groundTruth.camera(rec.cameras[0].frame).K(0, 0) - 1);
    {
        // Mattes in the frames against the truth.
        ObjectMasks mattes;
        renderMattes(*res.run.clones, rec, mattes);
        double sum = 0;
        int cnt = 0;
        for (const auto& o : mattes)
        {
            const auto vis = scene.visibleMasks.find(o.first);
            if (vis == scene.visibleMasks.end())
                continue;
            const std::vector<int>& keys = scene.keyFrames;
            for (const auto& fm : o.second)
            {
                const int f = fm.first;
                Mat others(fm.second.size(), CV_8U, Scalar(0));
                for (const auto& v : scene.visibleMasks)
                    if (v.first != o.first)
                        others |= v.second.at(f);
                const Mat m = fm.second & ~others, t = vis->second.at(f) & ~others;
                const double uni = countNonZero(m | t);
                const double iou = uni > 0 ? countNonZero(m & t) / uni : 1.0;
                if (std::find(keys.begin(), keys.end(), f) != keys.end())
                    res.keyFrameIoU = std::min(res.keyFrameIoU, iou);
                else
                {
                    sum += iou;
                    cnt++;
                }
            }
        }
        res.nonKeyIoU = cnt > 0 ? sum / cnt : 1.0;
    }
    res.fractionWithin /= scored;
    if (res.shadowReal.bandPixels > 0)
        res.shadowReal.fractionWithin = sumReal / res.shadowReal.bandPixels;
    if (res.shadowVirtual.bandPixels > 0)
        res.shadowVirtual.fractionWithin = sumVirtual / res.shadowVirtual.bandPixels;
    res.shadowReal.boundaryPixels = boundFramesReal;
    res.shadowVirtual.boundaryPixels = boundFramesVirtual;
    res.shadowReal.boundaryDistance = sumBoundReal / std::max(1, boundFramesReal);
    res.shadowVirtual.boundaryDistance = sumBoundVirtual / std::max(1, boundFramesVirtual);
    res.boundaryDistance /= std::max(1, res.boundaryFrames);
    res.rotationErrorDeg /= scored;
    std::vector<Mat> sheet;
    for (size_t i = 0; i < before.size(); i++)
    {
        sheet.push_back(before[i]);
        captions.push_back(cv::format("frame %d: input",
                                      (int)(i * ((n - 1) / (kSheetFrames - 1)))));
    }
    for (size_t i = 0; i < after.size(); i++)
    {
        sheet.push_back(after[i]);
        captions.push_back(cv::format("frame %d: composite",
                                      (int)(i * ((n - 1) / (kSheetFrames - 1)))));
    }
    res.contactSheetPath = (dir / "contact_sheet.png").string();
    const Mat sheetImg = makeContactSheet(sheet, captions, (int)before.size(), 320);
    writeAtomically(res.contactSheetPath, [&](const String& tmp) {
        detail::writeImageFile(tmp, sheetImg, res.contactSheetPath);
    });
    return res;
}

} // namespace augocc
} // namespace cv
