// augocc join: the chunks of a per-frame stage (composite or matte run with --frames a:b, as
// augocc farm's jobs do) into one output; PNG files copied unchanged, a video encoded once
// (cv::augocc::joinFrameChunks, joinMaskChunks; doc/farm.md).

#include "cli_common.hpp"

#include <opencv2/augocc.hpp>
#include <opencv2/augocc/chunks.hpp>

namespace augocc_cli {

namespace {

struct JoinOptions
{
    std::string kind, out;
    std::vector<std::string> chunks;
    double fps = 25;
};

void runJoin(const JoinOptions& o, const Globals& g)
{
    for (const std::string& c : o.chunks)
        requireFile("chunk", c);
    if (!(o.fps > 0))
        throw UsageError(cv::format("--fps %g: must be positive", o.fps));
    std::vector<cv::String> chunks(o.chunks.begin(), o.chunks.end());
    if (o.kind == "frames")
    {
        const int n = cv::augocc::joinFrameChunks(chunks, o.out, o.fps);
        info(g, cv::format("joined %d frames of %d chunks into %s", n, (int)chunks.size(),
                           o.out.c_str()));
    }
    else if (o.kind == "masks")
    {
        const int n = cv::augocc::joinMaskChunks(chunks, o.out);
        info(g, cv::format("joined %d masks of %d chunks into %s", n, (int)chunks.size(),
                           o.out.c_str()));
    }
    else
        throw UsageError("--kind " + o.kind + ": expected frames or masks");
}

} // namespace

void registerJoin(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<JoinOptions>();
    CLI::App* sub = app.add_subcommand("join", "join the chunks of a per-frame stage (composite "
                                       "or matte --frames a:b) into one output");
    sub->add_option("--kind", o->kind, "frames: folders of %04d.png (composite chunks) into a "
                    "video or a folder; masks: mattes trees <object>/%04d.png into one tree")
        ->required();
    sub->add_option("--out", o->out, "the joined output: video (.mp4 ...) or folder")
        ->required();
    sub->add_option("--fps", o->fps, "frame rate of a video output")->capture_default_str();
    sub->add_option("chunks", o->chunks, "the chunks' folders (any order; together every frame "
                    "once)")->required();
    sub->callback([o, &g]() { runJoin(*o, g); });
}

} // namespace augocc_cli
