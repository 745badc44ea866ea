// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// writeSyntheticScene(): a synthesized data set on disk (the layout of `augocc synth`,
// doc/synthesizer.md).

#include "precomp.hpp"

#include "atomic_write.hpp"
#include "synthetic_scene_io.hpp"
#include "video_out.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

extern char** environ;  // POSIX: the environment handed to ffmpeg

namespace cv {
namespace augocc {

namespace {

namespace fs = std::filesystem;

const double kVideoFps = 25.0;
// Frames rendered, then encoded in parallel, per batch (progress is reported between batches):
// at most kWriteBatch, and at most kWriteBatchPixels pixels in all (a frame with its truth holds
// about 14 bytes a pixel: 8 frames of 3840x2160 peaked at 3.2 GB).
const int kWriteBatch = 8;
const double kWriteBatchPixels = 8.0 * 1920 * 1080;

void writeImage(const String& path, const Mat& img)
{
    detail::writeImageFile(path, img, path);
}

/* video.mp4 at a set bit rate: H.264 by libx264 through the `ffmpeg` tool (Debian's ffmpeg,
installed by scripts/setup.sh), reading the frames/%04d.png just written. OpenCV 4.6's
VideoWriter cannot set a bit rate: its FFmpeg backend fixes the rate from the frame size and
ignores VIDEOWRITER_PROP_QUALITY for H.264; the only other door, the process-wide environment
variable OPENCV_FFMPEG_WRITER_OPTIONS, is not thread-safe to set from a library. libavcodec
directly would be ~200 lines of encoder plumbing for one synthetic-data option; the tool is one
process with a documented command line. Rate control as a phone's encoder: average rate R with
a VBV of maxrate R and a buffer of 2 R (near-constant bit rate), 4:2:0, High profile. */
void writeVideoAtBitrate(const fs::path& framesDir, const String& path, int frames, double mbps)
{
    detail::checkCreatable(path, path);
    const std::string rate = format("%.0fk", mbps * 1000);
    const std::string buf = format("%.0fk", 2 * mbps * 1000);
    std::vector<std::string> args = {
        "ffmpeg", "-hide_banner", "-nostdin", "-loglevel", "error", "-y",
        "-framerate", format("%g", kVideoFps), "-start_number", "0",
        "-i", (framesDir / "%04d.png").string(), "-frames:v", std::to_string(frames),
        "-c:v", "libx264", "-preset", "medium", "-profile:v", "high", "-pix_fmt", "yuv420p",
        "-b:v", rate, "-maxrate", rate, "-bufsize", buf, "-movflags", "+faststart", path};
    std::vector<char*> argv;
    for (std::string& a : args)
        argv.push_back(&a[0]);
    argv.push_back(nullptr);
    // ffmpeg's stderr goes to a log beside the video, read back on failure.
    const std::string logPath = path + ".log";
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, "ffmpeg", &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0)
    {
        std::remove(logPath.c_str());
        CV_Error(Error::StsError, path + ": cannot run the ffmpeg tool for the H.264 bit rate "
                 "(videoBitrateMbps): " + std::string(strerror(rc)) + "; scripts/setup.sh "
                 "installs it (Debian package ffmpeg)");
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
    {
    }
    std::ifstream logFile(logPath);
    std::stringstream log;
    log << logFile.rdbuf();
    logFile.close();
    std::remove(logPath.c_str());
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        CV_Error(Error::StsError, path + ": ffmpeg (libx264 at " + rate + "bit/s) failed: " +
                 log.str());
    detail::checkVideoFile(path, frames, path);
}

// calibration.yml: the true intrinsics in OpenCV's calibration format (CONTRACT.md), as a
// calibrateCamera user writes them; no lens = five zero coefficients, as calibrateCamera writes.
void writeCalibration(const String& path, const Camera& cam, Size size)
{
    detail::writeStorageFile(path, [&](FileStorage& fs) {
        fs << "image_width" << size.width;
        fs << "image_height" << size.height;
        fs << "camera_matrix" << Mat(cam.K);
        std::vector<double> d = cam.distortion;
        if (d.empty())
            d.assign(5, 0.0);
        fs << "distortion_coefficients" << Mat(d).reshape(1, 1);
    }, path);
}

/* Depth as 16-bit PNG: value = round(z * scale), 0 where nothing; scale a power of ten chosen so
that the farthest depth fits with 1 to 10 times headroom (the defaults: 100, 1 cm steps), written
to depth.yml beside the images. `maxDepth` bounds the depths: their maximum when the whole scene
is in memory; when it is written as rendered, the farthest corner of the scene's bounds from any
camera, which can cost one decade of precision. */
double depthScale(double maxDepth)
{
    double scale = 1;
    while (maxDepth * scale * 10 < 65000 && scale < 1e6)
        scale *= 10;
    while (maxDepth * scale >= 65000 && scale > 1e-6)
        scale /= 10;
    return scale;
}

void writeDepthImage(const String& path, const Mat& depth, double scale)
{
    Mat z = depth.clone();
    z.setTo(0, z == std::numeric_limits<float>::infinity());
    Mat png;
    z.convertTo(png, CV_16U, scale);
    writeImage(path, png);
}

} // namespace

namespace detail {

void writeSyntheticScene(const String& dir, const std::vector<String>& names,
                         const SceneSynthesizer::Params& p, int F, double maxDepth,
                         const std::function<void(int, SyntheticFrame&)>& frame,
                         const std::function<const SyntheticScene&()>& rest,
                         const ProgressCallback& progress)
{
    if (F <= 0)
        CV_Error(Error::StsBadArg, dir + ": writeSyntheticScene: the scene has no frame");
    for (const String& name : names)
        if (name.empty() || name.find('/') != String::npos)
            CV_Error(Error::StsBadArg, dir + ": writeSyntheticScene: invalid object name '" +
                     name + "'");
    const size_t nObj = names.size();
    const double scale = depthScale(maxDepth);
    String staged;  // the temporary folder writeAtomically builds DIR in
    try
    {
        const fs::path target(dir);
        if (target.has_parent_path())
            fs::create_directories(target.parent_path());
        writeAtomically(dir, [&](const String& tmpPath) {
            staged = tmpPath;
            const fs::path tmp(tmpPath);
            for (const char* sub : {"frames", "gt/labels", "gt/depth"})
                fs::create_directories(tmp / sub);
            for (const char* sub : {"gt/masks", "gt/visible_masks"})
                for (const String& name : names)
                    fs::create_directories(tmp / sub / name);
            const String videoPath = (tmp / "video.mp4").string();
            VideoWriter video;  // without a bit rate: fed as the frames come
            // A batch rendered from this thread, then its PNGs encoded in parallel (encoding
            // dominates; each frame its own files): memory holds one batch.
            const Size frameSize = p.imageSize;
            const int perBatch = std::max(1, std::min(kWriteBatch, (int)(kWriteBatchPixels /
                                                      std::max(1.0, (double)frameSize.area()))));
            std::vector<SyntheticFrame> batch(perBatch);
            for (int start = 0; start < F; start += perBatch)
            {
                const int end = std::min(F, start + perBatch);
                for (int f = start; f < end; f++)
                {
                    SyntheticFrame& out = batch[f - start];
                    out = SyntheticFrame();
                    frame(f, out);
                    if (out.whole.size() != nObj || out.visible.size() != nObj)
                        CV_Error(Error::StsBadArg, cv::format("%s: writeSyntheticScene: frame "
                                 "%d has masks of %d / %d objects, expected %d", dir.c_str(), f,
                                 (int)out.whole.size(), (int)out.visible.size(), (int)nObj));
                }
                parallel_for_(Range(start, end), [&](const Range& r) {
                    for (int f = r.start; f < r.end; f++)
                    {
                        const SyntheticFrame& in = batch[f - start];
                        const String name = format("%04d.png", f);
                        writeImage((tmp / "frames" / name).string(), in.bgr);
                        writeImage((tmp / "gt" / "labels" / name).string(), in.labels);
                        writeDepthImage((tmp / "gt" / "depth" / name).string(), in.depth, scale);
                        for (size_t i = 0; i < nObj; i++)
                        {
                            writeImage((tmp / "gt" / "masks" / names[i] / name).string(),
                                       in.whole[i]);
                            writeImage((tmp / "gt" / "visible_masks" / names[i] /
                                        name).string(), in.visible[i]);
                        }
                    }
                });
                if (p.videoBitrateMbps <= 0)
                    for (int f = start; f < end; f++)
                    {
                        if (!video.isOpened())
                            video = openVideo(videoPath, videoPath, kVideoFps,
                                              batch[f - start].bgr.size());
                        video.write(batch[f - start].bgr);
                    }
                detail::reportProgress(progress, "synth", "write", end, F, "frames");
            }
            batch.clear();
            if (p.videoBitrateMbps > 0)
                writeVideoAtBitrate(tmp / "frames", videoPath, F, p.videoBitrateMbps);
            else
            {
                video.release();
                checkVideoFile(videoPath, F, videoPath);
            }
            detail::writeStorageFile((tmp / "gt" / "depth" / "depth.yml").string(),
                                     [&](FileStorage& fs) {
                fs << "scale" << scale;
                fs << "description" << "camera-space z = value / scale; 0 = nothing (infinite)";
            }, (tmp / "gt" / "depth" / "depth.yml").string());
            const SyntheticScene& scene = rest();
            if (scene.groundTruth.model == PERSPECTIVE && !scene.groundTruth.cameras.empty())
                writeCalibration((tmp / "calibration.yml").string(),
                                 scene.groundTruth.cameras.front(), scene.groundTruth.imageSize);
            fs::create_directories(tmp / "input");
            writeMasks((tmp / "input" / "masks").string(), scene.keyFrameMasks);
            writeReconstruction((tmp / "gt" / "reconstruction.yml").string(), scene.groundTruth);
            writeTracks((tmp / "tracks.yml").string(), scene.tracks);
            writeTracks((tmp / "gt" / "clean_tracks.yml").string(), scene.cleanTracks);
            fs::create_directories(tmp / "gt" / "meshes");
            for (size_t i = 0; i < scene.objectNames.size(); i++)
                writeMeshPly((tmp / "gt" / "meshes" / (scene.objectNames[i] + ".ply")).string(),
                             scene.objectMeshes[i]);
            const String synthYml = (tmp / "gt" / "synth.yml").string();
            detail::writeStorageFile(synthYml, [&](FileStorage& info) {
                info << "model" << cameraModelName(p.model);
                info << "frames" << p.frames;
                info << "seed" << format("%llu", (unsigned long long)p.seed);
                info << "noise_sigma" << p.noiseSigma;
                info << "partial_fraction" << p.partialFraction;
                info << "outlier_fraction" << p.outlierFraction;
                info << "distance_ratio" << p.distanceRatio;
                info << "frame_supersample" << p.frameSupersample;
                info << "orbit_degrees" << p.orbitDegrees;
                info << "elevation_degrees" << p.elevationDegrees;
                info << "path" << (p.path == SceneSynthesizer::PATH_HANDHELD ? "handheld"
                                                                              : "orbit");
                info << "distortion" << "[:";
                for (double d : p.distortion)
                    info << d;
                info << "]";
                info << "exposure_drift" << p.exposureDrift;
                info << "white_balance_drift" << p.whiteBalanceDrift;
                info << "video_bitrate_mbps" << p.videoBitrateMbps;
                info << "objects" << "[";
                for (const String& name : scene.objectNames)
                    info << name;
                info << "]";
                info << "key_frames" << Mat(scene.keyFrames).reshape(1, 1);
                info << "outlier_tracks" << Mat(scene.outlierTrack).reshape(1, 1);
            }, synthYml);
        });
    }
    catch (const fs::filesystem_error& e)
    {
        // Disk full, permissions...: nothing partial is left (writeAtomically cleans up).
        CV_Error(Error::StsError, dir + ": " + e.what());
    }
    catch (const cv::Exception& e)
    {
        // The writers name the file they write, inside the temporary folder: name it in DIR,
        // the folder the user asked for (the temporary is gone).
        if (staged.empty() || e.err.find(staged) == String::npos)
            throw;
        String msg = e.err;
        for (size_t at; (at = msg.find(staged)) != String::npos;)
            msg.replace(at, staged.size(), dir);
        CV_Error(e.code, msg);
    }
}

} // namespace detail

void writeSyntheticScene(const String& dir, const SyntheticScene& scene,
                         const SceneSynthesizer::Params& p,
                         const ProgressCallback& progress)
{
    const int F = (int)scene.frames.size();
    if ((int)scene.labels.size() != F || (int)scene.depth.size() != F)
        CV_Error(Error::StsBadArg, dir + ": writeSyntheticScene: frames, labels and depth differ "
                 "in count");
    double maxDepth = 0;
    for (const Mat& d : scene.depth)
    {
        double lo = 0, hi = 0;
        minMaxIdx(d, &lo, &hi, nullptr, nullptr, d < std::numeric_limits<float>::infinity());
        maxDepth = std::max(maxDepth, hi);
    }
    // Headers of the scene's own images: nothing is copied.
    auto maskOf = [&](const ObjectMasks& masks, const String& name, int f) -> Mat {
        const auto obj = masks.find(name);
        if (obj != masks.end())
        {
            const auto m = obj->second.find(f);
            if (m != obj->second.end())
                return m->second;
        }
        CV_Error(Error::StsBadArg, cv::format("%s: writeSyntheticScene: no mask of '%s' in "
                 "frame %d", dir.c_str(), name.c_str(), f));
    };
    detail::writeSyntheticScene(dir, scene.objectNames, p, F, maxDepth,
                                [&](int f, detail::SyntheticFrame& out) {
        out.bgr = scene.frames[f];
        out.labels = scene.labels[f];
        out.depth = scene.depth[f];
        for (const String& name : scene.objectNames)
        {
            out.whole.push_back(maskOf(scene.wholeMasks, name, f));
            out.visible.push_back(maskOf(scene.visibleMasks, name, f));
        }
    }, [&]() -> const SyntheticScene& { return scene; }, progress);
}

} // namespace augocc
} // namespace cv
