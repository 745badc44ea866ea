// augocc run: track -> sfm -> clone -> matte -> composite, every intermediate in --out-dir.

#include "cli_common.hpp"

#include "opencv2/augocc.hpp"

using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

namespace {

struct RunCliOptions
{
    std::string input, masks, scene, outDir, frames;
    bool hardEdges = false;
    bool antialiasVirtual = false;
    bool noPhotoRefine = false;
    std::string calibration;
    double focal = 0;
    bool refineIntrinsics = false;
    std::string model = RunOptions().model;
    double voxelPixels = RunOptions().voxelPixels;
    bool noFreeSpace = false;
    int threads = 0;
    bool force = false;
};

void runRun(const Globals& g, const RunCliOptions& o)
{
    requireFile("--masks", o.masks);
    if (!o.scene.empty())
        requireFile("--scene", o.scene);
    if (o.threads < 0)
        throw UsageError(cv::format("--threads %d: must be at least 1 (0: every core)",
                                    o.threads));
    if (o.threads > 0)
        cv::setNumThreads(o.threads);
    RunOptions ro;
    ro.input = o.input;
    ro.masksDir = o.masks;
    ro.scenePath = o.scene;
    ro.outDir = o.outDir;
    if (!o.frames.empty())
    {
        const FrameRange fr = parseFrameSpan("--frames", o.frames, "run");
        ro.firstFrame = fr.first;
        ro.endFrame = fr.end;
    }
    ro.supersample = o.hardEdges ? 1 : Compositor::Params().supersample;
    ro.antialiasVirtual = o.antialiasVirtual;
    ro.photoRefine = !o.noPhotoRefine;
    checkIntrinsicsFlags(o.calibration, o.focal, o.refineIntrinsics);
    ro.calibrationPath = o.calibration;
    ro.focal = o.focal;
    ro.refineIntrinsics = o.refineIntrinsics;
    ro.model = o.model;
    ro.voxelPixels = o.voxelPixels;
    ro.freeSpace = !o.noFreeSpace;
    ro.force = o.force;
    ProgressPrinter progress(g);
    ro.progress = progress.callback();
    const RunResult r = runPipeline(ro);
    progress.finish();
    if (!r.ignoredMasks.empty())
        info(g, cv::format("%d key-frame mask(s) outside --frames %s ignored (first: %s)",
                           (int)r.ignoredMasks.size(), o.frames.c_str(),
                           r.ignoredMasks.front().c_str()));
    for (const auto& s : r.stageSeconds)
    {
        const bool reused =
            std::find(r.reused.begin(), r.reused.end(), s.first) != r.reused.end();
        info(g, cv::format("%-10s %7.2f s%s", s.first.c_str(), s.second,
                           reused ? "  (reused: inputs and options unchanged)" : ""));
    }
    if (std::find(r.reused.begin(), r.reused.end(), "sfm") == r.reused.end())
        info(g, lensLine(r.sfm));
    info(g, "outputs in " + o.outDir + (r.compositePath.empty()
                                            ? " (no --scene: stopped after the mattes)"
                                            : ", composite: " + r.compositePath));
}

} // namespace

void registerRun(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<RunCliOptions>();
    CLI::App* sub = app.add_subcommand("run", "the whole pipeline: track, sfm, clone, matte, "
                                       "composite (re-runs reuse what is unchanged)");
    sub->add_option("--input", o->input, "video, image folder or printf pattern")->required();
    sub->add_option("--masks", o->masks, "key-frame masks, MASKS/<object>/%04d.png")->required();
    sub->add_option("--scene", o->scene, "scene.yml (without it, run stops after the mattes)");
    sub->add_option("--out-dir", o->outDir, "folder for every intermediate and the composite")
        ->required();
    sub->add_option("--frames", o->frames, "process only frames a..b-1 as a:b (half-open), a: "
                    "to the end; outputs keep the input's frame numbers, key-frame masks "
                    "outside are ignored");
    sub->add_flag("--hard-edges", o->hardEdges, "the paper's per-pixel depth test");
    sub->add_flag("--antialias-virtual", o->antialiasVirtual, "also anti-alias the virtual "
                  "objects' own outlines (renders them at 3x: slower)")->excludes("--hard-edges");
    sub->add_flag("--no-photo-refine", o->noPhotoRefine, "clones from the silhouettes alone (no "
                  "photo-consistency carving over the frames)");
    sub->add_option("--calibration", o->calibration, "known intrinsics: OpenCV's calibration "
                    "file (as augocc sfm --calibration)");
    sub->add_option("--focal", o->focal, "known focal length only, pixels")
        ->excludes("--calibration");
    sub->add_flag("--refine-intrinsics", o->refineIntrinsics, "refine the given intrinsics");
    sub->add_option("--model", o->model, "camera model: scaled_orthographic | perspective | "
                    "auto (as augocc sfm --model)")->capture_default_str();
    sub->add_option("--voxel-pixels", o->voxelPixels, "voxel edge in pixels (as augocc clone "
                    "--voxel-pixels)")->capture_default_str();
    sub->add_flag("--no-free-space", o->noFreeSpace, "do not carve the free space the tracks "
                  "show (silhouettes only, the paper's rule)");
    sub->add_option("--threads", o->threads, "worker threads (default 0: every core; results "
                    "do not depend on it)");
    sub->add_flag("--force", o->force, "redo every stage (default: reuse each intermediate "
                  "whose inputs and options are unchanged, see its .manifest.yml)");
    sub->callback([&g, o]() { runRun(g, *o); });
}

} // namespace augocc_cli
