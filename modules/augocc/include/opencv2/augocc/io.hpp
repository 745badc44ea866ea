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

/** @brief 2D feature tracks: the measurement matrix of the factorization.

`tracks` is F x P CV_32FC2, (u, v) of track p in frame f, both NaN where not observed.
@sa @ref augocc_conventions_units "Units and indices"
*/
struct CV_EXPORTS Tracks
{
    Size imageSize;  //!< size of the frames, pixels
    Mat tracks;      //!< F x P CV_32FC2: (u, v) of track p in frame f, pixels; NaN: not observed

    //! Number of frames F (rows of `tracks`).
    int frames() const { return tracks.rows; }
    //! Number of tracks P (columns of `tracks`).
    int points() const { return tracks.cols; }
    //! True when track p is observed (finite) in frame f.
    bool observed(int f, int p) const;
    //! Observation of track p in frame f (NaN if unobserved).
    Point2f at(int f, int p) const { return tracks.at<Point2f>(f, p); }
    //! Number of frames in which track p is observed.
    int observationCount(int p) const;
    //! Throws when the matrix type, the size or a value is inconsistent.
    //! @param what names the source (file, key) in the message.
    void validate(const String& what = String()) const;
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

//! @brief Reads tracks.yml (also .yml.gz / .json). Throws naming the file and key on error.
CV_EXPORTS Tracks readTracks(const String& path);
//! @brief Writes tracks.yml atomically.
CV_EXPORTS void writeTracks(const String& path, const Tracks& tracks);

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

//! @}

} // namespace augocc
} // namespace cv

#endif
