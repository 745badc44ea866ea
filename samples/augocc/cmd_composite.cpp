// augocc composite: virtual objects of a scene file inserted into the frames, hidden by the
// clones of the real objects (doc/compositor.md).

#include "cli_common.hpp"

#include "opencv2/augocc.hpp"

using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

namespace {

struct CompositeCliOptions
{
    std::string input, reconstruction, clones, scene, out, frames, mattes, depth, layer;
    bool hardEdges = false;
    bool antialiasVirtual = false;
};

void runComposite(const Globals& g, const CompositeCliOptions& o)
{
    requireFile("--input", o.input.find('%') == std::string::npos ? o.input : ".");
    requireFile("--reconstruction", o.reconstruction);
    requireFile("--clones", o.clones);
    requireFile("--scene", o.scene);
    CompositeOptions opt;
    if (!o.frames.empty())
    {
        const FrameRange r = parseFrameSpan("--frames", o.frames, "composite");
        opt.firstFrame = r.first;
        opt.endFrame = r.end;
    }
    const Reconstruction rec = readReconstruction(o.reconstruction);
    const Ptr<CloneSet> clones = CloneSet::load(o.clones);
    const VirtualScene scene = readScene(o.scene);
    const std::vector<Mesh> meshes = placeScene(scene, rec, clones.get());
    opt.sun = resolveSun(scene, rec);
    opt.supersample = o.hardEdges ? 1 : Compositor::Params().supersample;
    opt.antialiasVirtual = o.antialiasVirtual;
    opt.mattesDir = o.mattes;
    opt.depthDir = o.depth;
    opt.virtualLayerDir = o.layer;
    opt.reconstructionName = o.reconstruction;
    ProgressPrinter progress(g);
    opt.progress = progress.callback();
    const int n = compositeSequence(o.input, rec, *clones, meshes, o.out, opt);
    progress.finish();
    info(g, "composited " + std::to_string(n) + " frames into " + o.out);
}

} // namespace

void registerComposite(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<CompositeCliOptions>();
    CLI::App* sub = app.add_subcommand("composite", "insert the virtual objects of a scene file "
                                       "into the frames, hidden by the real objects' clones");
    sub->add_option("--input", o->input, "video, image folder or printf pattern")->required();
    sub->add_option("--reconstruction", o->reconstruction, "reconstruction.yml")->required();
    sub->add_option("--clones", o->clones, "clones.yml.gz (augocc clone)")->required();
    sub->add_option("--scene", o->scene, "scene.yml: the virtual objects")->required();
    sub->add_option("--out", o->out, "output video (.mp4 ...) or folder for %04d.png")
        ->required();
    sub->add_option("--frames", o->frames, "composite only frames a..b-1 as a:b (a render farm "
                    "chunk), a: to the end, a for one frame (README, Command line)");
    sub->add_option("--mattes", o->mattes, "also write the clones' mattes, DIR/<object>/%04d.png");
    sub->add_option("--depth", o->depth, "also write depth, DIR/%04d.png 16-bit + DIR/depth.yml");
    sub->add_option("--virtual-layer", o->layer, "also write the virtual layer, DIR/%04d.png "
                    "BGRA");
    sub->add_flag("--hard-edges", o->hardEdges, "the paper's per-pixel depth test (no soft "
                  "occlusion edges)");
    sub->add_flag("--antialias-virtual", o->antialiasVirtual, "also anti-alias the virtual "
                  "objects' own outlines (renders them at 3x: slower)")->excludes("--hard-edges");
    sub->callback([&g, o]() { runComposite(g, *o); });
}

} // namespace augocc_cli
