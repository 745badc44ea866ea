// augocc matte: renders every object's clone in every frame of a reconstruction into the
// contract's MATTES folder, and optionally camera-space depth maps.

#include "cli_common.hpp"

#include <opencv2/augocc.hpp>

namespace augocc_cli {

namespace {

struct MatteOptions
{
    std::string reconstruction, clones, out, depth, frames;
};

void runMatte(const MatteOptions& o, const Globals& g)
{
    using namespace cv::augocc;
    requireFile("--reconstruction", o.reconstruction);
    requireFile("--clones", o.clones);
    std::vector<FrameRange> ranges;
    if (!o.frames.empty())
        ranges = parseFrameRanges("--frames", o.frames);
    Reconstruction rec = readReconstruction(o.reconstruction);
    if (!o.frames.empty())
    {
        // A chunk (augocc farm): the cameras of the chosen frames only, each one required.
        const int frameCount = rec.cameras.empty() ? 0 : rec.cameras.back().frame + 1;
        const std::set<int> frames = listFrames("--frames", o.frames, ranges, frameCount);
        std::vector<Camera> chosen;
        for (int f : frames)
        {
            if (rec.findCamera(f) < 0)
                throw UsageError(cv::format("--frames: frame %d has no camera in %s", f,
                                            o.reconstruction.c_str()));
            chosen.push_back(rec.camera(f));
        }
        rec.cameras = chosen;
    }
    const cv::Ptr<CloneSet> clones = CloneSet::load(o.clones);
    ProgressPrinter progress(g);
    writeMattes(o.out, *clones, rec, o.depth, progress.callback());
    progress.finish();
    info(g, cv::format("mattes of %d objects in %d frames written to %s",
                       (int)clones->objectNames().size(), (int)rec.cameras.size(), o.out.c_str()));
    if (!o.depth.empty())
        info(g, "depth maps (32-bit float TIFF, camera-space z, +inf off the clone) written to " +
                o.depth);
}

} // namespace

void registerMatte(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<MatteOptions>();
    CLI::App* sub = app.add_subcommand("matte", "render the clones' mattes (and depth) in every "
                                       "frame");
    sub->add_option("--reconstruction", o->reconstruction, "reconstruction.yml")->required();
    sub->add_option("--clones", o->clones, "clones file from augocc clone")->required();
    sub->add_option("--out", o->out, "MATTES folder to write: <object>/%04d.png")->required();
    sub->add_option("--depth", o->depth, "also write depth maps here: <object>/%04d.tiff");
    sub->add_option("--frames", o->frames, "only these frames, e.g. 0:50 (frames 0..49, a render "
                    "farm chunk; README, Command line); default: every frame with a camera");
    sub->callback([o, &g]() { runMatte(*o, g); });
}

} // namespace augocc_cli
