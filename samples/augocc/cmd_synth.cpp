// augocc synth: writes a synthesized data set with its ground truth (doc/synthesizer.md).

#include "cli_common.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include "opencv2/augocc.hpp"

namespace fs = std::filesystem;
using namespace cv;
using namespace cv::augocc;

namespace augocc_cli {

namespace {

struct SynthOptions
{
    std::string out;
    std::string model = "scaled_orthographic";
    int frames = 60;
    unsigned long long seed = 1;
    double noise = 0.5;
    double partial = 0.0;
    double outliers = 0.0;
    std::string size = "640x480";
    int tracks = 600;
    int keyFrames = -1;  // default: min(6, frames)
    double distanceRatio = 10.0;
    int supersample = 1;
    double orbit = 50.0;
    double elevation = 25.0;
    std::string contactSheet;
};

const double kVideoFps = 25.0;
// Contact sheet: frames shown, columns, thumbnail width, outline colours per object (BGR).
const int kSheetFrames = 8;
const int kSheetColumns = 4;
const int kSheetThumbWidth = 320;
const Scalar kOutlineColours[] = {Scalar(0, 0, 255), Scalar(0, 220, 0), Scalar(255, 80, 0),
                                  Scalar(0, 220, 255), Scalar(255, 0, 255), Scalar(255, 255, 0)};

Size parseSize(const std::string& s)
{
    int w = 0, h = 0;
    char x = 0;
    if (std::sscanf(s.c_str(), "%d%c%d", &w, &x, &h) != 3 || (x != 'x' && x != 'X') || w <= 0 ||
        h <= 0)
        throw UsageError("--size " + s + ": expected WIDTHxHEIGHT, e.g. 640x480");
    return Size(w, h);
}

void writeImage(const std::string& path, const Mat& img)
{
    if (!imwrite(path, img))
        CV_Error(Error::StsError, path + ": cannot write");
}

void writeVideo(const std::string& path, const std::vector<Mat>& frames)
{
    // H.264 first (plays everywhere), MPEG-4 part 2 when this FFmpeg has no H.264 encoder.
    VideoWriter writer;
    for (const char* cc : {"avc1", "H264", "mp4v"})
    {
        writer.open(path, VideoWriter::fourcc(cc[0], cc[1], cc[2], cc[3]), kVideoFps,
                    frames[0].size());
        if (writer.isOpened())
            break;
    }
    if (!writer.isOpened())
        CV_Error(Error::StsError, path + ": no video encoder (H.264 or MPEG-4) could be opened");
    for (const Mat& f : frames)
        writer.write(f);
    writer.release();
}

// Depth as 16-bit PNG: value = round(z * scale), 0 where nothing; scale a power of ten chosen so
// that the farthest depth fits, written to depth.yml beside the images.
void writeDepth(const fs::path& dir, const std::vector<Mat>& depth)
{
    fs::create_directories(dir);
    double maxZ = 0;
    for (const Mat& d : depth)
        for (int y = 0; y < d.rows; y++)
        {
            const float* row = d.ptr<float>(y);
            for (int x = 0; x < d.cols; x++)
                if (std::isfinite(row[x]))
                    maxZ = std::max(maxZ, (double)row[x]);
        }
    double scale = 1;
    while (maxZ * scale * 10 < 65000 && scale < 1e6)
        scale *= 10;
    while (maxZ * scale >= 65000 && scale > 1e-6)
        scale /= 10;
    {
        FileStorage fs((dir / "depth.yml").string(), FileStorage::WRITE);
        fs << "scale" << scale;
        fs << "description" << "camera-space z = value / scale; 0 = nothing (infinite)";
    }
    parallel_for_(Range(0, (int)depth.size()), [&](const Range& r) {
        for (int f = r.start; f < r.end; f++)
        {
            Mat z = depth[f].clone();
            z.setTo(0, z == std::numeric_limits<float>::infinity());
            Mat png;
            z.convertTo(png, CV_16U, scale);
            writeImage((dir / format("%04d.png", f)).string(), png);
        }
    });
}

Mat contactSheet(const SyntheticScene& scene)
{
    const int F = (int)scene.frames.size();
    const int n = std::min(kSheetFrames, F);
    std::vector<Mat> images;
    std::vector<String> captions;
    for (int k = 0; k < n; k++)
    {
        const int f = n > 1 ? (int)std::lround((double)k * (F - 1) / (n - 1)) : 0;
        Mat img = scene.frames[f].clone();
        for (size_t i = 0; i < scene.objectNames.size(); i++)
        {
            const Scalar col = kOutlineColours[i % (sizeof(kOutlineColours) /
                                                    sizeof(kOutlineColours[0]))];
            drawMaskOutlines(img, scene.wholeMasks.at(scene.objectNames[i]).at(f), col, 2);
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
    p.imageSize = parseSize(o.size);
    p.numTracks = o.tracks;
    p.numKeyFrames = o.keyFrames > 0 ? o.keyFrames : std::min(6, std::max(2, o.frames));
    p.distanceRatio = o.distanceRatio;
    p.frameSupersample = o.supersample;
    p.orbitDegrees = o.orbit;
    p.elevationDegrees = o.elevation;
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
            {"orbitDegrees", "--orbit"}, {"elevationDegrees", "--elevation"}};
        std::string flag;
        for (const auto& kv : kFlags)
            if (e.err.find(std::string(kv.first) + " must") != std::string::npos)
                flag = std::string(kv.second) + ": ";
        throw UsageError("synth: " + flag + e.err);
    }

    info(g, "synthesizing " + std::to_string(p.frames) + " frames (" + o.model + ", seed " +
                std::to_string(o.seed) + ")");
    SyntheticScene scene;
    synth->synthesize(scene);

    const fs::path outDir(o.out);
    if (outDir.has_parent_path())
        fs::create_directories(outDir.parent_path());
    Progress progress(g, "writing", (int)scene.frames.size());
    // The whole folder is built under a temporary name and renamed into place: a failure leaves
    // no partial DIR (an existing DIR is replaced only on success).
    writeAtomically(o.out, [&](const String& tmpPath) {
        const fs::path tmp(tmpPath);
        fs::create_directories(tmp / "frames");
        fs::create_directories(tmp / "gt" / "labels");
        // PNG encoding dominates: frames and labels in parallel (each chunk its own files).
        const int F = (int)scene.frames.size();
        const int chunk = 8;
        for (int start = 0; start < F; start += chunk)
        {
            const int end = std::min(F, start + chunk);
            parallel_for_(Range(start, end), [&](const Range& r) {
                for (int f = r.start; f < r.end; f++)
                {
                    writeImage((tmp / "frames" / format("%04d.png", f)).string(),
                               scene.frames[f]);
                    writeImage((tmp / "gt" / "labels" / format("%04d.png", f)).string(),
                               scene.labels[f]);
                }
            });
            progress.update(end);
        }
        writeVideo((tmp / "video.mp4").string(), scene.frames);
        fs::create_directories(tmp / "input");
        fs::create_directories(tmp / "gt");
        writeMasks((tmp / "input" / "masks").string(), scene.keyFrameMasks);
        writeMasks((tmp / "gt" / "masks").string(), scene.wholeMasks);
        writeMasks((tmp / "gt" / "visible_masks").string(), scene.visibleMasks);
        writeReconstruction((tmp / "gt" / "reconstruction.yml").string(), scene.groundTruth);
        writeTracks((tmp / "tracks.yml").string(), scene.tracks);
        writeTracks((tmp / "gt" / "clean_tracks.yml").string(), scene.cleanTracks);
        writeDepth(tmp / "gt" / "depth", scene.depth);
        fs::create_directories(tmp / "gt" / "meshes");
        for (size_t i = 0; i < scene.objectNames.size(); i++)
            writeMeshPly((tmp / "gt" / "meshes" / (scene.objectNames[i] + ".ply")).string(),
                         scene.objectMeshes[i]);
        FileStorage fs((tmp / "gt" / "synth.yml").string(), FileStorage::WRITE);
        fs << "model" << cameraModelName(p.model);
        fs << "frames" << p.frames;
        fs << "seed" << format("%llu", o.seed);
        fs << "noise_sigma" << p.noiseSigma;
        fs << "partial_fraction" << p.partialFraction;
        fs << "outlier_fraction" << p.outlierFraction;
        fs << "distance_ratio" << p.distanceRatio;
        fs << "frame_supersample" << p.frameSupersample;
        fs << "orbit_degrees" << p.orbitDegrees;
        fs << "elevation_degrees" << p.elevationDegrees;
        fs << "objects" << "[";
        for (const String& name : scene.objectNames)
            fs << name;
        fs << "]";
        fs << "key_frames" << Mat(scene.keyFrames).reshape(1, 1);
        fs << "outlier_tracks" << Mat(scene.outlierTrack).reshape(1, 1);
        fs.release();
    });
    progress.finish();
    if (!o.contactSheet.empty())
    {
        const Mat sheet = contactSheet(scene);
        const fs::path sheetPath(o.contactSheet);
        if (sheetPath.has_parent_path())
            fs::create_directories(sheetPath.parent_path());
        writeAtomically(o.contactSheet, [&](const String& tmp) { writeImage(tmp, sheet); });
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
                    "key frames, evenly spaced, first and last included (default min(6, frames))");
    sub->add_option("--distance-ratio", o->distanceRatio,
                    "perspective: camera distance / scene size")->capture_default_str();
    sub->add_option("--orbit", o->orbit, "azimuth swept by the camera, degrees")
        ->capture_default_str();
    sub->add_option("--elevation", o->elevation, "mean camera elevation, degrees")
        ->capture_default_str();
    sub->add_option("--supersample", o->supersample,
                    "render frames K x K times finer and average down (anti-aliased)")
        ->capture_default_str();
    sub->add_option("--contact-sheet", o->contactSheet,
                    "also write a PNG of 8 frames with the GT silhouettes outlined");
    sub->callback([&g, o]() { runSynth(g, *o); });
}

} // namespace augocc_cli
