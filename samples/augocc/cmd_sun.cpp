// augocc sun: the sun's direction and sky share estimated from the footage, the reconstruction
// and the clones (issue 19 item 3, estimateSun()), printed relative to the ground and written
// as a scene.yml `sun` block.

#include "cli_common.hpp"

#include "opencv2/augocc.hpp"
#include "opencv2/augocc/sun_estimation.hpp"

using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

namespace {

struct SunCliOptions
{
    std::string input, reconstruction, clones, out;
    int frames = 6;
    int sideBins = SunEstimationParams().sideBins;
    bool noUncertainty = false;
};

void runSun(const Globals& g, const SunCliOptions& o)
{
    requireFile("--input", o.input.find('%') == std::string::npos ? o.input : ".");
    requireFile("--reconstruction", o.reconstruction);
    requireFile("--clones", o.clones);
    const Reconstruction rec = readReconstruction(o.reconstruction);
    const Ptr<CloneSet> clones = CloneSet::load(o.clones);
    const GroundFrame ground = estimateGround(rec);
    const std::vector<int> frames = sunEstimationFrames(rec, o.frames);
    if (frames.empty())
        throw UsageError(o.reconstruction + ": no camera");
    Ptr<FrameSource> src = FrameSource::open(o.input);
    if (src->size() != rec.imageSize)
        throw UsageError(cv::format("--input: frames are %dx%d, %s's %dx%d", src->size().width,
                                    src->size().height, o.reconstruction.c_str(),
                                    rec.imageSize.width, rec.imageSize.height));
    std::vector<Mat> images;
    for (int f : frames)
    {
        if (f >= src->count())
            throw UsageError(cv::format("--input: no frame %d (%d frames)", f, src->count()));
        src->seek(f);
        Mat img;
        if (!src->read(img))
            throw UsageError(cv::format("--input: frame %d cannot be read", f));
        images.push_back(img);
    }
    src->checkUnchanged();
    SunEstimationParams p;
    p.sideBins = o.sideBins;
    if (o.noUncertainty)
        p.jackknifeGroups = 0;
    const SunEstimate e = estimateSun(images, frames, rec, *clones, ground, p);
    info(g, cv::format("sun: azimuth %.1f deg (clockwise from north = the mean view direction), "
                       "elevation %.1f deg above the ground", e.azimuthDeg, e.elevationDeg));
    info(g, cv::format("sun: direction [%.4f, %.4f, %.4f] (reconstruction frame)",
                       e.direction[0], e.direction[1], e.direction[2]));
    if (e.angularSigmaDeg >= 0)
        info(g, cv::format("sun: 1-sigma %.2f deg (jackknife over %d ground sectors); sky share "
                           "%.3f +- %.3f", e.angularSigmaDeg, p.jackknifeGroups, e.sky,
                           e.skySigma));
    else
        info(g, cv::format("sun: sky share %.3f (no uncertainty computed)", e.sky));
    info(g, cv::format("sun: fit RMS %.3f (log brightness; %.3f with no sun), %d frames, %d "
                       "ground and %d clone samples", e.rmsLog, e.rmsLogNoSun, e.frames,
                       e.groundSamples, e.cloneSamples));
    if (!o.out.empty())
    {
        // A `sun` node as readScene() reads it (SceneSun's direction form), to paste into (or
        // merge with) a scene.yml; the estimate's figures as comments.
        const String text = cv::format(
            "%%YAML:1.0\n---\n"
            "# augocc sun: estimated from %s (%d frames)\n"
            "# azimuth %.2f deg, elevation %.2f deg relative to the ground; 1-sigma %.2f deg\n"
            "# sky share 1-sigma %.3f\n"
            "sun:\n"
            "  direction: [%.6f, %.6f, %.6f]\n"
            "  sky: %.4f\n",
            o.input.c_str(), e.frames, e.azimuthDeg, e.elevationDeg, e.angularSigmaDeg,
            e.skySigma, e.direction[0], e.direction[1], e.direction[2],
            std::min(0.99, std::max(0.0, e.sky)));
        writeFileAtomically(o.out, text);
        info(g, "sun block written to " + o.out);
    }
}

} // namespace

void registerSun(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<SunCliOptions>();
    CLI::App* sub = app.add_subcommand("sun", "estimate the sun's direction and sky share from "
                                       "the footage (the clones' shadows and shading)");
    sub->add_option("--input", o->input, "video, image folder or printf pattern")->required();
    sub->add_option("--reconstruction", o->reconstruction, "reconstruction.yml")->required();
    sub->add_option("--clones", o->clones, "clones file from augocc clone")->required();
    sub->add_option("--out", o->out, "write a scene file with the estimated `sun` block");
    sub->add_option("--sample-frames", o->frames, "how many frames to use, evenly spaced over the "
                    "cameras (default 6)")
        ->check(CLI::Range(1, 1000));
    sub->add_option("--side-bins", o->sideBins, "albedo groups per clone side by normal "
                    "azimuth (1: one albedo for all sides)")
        ->check(CLI::Range(1, 72));
    sub->add_flag("--no-uncertainty", o->noUncertainty, "skip the jackknife (faster)");
    sub->callback([o, &g]() { runSun(g, *o); });
}

} // namespace augocc_cli
