// augocc clone: builds the clones of the real objects (the paper's Section 6) from a reconstruction
// and key-frame masks. A thin shell over cv::augocc::CloneBuilder: build(), or buildPart()
// (--object) and mergeParts() (--merge) for per-object jobs on a farm.

#include "cli_common.hpp"

#include <sstream>
#include <opencv2/augocc.hpp>

namespace augocc_cli {

namespace {

struct CloneOptions
{
    std::string reconstruction, masks, out, tracks, orientation, ply, input,
        patchRule = "nearest";
    cv::augocc::CloneBuilder::Params params;  // --voxel-pixels, --rays-per-pixel
    std::vector<std::string> objects;  // --object: a partial clones file of these
    std::vector<std::string> merge;    // --merge: partial clones files to merge and finish
    bool noOcclusion = false;
    bool noFreeSpace = false;
};

cv::Vec3d parseOrientation(const std::string& text)
{
    std::stringstream ss(text);
    cv::Vec3d v;
    char c1 = 0, c2 = 0;
    if (!(ss >> v[0] >> c1 >> v[1] >> c2 >> v[2]) || c1 != ',' || c2 != ',' || !ss.eof())
        throw UsageError("--orientation " + text + ": expected rx,ry,rz (degrees)");
    return v * (CV_PI / 180.0);
}

void runClone(const CloneOptions& o, const Globals& g)
{
    using namespace cv::augocc;
    requireFile("--reconstruction", o.reconstruction);
    requireFile("--masks", o.masks);
    if (!o.tracks.empty())
        requireFile("--tracks", o.tracks);
    if (!o.input.empty() && o.input.find('%') == std::string::npos)
        requireFile("--input", o.input);
    CloneBuilder::Params p = o.params;
    p.occlusionAware = !o.noOcclusion;
    if (o.noFreeSpace)
        p.freeSpace.minViews = 0;
    if (o.patchRule == "bracketing")
        p.patches.rule = CloneBuilder::PATCH_BRACKETING;
    else if (o.patchRule != "nearest")
        throw UsageError("--patch-rule " + o.patchRule + ": expected nearest or bracketing");
    if (!o.orientation.empty())
    {
        p.box.orientation = CloneBuilder::ORIENT_USER;
        p.box.userRotation = parseOrientation(o.orientation);
    }
    if (!o.objects.empty() && !o.merge.empty())
        throw UsageError("--object, --merge: give one of them (--object builds a part, --merge "
                         "merges the parts)");
    if (!o.objects.empty() && !o.input.empty())
        throw UsageError("--input: the photo-consistency carving looks at every object, so it "
                         "runs when the parts are merged: give --input to clone --merge");
    for (const std::string& part : o.merge)
        requireFile("--merge", part);
    const Reconstruction rec = readReconstruction(o.reconstruction);
    const ObjectMasks masks = readMasks(o.masks, rec.imageSize);
    if (masks.empty())
        throw UsageError("--masks " + o.masks + ": no object folder with masks");
    for (size_t i = 0; i < o.objects.size(); i++)
    {
        if (!masks.count(o.objects[i]))
            throw UsageError("--object " + o.objects[i] + ": no such object in the masks " +
                             o.masks);
        for (size_t j = 0; j < i; j++)
            if (o.objects[j] == o.objects[i])
                throw UsageError("--object " + o.objects[i] + ": given twice");
    }
    Tracks tracks;
    if (!o.tracks.empty())
        tracks = readTracks(o.tracks);
    ProgressPrinter progress(g);
    p.progress = progress.callback();
    cv::Ptr<CloneBuilder> builder = CloneBuilder::create(p);
    std::vector<cv::Mat> frames;
    if (!o.input.empty())
    {
        // The frames the photo-consistency carving compares (at most PhotoParams::maxViews),
        // read before the build so a bad video fails early; the others are not held.
        cv::Ptr<FrameSource> src = FrameSource::open(o.input);
        if (src->size() != rec.imageSize)
            throw UsageError("--input " + o.input + cv::format(": frames are %dx%d, the "
                             "reconstruction's %dx%d", src->size().width, src->size().height,
                             rec.imageSize.width, rec.imageSize.height));
        for (const Camera& cam : rec.cameras)
            if (cam.frame >= src->count())
                throw UsageError("--input " + o.input + cv::format(": %d frames, but the "
                                 "reconstruction has a camera for frame %d", src->count(),
                                 cam.frame));
        const std::vector<int> used = builder->photoFrames(rec);
        frames.resize(src->count());
        size_t next = 0;
        for (int f = 0; f < src->count() && next < used.size(); f++)
        {
            cv::Mat img;
            if (!src->read(img))
                throw UsageError("--input " + o.input + cv::format(": frame %d cannot be read",
                                                                   f));
            if (f == used[next])
            {
                frames[f] = img;
                next++;
            }
        }
        src->checkUnchanged();  // frames of two versions would carve a wrong clone
    }
    const Tracks* tr = o.tracks.empty() ? nullptr : &tracks;
    cv::Ptr<CloneSet> clones;
    if (!o.objects.empty())
    {
        // Passes 1-4 of these objects: a partial clones file for clone --merge.
        clones = builder->buildPart(rec, masks, std::vector<cv::String>(o.objects.begin(),
                                                                        o.objects.end()), tr);
    }
    else if (!o.merge.empty())
    {
        std::vector<cv::Ptr<CloneSet> > parts;
        for (const std::string& part : o.merge)
            parts.push_back(CloneSet::loadPart(part));
        clones = builder->mergeParts(parts, rec, masks, tr);
    }
    else
        clones = builder->build(rec, masks, tr);
    if (!frames.empty())
        builder->refine(*clones, rec, frames);
    progress.finish();
    clones->save(o.out);
    if (!o.ply.empty())
        clones->exportPly(o.ply);
    for (const cv::String& name : clones->objectNames())
    {
        const cv::Vec3i d = clones->gridSize(name);
        info(g, cv::format("%s: %d voxels in a %dx%dx%d grid, %d key frames", name.c_str(),
                           clones->voxelCount(name), d[0], d[1], d[2],
                           (int)clones->keyFrames(name).size()));
    }
    info(g, std::string(o.objects.empty() ? "clones" : "partial clones (merge them with clone "
                        "--merge)") + " written to " + o.out);
}

} // namespace

void registerClone(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<CloneOptions>();
    CLI::App* sub = app.add_subcommand("clone", "build the clones of the real objects (voxel "
                                       "models with patch voxels) from key-frame masks");
    sub->add_option("--reconstruction", o->reconstruction, "reconstruction.yml")->required();
    sub->add_option("--masks", o->masks, "MASKS folder: <object>/%04d.png key-frame silhouettes")
        ->required();
    sub->add_option("--out", o->out, "clones file to write (.yml.gz)")->required();
    sub->add_option("--tracks", o->tracks, "tracks.yml the points came from (clusters points by "
                    "the frames where they are seen, and carves the free space they show)");
    sub->add_option("--orientation", o->orientation, "box rotation rx,ry,rz in degrees "
                    "(Rodrigues); default: automatic");
    sub->add_option("--input", o->input, "the video (or image folder, printf pattern): carve the "
                    "clones further by photo-consistency over every frame with a camera");
    sub->add_option("--ply", o->ply, "also write PLY files of each clone and patch set here");
    sub->add_option("--voxel-pixels", o->params.voxelPixels, "voxel edge in pixels")
        ->capture_default_str();
    sub->add_option("--rays-per-pixel", o->params.patches.raysPerPixel, "patch rays per pixel "
                    "along each axis")->capture_default_str();
    sub->add_option("--patch-rule", o->patchRule, "patches for frames between key frames: "
                    "nearest (default) or bracketing");
    sub->add_flag("--no-occlusion", o->noOcclusion, "carve under nearer objects' silhouettes too "
                  "(the paper's rule)");
    sub->add_flag("--no-free-space", o->noFreeSpace, "with --tracks, do not carve the free space "
                  "the tracks show (silhouettes only, the paper's rule)");
    sub->add_option("--object", o->objects, "build only this object (repeatable): writes a "
                    "partial clones file of the passes that need no other object's clone, for "
                    "clone --merge (doc/farm.md)");
    sub->add_option("--merge", o->merge, "partial clones files written by clone --object "
                    "(together every object of --masks, each once): merges them and runs the "
                    "passes that look at every object; the other flags as for the parts");
    sub->callback([o, &g]() { runClone(*o, g); });
}

} // namespace augocc_cli
