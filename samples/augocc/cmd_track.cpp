// augocc track: video / image folder / printf pattern -> tracks.yml (Shi-Tomasi + pyramidal
// Lucas-Kanade with a forward-backward check).

#include "cli_common.hpp"

#include <opencv2/augocc.hpp>
#include <opencv2/imgcodecs.hpp>

namespace augocc_cli {

namespace {

// Flags start at the library's defaults (FeatureTracker::Params), which the help text shows.
const cv::augocc::FeatureTracker::Params kDefaults;

struct TrackArgs
{
    std::string input, out, mask;
    int maxTracks = kDefaults.maxTracks;
    double fb = kDefaults.fbThreshold;
    int minLength = kDefaults.minTrackLength;
};

} // namespace

void registerTrack(CLI::App& app, Globals& g)
{
    auto args = std::make_shared<TrackArgs>();
    CLI::App* sub = app.add_subcommand("track", "track features through a video (Shi-Tomasi "
                                       "corners, pyramidal Lucas-Kanade, forward-backward "
                                       "check)");
    sub->add_option("--input", args->input, "video file, image folder or printf pattern")
        ->required();
    sub->add_option("--out", args->out, "tracks.yml to write")->required();
    sub->add_option("--max-tracks", args->maxTracks,
                    cv::format("target number of live tracks (default %d)", kDefaults.maxTracks));
    sub->add_option("--mask", args->mask, "exclusion mask image (white = no features there), "
                    "the size of the frames");
    sub->add_option("--fb-threshold", args->fb,
                    cv::format("forward-backward error that ends a track, pixels (default %.1f)",
                               kDefaults.fbThreshold));
    sub->add_option("--min-length", args->minLength,
                    cv::format("drop tracks seen in fewer frames (default %d)",
                               kDefaults.minTrackLength));
    sub->callback([args, &g]() {
        cv::augocc::FeatureTracker::Params p;
        if (args->maxTracks < 4)
            throw UsageError(cv::format("--max-tracks %d: must be at least 4", args->maxTracks));
        if (!(args->fb > 0))
            throw UsageError("--fb-threshold must be positive");
        if (args->minLength < 1)
            throw UsageError("--min-length must be at least 1");
        p.maxTracks = args->maxTracks;
        p.fbThreshold = args->fb;
        p.minTrackLength = args->minLength;
        if (!args->mask.empty())
        {
            requireFile("--mask", args->mask);
            p.exclusionMask = cv::imread(args->mask, cv::IMREAD_GRAYSCALE);
            if (p.exclusionMask.empty())
                throw UsageError("--mask " + args->mask + ": not a readable image");
        }
        cv::Ptr<cv::augocc::FrameSource> src = cv::augocc::FrameSource::open(args->input);
        if (!p.exclusionMask.empty() && p.exclusionMask.size() != src->size())
            throw UsageError(cv::format("--mask %s: %dx%d, the frames are %dx%d",
                             args->mask.c_str(), p.exclusionMask.cols, p.exclusionMask.rows,
                             src->size().width, src->size().height));
        cv::augocc::Tracks tracks;
        ProgressPrinter progress(g);
        p.progress = progress.callback();
        cv::augocc::FeatureTracker::create(p)->track(src, tracks);
        progress.finish();
        cv::augocc::writeTracks(args->out, tracks);
        int full = 0;
        for (int c = 0; c < tracks.points(); c++)
            full += tracks.observationCount(c) == tracks.frames() ? 1 : 0;
        info(g, cv::format("track: %d frames, %d tracks (%d over the whole sequence)",
                           tracks.frames(), tracks.points(), full));
        info(g, "wrote " + args->out);
    });
}

} // namespace augocc_cli
