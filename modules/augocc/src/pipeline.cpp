// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Sequence compositing with all-or-nothing outputs, and the scores against a ground truth.

#include "precomp.hpp"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

bool isVideoPath(const String& path)
{
    String e = fs::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
    return e == ".mp4" || e == ".avi" || e == ".mkv" || e == ".mov" || e == ".m4v";
}

// A temporary sibling of `path` with the same extension (video writers pick the container from
// it), renamed onto `path` by commit(); removed on destruction otherwise.
class PendingOutput
{
public:
    explicit PendingOutput(const String& path) : path_(path)
    {
        fs::path p(path);
        if (p.has_parent_path())
            fs::create_directories(p.parent_path());
        const String name = "." + p.stem().string() +
                            cv::format(".tmp%d", (int)(cv::getTickCount() & 0xffffff)) +
                            p.extension().string();
        tmp_ = (p.parent_path() / name).string();
    }
    ~PendingOutput()
    {
        if (!committed_)
        {
            std::error_code ec;
            fs::remove_all(tmp_, ec);
        }
    }
    const String& tmp() const { return tmp_; }
    void commit()
    {
        std::error_code ec;
        if (fs::exists(path_))
            fs::remove_all(path_, ec);
        fs::rename(tmp_, path_, ec);
        if (ec)
            CV_Error(Error::StsError, path_ + ": cannot rename from " + tmp_ + ": " + ec.message());
        committed_ = true;
    }

private:
    String path_, tmp_;
    bool committed_ = false;
};

void writeImage(const String& file, const Mat& img)
{
    if (!cv::imwrite(file, img))
        CV_Error(Error::StsError, file + ": cannot write image");
}

VideoWriter openVideo(const String& tmp, const String& shown, double fps, Size size)
{
    VideoWriter writer;
    // H.264 first (plays everywhere), MPEG-4 part 2 when this FFmpeg cannot encode it.
    for (const char* cc : {"avc1", "H264", "mp4v"})
    {
        writer.open(tmp, CAP_FFMPEG, VideoWriter::fourcc(cc[0], cc[1], cc[2], cc[3]), fps, size,
                    true);
        if (writer.isOpened())
            return writer;
    }
    CV_Error(Error::StsError, shown + ": cannot open a video writer (H.264 or mp4v)");
}

// Depth range of the 16-bit depth output, fixed for the sequence (first frame, 50% margin).
struct DepthEncoding
{
    double offset = 0, scale = 1;
    bool ready = false;
};

Mat encodeDepth(const Mat& z, DepthEncoding& enc)
{
    if (!enc.ready)
    {
        Mat finite = z < std::numeric_limits<float>::infinity();
        double lo = 0, hi = 1;
        if (cv::countNonZero(finite) > 0)
            cv::minMaxLoc(z, &lo, &hi, nullptr, nullptr, finite);
        const double range = std::max(hi - lo, 1e-9);
        enc.offset = lo - 0.5 * range;
        enc.scale = 65534.0 / (2.0 * range);
        enc.ready = true;
    }
    Mat out(z.size(), CV_16U);
    for (int y = 0; y < z.rows; y++)
    {
        const float* s = z.ptr<float>(y);
        ushort* d = out.ptr<ushort>(y);
        for (int x = 0; x < z.cols; x++)
            d[x] = std::isfinite(s[x])
                       ? (ushort)std::min(65535.0, std::max(1.0, std::round((s[x] - enc.offset) *
                                                                            enc.scale) + 1))
                       : 0;
    }
    return out;
}

} // namespace

void parseFrameRange(const String& text, int& firstFrame, int& endFrame)
{
    auto parseInt = [&](const String& s, int& v) {
        if (s.empty())
            return false;
        size_t pos = 0;
        try
        {
            v = std::stoi(s, &pos);
        }
        catch (const std::exception&)
        {
            return false;
        }
        return pos == s.size();
    };
    const size_t colon = text.find(':');
    bool ok;
    if (colon == String::npos)
    {
        ok = parseInt(text, firstFrame);
        endFrame = firstFrame + 1;
    }
    else
    {
        ok = parseInt(text.substr(0, colon), firstFrame);
        const String rest = text.substr(colon + 1);
        if (rest.empty())
            endFrame = -1;
        else
            ok = ok && parseInt(rest, endFrame);
    }
    if (!ok || firstFrame < 0 || (endFrame != -1 && endFrame <= firstFrame))
        CV_Error(Error::StsBadArg, "frame range '" + text + "': expected a:b with 0 <= a < b, "
                 "a: or a");
}

int compositeSequence(const String& input, const Reconstruction& rec, const CloneSet& clones,
                      const std::vector<Mesh>& virtualObjects, const String& output,
                      const CompositeOptions& options)
{
    if (output.empty())
        CV_Error(Error::StsBadArg, "no output given");
    Ptr<FrameSource> src = FrameSource::open(input);
    const int count = src->count();
    const int first = options.firstFrame;
    const int end = options.endFrame < 0 ? count : options.endFrame;
    if (first < 0 || first >= end || end > count)
        CV_Error(Error::StsOutOfRange, input + cv::format(": frames %d:%d out of range, the input "
                 "has %d frames (0:%d)", first, end, count, count));
    rec.validate("reconstruction");
    if (rec.imageSize != src->size())
        CV_Error(Error::StsBadSize, input + cv::format(": frames are %dx%d but the reconstruction's "
                 "image_size is %dx%d", src->size().width, src->size().height,
                 rec.imageSize.width, rec.imageSize.height));
    if (!rec.cameras.empty() && rec.cameras.back().frame >= count)
        CV_Error(Error::StsBadArg, input + cv::format(": the reconstruction has a camera for frame "
                 "%d but the input has %d frames: they do not belong together",
                 rec.cameras.back().frame, count));
    for (int f = first; f < end; f++)
        if (rec.findCamera(f) < 0)
            CV_Error(Error::StsBadArg, cv::format("reconstruction: frame %d has no camera", f));

    const bool video = isVideoPath(output);
    PendingOutput out(output);
    std::unique_ptr<PendingOutput> mattesOut, depthOut, layerOut;
    if (!options.mattesDir.empty())
        mattesOut.reset(new PendingOutput(options.mattesDir));
    if (!options.depthDir.empty())
        depthOut.reset(new PendingOutput(options.depthDir));
    if (!options.virtualLayerDir.empty())
        layerOut.reset(new PendingOutput(options.virtualLayerDir));
    if (!video)
        fs::create_directories(out.tmp());
    const std::vector<String> objects = clones.objectNames();
    if (mattesOut)
        for (const String& o : objects)
            fs::create_directories(fs::path(mattesOut->tmp()) / o);
    if (depthOut)
        fs::create_directories(depthOut->tmp());
    if (layerOut)
        fs::create_directories(layerOut->tmp());

    Compositor::Params cp;
    cp.supersample = options.supersample;
    Ptr<Compositor> comp = Compositor::create(cp);
    comp->setVirtualObjects(virtualObjects);
    VideoWriter writer;
    if (video)
        writer = openVideo(out.tmp(), output, options.fps > 0 ? options.fps : src->fps(),
                           src->size());
    DepthEncoding enc;
    src->seek(first);
    Mat frame, result, layer, depth, matte;
    for (int f = first; f < end; f++)
    {
        if (!src->read(frame))
            CV_Error(Error::StsParseError, input + cv::format(": cannot decode frame %d (the "
                     "input ends early or is corrupt)", f));
        const Camera& cam = rec.camera(f);
        comp->composite(frame, f, cam, clones, result,
                        layerOut ? _OutputArray(layer) : _OutputArray(noArray()),
                        depthOut ? _OutputArray(depth) : _OutputArray(noArray()));
        const String name = cv::format("%04d.png", f);
        if (video)
            writer.write(result);
        else
            writeImage((fs::path(out.tmp()) / name).string(), result);
        if (layerOut)
            writeImage((fs::path(layerOut->tmp()) / name).string(), layer);
        if (depthOut)
            writeImage((fs::path(depthOut->tmp()) / name).string(), encodeDepth(depth, enc));
        if (mattesOut)
            for (const String& o : objects)
            {
                clones.render(o, f, cam, rec.imageSize, matte);
                writeImage((fs::path(mattesOut->tmp()) / o / name).string(), matte);
            }
        if (options.progress)
            options.progress(f - first + 1, end - first);
    }
    if (video)
        writer.release();
    if (depthOut)
    {
        FileStorage fsd((fs::path(depthOut->tmp()) / "depth.yml").string(), FileStorage::WRITE);
        fsd << "description" << "z = (value - 1) / scale + offset; value 0 = nothing";
        fsd << "scale" << enc.scale << "offset" << enc.offset;
    }
    out.commit();
    if (mattesOut)
        mattesOut->commit();
    if (depthOut)
        depthOut->commit();
    if (layerOut)
        layerOut->commit();
    return end - first;
}

// ---------------------------------------------------------------------------------------------
// Scores

namespace {

Mat binary(InputArray a, const char* what, Size size)
{
    Mat m = a.getMat();
    if (m.type() != CV_8UC1 || m.size() != size)
        CV_Error(Error::StsBadArg, String("scoreComposite: ") + what + " must be CV_8U of the "
                 "composite's size");
    return m > 127;
}

// Inner boundary: pixels of the mask with a 4-neighbour outside it.
Mat innerBoundary(const Mat& mask)
{
    Mat eroded;
    cv::erode(mask, eroded, getStructuringElement(MORPH_CROSS, Size(3, 3)), Point(-1, -1), 1,
              BORDER_CONSTANT, Scalar(0));
    return mask & ~eroded;
}

} // namespace

CompositeScore scoreComposite(InputArray compositeArr, InputArray truthArr, InputArray visibleArr,
                              InputArray visibleTruthArr, InputArray silhouetteArr,
                              int greyTolerance, int bandRadius)
{
    Mat comp = compositeArr.getMat(), truth = truthArr.getMat();
    CV_CheckTypeEQ(comp.type(), CV_8UC3, "composite");
    CV_CheckTypeEQ(truth.type(), CV_8UC3, "ground truth");
    CV_CheckEQ(comp.size(), truth.size(), "composite and ground truth sizes");
    const Size sz = comp.size();
    const Mat vis = binary(visibleArr, "visible", sz);
    const Mat visT = binary(visibleTruthArr, "visibleTruth", sz);
    const Mat sil = binary(silhouetteArr, "silhouette", sz);
    CompositeScore s;

    Mat g1, g2, diff;
    cv::cvtColor(comp, g1, COLOR_BGR2GRAY);
    cv::cvtColor(truth, g2, COLOR_BGR2GRAY);
    cv::absdiff(g1, g2, diff);
    s.fractionWithin = (double)cv::countNonZero(diff <= greyTolerance) / (double)sz.area();

    // Occlusion boundaries: visible boundary away from the silhouette's own boundary.
    Mat silEdge;
    cv::dilate(innerBoundary(sil), silEdge, Mat(), Point(-1, -1), 1);
    const Mat bT = innerBoundary(visT) & ~silEdge;
    const Mat b = innerBoundary(vis) & ~silEdge;
    s.boundaryPixels = cv::countNonZero(bT);
    const int nb = cv::countNonZero(b);
    auto meanDistTo = [&](const Mat& from, const Mat& toMask) {
        Mat dist;
        const Mat toEdge = innerBoundary(toMask);
        if (cv::countNonZero(toEdge) == 0)
            return std::sqrt((double)sz.area());  // nothing to match: as far as it gets
        cv::distanceTransform(~toEdge, dist, DIST_L2, DIST_MASK_PRECISE);
        return cv::mean(dist, from)[0];
    };
    if (s.boundaryPixels == 0 && nb == 0)
        s.boundaryDistance = 0;
    else
    {
        double sum = 0, n = 0;
        if (nb > 0)
        {
            sum += meanDistTo(b, visT) * nb;
            n += nb;
        }
        if (s.boundaryPixels > 0)
        {
            sum += meanDistTo(bT, vis) * s.boundaryPixels;
            n += s.boundaryPixels;
        }
        s.boundaryDistance = sum / n;
    }

    // Band around the true occlusion boundary.
    Mat band;
    const int r = std::max(0, bandRadius);
    cv::dilate(bT, band, getStructuringElement(MORPH_ELLIPSE, Size(2 * r + 1, 2 * r + 1)));
    s.bandPixels = cv::countNonZero(band);
    if (s.bandPixels > 0)
    {
        Mat cdiff;
        cv::absdiff(comp, truth, cdiff);
        const Scalar m = cv::mean(cdiff, band);
        s.bandError = (m[0] + m[1] + m[2]) / 3.0;
    }
    return s;
}

} // namespace augocc
} // namespace cv
