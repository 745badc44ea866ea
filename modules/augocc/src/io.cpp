// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "io_internal.hpp"

#include "atomic_write.hpp"
#include "frame_pattern.hpp"
#include "input_limits.hpp"

#include <atomic>
#include <cstdio>
#include <numeric>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

bool isFinite2(const Point2f& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y);
}

FileNode requireKey(const FileNode& parent, const char* key, const String& where)
{
    FileNode n = parent[key];
    if (n.empty() || n.isNone())
        CV_Error(Error::StsParseError, where + ": missing key '" + key + "'");
    return n;
}

Mat readMatKey(const FileNode& parent, const char* key, const String& where)
{
    return detail::readStorageMat(requireKey(parent, key, where), where, key);
}

int readIntKey(const FileNode& parent, const char* key, const String& where)
{
    FileNode n = requireKey(parent, key, where);
    if (!n.isInt())
        CV_Error(Error::StsParseError, where + ": key '" + key + "' must be an integer");
    return (int)n;
}

double readRealKey(const FileNode& parent, const char* key, const String& where)
{
    FileNode n = requireKey(parent, key, where);
    if (!n.isReal() && !n.isInt())
        CV_Error(Error::StsParseError, where + ": key '" + key + "' must be a number");
    return (double)n;
}

Size readImageSize(const FileNode& root, const String& where)
{
    Mat m = readMatKey(root, "image_size", where);
    if (m.total() != 2 || m.channels() != 1)
        CV_Error(Error::StsBadSize, where + ": key 'image_size' must be a 1x2 matrix [width, height]");
    Mat mi;
    m.convertTo(mi, CV_32S);
    Size sz(mi.at<int>(0), mi.at<int>(1));
    if (sz.width <= 0 || sz.height <= 0)
        CV_Error(Error::StsBadArg, where + cv::format(": key 'image_size' = [%d, %d] must be "
                 "positive", sz.width, sz.height));
    return sz;
}

template <typename M>
M readFixedMat(const FileNode& parent, const char* key, const String& where)
{
    Mat m = readMatKey(parent, key, where);
    if (m.channels() != 1 || m.rows != M::rows || m.cols != M::cols)
        CV_Error(Error::StsBadSize, where + cv::format(": key '%s' must be a %dx%d matrix, got "
                 "%dx%d with %d channel(s)", key, M::rows, M::cols, m.rows, m.cols, m.channels()));
    if (m.depth() != CV_64F && m.depth() != CV_32F)
        CV_Error(Error::StsUnsupportedFormat, where + ": key '" + key + "' must be a floating "
                 "point matrix");
    Mat md;
    m.convertTo(md, CV_64F);
    return M(md.ptr<double>());
}

} // namespace

namespace detail {

FileStorage openFileStorageForRead(const String& path, const String& what)
{
    if (!fs::is_regular_file(path))
        CV_Error(Error::StsObjectNotFound, path + ": " + what + " not found");
    checkStorageFile(path, what);
    FileStorage storage;
    try
    {
        storage.open(path, FileStorage::READ);
    }
    catch (const cv::Exception& e)
    {
        CV_Error(Error::StsParseError, path + ": cannot parse " + what + ": " + e.err);
    }
    catch (const std::exception& e)
    {
        // OpenCV 4.6's parsers also let std::length_error escape (a string key cut short by a
        // mutation: found by fuzz_reconstruction).
        CV_Error(Error::StsParseError, path + ": cannot parse " + what + ": " + e.what());
    }
    if (!storage.isOpened())
        CV_Error(Error::StsParseError, path + ": cannot open or parse " + what + " as a "
                 "FileStorage file");
    // Every augocc file is a map of keys: FileNode::operator[] asserts on anything else (found by
    // fuzz_reconstruction, fuzz_calibration and fuzz_clones).
    if (!storage.root().isMap())
        CV_Error(Error::StsParseError, path + ": " + what + ": the top level is not a map of keys");
    checkDuplicateKeys(storage.root(), path);
    return storage;
}

} // namespace detail

FileStorage openStorageForRead(const String& path, const String& what)
{
    return detail::openFileStorageForRead(path, what);
}

// ---------------------------------------------------------------------------------------------
// Tracks

Point2f Tracks::at(int f, int p) const
{
    const int i = find(f, p);
    if (i >= 0)
        return uv_[i];
    const float nan = std::numeric_limits<float>::quiet_NaN();
    return Point2f(nan, nan);
}

int Tracks::find(int f, int p) const
{
    const auto b = frame_.begin() + trackStart_[p], e = frame_.begin() + trackStart_[p + 1];
    const auto it = std::lower_bound(b, e, f);
    return it != e && *it == f ? (int)(it - frame_.begin()) : -1;
}

void Tracks::buildFrameIndex()
{
    const int N = observations();
    frameStart_.assign(frames_ + 1, 0);
    for (int i = 0; i < N; i++)
        frameStart_[frame_[i] + 1]++;
    for (int f = 0; f < frames_; f++)
        frameStart_[f + 1] += frameStart_[f];
    byFrame_.resize(N);
    std::vector<int> fill(frameStart_.begin(), frameStart_.end() - 1);
    // Observations are by point, so each frame's list comes out by increasing point.
    for (int i = 0; i < N; i++)
        byFrame_[fill[frame_[i]]++] = i;
}

Tracks Tracks::fromDense(Size imageSize, const Mat& denseIn, const String& what)
{
    if (denseIn.empty())
        CV_Error(Error::StsBadSize, what + ": key 'tracks' is empty");
    Mat dense = denseIn;
    if (dense.type() != CV_32FC2)
    {
        if (dense.channels() == 2 && dense.depth() == CV_64F)
            dense.convertTo(dense, CV_32FC2);
        else
            CV_Error(Error::StsUnsupportedFormat, what + ": key 'tracks' must be a 2f "
                     "(CV_32FC2) matrix, got " + typeToString(dense.type()));
    }
    const int F = dense.rows, P = dense.cols;
    Tracks t;
    t.imageSize = imageSize;
    t.frames_ = F;
    t.trackStart_.assign(P + 1, 0);
    for (int f = 0; f < F; f++)
    {
        const Point2f* row = dense.ptr<Point2f>(f);
        for (int p = 0; p < P; p++)
        {
            const bool nx = std::isnan(row[p].x), ny = std::isnan(row[p].y);
            if (nx && ny)
                continue;
            if (nx != ny)
                CV_Error(Error::StsBadArg, what + cv::format(": key 'tracks' (%d, %d) has one "
                         "coordinate NaN and the other not", f, p));
            if (!isFinite2(row[p]))
                CV_Error(Error::StsBadArg, what + cv::format(": key 'tracks' (%d, %d) is not "
                         "finite (only a NaN pair may mark an unobserved entry)", f, p));
            t.trackStart_[p + 1]++;
        }
    }
    for (int p = 0; p < P; p++)
        t.trackStart_[p + 1] += t.trackStart_[p];
    const int N = t.trackStart_[P];
    t.frame_.resize(N);
    t.point_.resize(N);
    t.uv_.resize(N);
    std::vector<int> fill(t.trackStart_.begin(), t.trackStart_.end() - 1);
    for (int f = 0; f < F; f++)
    {
        const Point2f* row = dense.ptr<Point2f>(f);
        for (int p = 0; p < P; p++)
            if (!std::isnan(row[p].x))
            {
                const int i = fill[p]++;
                t.frame_[i] = f;
                t.point_[i] = p;
                t.uv_[i] = row[p];
            }
    }
    t.buildFrameIndex();
    return t;
}

Tracks Tracks::fromObservations(Size imageSize, int frames, int points, const Mat& indexIn,
                                const Mat& uvIn, const String& what)
{
    if (frames < 0 || points < 0)
        CV_Error(Error::StsBadArg, what + cv::format(": frames = %d and points = %d must not be "
                 "negative", frames, points));
    Mat index = indexIn, uvm = uvIn;
    if (index.empty() != uvm.empty())
        CV_Error(Error::StsBadSize, what + ": key 'obs_index' and key 'obs_uv' must both be "
                 "empty or both hold the observations");
    if (!index.empty())
    {
        if (index.type() != CV_32SC1 || index.cols != 2)
            CV_Error(Error::StsBadSize, what + ": key 'obs_index' must be an N x 2 32S matrix "
                     "(frame, point), got " + cv::format("%dx%d ", index.rows, index.cols) +
                     typeToString(index.type()));
        if (uvm.depth() == CV_64F && uvm.channels() == 1)
            uvm.convertTo(uvm, CV_32F);
        if (uvm.type() != CV_32FC1 || uvm.cols != 2)
            CV_Error(Error::StsBadSize, what + ": key 'obs_uv' must be an N x 2 32F matrix "
                     "(u, v), got " + cv::format("%dx%d ", uvm.rows, uvm.cols) +
                     typeToString(uvm.type()));
        if (uvm.rows != index.rows)
            CV_Error(Error::StsBadSize, what + cv::format(": key 'obs_index' has %d rows but key "
                     "'obs_uv' has %d", index.rows, uvm.rows));
        if (!index.isContinuous())
            index = index.clone();
        if (!uvm.isContinuous())
            uvm = uvm.clone();
    }
    const int N = index.rows;
    const int* ix = index.empty() ? nullptr : index.ptr<int>();
    const float* q = uvm.empty() ? nullptr : uvm.ptr<float>();
    for (int i = 0; i < N; i++)
    {
        const int f = ix[2 * i], p = ix[2 * i + 1];
        if (f < 0 || f >= frames || p < 0 || p >= points)
            CV_Error(Error::StsOutOfRange, what + cv::format(": key 'obs_index' row %d = (%d, %d) "
                     "is outside frames [0, %d) or points [0, %d)", i, f, p, frames, points));
        if (!std::isfinite(q[2 * i]) || !std::isfinite(q[2 * i + 1]))
            CV_Error(Error::StsBadArg, what + cv::format(": key 'obs_uv' row %d (frame %d, "
                     "point %d) is not finite", i, f, p));
    }
    // By point, then frame (the file's order when it follows the contract: then a no-op).
    std::vector<int> order(N);
    std::iota(order.begin(), order.end(), 0);
    bool sorted = true;
    for (int i = 1; i < N && sorted; i++)
        sorted = std::make_pair(ix[2 * i - 1], ix[2 * i - 2]) <
                 std::make_pair(ix[2 * i + 1], ix[2 * i]);
    if (!sorted)
        std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
            return std::make_pair(ix[2 * a + 1], ix[2 * a]) <
                   std::make_pair(ix[2 * b + 1], ix[2 * b]);
        });
    Tracks t;
    t.imageSize = imageSize;
    t.frames_ = frames;
    t.trackStart_.assign(points + 1, 0);
    t.frame_.resize(N);
    t.point_.resize(N);
    t.uv_.resize(N);
    for (int k = 0; k < N; k++)
    {
        const int i = order[k];
        t.frame_[k] = ix[2 * i];
        t.point_[k] = ix[2 * i + 1];
        t.uv_[k] = Point2f(q[2 * i], q[2 * i + 1]);
        t.trackStart_[t.point_[k] + 1]++;
        if (k > 0 && t.point_[k] == t.point_[k - 1] && t.frame_[k] == t.frame_[k - 1])
            CV_Error(Error::StsBadArg, what + cv::format(": key 'obs_index' holds (frame %d, "
                     "point %d) twice", t.frame_[k], t.point_[k]));
    }
    for (int p = 0; p < points; p++)
        t.trackStart_[p + 1] += t.trackStart_[p];
    t.buildFrameIndex();
    return t;
}

Tracks Tracks::mapped(const std::function<Point2f(int, int, const Point2f&)>& fn,
                      Size newImageSize) const
{
    Tracks out = *this;
    out.imageSize = newImageSize;
    std::atomic<bool> dropped(false);
    parallel_for_(Range(0, observations()), [&](const Range& r) {
        for (int i = r.start; i < r.end; i++)
        {
            out.uv_[i] = fn(frame_[i], point_[i], uv_[i]);
            if (!isFinite2(out.uv_[i]))
                dropped = true;
        }
    });
    if (!dropped)
        return out;
    Tracks kept;
    kept.imageSize = newImageSize;
    kept.frames_ = frames_;
    kept.trackStart_.assign(trackStart_.size(), 0);
    for (int i = 0; i < observations(); i++)
        if (isFinite2(out.uv_[i]))
        {
            kept.frame_.push_back(frame_[i]);
            kept.point_.push_back(point_[i]);
            kept.uv_.push_back(out.uv_[i]);
            kept.trackStart_[point_[i] + 1]++;
        }
    for (int p = 0; p < points(); p++)
        kept.trackStart_[p + 1] += kept.trackStart_[p];
    kept.buildFrameIndex();
    return kept;
}

Mat Tracks::dense(const std::vector<int>& framesIn, const std::vector<int>& pointsIn) const
{
    std::vector<int> rows = framesIn, cols = pointsIn;
    if (rows.empty())
    {
        rows.resize(frames_);
        std::iota(rows.begin(), rows.end(), 0);
    }
    if (cols.empty())
    {
        cols.resize(points());
        std::iota(cols.begin(), cols.end(), 0);
    }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    Mat m((int)rows.size(), (int)cols.size(), CV_32FC2, Scalar::all(nan));
    for (int c = 0; c < (int)cols.size(); c++)
        for (int r = 0; r < (int)rows.size(); r++)
        {
            const int i = find(rows[r], cols[c]);
            if (i >= 0)
                m.at<Point2f>(r, c) = uv_[i];
        }
    return m;
}

void Tracks::validate(const String& what) const
{
    const String where = what.empty() ? String("tracks") : what;
    if (imageSize.width <= 0 || imageSize.height <= 0)
        CV_Error(Error::StsBadArg, where + ": image_size must be positive");
    if (frames_ <= 0 || points() <= 0)
        CV_Error(Error::StsBadSize, where + ": key 'tracks' is empty");
    const int N = observations();
    if (trackStart_[0] != 0 || trackStart_[points()] != N || (int)point_.size() != N ||
        (int)uv_.size() != N || (int)frameStart_.size() != frames_ + 1 ||
        (int)byFrame_.size() != N)
        CV_Error(Error::StsInternal, where + ": inconsistent observation index");
    for (int p = 0; p < points(); p++)
        for (int i = trackStart_[p]; i < trackStart_[p + 1]; i++)
        {
            if (point_[i] != p || frame_[i] < 0 || frame_[i] >= frames_ ||
                (i > trackStart_[p] && frame_[i] <= frame_[i - 1]))
                CV_Error(Error::StsInternal, where + ": inconsistent observation index");
            if (!isFinite2(uv_[i]))
                CV_Error(Error::StsBadArg, where + cv::format(": observation of track %d in frame "
                         "%d is not finite", p, frame_[i]));
            if (std::abs(uv_[i].x) > detail::kMaxPixelCoordinate ||
                std::abs(uv_[i].y) > detail::kMaxPixelCoordinate)
                CV_Error(Error::StsOutOfRange, where + cv::format(": observation of track %d in "
                         "frame %d = (%g, %g) px is beyond augocc's limit of %g px", p, frame_[i],
                         uv_[i].x, uv_[i].y, detail::kMaxPixelCoordinate));
        }
}

Tracks::Builder::Builder(Size imageSize, int frames) : size_(imageSize), frames_(frames)
{
    start_.push_back(0);
}

int Tracks::Builder::addTrack()
{
    start_.push_back((int)frame_.size());
    return (int)start_.size() - 2;
}

void Tracks::Builder::add(int f, const Point2f& uv)
{
    CV_Assert(start_.size() >= 2);
    frame_.push_back(f);
    uv_.push_back(uv);
    start_.back() = (int)frame_.size();
}

Tracks Tracks::Builder::build(const String& what)
{
    const int N = (int)frame_.size(), P = (int)start_.size() - 1;
    Mat index(N, 2, CV_32S), uv(N, 2, CV_32F);
    for (int p = 0; p < P; p++)
        for (int i = start_[p]; i < start_[p + 1]; i++)
        {
            index.at<int>(i, 0) = frame_[i];
            index.at<int>(i, 1) = p;
            uv.at<float>(i, 0) = uv_[i].x;
            uv.at<float>(i, 1) = uv_[i].y;
        }
    return Tracks::fromObservations(size_, frames_, P, index, uv, what);
}

namespace {

// Observations below this count are written as text (readable), above in base64.
const int kBase64Observations = 1024;
// Every value of the dense matrix takes at least this many bytes of text (".Nan" or a number,
// and a separator: YAML, JSON and XML alike), so a cell at least twice it.
const size_t kMinDenseCellBytes = 8;

void fillTracks(FileStorage& storage, const Tracks& tracks, TracksForm form)
{
    storage << "image_size" << (Mat_<int>(1, 2) << tracks.imageSize.width,
                                tracks.imageSize.height);
    storage << "frames" << tracks.frames();
    storage << "points" << tracks.points();
    if (form == TRACKS_DENSE)
    {
        storage << "tracks" << tracks.dense();
        return;
    }
    const int N = tracks.observations();
    Mat index(N, 2, CV_32S), uv(N, 2, CV_32F);
    for (int i = 0; i < N; i++)
    {
        index.at<int>(i, 0) = tracks.frameOf(i);
        index.at<int>(i, 1) = tracks.pointOf(i);
        uv.at<float>(i, 0) = tracks.uv(i).x;
        uv.at<float>(i, 1) = tracks.uv(i).y;
    }
    storage << "obs_index" << index;
    storage << "obs_uv" << uv;
}

int formFlags(const Tracks& tracks, TracksForm form)
{
    return form == TRACKS_SPARSE && tracks.observations() >= kBase64Observations
               ? (int)FileStorage::BASE64 : 0;
}

} // namespace

size_t tracksFileBytes(const String& path, const Tracks& tracks, TracksForm form)
{
    CV_Assert(form == TRACKS_DENSE || form == TRACKS_SPARSE);
    tracks.validate(path);
    return detail::storageText([&](FileStorage& s) { fillTracks(s, tracks, form); }, path,
                               formFlags(tracks, form)).size();
}

Tracks readTracks(const String& path)
{
    FileStorage storage = detail::openFileStorageForRead(path);
    FileNode root = storage.root();
    const Size imageSize = readImageSize(root, path);
    const int frames = readIntKey(root, "frames", path);
    const int points = readIntKey(root, "points", path);
    if (frames <= 0 || points <= 0)
        CV_Error(Error::StsBadArg, path + cv::format(": frames = %d and points = %d must be "
                 "positive", frames, points));
    const FileNode denseNode = root["tracks"], indexNode = root["obs_index"];
    const bool dense = !denseNode.empty() && !denseNode.isNone();
    const bool sparse = !indexNode.empty() && !indexNode.isNone();
    if (dense && sparse)
        CV_Error(Error::StsParseError, path + ": holds both key 'tracks' (dense form) and key "
                 "'obs_index' (sparse form); one only");
    Tracks t;
    if (sparse || (!dense && !root["obs_uv"].empty()))
    {
        const Mat index = readMatKey(root, "obs_index", path);
        const Mat uv = readMatKey(root, "obs_uv", path);
        t = Tracks::fromObservations(imageSize, frames, points, index, uv, path);
    }
    else
    {
        const Mat m = readMatKey(root, "tracks", path);
        if (m.rows != frames || m.cols != points)
            CV_Error(Error::StsBadSize, path + cv::format(": key 'tracks' is %dx%d but frames = "
                     "%d and points = %d", m.rows, m.cols, frames, points));
        t = Tracks::fromDense(imageSize, m, path);
    }
    t.validate(path);
    return t;
}

void writeTracks(const String& path, const Tracks& tracks, TracksForm form)
{
    tracks.validate(path);
    if (form == TRACKS_SMALLER)
    {
        // The sparse text is linear in the observations; the dense one is made only when it can
        // be the smaller, i.e. when F x P is within a constant of the sparse text.
        const size_t sparse = tracksFileBytes(path, tracks, TRACKS_SPARSE);
        const double cells = (double)tracks.frames() * tracks.points();
        form = tracks.observations() > 0 &&
                       (cells * kMinDenseCellBytes > (double)sparse ||
                        sparse < tracksFileBytes(path, tracks, TRACKS_DENSE))
                   ? TRACKS_SPARSE : TRACKS_DENSE;
    }
    detail::writeStorageAtomically(path, [&](FileStorage& s) { fillTracks(s, tracks, form); },
                                   formFlags(tracks, form));
}

// ---------------------------------------------------------------------------------------------
// Reconstruction

int Reconstruction::findCamera(int frame) const
{
    auto it = std::lower_bound(cameras.begin(), cameras.end(), frame,
                               [](const Camera& c, int f) { return c.frame < f; });
    if (it != cameras.end() && it->frame == frame)
        return (int)(it - cameras.begin());
    return -1;
}

const Camera& Reconstruction::camera(int frame) const
{
    const int i = findCamera(frame);
    if (i < 0)
        CV_Error(Error::StsObjectNotFound, cv::format("the reconstruction has no camera for "
                 "frame %d", frame));
    return cameras[i];
}

bool Reconstruction::hasPoint(int p) const
{
    if (p < 0 || p >= points.rows)
        return false;
    const double* X = points.ptr<double>(p);
    return std::isfinite(X[0]) && std::isfinite(X[1]) && std::isfinite(X[2]);
}

int Reconstruction::validPointCount() const
{
    int n = 0;
    for (int i = 0; i < points.rows; i++)
        n += hasPoint(i) ? 1 : 0;
    return n;
}

void Reconstruction::validate(const String& what) const
{
    const String where = what.empty() ? String("reconstruction") : what;
    if (imageSize.width <= 0 || imageSize.height <= 0)
        CV_Error(Error::StsBadArg, where + ": image_size must be positive");
    if (cameras.empty())
        CV_Error(Error::StsBadSize, where + ": key 'cameras' holds no camera");
    for (size_t i = 0; i < cameras.size(); i++)
    {
        const String ci = where + cv::format(": cameras[%d]", (int)i);
        if (cameras[i].model != model)
            CV_Error(Error::StsBadArg, ci + ": camera model differs from the file's 'model'");
        if (cameras[i].frame < 0)
            CV_Error(Error::StsBadArg, ci + ": key 'frame' must be >= 0");
        if (i > 0 && cameras[i].frame <= cameras[i - 1].frame)
            CV_Error(Error::StsBadArg, ci + cv::format(": frame %d is not after the previous "
                     "camera's frame %d (cameras must be in increasing frame order)",
                     cameras[i].frame, cameras[i - 1].frame));
        cameras[i].validate(ci);
    }
    if (!points.empty())
    {
        if (points.type() != CV_64FC1 || points.cols != 3)
            CV_Error(Error::StsBadSize, where + ": key 'points' must be a P x 3 double matrix, "
                     "got " + cv::format("%dx%d ", points.rows, points.cols) +
                     typeToString(points.type()));
        // NaN marks a point that is not reconstructed; an infinite or absurd one is an error.
        for (int i = 0; i < points.rows; i++)
            for (int k = 0; k < 3; k++)
            {
                const double v = points.at<double>(i, k);
                if (!std::isnan(v))
                    detail::checkMagnitude(v, detail::kMaxSceneCoordinate,
                                           where + cv::format(": key 'points' (%d, %d)", i, k));
            }
    }
}

Reconstruction readReconstruction(const String& path)
{
    FileStorage storage = detail::openFileStorageForRead(path);
    FileNode root = storage.root();
    Reconstruction rec;
    FileNode modelNode = requireKey(root, "model", path);
    if (!modelNode.isString())
        CV_Error(Error::StsParseError, path + ": key 'model' must be a string");
    try
    {
        rec.model = parseCameraModel((String)modelNode);
    }
    catch (const cv::Exception& e)
    {
        CV_Error(Error::StsBadArg, path + ": key 'model': " + e.err);
    }
    rec.imageSize = readImageSize(root, path);
    FileNode cams = requireKey(root, "cameras", path);
    if (!cams.isSeq())
        CV_Error(Error::StsParseError, path + ": key 'cameras' must be a sequence of maps");
    int i = 0;
    for (FileNodeIterator it = cams.begin(); it != cams.end(); ++it, ++i)
    {
        const String ci = path + cv::format(": cameras[%d]", i);
        FileNode c = *it;
        if (!c.isMap())
            CV_Error(Error::StsParseError, ci + " is not a map");
        Camera cam;
        cam.model = rec.model;
        cam.frame = readIntKey(c, "frame", ci);
        cam.R = readFixedMat<Matx33d>(c, "R", ci);
        {
            const Matx31d tt = readFixedMat<Matx31d>(c, "t", ci);
            cam.t = Vec3d(tt(0), tt(1), tt(2));
        }
        if (rec.model == SCALED_ORTHOGRAPHIC)
        {
            cam.s = readRealKey(c, "s", ci);
            Matx12d pp = readFixedMat<Matx12d>(c, "principal_point", ci);
            cam.pp = Point2d(pp(0), pp(1));
        }
        else
        {
            cam.K = readFixedMat<Matx33d>(c, "K", ci);
            cam.pp = Point2d(cam.K(0, 2), cam.K(1, 2));
            if (!c["principal_point"].empty())
            {
                Matx12d pp = readFixedMat<Matx12d>(c, "principal_point", ci);
                if (std::abs(pp(0) - cam.K(0, 2)) > 1e-6 || std::abs(pp(1) - cam.K(1, 2)) > 1e-6)
                    CV_Error(Error::StsBadArg, ci + ": key 'principal_point' differs from K");
            }
            FileNode dn = c["distortion_coefficients"];
            if (!dn.empty() && !dn.isNone())
            {
                Mat D = readMatKey(c, "distortion_coefficients", ci);
                if (D.channels() != 1 || (D.rows != 1 && D.cols != 1) ||
                    (D.depth() != CV_64F && D.depth() != CV_32F))
                    CV_Error(Error::StsBadSize, ci + cv::format(": key 'distortion_coefficients' "
                             "must be a 1xN double matrix, got %dx%d ", D.rows, D.cols) +
                             typeToString(D.type()));
                Mat D64;
                D.reshape(1, 1).convertTo(D64, CV_64F);
                cam.distortion.assign(D64.ptr<double>(), D64.ptr<double>() + D64.cols);
            }
        }
        rec.cameras.push_back(cam);
    }
    FileNode pts = root["points"];
    if (!pts.empty() && !pts.isNone())
    {
        Mat P = readMatKey(root, "points", path);
        if (!P.empty())
        {
            if (P.channels() != 1 || P.cols != 3)
                CV_Error(Error::StsBadSize, path + cv::format(": key 'points' must be P x 3, got "
                         "%dx%d with %d channel(s)", P.rows, P.cols, P.channels()));
            if (P.depth() != CV_64F && P.depth() != CV_32F)
                CV_Error(Error::StsUnsupportedFormat, path + ": key 'points' must be a double "
                         "matrix");
            P.convertTo(rec.points, CV_64F);
        }
    }
    rec.validate(path);
    return rec;
}

void writeReconstruction(const String& path, const Reconstruction& rec)
{
    rec.validate(path);
    detail::writeStorageAtomically(path, [&](FileStorage& storage) {
        storage << "model" << cameraModelName(rec.model);
        storage << "image_size" << (Mat_<int>(1, 2) << rec.imageSize.width,
                                    rec.imageSize.height);
        storage << "cameras" << "[";
        for (const Camera& c : rec.cameras)
        {
            storage << "{";
            storage << "frame" << c.frame;
            storage << "R" << Mat(c.R);
            storage << "t" << Mat(c.t);
            const Point2d pp = c.principalPoint();
            if (rec.model == SCALED_ORTHOGRAPHIC)
                storage << "s" << c.s;
            else
                storage << "K" << Mat(c.K);
            if (!c.distortion.empty())
                storage << "distortion_coefficients" << Mat(c.distortion).reshape(1, 1);
            storage << "principal_point" << (Mat_<double>(1, 2) << pp.x, pp.y);
            storage << "}";
        }
        storage << "]";
        storage << "points" << (rec.points.empty() ? Mat(0, 3, CV_64F) : rec.points);
    });
}

// ---------------------------------------------------------------------------------------------
// Masks

// ---------------------------------------------------------------------------------------------
// Calibration (OpenCV's calibrateCamera file)

Calibration readCalibration(const String& path, Size frameSize)
{
    FileStorage storage = detail::openFileStorageForRead(path, "calibration file");
    FileNode root = storage.root();
    Calibration cal;
    cal.K = readFixedMat<Matx33d>(root, "camera_matrix", path);
    for (int k = 0; k < 9; k++)
        if (!std::isfinite(cal.K.val[k]))
            CV_Error(Error::StsBadArg, path + ": key 'camera_matrix' has a value that is not "
                     "finite");
    if (!(cal.K(0, 0) > 0) || !(cal.K(1, 1) > 0))
        CV_Error(Error::StsBadArg, path + cv::format(": key 'camera_matrix': the focal lengths "
                 "fx = %g, fy = %g must be positive", cal.K(0, 0), cal.K(1, 1)));
    if (cal.K(1, 0) != 0 || cal.K(2, 0) != 0 || cal.K(2, 1) != 0 || cal.K(2, 2) != 1)
        CV_Error(Error::StsBadArg, path + ": key 'camera_matrix' must be (fx, s, cx; 0, fy, cy; "
                 "0, 0, 1)");
    {
        const Mat D = readMatKey(root, "distortion_coefficients", path);
        const int n = (int)D.total();
        if (D.channels() != 1 || (D.rows != 1 && D.cols != 1) ||
            (n != 4 && n != 5 && n != 8 && n != 12 && n != 14))
            CV_Error(Error::StsBadSize, path + cv::format(": key 'distortion_coefficients' must "
                     "be 1xN or Nx1 with N in 4, 5, 8, 12, 14, got %dx%d with %d channel(s)",
                     D.rows, D.cols, D.channels()));
        if (D.depth() != CV_64F && D.depth() != CV_32F)
            CV_Error(Error::StsUnsupportedFormat, path + ": key 'distortion_coefficients' must "
                     "be a floating point matrix");
        Mat D64;
        D.reshape(1, 1).convertTo(D64, CV_64F);
        cal.distortion.assign(D64.ptr<double>(), D64.ptr<double>() + n);
        for (double d : cal.distortion)
            if (!std::isfinite(d))
                CV_Error(Error::StsBadArg, path + ": key 'distortion_coefficients' has a value "
                         "that is not finite");
    }
    const bool hasW = !root["image_width"].empty() && !root["image_width"].isNone();
    const bool hasH = !root["image_height"].empty() && !root["image_height"].isNone();
    if (hasW != hasH)
        CV_Error(Error::StsParseError, path + ": keys 'image_width' and 'image_height' go "
                 "together, only '" + String(hasW ? "image_width" : "image_height") + "' given");
    Size calSize = frameSize;
    if (hasW)
    {
        calSize = Size(readIntKey(root, "image_width", path), readIntKey(root, "image_height",
                       path));
        if (calSize.width <= 0 || calSize.height <= 0)
            CV_Error(Error::StsBadArg, path + cv::format(": keys 'image_width', 'image_height' "
                     "= %d x %d must be positive", calSize.width, calSize.height));
    }
    cal.imageSize = calSize;
    if (frameSize.empty() || calSize == frameSize)
        return cal;
    // Another resolution: the same aspect when the scaled height rounds to the frames' (half a
    // pixel); per-axis scale in the pixel-centre convention, c' = r (c + 0.5) - 0.5.
    const double rx = (double)frameSize.width / calSize.width;
    const double ry = (double)frameSize.height / calSize.height;
    if (std::abs(calSize.height * rx - frameSize.height) > 0.5)
        CV_Error(Error::StsBadSize, path + cv::format(": keys 'image_width', 'image_height': "
                 "calibrated at %d x %d, another aspect than the frames' %d x %d",
                 calSize.width, calSize.height, frameSize.width, frameSize.height));
    cal.K(0, 0) *= rx;
    cal.K(0, 1) *= rx;
    cal.K(0, 2) = rx * (cal.K(0, 2) + 0.5) - 0.5;
    cal.K(1, 1) *= ry;
    cal.K(1, 2) = ry * (cal.K(1, 2) + 0.5) - 0.5;
    cal.imageSize = frameSize;
    return cal;
}

ObjectMasks readMasks(const String& dir, Size expectedSize)
{
    if (!fs::is_directory(dir))
        CV_Error(Error::StsObjectNotFound, dir + ": masks folder not found");
    ObjectMasks out;
    std::vector<fs::path> objects;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.is_directory())
            objects.push_back(e.path());
    std::sort(objects.begin(), objects.end());
    for (const fs::path& obj : objects)
    {
        const String name = obj.filename().string();
        if (name.empty() || name[0] == '.')
            continue;
        FrameMasks frames;
        std::vector<fs::path> files;
        for (const auto& e : fs::directory_iterator(obj))
            if (e.is_regular_file())
                files.push_back(e.path());
        std::sort(files.begin(), files.end());
        for (const fs::path& f : files)
        {
            const String fname = f.filename().string();
            // CONTRACT.md names masks <frame>.png: an upper-case .PNG is an error rather than a
            // file silently skipped; the stem only decimal digits (" 5", "+5", "5x" are errors,
            // not frame 5).
            String ext = f.extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
            if (ext != ".png" || fname[0] == '.')
                continue;
            if (f.extension() != ".png")
                CV_Error(Error::StsBadArg, f.string() + ": mask files end in lower-case '.png' "
                         "(rename it to " + f.stem().string() + ".png)");
            const String stem = f.stem().string();
            const bool digits = !stem.empty() && stem.size() <= 9 &&
                                std::all_of(stem.begin(), stem.end(),
                                            [](char c) { return c >= '0' && c <= '9'; });
            if (!digits)
                CV_Error(Error::StsBadArg, f.string() + ": mask file name must be a frame "
                         "index of 1 to 9 decimal digits such as 0042.png");
            const int index = std::atoi(stem.c_str());
            Mat m = detail::readImageChecked(f.string(), IMREAD_GRAYSCALE, true);
            if (!expectedSize.empty() && m.size() != expectedSize)
                CV_Error(Error::StsBadSize, f.string() + cv::format(": mask is %dx%d but the "
                         "frames are %dx%d", m.cols, m.rows, expectedSize.width,
                         expectedSize.height));
            cv::threshold(m, m, 127, 255, THRESH_BINARY);
            if (frames.count(index))
                CV_Error(Error::StsBadArg, f.string() + cv::format(": a second mask for frame %d",
                         index));
            frames[index] = m;
        }
        if (!frames.empty())
            out[name] = frames;
    }
    if (out.empty())
        CV_Error(Error::StsBadArg, dir + ": holds no <object>/<frame>.png mask");
    return out;
}

void writeMasks(const String& dir, const ObjectMasks& masks)
{
    fs::path target(dir);
    if (target.has_parent_path())
        detail::createDirectories(target.parent_path().string());
    writeAtomically(dir, [&](const String& tmp) {
        detail::createDirectories(tmp, dir);
        for (const auto& obj : masks)
        {
            if (obj.first.empty() || obj.first.find('/') != String::npos)
                CV_Error(Error::StsBadArg, "invalid object name '" + obj.first + "'");
            fs::path od = fs::path(tmp) / obj.first;
            detail::createDirectories(od.string(), (target / obj.first).string());
            for (const auto& fm : obj.second)
            {
                CV_CheckTypeEQ(fm.second.type(), CV_8UC1, "masks must be 8-bit single channel");
                const String name = cv::format("%04d.png", fm.first);
                detail::writeImageFile((od / name).string(), fm.second,
                                       (target / obj.first / name).string());
            }
        }
    });
}

// ---------------------------------------------------------------------------------------------
// Frame sources

FrameSource::~FrameSource() {}

namespace {

class ImageListSource CV_FINAL : public FrameSource
{
public:
    ImageListSource(const String& input, std::vector<String> files)
        : input_(input), files_(std::move(files))
    {
        Mat first = detail::readImageChecked(files_[0], IMREAD_COLOR);
        if (first.empty())
            CV_Error(Error::StsParseError, files_[0] + ": cannot read image (corrupt or not an "
                     "image)");
        size_ = first.size();
    }
    int count() const CV_OVERRIDE { return (int)files_.size(); }
    Size size() const CV_OVERRIDE { return size_; }
    double fps() const CV_OVERRIDE { return 25.0; }
    int position() const CV_OVERRIDE { return pos_; }
    void seek(int index) CV_OVERRIDE
    {
        CV_CheckGE(index, 0, "seek index");
        CV_CheckLE(index, count(), "seek index");
        pos_ = index;
    }
    bool read(OutputArray frame) CV_OVERRIDE
    {
        if (pos_ >= (int)files_.size())
            return false;
        Mat m = detail::readImageChecked(files_[pos_], IMREAD_COLOR);
        if (m.size() != size_)
            CV_Error(Error::StsBadSize, files_[pos_] + cv::format(": image is %dx%d, the first "
                     "frame is %dx%d", m.cols, m.rows, size_.width, size_.height));
        m.copyTo(frame);
        pos_++;
        return true;
    }

private:
    String input_;
    std::vector<String> files_;
    Size size_;
    int pos_ = 0;
};

class VideoSource CV_FINAL : public FrameSource
{
public:
    explicit VideoSource(const String& path) : path_(path)
    {
        open();
        Mat first;
        if (!cap_.read(first) || first.empty())
            CV_Error(Error::StsParseError, path_ + ": cannot decode a frame (corrupt video or "
                     "unsupported codec)");
        size_ = first.size();
        count_ = (int)cap_.get(CAP_PROP_FRAME_COUNT);
        fps_ = cap_.get(CAP_PROP_FPS);
        if (!(fps_ > 0 && fps_ < 1000))
            fps_ = 25.0;
        open();
    }
    int count() const CV_OVERRIDE { return count_; }
    Size size() const CV_OVERRIDE { return size_; }
    double fps() const CV_OVERRIDE { return fps_; }
    int position() const CV_OVERRIDE { return pos_; }
    void seek(int index) CV_OVERRIDE
    {
        CV_CheckGE(index, 0, "seek index");
        if (index < pos_)
            open();
        Mat skip;
        while (pos_ < index)
        {
            if (!cap_.grab())
                CV_Error(Error::StsOutOfRange, path_ + cv::format(": cannot seek to frame %d, "
                         "the video ends at %d", index, pos_));
            pos_++;
        }
    }
    bool read(OutputArray frame) CV_OVERRIDE
    {
        Mat m;
        if (!cap_.read(m) || m.empty())
            return false;
        if (m.size() != size_)
            CV_Error(Error::StsBadSize, path_ + cv::format(": frame %d is %dx%d, expected %dx%d",
                     pos_, m.cols, m.rows, size_.width, size_.height));
        if (m.type() != CV_8UC3)
        {
            if (m.channels() == 1)
                cv::cvtColor(m, m, COLOR_GRAY2BGR);
            else if (m.channels() == 4)
                cv::cvtColor(m, m, COLOR_BGRA2BGR);
        }
        m.copyTo(frame);
        pos_++;
        return true;
    }

private:
    void open()
    {
        cap_.release();
        if (!cap_.open(path_, CAP_FFMPEG))
            CV_Error(Error::StsParseError, path_ + ": cannot open as a video (corrupt or "
                     "unsupported format)");
        pos_ = 0;
    }

    String path_;
    VideoCapture cap_;
    Size size_;
    int count_ = 0;
    double fps_ = 25.0;
    int pos_ = 0;
};

bool isImageFile(const fs::path& p)
{
    String e = p.extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
    return e == ".png" || e == ".jpg" || e == ".jpeg" || e == ".bmp" || e == ".tif" ||
           e == ".tiff" || e == ".pgm" || e == ".ppm" || e == ".exr" || e == ".webp";
}

} // namespace

namespace detail {

String FramePattern::expand(int index) const
{
    CV_Assert(index >= 0);
    String digits = std::to_string(index);
    if ((int)digits.size() < width)
        digits.insert(0, width - digits.size(), zeroPad ? '0' : ' ');
    return prefix + digits + suffix;
}

FramePattern parseFramePattern(const String& pattern)
{
    const String what = "'" + pattern + "': not a frame pattern: ";
    const String expected = " (expected one %d, %Nd or %0Nd, as in frames/%04d.png; %% for a "
                            "literal %)";
    FramePattern p;
    bool converted = false;
    for (size_t i = 0; i < pattern.size(); i++)
    {
        String& literal = converted ? p.suffix : p.prefix;
        if (pattern[i] != '%')
        {
            literal += pattern[i];
            continue;
        }
        if (i + 1 < pattern.size() && pattern[i + 1] == '%')
        {
            literal += '%';
            i++;
            continue;
        }
        // %[0][N]d; the conversion spans [i, j].
        size_t j = i + 1;
        const bool zero = j < pattern.size() && pattern[j] == '0';
        if (zero)
            j++;
        const size_t digitsStart = j;
        while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9')
            j++;
        const String digits = pattern.substr(digitsStart, j - digitsStart);
        if (j >= pattern.size() || pattern[j] != 'd' || (zero && !digits.empty() &&
                                                          digits[0] == '0'))
        {
            const size_t shown = std::min(pattern.size(), j + 1) - i;
            CV_Error(Error::StsBadArg, what + "'" + pattern.substr(i, shown) + "' is not an "
                     "integer conversion" + expected);
        }
        if (converted)
            CV_Error(Error::StsBadArg, what + "more than one conversion" + expected);
        if (digits.size() > 2 || (!digits.empty() && std::stoi(digits) > kMaxFramePatternWidth))
            CV_Error(Error::StsBadArg, what + "width " + digits + cv::format(" is over %d",
                     kMaxFramePatternWidth) + expected);
        p.width = digits.empty() ? 0 : std::stoi(digits);
        p.zeroPad = zero;
        converted = true;
        i = j;
    }
    if (!converted)
        CV_Error(Error::StsBadArg, what + "no integer conversion" + expected);
    return p;
}

} // namespace detail

Ptr<FrameSource> FrameSource::open(const String& input)
{
    if (input.empty())
        CV_Error(Error::StsBadArg, "no input given");
    if (fs::is_directory(input))
    {
        std::vector<String> files;
        for (const auto& e : fs::directory_iterator(input))
            if (e.is_regular_file() && isImageFile(e.path()) &&
                e.path().filename().string()[0] != '.')
                files.push_back(e.path().string());
        std::sort(files.begin(), files.end());
        if (files.empty())
            CV_Error(Error::StsObjectNotFound, input + ": folder holds no image");
        return makePtr<ImageListSource>(input, files);
    }
    if (input.find('%') != String::npos && !fs::exists(input))
    {
        // Expanded here, never by printf or by VideoCapture (whose image sequences would use
        // the user's text as a format): a bad pattern is an error before any file is looked at.
        const detail::FramePattern pattern = detail::parseFramePattern(input);
        std::vector<String> files;
        for (int i = 0; i < std::numeric_limits<int>::max(); i++)
        {
            const String f = pattern.expand(i);
            if (!fs::exists(f))
            {
                // Patterns may start at 1 (ffmpeg's default).
                if (i == 0 && fs::exists(pattern.expand(1)))
                    continue;
                break;
            }
            files.push_back(f);
        }
        if (files.empty())
            CV_Error(Error::StsObjectNotFound, input + ": pattern matches no file");
        return makePtr<ImageListSource>(input, files);
    }
    if (!fs::exists(input))
        CV_Error(Error::StsObjectNotFound, input + ": input not found");
    if (isImageFile(fs::path(input)))
        return makePtr<ImageListSource>(input, std::vector<String>{input});
    return makePtr<VideoSource>(input);
}

} // namespace augocc
} // namespace cv
