// augocc propagate: proposed silhouettes for chosen frames, headless. From the clones (each
// object's clone rendered into the frame, hidden parts removed by depth) or from coarse mattes
// given as a folder, each outline snapped to the frame's edges (cv::augocc::proposeSilhouettes,
// cv::augocc::SilhouetteEditor::snapMask). The user then corrects them in `augocc annotate`.

#include "cli_common.hpp"

#include <filesystem>
#include <set>

#include <opencv2/augocc.hpp>

namespace augocc_cli {

namespace {

using namespace cv;
using namespace cv::augocc;

struct Options
{
    std::string input, reconstruction, clones, mattes, frames, out;
    std::vector<std::string> objects;
    bool noSnap = false;
};

void runPropagate(const Options& opt, const Globals& g)
{
    std::vector<FrameRange> ranges;
    if (!opt.frames.empty())
        ranges = parseFrameRanges("--frames", opt.frames);
    requireFile("--input", opt.input);
    const bool fromClones = !opt.clones.empty();
    if (fromClones == !opt.mattes.empty())
        throw UsageError("give exactly one of --clones (with --reconstruction) or --mattes");
    if (fromClones)
    {
        if (opt.reconstruction.empty())
            throw UsageError("--clones needs --reconstruction");
        requireFile("--reconstruction", opt.reconstruction);
        requireFile("--clones", opt.clones);
    }
    else
        requireFile("--mattes", opt.mattes);

    Ptr<FrameSource> source = FrameSource::open(opt.input);
    const int frameCount = source->count();
    const Size size = source->size();
    Reconstruction rec;
    Ptr<CloneSet> clones;
    ObjectMasks mattes;
    if (fromClones)
    {
        rec = readReconstruction(opt.reconstruction);
        if (rec.imageSize != size)
            throw UsageError(format("--reconstruction %s: image size %dx%d, the frames of "
                                    "--input are %dx%d", opt.reconstruction.c_str(),
                                    rec.imageSize.width, rec.imageSize.height, size.width,
                                    size.height));
        clones = CloneSet::load(opt.clones);
    }
    else
        mattes = readMasks(opt.mattes, size);

    std::set<int> frames;
    if (!opt.frames.empty())
        frames = listFrames("--frames", opt.frames, ranges, frameCount);
    else if (fromClones)
        for (const Camera& c : rec.cameras)
            frames.insert(c.frame);
    else
        for (int f = 0; f < frameCount; ++f)
            frames.insert(f);
    for (int f : frames)
        if (fromClones && rec.findCamera(f) < 0)
            throw UsageError(format("--frames: frame %d has no camera in %s", f,
                                    opt.reconstruction.c_str()));

    std::set<std::string> wanted(opt.objects.begin(), opt.objects.end());
    ObjectMasks out;
    ProgressPrinter progress(g);
    int done = 0;
    SilhouetteEditor::Params params;
    for (int f : frames)
    {
        Mat image;
        source->seek(f);
        if (!source->read(image) || image.empty())
            throw UsageError(format("--input %s: cannot read frame %d", opt.input.c_str(), f));
        std::map<String, Mat> proposals;
        if (fromClones)
            proposeSilhouettes(*clones, f, rec.camera(f), image, proposals, !opt.noSnap, params);
        else
        {
            Ptr<SilhouetteEditor> editor = SilhouetteEditor::create(params);
            editor->setImage(image);
            for (const auto& om : mattes)
            {
                auto it = om.second.find(f);
                if (it == om.second.end())
                    continue;
                Mat m = it->second;
                if (!opt.noSnap && countNonZero(m) > 0)
                    editor->snapMask(it->second, m);
                proposals[om.first] = m;
            }
        }
        for (const auto& p : proposals)
        {
            if (!wanted.empty() && !wanted.count(p.first))
                continue;
            if (countNonZero(p.second) > 0)  // an object not seen in this frame gets no mask
                out[p.first][f] = p.second;
            else
                out[p.first];
        }
        progress.report("propagate", ++done, (long long)frames.size(), "frames");
    }
    progress.finish();
    source->checkUnchanged();  // masks snapped to two versions of the footage are not kept
    for (const std::string& name : wanted)
        if (!out.count(name))
            throw UsageError("--object " + name + ": no such object in the " +
                             (fromClones ? "clones" : "mattes"));
    writeMasks(opt.out, out);
    int total = 0;
    for (const auto& om : out)
        total += int(om.second.size());
    info(g, format("propagate: %d proposed mask(s) for %d frame(s) in %s", total,
                   int(frames.size()), opt.out.c_str()));
}

} // namespace

void registerPropagate(CLI::App& app, Globals& g)
{
    auto opt = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand(
        "propagate", "propose silhouettes for chosen frames from the clones (or from coarse "
                     "mattes), snapped to the image edges; headless");
    sub->add_option("--input", opt->input, "video, image folder or printf pattern")->required();
    sub->add_option("--reconstruction", opt->reconstruction, "reconstruction.yml (with --clones)");
    sub->add_option("--clones", opt->clones, "clones file from `augocc clone`");
    sub->add_option("--mattes", opt->mattes,
                    "instead of --clones: coarse masks MATTES/<object>/%04d.png to snap");
    sub->add_option("--frames", opt->frames,
                    "frames, e.g. 5,9,20:30 (20..29), 40::5 (README, Command line; default: every "
                    "frame with a camera / a matte)");
    sub->add_option("--out", opt->out, "output masks folder MASKS/<object>/%04d.png")
        ->required();
    sub->add_option("--object", opt->objects, "only these objects (repeatable)");
    sub->add_flag("--no-snap", opt->noSnap, "write the projected outlines without snapping");
    sub->callback([opt, &g]() { runPropagate(*opt, g); });
}

} // namespace augocc_cli
