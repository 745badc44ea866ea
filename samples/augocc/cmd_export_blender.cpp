// augocc export-blender: the shot as a Python script that Blender runs to build it (footage,
// animated camera, clones as holdouts, ground as shadow catcher, virtual objects, sun), with its
// assets (doc/blender.md).

#include "cli_common.hpp"

#include "opencv2/augocc.hpp"

using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

namespace {

struct ExportBlenderCliOptions
{
    std::string input, reconstruction, clones, scene, out, frames, save;
    double fps = 0;
    int samples = BlenderShotOptions().samples;
};

bool endsWith(const std::string& s, const std::string& tail)
{
    return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

void runExportBlender(const Globals& g, const ExportBlenderCliOptions& o)
{
    requireFile("--input", o.input.find('%') == std::string::npos ? o.input : ".");
    requireFile("--reconstruction", o.reconstruction);
    requireFile("--clones", o.clones);
    requireFile("--scene", o.scene);
    if (!endsWith(o.out, ".py"))
        throw UsageError("--out " + o.out + ": expected a Python script name, e.g. shot.py");
    if (!o.save.empty() && !endsWith(o.save, ".blend"))
        throw UsageError("--save " + o.save + ": expected a .blend file name, e.g. shot.blend");
    if (!(o.fps >= 0))
        throw UsageError(cv::format("--fps %g: must be positive (0: the input's)", o.fps));
    if (o.samples < 1)
        throw UsageError(cv::format("--samples %d: must be >= 1", o.samples));
    BlenderShotOptions opt;
    if (!o.frames.empty())
    {
        const std::vector<FrameRange> r = parseFrameRanges("--frames", o.frames);
        if (r.size() != 1 || r[0].step != 1)
            throw UsageError("--frames " + o.frames + ": export-blender takes one range of "
                             "consecutive frames (a, a:b or a:)");
        opt.firstFrame = r[0].first;
        opt.endFrame = r[0].end;
    }
    opt.footage = o.input;
    opt.fps = o.fps;
    opt.blendPath = o.save;
    opt.samples = o.samples;
    opt.reconstructionName = o.reconstruction;
    const Reconstruction rec = readReconstruction(o.reconstruction);
    const Ptr<CloneSet> clones = CloneSet::load(o.clones);
    const VirtualScene scene = readScene(o.scene);
    writeBlenderShot(o.out, rec, *clones, scene, opt);
    info(g, "wrote " + o.out + "; build the shot with: blender -b -P " + o.out);
}

} // namespace

void registerExportBlender(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<ExportBlenderCliOptions>();
    CLI::App* sub = app.add_subcommand("export-blender", "write a Python script (and its assets) "
                                       "that builds the shot in Blender: blender -b -P shot.py");
    sub->add_option("--input", o->input, "video, image folder or printf pattern (the footage)")
        ->required();
    sub->add_option("--reconstruction", o->reconstruction, "reconstruction.yml")->required();
    sub->add_option("--clones", o->clones, "clones.yml.gz (augocc clone)")->required();
    sub->add_option("--scene", o->scene, "scene.yml: the virtual objects")->required();
    sub->add_option("--out", o->out, "the script, shot.py (assets go to shot_assets/ beside it)")
        ->required();
    sub->add_option("--frames", o->frames, "export only frames a..b-1 as a:b, a: to the end, a "
                    "for one frame (README, Command line)");
    sub->add_option("--save", o->save, "the script also saves the built shot as this .blend");
    sub->add_option("--fps", o->fps, "frame rate of the shot (default: the input's; 25 for "
                    "images)");
    sub->add_option("--samples", o->samples, "Cycles samples per pixel the shot renders with")
        ->capture_default_str();
    sub->callback([&g, o]() { runExportBlender(g, *o); });
}

} // namespace augocc_cli
