// augocc synth: writes a synthesized data set with its ground truth (doc/synthesizer.md).

#include "cli_common.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include "opencv2/augocc.hpp"

namespace fs = std::filesystem;
using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

namespace {

// Flags start at the library's defaults (SceneSynthesizer::Params), which the help text shows.
const SceneSynthesizer::Params kDefaults;

struct SynthOptions
{
    std::string out;
    std::string model = cameraModelName(kDefaults.model);
    int frames = kDefaults.frames;
    unsigned long long seed = kDefaults.seed;
    double noise = kDefaults.noiseSigma;
    double partial = kDefaults.partialFraction;
    double outliers = kDefaults.outlierFraction;
    std::string size = format("%dx%d", kDefaults.imageSize.width, kDefaults.imageSize.height);
    int tracks = kDefaults.numTracks;
    int keyFrames = -1;  // default: min(kDefaults.numKeyFrames, frames)
    double distanceRatio = kDefaults.distanceRatio;
    int supersample = kDefaults.frameSupersample;
    double orbit = kDefaults.orbitDegrees;
    double elevation = kDefaults.elevationDegrees;
    std::string contactSheet;
    std::string distortion;
    std::string path = "orbit";
    double exposureDrift = kDefaults.exposureDrift;
    double whiteBalanceDrift = kDefaults.whiteBalanceDrift;
    double bitrate = kDefaults.videoBitrateMbps;
};

// Contact sheet: frames shown, columns, thumbnail width, outline colours per object (BGR).
const int kSheetFrames = 8;
const int kSheetColumns = 4;
const int kSheetThumbWidth = 320;
const Scalar kOutlineColours[] = {Scalar(0, 0, 255), Scalar(0, 220, 0), Scalar(255, 80, 0),
                                  Scalar(0, 220, 255), Scalar(255, 0, 255), Scalar(255, 255, 0)};

// "k1,k2,p1,p2[,k3...]": OpenCV's coefficients, 4, 5, 8, 12 or 14 of them (the library checks
// the count and says which).
std::vector<double> parseDistortion(const std::string& s)
{
    std::vector<double> d;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ','))
    {
        char* end = nullptr;
        const double v = std::strtod(item.c_str(), &end);
        if (item.empty() || end == item.c_str() || *end != 0 || !std::isfinite(v))
            throw UsageError("--distortion " + s + ": expected comma-separated numbers "
                             "k1,k2,p1,p2[,k3...], e.g. -0.12,0,0,0,0");
        d.push_back(v);
    }
    return d;
}

// The frames are rendered again (the data set is written as rendered, not held).
Mat contactSheet(const SceneSynthesizer& synth)
{
    const int F = synth.getParams().frames;
    const int n = std::min(kSheetFrames, F);
    std::vector<Mat> images;
    std::vector<String> captions;
    for (int k = 0; k < n; k++)
    {
        const int f = n > 1 ? (int)std::lround((double)k * (F - 1) / (n - 1)) : 0;
        Mat img;
        std::vector<Mat> whole;
        synth.renderFrame(f, img, noArray(), noArray(), whole);
        for (size_t i = 0; i < whole.size(); i++)
        {
            const Scalar col = kOutlineColours[i % (sizeof(kOutlineColours) /
                                                    sizeof(kOutlineColours[0]))];
            drawMaskOutlines(img, whole[i], col, 2);
        }
        images.push_back(img);
        captions.push_back(format("frame %d", f));
    }
    return makeContactSheet(images, captions, kSheetColumns, kSheetThumbWidth);
}

void runSynth(const Globals& g, const SynthOptions& o)
{
    SceneSynthesizer::Params p;
    try
    {
        p.model = parseCameraModel(o.model);
    }
    catch (const cv::Exception&)
    {
        throw UsageError("--model " + o.model + ": expected scaled_orthographic or perspective");
    }
    p.frames = o.frames;
    p.seed = (uint64)o.seed;
    p.noiseSigma = o.noise;
    p.partialFraction = o.partial;
    p.outlierFraction = o.outliers;
    p.imageSize = parseSize("--size", o.size);
    p.numTracks = o.tracks;
    p.numKeyFrames = o.keyFrames > 0 ? o.keyFrames
                                     : std::min(kDefaults.numKeyFrames, std::max(2, o.frames));
    p.distanceRatio = o.distanceRatio;
    p.frameSupersample = o.supersample;
    p.orbitDegrees = o.orbit;
    p.elevationDegrees = o.elevation;
    if (!o.distortion.empty())
        p.distortion = parseDistortion(o.distortion);
    if (o.path == "handheld")
        p.path = SceneSynthesizer::PATH_HANDHELD;
    else if (o.path != "orbit")
        throw UsageError("--path " + o.path + ": expected orbit or handheld");
    p.exposureDrift = o.exposureDrift;
    p.whiteBalanceDrift = o.whiteBalanceDrift;
    p.videoBitrateMbps = o.bitrate;
    ProgressPrinter progress(g);
    p.progress = progress.callback();
    Ptr<SceneSynthesizer> synth;
    try
    {
        synth = SceneSynthesizer::create(p);
    }
    catch (const cv::Exception& e)
    {
        // Name the flag behind the rejected parameter.
        static const std::pair<const char*, const char*> kFlags[] = {
            {"frames", "--frames"}, {"imageSize", "--size"}, {"noiseSigma", "--noise"},
            {"partialFraction", "--partial"}, {"outlierFraction", "--outliers"},
            {"numTracks", "--tracks"}, {"numKeyFrames", "--key-frames"},
            {"distanceRatio", "--distance-ratio"}, {"frameSupersample", "--supersample"},
            {"orbitDegrees", "--orbit"}, {"elevationDegrees", "--elevation"},
            {"distortion", "--distortion"}, {"path", "--path"},
            {"exposureDrift", "--exposure-drift"},
            {"whiteBalanceDrift", "--white-balance-drift"}, {"videoBitrateMbps", "--bitrate"}};
        std::string flag;
        for (const auto& kv : kFlags)
            if (e.err.find(std::string(kv.first) + " must") != std::string::npos ||
                e.err.find(std::string(kv.first) + " needs") != std::string::npos ||
                e.err.find(std::string(kv.first) + ":") != std::string::npos)
                flag = std::string(kv.second) + ": ";
        throw UsageError("synth: " + flag + e.err);
    }

    const fs::path outDir(o.out);
    std::error_code ec;
    if (outDir.has_parent_path())
        fs::create_directories(outDir.parent_path(), ec);
    if (ec)
        throw UsageError("--out " + o.out + ": cannot create its parent folder: " + ec.message());
    info(g, "synthesizing " + std::to_string(p.frames) + " frames (" + o.model + ", seed " +
                std::to_string(o.seed) + ")");
    // Rendered and written frame by frame (memory does not grow with the shot); the whole
    // folder is built under a temporary name and renamed into place: a failure leaves no
    // partial DIR (an existing DIR is replaced only on success).
    synth->write(o.out);
    progress.finish();
    if (!o.contactSheet.empty())
    {
        const Mat sheet = contactSheet(*synth);
        const fs::path sheetPath(o.contactSheet);
        if (sheetPath.has_parent_path())
            fs::create_directories(sheetPath.parent_path(), ec);
        if (ec)
            throw UsageError("--contact-sheet " + o.contactSheet + ": cannot create its folder: " +
                             ec.message());
        writeImageAtomically(o.contactSheet, sheet);  // every write checked (a full disk)
        info(g, "contact sheet: " + o.contactSheet);
    }
    info(g, "wrote " + o.out);
}

} // namespace

void registerSynth(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<SynthOptions>();
    CLI::App* sub = app.add_subcommand(
        "synth", "write a synthesized data set: frames, video, key-frame masks, ground truth");
    sub->add_option("--out", o->out, "output folder (replaced if it exists)")->required();
    sub->add_option("--model", o->model, "scaled_orthographic | perspective")
        ->capture_default_str();
    sub->add_option("--frames", o->frames, "number of frames")->capture_default_str();
    sub->add_option("--seed", o->seed, "random seed")->capture_default_str();
    sub->add_option("--noise", o->noise, "Gaussian pixel noise of tracks.yml (sigma per axis)")
        ->capture_default_str();
    sub->add_option("--partial", o->partial, "fraction of tracks observed on a sub-range")
        ->capture_default_str();
    sub->add_option("--outliers", o->outliers, "fraction of gross-outlier tracks")
        ->capture_default_str();
    sub->add_option("--size", o->size, "frame size WIDTHxHEIGHT")->capture_default_str();
    sub->add_option("--tracks", o->tracks, "number of tracks")->capture_default_str();
    sub->add_option("--key-frames", o->keyFrames,
                    format("key frames, evenly spaced, first and last included (default min(%d, "
                           "frames))", kDefaults.numKeyFrames));
    sub->add_option("--distance-ratio", o->distanceRatio,
                    "perspective: camera distance / scene size")->capture_default_str();
    sub->add_option("--orbit", o->orbit, "azimuth swept by the camera, degrees")
        ->capture_default_str();
    sub->add_option("--elevation", o->elevation, "mean camera elevation, degrees")
        ->capture_default_str();
    sub->add_option("--supersample", o->supersample,
                    "render frames K x K times finer and average down (anti-aliased)")
        ->capture_default_str();
    sub->add_option("--distortion", o->distortion,
                    "lens distortion k1,k2,p1,p2[,k3...] (OpenCV's model; perspective only)");
    sub->add_option("--path", o->path, "camera path: orbit (far, smooth) or handheld (street "
                    "level, sway, wobble and roll; perspective only)")->capture_default_str();
    sub->add_option("--exposure-drift", o->exposureDrift,
                    "auto-exposure: frame gain ramps from 1 to 1 + this over the shot")
        ->capture_default_str();
    sub->add_option("--white-balance-drift", o->whiteBalanceDrift,
                    "white balance: red gain 1 + w, blue 1 - w, w ramping from 0 to this")
        ->capture_default_str();
    sub->add_option("--bitrate", o->bitrate, "video.mp4 bit rate, Mbit/s (H.264 by the ffmpeg "
                    "tool; a phone's 8-16 at 1080p); 0 = OpenCV's writer")->capture_default_str();
    sub->add_option("--contact-sheet", o->contactSheet,
                    "also write a PNG of 8 frames with the GT silhouettes outlined");
    sub->callback([&g, o]() { runSynth(g, *o); });
}

} // namespace augocc_cli
