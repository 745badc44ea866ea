// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// CloneBuilder: the clone stage's driver. build() runs the passes of clone/passes.hpp in order;
// each pass is in its own file (pass_*.cpp).

#include "precomp.hpp"
#include "clone/ideal_space.hpp"
#include "clone/key_frame_coverage.hpp"
#include "clone/clone_parts.hpp"
#include "clone/passes.hpp"

namespace cv {
namespace augocc {

namespace {

using namespace detail;

void checkMask(const Mat& m, const Reconstruction& rec, const String& object, int frame)
{
    const String where = cv::format("masks of object '%s', frame %d", object.c_str(), frame);
    if (m.empty())
        CV_Error(Error::StsBadArg, where + ": empty image");
    if (m.type() != CV_8UC1)
        CV_Error(Error::StsBadArg, where + ": must be 8-bit single channel");
    if (m.size() != rec.imageSize)
        CV_Error(Error::StsBadSize, where + cv::format(": size %dx%d differs from the "
                 "reconstruction's %dx%d", m.cols, m.rows, rec.imageSize.width,
                 rec.imageSize.height));
    if (rec.findCamera(frame) < 0)
        CV_Error(Error::StsBadArg, where + ": the reconstruction has no camera for this frame");
    const int n = countNonZero(m > 127);
    if (n == 0)
        CV_Error(Error::StsBadArg, where + ": the silhouette is empty");
    if (n == (int)m.total())
        CV_Error(Error::StsBadArg, where + ": the silhouette covers the whole frame (all white)");
}

//! Object passes of one build() (step "build" of stage "clone"): one unit per pass and object.
struct PassProgress
{
    const ProgressCallback& cb;
    int64 done;
    int64 total;
};

//! Runs `pass` over the objects `names` of `set` (name order) and logs what it did to each.
void runPass(const char* name, int64 (*pass)(ObjectClone&, const PassContext&),
             CloneSetImpl& set, const std::vector<String>& names, const PassContext& ctx,
             PassProgress& progress)
{
    for (const String& object : names)
    {
        const int64 n = pass(set.get(object), ctx);
        CV_UNUSED(n);  // with the debug log compiled out
        CV_UNUSED(name);
        CV_LOG_DEBUG(NULL, cv::format("augocc: clone pass '%s': object '%s': %lld voxels", name,
                                      object.c_str(), (long long)n));
        detail::reportProgress(progress.cb, "clone", "build", ++progress.done, progress.total,
                               "passes", String(name) + ": " + object);
    }
}

//! build()'s and buildPart()'s input checks; the silhouettes made binary (0 / 255).
ObjectMasks checkedSilhouettes(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                               const Tracks* tracks, const char* who)
{
    if (keyFrameMasks.empty())
        CV_Error(Error::StsBadArg, cv::format("%s: no object masks", who));
    if (rec.imageSize.width <= 0 || rec.imageSize.height <= 0)
        CV_Error(Error::StsBadSize, cv::format("%s: the reconstruction has no image size", who));
    if (tracks && !rec.points.empty() && tracks->points() != rec.points.rows)
        CV_Error(Error::StsBadSize, cv::format("%s: tracks have %d columns, the reconstruction "
                 "%d points", who, tracks->points(), rec.points.rows));
    if (!rec.points.empty() && (rec.points.cols != 3 || rec.points.type() != CV_64FC1))
        CV_Error(Error::StsBadArg, cv::format("%s: reconstruction points must be Nx3 CV_64F",
                                              who));
    ObjectMasks bins;
    for (const auto& o : keyFrameMasks)
    {
        if (o.second.empty())
            CV_Error(Error::StsBadArg, cv::format("%s: object '%s' has no key frame", who,
                                                  o.first.c_str()));
        for (const auto& fm : o.second)
        {
            checkMask(fm.second, rec, o.first, fm.first);
            bins[o.first][fm.first] = fm.second > 127;
        }
    }
    return bins;
}

//! What a part records of its inputs (and what mergeParts() expects of every part).
PartInfo partInfoOf(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                    const Tracks* tracks, const CloneBuilder::Params& params)
{
    PartInfo info;
    for (const auto& o : keyFrameMasks)
        info.allObjects.push_back(o.first);
    info.params = paramsText(params);
    info.reconstruction = fingerprintReconstruction(rec);
    info.masks = fingerprintMasks(keyFrameMasks);
    info.tracks = fingerprintTracks(tracks);
    return info;
}

CloneSetImpl& cloneSetOf(CloneSet& clones, const char* who)
{
    CloneSetImpl* set = dynamic_cast<CloneSetImpl*>(&clones);
    if (!set)
        CV_Error(Error::StsBadArg, cv::format("%s: the clone set was not made by CloneBuilder or "
                                              "CloneSet::load", who));
    return *set;
}

class CloneBuilderImpl CV_FINAL : public CloneBuilder
{
public:
    explicit CloneBuilderImpl(const Params& p) { setParams(p); }

    Params getParams() const CV_OVERRIDE { return params_; }
    void setParams(const Params& p) CV_OVERRIDE;

    Ptr<CloneSet> build(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                        const Tracks* tracks) const CV_OVERRIDE;
    Ptr<CloneSet> buildPart(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                            const std::vector<String>& objects,
                            const Tracks* tracks) const CV_OVERRIDE;
    Ptr<CloneSet> mergeParts(const std::vector<Ptr<CloneSet> >& parts, const Reconstruction& rec,
                             const ObjectMasks& keyFrameMasks,
                             const Tracks* tracks) const CV_OVERRIDE;
    void addKeyFrame(CloneSet& clones, const Reconstruction& rec, const String& object,
                     int frame, InputArray mask) const CV_OVERRIDE;
    int64 refine(CloneSet& clones, const Reconstruction& rec,
                 InputArrayOfArrays frames) const CV_OVERRIDE;
    std::vector<int> photoFrames(const Reconstruction& rec) const CV_OVERRIDE;

private:
    //! Passes 1-4 (clone/passes.hpp) of `objects` (sorted, of `bins`): a partial set.
    Ptr<CloneSetImpl> buildObjects(const Reconstruction& rec, const ObjectMasks& bins,
                                   const std::vector<String>& objects, const Tracks* tracks,
                                   const PartInfo& info, PassProgress& progress) const;
    //! Passes 5-6 over every object of a merged set.
    void finish(CloneSetImpl& set, const Reconstruction& rec, PassProgress& progress) const;
    //! Units of step "build" per object: in buildObjects(), in finish().
    int64 partUnits(bool tracks) const;
    int64 finishUnits() const { return 1 + (params_.unobserved.enabled ? 1 : 0); }

    Params params_;
};

void CloneBuilderImpl::setParams(const Params& p)
{
    const char* kWhere = "CloneBuilder::Params::";
    auto check = [&](bool ok, const char* field, const char* rule) {
        if (!ok)
            CV_Error(Error::StsBadArg, cv::format("%s%s %s", kWhere, field, rule));
    };
    check(p.voxelPixels > 0 && std::isfinite(p.voxelPixels), "voxelPixels", "must be positive");
    check(p.maxVoxels >= 8, "maxVoxels", "must be at least 8");
    check(p.box.maxEnlargeIterations >= 1, "box.maxEnlargeIterations", "must be >= 1");
    check(p.box.orientation >= ORIENT_AUTO && p.box.orientation <= ORIENT_USER,
          "box.orientation", "is not an Orientation");
    check(p.box.trimFraction >= 0 && p.box.trimFraction < 0.5, "box.trimFraction",
          "must be in [0, 0.5)");
    check(p.box.minPoints >= 1, "box.minPoints", "must be >= 1");
    check(p.patches.raysPerPixel >= 1 && p.patches.raysPerPixel <= 8, "patches.raysPerPixel",
          "must be in [1, 8]");
    check(p.patches.rule == PATCH_NEAREST || p.patches.rule == PATCH_BRACKETING, "patches.rule",
          "is not a PatchRule");
    check(p.freeSpace.minViews >= 0, "freeSpace.minViews", "must be >= 0");
    check(p.freeSpace.edgeMargin >= 0 && std::isfinite(p.freeSpace.edgeMargin),
          "freeSpace.edgeMargin", "must be >= 0");
    check(p.freeSpace.planarDeg >= 0 && p.freeSpace.planarDeg <= 90, "freeSpace.planarDeg",
          "must be in [0, 90]");
    check(p.freeSpace.marginVoxels >= 0 && std::isfinite(p.freeSpace.marginVoxels),
          "freeSpace.marginVoxels", "must be >= 0");
    check(p.freeSpace.maxEdgeRatio > 0, "freeSpace.maxEdgeRatio", "must be positive");
    check(p.freeSpace.maxReprojPx > 0, "freeSpace.maxReprojPx", "must be positive");
    check(p.freeSpace.maxViews >= 0, "freeSpace.maxViews", "must be >= 0 (0: every frame)");
    check(p.unobserved.views >= 1, "unobserved.views", "must be >= 1");
    check(p.unobserved.depthTolVoxels >= 0 && std::isfinite(p.unobserved.depthTolVoxels),
          "unobserved.depthTolVoxels", "must be >= 0");
    check(p.unobserved.keepNearSeen >= 0 && p.unobserved.keepNearSeen <= 16,
          "unobserved.keepNearSeen", "must be in [0, 16]");
    check(p.unobserved.regrowFromUnseen >= p.unobserved.keepNearSeen &&
              p.unobserved.regrowFromUnseen <= 16,
          "unobserved.regrowFromUnseen", "must be in [keepNearSeen, 16]");
    check(p.unobserved.maxTiltDeg >= 0 && p.unobserved.maxTiltDeg <= 90,
          "unobserved.maxTiltDeg", "must be in [0, 90]");
    check(p.photo.threshold >= 0 && p.photo.threshold <= 255, "photo.threshold",
          "must be in [0, 255]");
    check(p.photo.minAgreement > 0 && p.photo.minAgreement <= 1, "photo.minAgreement",
          "must be in (0, 1]");
    check(p.photo.minViews >= 2, "photo.minViews", "must be >= 2");
    check(p.photo.rounds >= 1, "photo.rounds", "must be >= 1");
    check(p.photo.patchStep >= 0 && p.photo.patchStep <= 8, "photo.patchStep",
          "must be in [0, 8]");
    check(p.photo.maxViews == 0 || p.photo.maxViews >= p.photo.minViews, "photo.maxViews",
          "must be 0 (every frame) or at least photo.minViews");
    params_ = p;
}

int64 CloneBuilderImpl::partUnits(bool tracks) const
{
    return 3 + (tracks && params_.freeSpace.minViews > 0 ? 1 : 0);
}

Ptr<CloneSetImpl> CloneBuilderImpl::buildObjects(const Reconstruction& rec,
                                                 const ObjectMasks& bins,
                                                 const std::vector<String>& objects,
                                                 const Tracks* tracks, const PartInfo& info,
                                                 PassProgress& pp) const
{
    // Every object is in the set while the passes run: their silhouettes and centres are what
    // the passes of `objects` read of them (unknownMask). The others leave before the return.
    Ptr<CloneSetImpl> set = makePtr<CloneSetImpl>();
    set->patchRule = params_.patches.rule;
    for (const auto& o : bins)
        for (const auto& m : o.second)
            set->add(o.first).masks[m.first] = m.second.clone();
    std::vector<String> others;
    for (const auto& o : bins)
        if (!std::binary_search(objects.begin(), objects.end(), o.first))
            others.push_back(o.first);

    // With a lens, the passes run in its ideal pinhole view (clone/ideal_space.hpp).
    const IdealSpace space = makeIdealSpace(rec, "CloneBuilder::build");
    ObjectMasks idealBins;
    Tracks idealTracks;
    if (space.active())
    {
        for (const auto& o : bins)
            for (const auto& m : o.second)
                idealBins[o.first][m.first] = space.mask(m.second);
        if (tracks)
            idealTracks = space.tracks(*tracks);
    }
    {
        const IdealMasks idealMasks(*set, space);
        PassContext ctx(space.active() ? space.rec : rec, *set, params_);
        ctx.keyFrameMasks = space.active() ? &idealBins : &bins;
        ctx.tracks = tracks && space.active() ? &idealTracks : tracks;
        ctx.inFrame = space.active() ? &space.inFrame : nullptr;
        // The objects of other parts: their centres alone, as passBox() sets them in theirs.
        for (const String& name : others)
            passCentre(set->get(name), ctx);
        runPass("box", passBox, *set, objects, ctx, pp);                // 1. Steps 1-3
        runPass("carve", passCarve, *set, objects, ctx, pp);            // 2. Step 4
        runPass("grid growth", passGridGrowth, *set, objects, ctx, pp);  // 3. beyond Step 3
        if (tracks && params_.freeSpace.minViews > 0)
            runPass("free space", passFreeSpace, *set, objects, ctx, pp);  // 4. the tracks
    }
    for (const String& name : others)
        set->erase(name);
    // Only what a clones file holds goes on (box and points are the first passes' own), so that
    // a part merged in memory (build()) and one saved and loaded are the same.
    for (const String& name : objects)
    {
        ObjectClone& o = set->get(name);
        o.box = Box();
        o.points.clear();
        o.patches.clear();
        o.surface = o.grid.surface();
    }
    set->partial = true;
    set->part = info;
    return set;
}

void CloneBuilderImpl::finish(CloneSetImpl& set, const Reconstruction& rec,
                              PassProgress& pp) const
{
    const IdealSpace space = makeIdealSpace(rec, "CloneBuilder::build");
    const IdealMasks idealMasks(set, space);
    PassContext ctx(space.active() ? space.rec : rec, set, params_);
    ctx.inFrame = space.active() ? &space.inFrame : nullptr;
    const std::vector<String> all = set.objectNames();
    if (params_.unobserved.enabled)
    {
        // Every clone's surface as passes 1-4 left it, drawn once for all objects.
        const ObservedSurfaces observed = observeSurfaces(set, ctx.rec, params_.unobserved,
                                                          ctx.inFrame);
        ctx.observed = &observed;
        runPass("unobserved", passUnobserved, set, all, ctx, pp);  // 5. what no frame sees
        ctx.observed = nullptr;
    }
    runPass("patches", passPatches, set, all, ctx, pp);  // 6. Step 5: patch voxels
}

Ptr<CloneSet> CloneBuilderImpl::build(const Reconstruction& rec, const ObjectMasks& keyFrameMasks,
                                      const Tracks* tracks) const
{
    // Exactly buildPart() of every object, then mergeParts() of that one part.
    const ObjectMasks bins = checkedSilhouettes(rec, keyFrameMasks, tracks,
                                                "CloneBuilder::build");
    const PartInfo info = partInfoOf(rec, bins, tracks, params_);
    const int64 n = (int64)bins.size();
    PassProgress pp{params_.progress, 0, n * (partUnits(tracks != nullptr) + finishUnits())};
    detail::reportProgress(pp.cb, "clone", "build", 0, pp.total, "passes");
    Ptr<CloneSetImpl> part = buildObjects(rec, bins, info.allObjects, tracks, info, pp);
    Ptr<CloneSetImpl> set = combineParts({part.get()}, info);
    finish(*set, rec, pp);
    return set;
}

Ptr<CloneSet> CloneBuilderImpl::buildPart(const Reconstruction& rec,
                                          const ObjectMasks& keyFrameMasks,
                                          const std::vector<String>& objects,
                                          const Tracks* tracks) const
{
    const ObjectMasks bins = checkedSilhouettes(rec, keyFrameMasks, tracks,
                                                "CloneBuilder::buildPart");
    if (objects.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::buildPart: no object to build");
    std::vector<String> sorted;
    for (const String& o : objects)
    {
        if (!bins.count(o))
            CV_Error(Error::StsBadArg, "CloneBuilder::buildPart: object '" + o + "' is not an "
                     "object of the masks");
        if (std::find(sorted.begin(), sorted.end(), o) != sorted.end())
            CV_Error(Error::StsBadArg, "CloneBuilder::buildPart: object '" + o + "' is given "
                     "twice");
        sorted.push_back(o);
    }
    std::sort(sorted.begin(), sorted.end());
    const PartInfo info = partInfoOf(rec, bins, tracks, params_);
    PassProgress pp{params_.progress, 0, (int64)sorted.size() * partUnits(tracks != nullptr)};
    detail::reportProgress(pp.cb, "clone", "build", 0, pp.total, "passes");
    return buildObjects(rec, bins, sorted, tracks, info, pp);
}

Ptr<CloneSet> CloneBuilderImpl::mergeParts(const std::vector<Ptr<CloneSet> >& parts,
                                           const Reconstruction& rec,
                                           const ObjectMasks& keyFrameMasks,
                                           const Tracks* tracks) const
{
    if (parts.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::mergeParts: no part");
    if (rec.imageSize.width <= 0 || rec.imageSize.height <= 0)
        CV_Error(Error::StsBadSize, "CloneBuilder::mergeParts: the reconstruction has no image "
                 "size");
    // The parts hold their objects' silhouettes: the masks given here are only fingerprinted.
    const PartInfo expected = partInfoOf(rec, keyFrameMasks, tracks, params_);
    // The parts are copied (the caller keeps them); the copies' objects move into the merge.
    std::vector<CloneSetImpl> copies;
    copies.reserve(parts.size());
    for (size_t i = 0; i < parts.size(); i++)
    {
        if (parts[i].empty())
            CV_Error(Error::StsBadArg, cv::format("CloneBuilder::mergeParts: part %d is null",
                                                  (int)i + 1));
        const CloneSetImpl* impl = dynamic_cast<const CloneSetImpl*>(parts[i].get());
        if (!impl)
            CV_Error(Error::StsBadArg, cv::format("CloneBuilder::mergeParts: part %d was not "
                     "made by CloneBuilder::buildPart or CloneSet::loadPart", (int)i + 1));
        copies.push_back(*impl);
    }
    std::vector<CloneSetImpl*> ptrs;
    for (CloneSetImpl& c : copies)
        ptrs.push_back(&c);
    Ptr<CloneSetImpl> set = combineParts(ptrs, expected);
    for (const auto& o : set->objects())
        for (const auto& m : o.second.masks)
            if (m.second.size() != rec.imageSize || rec.findCamera(m.first) < 0)
                CV_Error(Error::StsBadArg, cv::format("CloneBuilder::mergeParts: object '%s': "
                         "key frame %d does not fit the reconstruction", o.first.c_str(),
                         m.first));
    PassProgress pp{params_.progress, 0, (int64)set->objects().size() * finishUnits()};
    detail::reportProgress(pp.cb, "clone", "build", 0, pp.total, "passes");
    finish(*set, rec, pp);
    return set;
}

void CloneBuilderImpl::addKeyFrame(CloneSet& clones, const Reconstruction& rec,
                                   const String& object, int frame, InputArray mask) const
{
    checkComplete(clones, "CloneBuilder::addKeyFrame");
    CloneSetImpl& set = cloneSetOf(clones, "addKeyFrame");
    ObjectClone& obj = set.get(object);
    Mat m = mask.getMat();
    checkMask(m, rec, object, frame);
    for (const auto& km : obj.masks)
        if (km.second.size() != rec.imageSize)
            CV_Error(Error::StsBadSize, cv::format("CloneBuilder::addKeyFrame: object '%s': key "
                     "frame %d's silhouette is %dx%d, the reconstruction's image size %dx%d",
                     object.c_str(), km.first, km.second.cols, km.second.rows,
                     rec.imageSize.width, rec.imageSize.height));
    obj.masks[frame] = m > 127;
    const IdealSpace space = makeIdealSpace(rec, "CloneBuilder::addKeyFrame");
    const IdealMasks idealMasks(set, space);
    PassContext ctx(space.active() ? space.rec : rec, set, params_);
    ctx.inFrame = space.active() ? &space.inFrame : nullptr;
    ctx.carveFrame = frame;
    passCarve(obj, ctx);    // Step 4 with the new key frame
    passPatches(obj, ctx);  // Step 5
}

std::vector<int> CloneBuilderImpl::photoFrames(const Reconstruction& rec) const
{
    std::vector<int> frames;
    for (const Camera* cam : evenlySpacedCameras(rec, params_.photo.maxViews))
        frames.push_back(cam->frame);
    return frames;
}

int64 CloneBuilderImpl::refine(CloneSet& clones, const Reconstruction& rec,
                               InputArrayOfArrays framesArr) const
{
    checkComplete(clones, "CloneBuilder::refine");
    CloneSetImpl& set = cloneSetOf(clones, "CloneBuilder::refine");
    if (rec.cameras.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::refine: the reconstruction has no camera");
    if (framesArr.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::refine: no frames");
    if (!framesArr.isMatVector() && !framesArr.isUMatVector())
        CV_Error(Error::StsBadArg, "CloneBuilder::refine: frames must be a vector of images");
    const int nframes = (int)framesArr.total();
    std::vector<Mat> frames(nframes);
    // Only the frames compared are read (the others may be empty: a long shot is streamed).
    const std::vector<int> used = photoFrames(rec);
    for (const int f : used)
    {
        if (f < 0 || f >= nframes)
            CV_Error(Error::StsBadArg, cv::format("CloneBuilder::refine: the reconstruction has a "
                     "camera for frame %d but %d frames are given", f, nframes));
        Mat m = framesArr.getMat(f);
        if (m.empty())
            CV_Error(Error::StsBadArg, cv::format("CloneBuilder::refine: frame %d is empty", f));
        if (m.size() != rec.imageSize)
            CV_Error(Error::StsBadSize, cv::format("CloneBuilder::refine: frame %d is %dx%d, the "
                     "reconstruction's image size %dx%d", f, m.cols, m.rows,
                     rec.imageSize.width, rec.imageSize.height));
        if (m.type() == CV_8UC1)
            cvtColor(m, frames[f], COLOR_GRAY2BGR);
        else if (m.type() == CV_8UC3)
            frames[f] = m;
        else
            CV_Error(Error::StsUnsupportedFormat, cv::format("CloneBuilder::refine: frame %d "
                     "must be CV_8UC3 or CV_8UC1", f));
    }
    for (const auto& o : set.objects())
        for (const auto& m : o.second.masks)
            if (m.second.size() != rec.imageSize)
                CV_Error(Error::StsBadSize, cv::format("CloneBuilder::refine: object '%s': key "
                         "frame %d's silhouette differs from the reconstruction's image size",
                         o.first.c_str(), m.first));
            else if (rec.findCamera(m.first) < 0)
                CV_Error(Error::StsBadArg, cv::format("CloneBuilder::refine: object '%s': key "
                         "frame %d has no camera", o.first.c_str(), m.first));

    const IdealSpace space = makeIdealSpace(rec, "CloneBuilder::refine");
    if (space.active())
    {
        parallel_for_(Range(0, (int)used.size()), [&](const Range& r) {
            for (int i = r.start; i < r.end; i++)
                frames[used[i]] = space.image(frames[used[i]]);
        });
    }
    const IdealMasks idealMasks(set, space);
    PassContext ctx(space.active() ? space.rec : rec, set, params_);
    ctx.inFrame = space.active() ? &space.inFrame : nullptr;
    std::map<String, int64> carved;
    // Step "photo-consistency": one unit per object and round (a round carving nothing ends
    // the work early: `total` is the bound), one per object re-patched.
    const int64 nObjects = (int64)set.objectNames().size();
    const int64 photoTotal = nObjects * (params_.photo.rounds + 1);
    int64 photoDone = 0;
    detail::reportProgress(params_.progress, "clone", "photo-consistency", 0, photoTotal,
                           "passes");
    for (int round = 0; round < params_.photo.rounds; round++)
    {
        // Each round sees the other clones as the last round left them.
        const PhotoViews views = preparePhotoViews(set, ctx.rec, frames, params_.photo,
                                                   ctx.inFrame);
        ctx.photo = &views;
        int64 roundCarved = 0;
        for (const String& name : set.objectNames())
        {
            const int64 n = passPhoto(set.get(name), ctx);
            carved[name] += n;
            roundCarved += n;
            CV_LOG_DEBUG(NULL, cv::format("augocc: photo-consistency round %d: object '%s': %lld "
                         "voxels carved", round, name.c_str(), (long long)n));
            detail::reportProgress(params_.progress, "clone", "photo-consistency", ++photoDone,
                                   photoTotal, "passes", "photo: " + name);
        }
        ctx.photo = nullptr;
        if (roundCarved == 0)
            break;
    }
    int64 total = 0;
    for (const auto& c : carved)
    {
        total += c.second;
        if (c.second > 0)
            passPatches(set.get(c.first), ctx);  // Step 5 again where the clone changed
    }
    detail::reportProgress(params_.progress, "clone", "photo-consistency", photoTotal,
                           photoTotal, "passes");
    return total;
}

} // namespace

Ptr<CloneBuilder> CloneBuilder::create(const Params& params)
{
    return makePtr<CloneBuilderImpl>(params);
}

Ptr<CloneBuilder> CloneBuilder::create()
{
    return makePtr<CloneBuilderImpl>(Params());
}

} // namespace augocc
} // namespace cv
