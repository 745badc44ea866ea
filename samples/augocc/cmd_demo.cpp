// augocc demo: synthesizes a scene, inserts a dome behind the front building and a tree in front
// of it, runs the whole pipeline from tracking on and scores it against the ground truth.

#include "cli_common.hpp"

#include "opencv2/augocc.hpp"

using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

void registerDemo(CLI::App& app, Globals& g)
{
    auto outDir = std::make_shared<std::string>("augocc_demo");
    auto noPhoto = std::make_shared<bool>(false);
    auto model = std::make_shared<std::string>("scaled_orthographic");
    auto distance = std::make_shared<double>(DemoOptions().distanceRatio);
    auto lens = std::make_shared<std::string>("self");
    auto noSun = std::make_shared<bool>(false);
    CLI::App* sub = app.add_subcommand("demo", "synthesize a scene and run the whole pipeline "
                                       "on it (no input needed)");
    sub->add_option("--out-dir", *outDir, "output folder (default augocc_demo)");
    sub->add_flag("--no-photo-refine", *noPhoto, "clones from the silhouettes alone (no "
                  "photo-consistency carving over the frames)");
    sub->add_option("--model", *model, "camera of the synthesized footage: scaled_orthographic "
                    "(default), perspective, or handheld (street-level hand-held 1280x720 "
                    "through a k1 = -0.12 lens, 1.5 scene sizes away, exposure and "
                    "white-balance drift, H.264 at 8 Mbit/s)");
    CLI::Option* distanceOpt = sub->add_option("--distance-ratio", *distance, "camera distance over the scene size (default "
                    "10; 3 is hand-held footage near the buildings, strong perspective)");
    sub->add_option("--lens", *lens, "how the run learns the lens: self (from the footage, "
                    "default), calibration (the synthesized calibration.yml, as augocc run "
                    "--calibration; handheld only), ignored (no lens model, for comparison)");
    sub->add_flag("--no-sun", *noSun, "the fixed light of the shading convention, no shadows "
                  "(default: the demo scene's sun, shadows both ways)");
    sub->callback([&g, outDir, noPhoto, model, distance, distanceOpt, lens, noSun]() {
        const bool handheld = *model == "handheld";
        DemoOptions o = handheld ? handheldDemoOptions() : DemoOptions();
        if (*model != "scaled_orthographic" && *model != "perspective" && !handheld)
            throw UsageError("--model " + *model + ": expected scaled_orthographic, perspective "
                             "or handheld");
        if (!(*distance >= 1.0))
            throw UsageError(cv::format("--distance-ratio %g: must be >= 1", *distance));
        if (!handheld)
        {
            o.model = *model == "perspective" ? PERSPECTIVE : SCALED_ORTHOGRAPHIC;
            o.distanceRatio = *distance;
        }
        else if (distanceOpt->count() > 0)
            o.distanceRatio = *distance;
        if (*lens == "self")
            o.lens = DEMO_LENS_SELF_CALIBRATE;
        else if (*lens == "calibration" && handheld)
            o.lens = DEMO_LENS_CALIBRATION;
        else if (*lens == "ignored")
            o.lens = DEMO_LENS_IGNORED;
        else
            throw UsageError("--lens " + *lens + ": expected self, calibration (with --model "
                             "handheld) or ignored");
        o.outDir = *outDir;
        o.photoRefine = !*noPhoto;
        o.sun = !*noSun;
        ProgressPrinter progress(g);
        o.progress = progress.callback();
        const DemoResult r = runDemo(o);
        progress.finish();
        for (const auto& s : r.run.stageSeconds)
            info(g, cv::format("%-10s %7.2f s", s.first.c_str(), s.second));
        info(g, "composite:     " + r.compositePath);
        info(g, "contact sheet: " + r.contactSheetPath);
        info(g, "scene file:    " + r.scenePath);
        if (!r.calibrationPath.empty())
            info(g, "calibration:   " + r.calibrationPath + (o.lens == DEMO_LENS_CALIBRATION ?
                 " (true intrinsics, given to the run)" : " (true intrinsics; not used by this "
                 "run)"));
        info(g, "lens:          " + r.run.sfm.lensReason);
        info(g, cv::format("accuracy against the synthetic ground truth: %.2f%% of pixels within "
                           "8 grey levels, occlusion boundary %.2f px (mean over the %d frames "
                           "with one), camera rotation error %.3f deg", 100 * r.fractionWithin,
                           r.boundaryDistance, r.boundaryFrames, r.rotationErrorDeg));
        info(g, cv::format("slide of a virtual point against the real scene: median %.2f px, "
                           "95th percentile %.2f px, worst %.2f px; focal length %.2f%% off; "
                           "mattes: key frames IoU >= %.4f, non-key mean IoU %.4f",
                           r.slide.median, r.slide.p95, r.slide.max, r.focalErrorPercent,
                           r.keyFrameIoU, r.nonKeyIoU));
        if (o.sun)
            info(g, cv::format("shadow agreement with the synthetic ground truth: %.2f%% of the "
                               "%d band pixels within 8 grey levels on the real surfaces, shadow "
                               "boundary %.2f px; %.2f%% of %d on the virtual objects, boundary "
                               "%.2f px", 100 * r.shadowReal.fractionWithin,
                               r.shadowReal.bandPixels, r.shadowReal.boundaryDistance,
                               100 * r.shadowVirtual.fractionWithin, r.shadowVirtual.bandPixels,
                               r.shadowVirtual.boundaryDistance));
    });
}

} // namespace augocc_cli
