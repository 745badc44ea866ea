// augocc run: track -> sfm -> clone -> matte -> composite, every intermediate in --out-dir.

#include "cli_common.hpp"

#include <map>
#include "opencv2/augocc.hpp"

using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

//! Progress lines per stage for the pipeline's callback (one line per stage on a terminal).
std::function<void(const String&, int, int)> stageProgress(const Globals& g,
                                                           std::shared_ptr<Progress>& current,
                                                           std::shared_ptr<std::string>& stage)
{
    return [&g, &current, &stage](const String& name, int done, int total) {
        if (!current || *stage != name)
        {
            if (current)
                current->finish();
            current = std::make_shared<Progress>(g, name, std::max(total, 1));
            *stage = name;
        }
        current->update(done);
    };
}

namespace {

struct RunCliOptions
{
    std::string input, masks, scene, outDir;
    bool hardEdges = false;
    bool antialiasVirtual = false;
    bool noPhotoRefine = false;
    std::string calibration;
    double focal = 0;
    bool refineIntrinsics = false;
};

void runRun(const Globals& g, const RunCliOptions& o)
{
    requireFile("--masks", o.masks);
    if (!o.scene.empty())
        requireFile("--scene", o.scene);
    RunOptions ro;
    ro.input = o.input;
    ro.masksDir = o.masks;
    ro.scenePath = o.scene;
    ro.outDir = o.outDir;
    ro.supersample = o.hardEdges ? 1 : Compositor::Params().supersample;
    ro.antialiasVirtual = o.antialiasVirtual;
    ro.photoRefine = !o.noPhotoRefine;
    checkIntrinsicsFlags(o.calibration, o.focal, o.refineIntrinsics);
    ro.calibrationPath = o.calibration;
    ro.focal = o.focal;
    ro.refineIntrinsics = o.refineIntrinsics;
    std::shared_ptr<Progress> current;
    auto stage = std::make_shared<std::string>();
    ro.progress = stageProgress(g, current, stage);
    const RunResult r = runPipeline(ro);
    if (current)
        current->finish();
    for (const auto& s : r.stageSeconds)
        info(g, cv::format("%-10s %7.2f s", s.first.c_str(), s.second));
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
                                       "composite");
    sub->add_option("--input", o->input, "video, image folder or printf pattern")->required();
    sub->add_option("--masks", o->masks, "key-frame masks, MASKS/<object>/%04d.png")->required();
    sub->add_option("--scene", o->scene, "scene.yml (without it, run stops after the mattes)");
    sub->add_option("--out-dir", o->outDir, "folder for every intermediate and the composite")
        ->required();
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
    sub->callback([&g, o]() { runRun(g, *o); });
}

} // namespace augocc_cli
