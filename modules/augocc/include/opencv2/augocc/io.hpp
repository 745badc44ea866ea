// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_IO_HPP
#define OPENCV_AUGOCC_IO_HPP

#include <functional>
#include <map>
#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"

/*
The interchange files (tracks.yml, reconstruction.yml, masks and mattes folders; README.md,
"Files") and frame sequences given as a video, an image folder or a printf pattern; conventions
in the augocc group (opencv2/augocc.hpp, @ref augocc_conventions). Algorithms never parse files;
they take these types. Every reader validates and throws cv::Exception (StsBadArg,
StsParseError, StsBadSize, StsObjectNotFound) with a message that names the file and the key.
Every writer writes to a temporary name and renames, so a failure leaves no partial file.
*/

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief 2D feature tracks: the measurement matrix of the factorization, stored sparse.

Track p observed in frame f at (u, v) is one observation; memory is linear in the observations
(about 20 bytes each), never F x P. Observations are numbered i = 0 .. observations() - 1 by
track, then frame (the order of the sparse form of tracks.yml); track(p) is the range of track p's
observations (frames increasing) and frame(f) the range k of frame f's observations, byFrame(k)
their numbers (points increasing). Every observation is finite; unobserved entries do not exist.
Build tracks with fromDense() (small shots, tests), fromObservations() or Builder.
@sa @ref augocc_conventions_units "Units and indices"
*/
struct CV_EXPORTS Tracks
{
    Size imageSize;  //!< size of the frames, pixels

    /** @brief Tracks from the dense F x P matrix (CV_32FC2, or CV_64FC2 converted); a NaN pair
    is "not observed". Throws StsBadArg naming `what` and the entry when one coordinate is NaN
    and the other not, or a value is infinite; StsBadSize when the matrix is empty;
    StsUnsupportedFormat for another type. */
    static Tracks fromDense(Size imageSize, const Mat& dense, const String& what = "tracks");
    /** @brief Tracks of F frames and P points from N observations in any order.
    @param imageSize size of the frames. @param frames F. @param points P.
    @param index N x 2 CV_32S (frame, point), or empty. @param uv N x 2 CV_32F (u, v) (CV_64F is
    converted), or empty. @param what names the source in error messages. Throws cv::Exception naming `what` on a bad shape or type, a frame or
    point out of range, a repeated (frame, point) or a non-finite position. */
    static Tracks fromObservations(Size imageSize, int frames, int points, const Mat& index,
                                   const Mat& uv, const String& what = "tracks");

    //! Number of frames F.
    int frames() const { return frames_; }
    //! Number of tracks P.
    int points() const { return trackStart_.empty() ? 0 : (int)trackStart_.size() - 1; }
    //! Number of observations N.
    int observations() const { return (int)frame_.size(); }
    //! True when track p is observed in frame f (binary search in the track).
    bool observed(int f, int p) const { return find(f, p) >= 0; }
    //! Observation of track p in frame f (NaN if unobserved).
    Point2f at(int f, int p) const;
    //! Number of frames in which track p is observed.
    int observationCount(int p) const { return trackStart_[p + 1] - trackStart_[p]; }
    //! Number of tracks observed in frame f.
    int frameObservationCount(int f) const { return frameStart_[f + 1] - frameStart_[f]; }
    //! Number of observation i of track p in frame f, or -1.
    int find(int f, int p) const;

    //! Observations of track p: i in [start, end), frames increasing.
    Range track(int p) const { return Range(trackStart_[p], trackStart_[p + 1]); }
    //! Positions k of frame f's observations: byFrame(k) for k in [start, end), points increasing.
    Range frame(int f) const { return Range(frameStart_[f], frameStart_[f + 1]); }
    //! Number of the k-th observation in frame order.
    int byFrame(int k) const { return byFrame_[k]; }
    //! Frame of observation i.
    int frameOf(int i) const { return frame_[i]; }
    //! Track (point) of observation i.
    int pointOf(int i) const { return point_[i]; }
    //! Position (u, v) of observation i, pixels.
    Point2f uv(int i) const { return uv_[i]; }

    /** @brief The same tracks with every position mapped by `fn(frame, point, uv)` (in parallel:
    `fn` must be thread-safe); observations mapped to a non-finite position are dropped. */
    Tracks mapped(const std::function<Point2f(int, int, const Point2f&)>& fn,
                  Size newImageSize) const;
    /** @brief The dense block of the given frames (rows) and points (columns), CV_32FC2, NaN
    where unobserved; empty lists = every frame / every point. For small blocks only (tests,
    displays): the whole shot's block is F x P. */
    Mat dense(const std::vector<int>& frames = std::vector<int>(),
              const std::vector<int>& points = std::vector<int>()) const;
    //! Throws naming `what` when the size, the index or a value is inconsistent.
    void validate(const String& what = String()) const;

    /** @brief Builds tracks one track at a time (the tracker, the synthesizer). */
    class CV_EXPORTS Builder
    {
    public:
        //! An empty set of tracks over `frames` frames of `imageSize`.
        Builder(Size imageSize, int frames);
        //! Starts a new track; returns its number p.
        int addTrack();
        //! Adds the observation of the current track in frame f (increasing f within a track).
        void add(int f, const Point2f& uv);
        //! The tracks (throws like fromObservations when an observation is bad).
        Tracks build(const String& what = "tracks");
    private:
        Size size_;
        int frames_;
        std::vector<int> start_, frame_;
        std::vector<Point2f> uv_;
    };

private:
    void buildFrameIndex();

    int frames_ = 0;
    std::vector<int> trackStart_;   // P + 1 offsets into the observations
    std::vector<int> frame_;        // N, by track then frame
    std::vector<int> point_;        // N
    std::vector<Point2f> uv_;       // N
    std::vector<int> frameStart_;   // F + 1 offsets into byFrame_
    std::vector<int> byFrame_;      // N observation numbers, by frame then point
};

/** @brief Cameras and 3D points. Row p of `points` belongs to column p of the tracks it came from;
a row of NaN is a rejected or unreconstructed track. */
struct CV_EXPORTS Reconstruction
{
    CameraModel model = SCALED_ORTHOGRAPHIC;  //!< model of every camera
    Size imageSize;               //!< size of the frames, pixels
    std::vector<Camera> cameras;  //!< any subset of frames, in increasing frame order
    Mat points;                   //!< P x 3 CV_64F (may be empty)

    //! Index into `cameras` of the camera of frame `frame`, or -1.
    int findCamera(int frame) const;
    //! Camera of frame `frame`; throws StsObjectNotFound when the frame has none.
    const Camera& camera(int frame) const;
    //! Projects a world point into frame `frame`.
    Point2d project(int frame, const Vec3d& Xw) const { return camera(frame).project(Xw); }
    //! True when track column `p` has a reconstructed point: row `p` of `points` exists and all
    //! three coordinates are finite (rejected and unreconstructed tracks are rows of NaN).
    bool hasPoint(int p) const;
    //! Point of track column `p` (check hasPoint() first).
    Vec3d point(int p) const { return Vec3d(points.ptr<double>(p)); }
    //! Number of points for which hasPoint() holds.
    int validPointCount() const;
    //! Throws on any inconsistency (model mix, frame order, R not a rotation, s <= 0, bad shapes).
    void validate(const String& what = String()) const;
};

/** @brief Known intrinsics: OpenCV's calibration file (contract: calibration.yml), as
`cv::calibrateCamera` users save it, brought to the size of the frames.

Pixel convention of the module (origin at the centre of the top-left pixel): a calibration made
at another resolution of the same aspect is scaled per axis with r = frame / calibration size as
c' = r * (c + 0.5) - 0.5 and f' = r * f; the distortion coefficients act on normalised
coordinates and are unchanged.
*/
struct CV_EXPORTS Calibration
{
    Matx33d K = Matx33d::eye();       //!< intrinsics (fx, skew, cx; 0, fy, cy; 0, 0, 1), pixels
    //! OpenCV's distortion coefficients (Camera::distortion): 0, 4, 5, 8, 12 or 14 values
    std::vector<double> distortion;
    Size imageSize;                   //!< the size K is expressed for, pixels

    //! A perspective camera with these intrinsics and the given pose.
    //! @param R rotation, world to camera. @param t translation, world to camera.
    //! @param frame frame index.
    Camera camera(const Matx33d& R = Matx33d::eye(), const Vec3d& t = Vec3d(0, 0, 0),
                  int frame = 0) const
    {
        return Camera::perspective(R, t, K, frame, distortion);
    }
};

/** @brief Reads OpenCV's calibration file (also .yml.gz / .json / .xml) for frames of
`frameSize`.

Keys: `camera_matrix` (3x3, fx > 0, fy > 0, finite, last row 0 0 1), `distortion_coefficients`
(1xN or Nx1, N in 4, 5, 8, 12, 14, finite), optional `image_width` and `image_height` (the size
it was calibrated at; both or neither). Other keys are ignored.
@param path the file.
@param frameSize size of the frames the intrinsics are for; when the file gives another size of
the same aspect (within half a pixel) K is scaled to it (see Calibration), another aspect is
StsBadSize naming both sizes. Empty: K is returned as read.
@return the intrinsics for `frameSize` (imageSize = frameSize, or the file's size when
`frameSize` is empty).
Throws cv::Exception naming the file and the key: StsObjectNotFound / StsParseError (missing
file, missing key, not a matrix), StsBadSize (matrix shape, coefficient count, sizes), StsBadArg
(NaN or infinite values, focal not positive).
*/
CV_EXPORTS Calibration readCalibration(const String& path, Size frameSize = Size());

//! Per-frame 8-bit masks of one object: frame index -> image (255 = object).
typedef std::map<int, Mat> FrameMasks;
//! Masks of several objects: object name -> its frames.
typedef std::map<String, FrameMasks> ObjectMasks;

//! Form of tracks.yml (contract: the dense `tracks` matrix or the sparse `obs_index`/`obs_uv`).
enum TracksForm
{
    TRACKS_SMALLER = 0,  //!< whichever file is smaller (the default)
    TRACKS_DENSE = 1,    //!< the F x P `tracks` matrix
    TRACKS_SPARSE = 2    //!< `obs_index` and `obs_uv`, base64 (FileStorage) when large
};

/** @brief Reads tracks.yml in either form (also .yml.gz / .json). Throws naming the file and the
key on error: a missing key, both forms at once, a bad type or shape, a frame or point out of
range, a repeated observation, a non-finite position (dense: one coordinate NaN, or infinite). */
CV_EXPORTS Tracks readTracks(const String& path);
/** @brief Writes tracks.yml atomically in `form`. TRACKS_SMALLER writes the sparse form when its
text is smaller than the dense one's (compared before any compression), else the dense form,
byte for byte as TRACKS_DENSE writes it; deciding costs memory linear in the observations (the
dense text is made only when F x P is within a constant of the sparse text). */
CV_EXPORTS void writeTracks(const String& path, const Tracks& tracks,
                            TracksForm form = TRACKS_SMALLER);
/** @brief Bytes of the text of tracks.yml in `form` (TRACKS_DENSE or TRACKS_SPARSE; before any
compression); `path` picks the format (YAML, JSON, XML) as in writeTracks(). For the size rule
and the perf scripts. */
CV_EXPORTS size_t tracksFileBytes(const String& path, const Tracks& tracks, TracksForm form);

//! @brief Reads reconstruction.yml. Throws naming the file and key on error.
CV_EXPORTS Reconstruction readReconstruction(const String& path);
//! @brief Writes reconstruction.yml atomically.
CV_EXPORTS void writeReconstruction(const String& path, const Reconstruction& rec);

/** @brief Reads a masks or mattes folder `DIR/<object>/%04d.png`.
@param dir the folder.
@param expectedSize if not empty, every mask must have this size (else StsBadSize naming the file).
@return binary masks (0 / 255, CV_8U) after thresholding at > 127.
*/
CV_EXPORTS ObjectMasks readMasks(const String& dir, Size expectedSize = Size());
/** @brief Writes masks as `DIR/<object>/%04d.png`. The whole folder tree is written under a
temporary name and renamed into place, so a failure leaves no partial output. An existing `dir`
is replaced. */
CV_EXPORTS void writeMasks(const String& dir, const ObjectMasks& masks);

/** @brief Sequential frames from a video file, an image folder (sorted by name), or a printf
pattern such as `frames/%04d.png`. */
class CV_EXPORTS FrameSource
{
public:
    virtual ~FrameSource();
    /** @brief Opens the input; throws StsObjectNotFound / StsBadArg naming it when it cannot be
    opened or holds no frame.

    An input that names no existing file and holds a '%' is a frame pattern: literal text, `%%`
    for a literal '%', and exactly one integer conversion `%d`, `%Nd` or `%0Nd` (N <= 10); frame
    i is the i-th existing file from index 0 (or 1 when index 0 is absent). Any other pattern is
    StsBadArg naming it. The pattern is expanded by augocc and the files read with imread: it is
    never used as a printf or VideoCapture format. */
    static Ptr<FrameSource> open(const String& input);
    //! Number of frames (exact for folders and patterns; the container's count for videos).
    virtual int count() const = 0;
    //! Frame size.
    virtual Size size() const = 0;
    //! Frames per second (videos), else 25.
    virtual double fps() const = 0;
    //! Reads the next frame (BGR, CV_8UC3); false at the end. Throws on a corrupt frame.
    virtual bool read(OutputArray frame) = 0;
    //! Index of the frame the next read() returns.
    virtual int position() const = 0;
    //! Seeks so that the next read() returns frame `index`.
    virtual void seek(int index) = 0;
};

/** @brief Writes `path` all or nothing: `writer(tmpPath)` writes a temporary sibling
(`.STEM.tmpPID-K.EXT`, same extension), which is fsync'ed (every file and folder under it) and
renamed onto `path`, then the folder is fsync'ed. On failure the temporary is removed and the
error rethrown (a std::filesystem error as StsError naming `path` and the OS reason). Temporaries
of `path` that a killed earlier run left are removed first. `writer` must check its own writes:
FileStorage and imwrite do not report a full disk (the module's writers write through checked
calls). Used by every writer of the module (and the CLI). */
CV_EXPORTS void writeAtomically(const String& path,
                                const std::function<void(const String& tmpPath)>& writer);

/** @brief Writes `bytes` to `path` all or nothing (writeAtomically()), every write(), fsync() and
close() checked: a full disk is StsError naming `path` and "No space left on device".
@param path the file.
@param bytes its whole content.
@param executable also make the file executable (mode 0755 before the rename: scripts).
*/
CV_EXPORTS void writeFileAtomically(const String& path, const String& bytes,
                                    bool executable = false);

/** @brief Encodes `image` in the format `path`'s extension names (as imwrite) and writes it all or
nothing, every write checked (imwrite itself does not report a full disk). StsError naming `path`
when the image cannot be encoded or written. */
CV_EXPORTS void writeImageAtomically(const String& path, InputArray image);

/** @brief Opens a YAML, JSON or XML file (optionally gzipped) of the user's for reading with
cv::FileStorage, after the limits every augocc reader applies (size, nesting depth, NUL bytes,
markup cut short: OpenCV 4.6's parsers crash or hang on such files; README, "Input limits").
@param path the file.
@param what what the file is, for the messages ("shots file").
cv::Exception naming `path` and the problem when it is missing, over a limit or does not parse.
*/
CV_EXPORTS FileStorage openStorageForRead(const String& path, const String& what = "file");

//! @}

} // namespace augocc
} // namespace cv

#endif
