// augocc sfm: tracks.yml -> reconstruction.yml (factorization, the paper's 3F+1 refinement,
// bundle adjustment, model selection), optionally a COLMAP text model and a PLY of the points.

#include "cli_common.hpp"

#include <opencv2/augocc.hpp>

namespace augocc_cli {

namespace {

struct SfmArgs
{
    std::string tracks, out, model = "auto", colmap, ply, calibration;
    double focal = 0;
    bool noBundle = false, refineIntrinsics = false;
};

std::string statsLine(const cv::augocc::ReprojectionStats& s)
{
    return cv::format("RMS %.3f px, median %.3f px, p95 %.3f px over %d observations", s.rms,
                      s.median, s.p95, s.observations);
}

} // namespace

void registerSfm(CLI::App& app, Globals& g)
{
    auto args = std::make_shared<SfmArgs>();
    CLI::App* sub = app.add_subcommand("sfm", "recover cameras and 3D points from tracks "
                                       "(Tomasi-Kanade factorization + Ceres refinement)");
    sub->add_option("--tracks", args->tracks, "tracks.yml (contract)")->required();
    sub->add_option("--out", args->out, "reconstruction.yml to write")->required();
    sub->add_option("--model", args->model, "scaled_orthographic | perspective | auto "
                    "(default auto: perspective only when it lowers the reprojection RMS by "
                    "more than 10%)");
    sub->add_option("--colmap", args->colmap, "also write a COLMAP text model into this folder");
    sub->add_option("--ply", args->ply, "also write the 3D points as a PLY file");
    sub->add_option("--calibration", args->calibration, "known intrinsics: OpenCV's "
                    "calibration file (camera_matrix, distortion_coefficients, optional "
                    "image_width / image_height; scaled to the frames when of the same aspect)");
    sub->add_option("--focal", args->focal, "known focal length only, pixels (principal point "
                    "at the image centre, no distortion)")->excludes("--calibration");
    sub->add_flag("--refine-intrinsics", args->refineIntrinsics, "refine the given focal length "
                  "and distortion (default: they stay fixed)");
    sub->add_flag("--no-ba", args->noBundle, "skip the full bundle adjustment (the paper's "
                  "3F+1 refinement only)");
    sub->callback([args, &g]() {
        requireFile("--tracks", args->tracks);
        if (args->model != "auto" && args->model != "scaled_orthographic" &&
            args->model != "perspective")
            throw UsageError("--model " + args->model + ": expected scaled_orthographic, "
                             "perspective or auto");
        const cv::augocc::Tracks tracks = cv::augocc::readTracks(args->tracks);
        cv::augocc::SfmOptions opt;
        opt.model = args->model;
        opt.bundleAdjust = !args->noBundle;
        setIntrinsicsOptions(args->calibration, args->focal, args->refineIntrinsics,
                             tracks.imageSize, opt);
        cv::augocc::SfmReport rep;
        ProgressPrinter progress(g);
        opt.progress = progress.callback();
        const cv::augocc::Reconstruction rec = cv::augocc::recoverCameras(tracks, opt, &rep);
        progress.finish();
        cv::augocc::writeReconstruction(args->out, rec);
        if (!args->colmap.empty())
            cv::augocc::writeColmapModel(args->colmap, rec, tracks);
        if (!args->ply.empty())
            cv::augocc::writePointsPly(args->ply, rec);
        info(g, cv::format("sfm: %d frames, %d tracks kept (%d of them rejected by the "
                           "factorization and explained by the final cameras), %d rejected "
                           "(%d of them too far for their depth to be measured); model %s",
                           (int)rec.cameras.size(), rep.inlierTracks, rep.rescuedTracks,
                           rep.rejectedTracks, rep.unmeasuredDepthTracks,
                           rep.chosenModel.c_str()));
        info(g, "  factorization:       " + statsLine(rep.factorization));
        info(g, "  3F+1 refinement:     " + statsLine(rep.positionZoom));
        if (opt.bundleAdjust)
            info(g, "  orthographic BA:     " + statsLine(rep.orthographic));
        if (rep.perspective.observations > 0)
            info(g, "  perspective BA:      " + statsLine(rep.perspective));
        if (rep.lens.observations > 0)
            info(g, "  lens BA:             " + statsLine(rep.lens));
        if (rep.unexplainedObservations > 0)
            info(g, cv::format("  final BA, without the %d observations beyond %.2f px: ",
                               rep.unexplainedObservations, rep.unexplainedThresholdPx) +
                 statsLine(rep.explained));
        info(g, lensLine(rep));
        info(g, "wrote " + args->out);
    });
}

} // namespace augocc_cli
