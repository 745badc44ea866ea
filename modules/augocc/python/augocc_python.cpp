// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// `import augocc`: pybind11 bindings of the public API (doc/python.md).
//
// Conventions: images are numpy arrays as cv2 uses them (H x W or H x W x C, BGR uint8);
// matrices are float64 arrays; sizes are (width, height) tuples; points (x, y) tuples. Arrays
// returned by the module own a reference to the cv::Mat they come from (a capsule as their
// base), so they stay valid after the object that returned them is gone. Algorithms take their
// Params as keyword arguments; nested parts (CloneBuilder's box, patches...) as dicts.
// cv::Exception becomes augocc.error (a subclass of cv2.error when cv2 is importable) with the
// C++ message; the GIL is released in every long call and re-taken in progress callbacks.

#include <chrono>
#include <pybind11/pybind11.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <opencv2/augocc.hpp>

namespace py = pybind11;
using namespace cv;
using namespace cv::augocc;

namespace {

// ---- cv::Mat <-> numpy ---------------------------------------------------------------------

py::dtype dtypeOf(int depth)
{
    switch (depth)
    {
    case CV_8U: return py::dtype::of<uint8_t>();
    case CV_8S: return py::dtype::of<int8_t>();
    case CV_16U: return py::dtype::of<uint16_t>();
    case CV_16S: return py::dtype::of<int16_t>();
    case CV_32S: return py::dtype::of<int32_t>();
    case CV_32F: return py::dtype::of<float>();
    case CV_64F: return py::dtype::of<double>();
    }
    CV_Error(Error::StsUnsupportedFormat, "augocc: unsupported Mat depth");
}

int depthOf(const py::dtype& dt)
{
    if (dt.is(py::dtype::of<uint8_t>())) return CV_8U;
    if (dt.is(py::dtype::of<int8_t>())) return CV_8S;
    if (dt.is(py::dtype::of<uint16_t>())) return CV_16U;
    if (dt.is(py::dtype::of<int16_t>())) return CV_16S;
    if (dt.is(py::dtype::of<int32_t>())) return CV_32S;
    if (dt.is(py::dtype::of<float>())) return CV_32F;
    if (dt.is(py::dtype::of<double>())) return CV_64F;
    const char k = dt.kind();
    const int size = (int)dt.itemsize();
    if (k == 'u' && size == 1) return CV_8U;
    if (k == 'i' && size == 4) return CV_32S;
    if (k == 'f' && size == 4) return CV_32F;
    if (k == 'f' && size == 8) return CV_64F;
    throw py::type_error("augocc: unsupported array dtype " + py::cast<std::string>(py::str(py::object(dt))));
}

//! A numpy view of `m` (continuous; cloned otherwise) that keeps its data alive.
py::array toNumpy(const Mat& src, bool keepChannelAxis = false)
{
    if (src.empty())
        return py::array(py::dtype::of<uint8_t>(), std::vector<py::ssize_t>{0});
    Mat m = src.isContinuous() ? src : src.clone();
    Mat* owner = new Mat(m);
    py::capsule base(owner, [](void* p) { delete static_cast<Mat*>(p); });
    std::vector<py::ssize_t> shape{m.rows, m.cols};
    const py::ssize_t es = (py::ssize_t)m.elemSize1();
    std::vector<py::ssize_t> strides{(py::ssize_t)m.step[0], (py::ssize_t)m.elemSize()};
    if (m.channels() > 1 || keepChannelAxis)
    {
        shape.push_back(m.channels());
        strides.push_back(es);
    }
    return py::array(dtypeOf(m.depth()), shape, strides, m.data, base);
}

//! A Mat header over a numpy array's data (no copy; C-contiguous input is made so). The array
//! must outlive the Mat: clone it to keep it.
Mat fromNumpy(const py::handle& obj, const char* what)
{
    if (obj.is_none())
        return Mat();
    py::array a = py::array::ensure(obj, py::array::c_style);
    if (!a)
        throw py::type_error(std::string("augocc: ") + what + ": expected a numpy array");
    const int depth = depthOf(a.dtype());
    if (a.ndim() == 0 || a.size() == 0)
        return Mat();
    if (a.ndim() == 1)
        return Mat(1, (int)a.shape(0), CV_MAKETYPE(depth, 1), a.mutable_data());
    if (a.ndim() == 2)
        return Mat((int)a.shape(0), (int)a.shape(1), CV_MAKETYPE(depth, 1), a.mutable_data());
    if (a.ndim() == 3 && a.shape(2) <= CV_CN_MAX)
        return Mat((int)a.shape(0), (int)a.shape(1), CV_MAKETYPE(depth, (int)a.shape(2)),
                   a.mutable_data());
    throw py::type_error(std::string("augocc: ") + what + ": expected a 1-, 2- or 3-d array");
}

//! An owning copy (for data stored in C++ objects).
Mat copyFromNumpy(const py::handle& obj, const char* what)
{
    return fromNumpy(obj, what).clone();
}

template <int M, int N>
py::array matxToNumpy(const Matx<double, M, N>& x)
{
    return toNumpy(Mat(x).clone());
}

template <int M, int N>
Matx<double, M, N> matxFromNumpy(const py::handle& obj, const char* what)
{
    Mat m = fromNumpy(obj, what);
    Mat d;
    m.reshape(1, m.total() * m.channels() == M * N ? M : m.rows).convertTo(d, CV_64F);
    if (d.rows * d.cols != M * N)
        throw py::value_error(format("augocc: %s: expected %d x %d values", what, M, N));
    return Matx<double, M, N>(d.reshape(1, M).ptr<double>());
}

// ---- masks ---------------------------------------------------------------------------------

py::dict masksToPy(const ObjectMasks& masks)
{
    py::dict out;
    for (const auto& obj : masks)
    {
        py::dict frames;
        for (const auto& kv : obj.second)
            frames[py::int_(kv.first)] = toNumpy(kv.second);
        out[py::str(obj.first)] = frames;
    }
    return out;
}

ObjectMasks masksFromPy(const py::dict& d)
{
    ObjectMasks masks;
    for (const auto& obj : d)
    {
        FrameMasks& fm = masks[obj.first.cast<std::string>()];
        for (const auto& kv : obj.second.cast<py::dict>())
            fm[kv.first.cast<int>()] = copyFromNumpy(kv.second, "mask");
    }
    return masks;
}

std::vector<Mat> framesFromPy(const py::sequence& seq, const char* what)
{
    std::vector<Mat> frames;
    for (const auto& f : seq)
        frames.push_back(fromNumpy(f, what));
    return frames;
}

// ---- progress and keyword Params -----------------------------------------------------------

//! A ProgressCallback that calls a Python callable with the GIL held.
ProgressCallback progressFromPy(const py::object& fn)
{
    if (fn.is_none())
        return ProgressCallback();
    auto holder = std::make_shared<py::object>(fn);
    return [holder](const Progress& p) {
        py::gil_scoped_acquire gil;
        (*holder)(p);
    };
}

//! Sets the attributes of a bound Params object from keyword arguments; a dict value sets the
//! attributes of a nested part; `progress` takes a Python callable.
void applyKwargs(py::object target, const py::kwargs& kwargs)
{
    for (const auto& kv : kwargs)
    {
        const std::string key = kv.first.cast<std::string>();
        if (!py::hasattr(target, key.c_str()))
            throw py::type_error("augocc: unknown parameter '" + key + "' of " +
                                 std::string(py::str(target.get_type().attr("__qualname__"))));
        if (py::isinstance<py::dict>(kv.second))
        {
            py::object part = target.attr(key.c_str());
            applyKwargs(part, kv.second.cast<py::dict>().attr("copy")().cast<py::kwargs>());
            target.attr(key.c_str()) = part;
        }
        else
            target.attr(key.c_str()) = kv.second;
    }
}

template <class P>
P paramsFromKwargs(const py::kwargs& kwargs)
{
    py::object obj = py::cast(P());
    applyKwargs(obj, kwargs);
    return obj.cast<P>();
}

// Progress members are std::function: expose them as write-only Python callables.
template <class C, class P>
void defProgress(C& cls, ProgressCallback P::*member)
{
    cls.def_property("progress", [](const P&) { return py::none(); },
                     [member](P& p, const py::object& fn) { p.*member = progressFromPy(fn); },
                     "callable(Progress) or None: progress reports of the long stages");
}

py::tuple sizeToPy(Size s) { return py::make_tuple(s.width, s.height); }
Size sizeFromPy(const py::handle& h)
{
    auto t = h.cast<std::pair<int, int>>();
    return Size(t.first, t.second);
}

// Short aliases for properties of Size / Point / Vec fields.
#define AUGOCC_SIZE_PROP(cls, Type, field, doc) \
    cls.def_property(#field, [](const Type& o) { return sizeToPy(o.field); }, \
                     [](Type& o, const py::object& v) { o.field = sizeFromPy(v); }, doc)
#define AUGOCC_VEC3_PROP(cls, Type, field, doc) \
    cls.def_property(#field, [](const Type& o) { \
        return py::make_tuple(o.field[0], o.field[1], o.field[2]); }, \
        [](Type& o, const std::array<double, 3>& v) { o.field = Vec3d(v[0], v[1], v[2]); }, doc)
#define AUGOCC_MATX_PROP(cls, Type, field, M, N, doc) \
    cls.def_property(#field, [](const Type& o) { return matxToNumpy<M, N>(o.field); }, \
                     [](Type& o, const py::object& v) { \
                         o.field = matxFromNumpy<M, N>(v, #field); }, doc)
#define AUGOCC_MAT_PROP(cls, Type, field, doc) \
    cls.def_property(#field, [](const Type& o) { return toNumpy(o.field); }, \
                     [](Type& o, const py::object& v) { o.field = copyFromNumpy(v, #field); }, \
                     doc)

// ---- points arrays ---------------------------------------------------------------------------

//! Nx3 (or 3) float array as Vec3d points.
std::vector<Vec3d> pointsFromPy(const py::handle& obj)
{
    Mat m = fromNumpy(obj, "points");
    Mat d;
    m.convertTo(d, CV_64F);
    d = d.reshape(1, (int)(d.total() * d.channels() / 3));
    if (d.cols != 3)
        throw py::value_error("augocc: points: expected an N x 3 array");
    std::vector<Vec3d> pts(d.rows);
    for (int i = 0; i < d.rows; i++)
        pts[i] = Vec3d(d.ptr<double>(i));
    return pts;
}

void registerError(py::module_& m)
{
    py::object base = py::reinterpret_borrow<py::object>(PyExc_Exception);
    try
    {
        base = py::module_::import("cv2").attr("error");
    }
    catch (const py::error_already_set&)
    {
        // cv2 is optional: then augocc.error derives from Exception.
    }
    static py::object error;
    error = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
        "augocc.error",
        "A cv::Exception of the library: str(e) is its message (as cv2.error's); attributes "
        "code, err, func, file, line as cv2.error has them.",
        base.ptr(), nullptr));
    m.attr("error") = error;
    py::register_exception_translator([](std::exception_ptr p) {
        try
        {
            if (p)
                std::rethrow_exception(p);
        }
        catch (const cv::Exception& e)
        {
            py::object inst = error(e.what());
            inst.attr("code") = e.code;
            inst.attr("err") = e.err;
            inst.attr("func") = e.func;
            inst.attr("file") = e.file;
            inst.attr("line") = e.line;
            PyErr_SetObject(error.ptr(), inst.ptr());
        }
    });
}

} // namespace

PYBIND11_MODULE(augocc, m)
{
    m.doc() = "augocc: virtual objects composited into video of a real static scene with "
              "correct occlusion (Ong, Teh & Tan 1998). Images are numpy BGR uint8 arrays as "
              "cv2 uses them. See doc/python.md.";
    registerError(m);

    // ---- camera ------------------------------------------------------------------------------
    py::enum_<CameraModel>(m, "CameraModel", "Camera models (CONTRACT.md, Camera models)")
        .value("SCALED_ORTHOGRAPHIC", SCALED_ORTHOGRAPHIC)
        .value("PERSPECTIVE", PERSPECTIVE)
        .export_values();
    m.def("cameraModelName", &cameraModelName, "Contract name of a camera model.");
    m.def("parseCameraModel", &parseCameraModel, "Camera model from its contract name.");

    py::class_<Camera> camera(m, "Camera",
        "One camera: pose (Xc = R Xw + t), model and intrinsics. project() and depth() take "
        "N x 3 arrays.");
    camera.def(py::init<>())
        .def_readwrite("model", &Camera::model, "CameraModel")
        .def_readwrite("frame", &Camera::frame, "0-based frame index")
        .def_readwrite("s", &Camera::s, "SCALED_ORTHOGRAPHIC: pixels per world unit")
        .def_readwrite("distortion", &Camera::distortion, "PERSPECTIVE: OpenCV distortion")
        .def_property("pp", [](const Camera& c) { return py::make_tuple(c.pp.x, c.pp.y); },
                      [](Camera& c, std::pair<double, double> v) {
                          c.pp = Point2d(v.first, v.second); },
                      "SCALED_ORTHOGRAPHIC: principal point (cx, cy)");
    AUGOCC_MATX_PROP(camera, Camera, R, 3, 3, "rotation, world to camera (3x3 float64)");
    AUGOCC_MATX_PROP(camera, Camera, K, 3, 3, "PERSPECTIVE: intrinsics (3x3 float64)");
    camera.def_property("t", [](const Camera& c) { return matxToNumpy<3, 1>(c.t).attr("ravel")(); },
                        [](Camera& c, const py::object& v) {
                            c.t = Vec3d(matxFromNumpy<3, 1>(v, "t").val); },
                        "translation, world to camera (3 float64)");
    camera
        .def_static("orthographic", [](const py::object& R, const py::object& t, double s,
                                       std::pair<double, double> pp, int frame) {
                        return Camera::orthographic(matxFromNumpy<3, 3>(R, "R"),
                                                    Vec3d(matxFromNumpy<3, 1>(t, "t").val), s,
                                                    Point2d(pp.first, pp.second), frame);
                    }, py::arg("R"), py::arg("t"), py::arg("s"), py::arg("pp"),
                    py::arg("frame") = 0, "A scaled-orthographic camera.")
        .def_static("perspective", [](const py::object& R, const py::object& t,
                                      const py::object& K, int frame,
                                      const std::vector<double>& dist) {
                        return Camera::perspective(matxFromNumpy<3, 3>(R, "R"),
                                                   Vec3d(matxFromNumpy<3, 1>(t, "t").val),
                                                   matxFromNumpy<3, 3>(K, "K"), frame, dist);
                    }, py::arg("R"), py::arg("t"), py::arg("K"), py::arg("frame") = 0,
                    py::arg("distortion") = std::vector<double>(), "A perspective camera.")
        .def("project", [](const Camera& c, const py::object& X) {
                 const std::vector<Vec3d> pts = pointsFromPy(X);
                 py::array_t<double> out({(py::ssize_t)pts.size(), (py::ssize_t)2});
                 auto o = out.mutable_unchecked<2>();
                 for (size_t i = 0; i < pts.size(); i++)
                 {
                     const Point2d p = c.project(pts[i]);
                     o(i, 0) = p.x;
                     o(i, 1) = p.y;
                 }
                 return out;
             }, py::arg("points"),
             "Projects world points (N x 3) to pixels (N x 2 float64), Camera::project per row.")
        .def("depth", [](const Camera& c, const py::object& X) {
                 const std::vector<Vec3d> pts = pointsFromPy(X);
                 py::array_t<double> out((py::ssize_t)pts.size());
                 auto o = out.mutable_unchecked<1>();
                 for (size_t i = 0; i < pts.size(); i++)
                     o(i) = c.depth(pts[i]);
                 return out;
             }, py::arg("points"), "Camera-space depth Xc.z of world points (N x 3) -> N.")
        .def("backproject", [](const Camera& c, std::pair<double, double> px) {
                 const Ray r = c.backproject(Point2d(px.first, px.second));
                 return py::make_tuple(py::make_tuple(r.origin[0], r.origin[1], r.origin[2]),
                     py::make_tuple(r.direction[0], r.direction[1], r.direction[2]));
             }, py::arg("px"), "World ray (origin, unit direction) through pixel (x, y).")
        .def("unproject", [](const Camera& c, std::pair<double, double> px, double z) {
                 const Vec3d X = c.unproject(Point2d(px.first, px.second), z);
                 return py::make_tuple(X[0], X[1], X[2]);
             }, py::arg("px"), py::arg("z"), "World point seen at pixel px at depth z.")
        .def("center", [](const Camera& c) {
                 const Vec3d X = c.center();
                 return py::make_tuple(X[0], X[1], X[2]); }, "Camera centre, world.")
        .def("principalPoint", [](const Camera& c) {
                 const Point2d p = c.principalPoint();
                 return py::make_tuple(p.x, p.y); }, "Principal point (cx, cy), pixels.")
        .def("projectionMatrix", [](const Camera& c) {
                 return matxToNumpy<3, 4>(c.projectionMatrix()); }, "3x4 projection matrix.")
        .def("pixelsPerUnit", &Camera::pixelsPerUnit, py::arg("z"))
        .def("hasDistortion", &Camera::hasDistortion)
        .def("validate", &Camera::validate, py::arg("what") = "",
             "Raises augocc.error when the camera is not valid.")
        .def("__repr__", [](const Camera& c) {
                 return format("<augocc.Camera %s frame %d>", cameraModelName(c.model).c_str(),
                               c.frame); });

    // ---- tracks, reconstruction, io ----------------------------------------------------------
    py::class_<Tracks>(m, "Tracks",
        "2D feature tracks, stored sparse. obs_index (N x 2 int32: frame, point) and obs_uv "
        "(N x 2 float32) are the observations by track then frame; dense() the F x P x 2 "
        "matrix, NaN where unobserved.")
        .def(py::init<>())
        .def_static("fromDense", [](std::pair<int, int> size, const py::object& dense,
                                    const String& what) {
                        Mat d = fromNumpy(dense, "dense");
                        if (d.channels() == 1 && d.cols % 2 == 0 &&
                            py::array(dense).ndim() == 3)
                            d = d.reshape(2);
                        return Tracks::fromDense(Size(size.first, size.second), d.clone(), what);
                    }, py::arg("imageSize"), py::arg("dense"), py::arg("what") = "tracks",
                    "Tracks from an F x P x 2 array (NaN = not observed).")
        .def_static("fromObservations", [](std::pair<int, int> size, int frames, int points,
                                           const py::object& index, const py::object& uv,
                                           const String& what) {
                        Mat i = fromNumpy(index, "index"), u = fromNumpy(uv, "uv");
                        return Tracks::fromObservations(Size(size.first, size.second), frames,
                                                        points, i.reshape(1, i.rows).clone(),
                                                        u.reshape(1, u.rows).clone(), what);
                    }, py::arg("imageSize"), py::arg("frames"), py::arg("points"),
                    py::arg("index"), py::arg("uv"), py::arg("what") = "tracks")
        .def_property_readonly("imageSize", [](const Tracks& t) { return sizeToPy(t.imageSize); })
        .def("frames", &Tracks::frames, "Number of frames F.")
        .def("points", &Tracks::points, "Number of tracks P.")
        .def("observations", &Tracks::observations, "Number of observations N.")
        .def("observationCount", &Tracks::observationCount, py::arg("p"))
        .def("at", [](const Tracks& t, int f, int p) {
                 const Point2f q = t.at(f, p);
                 return py::make_tuple(q.x, q.y); }, py::arg("f"), py::arg("p"))
        .def_property_readonly("obs_index", [](const Tracks& t) {
                 Mat idx(t.observations(), 2, CV_32S);
                 for (int i = 0; i < t.observations(); i++)
                 {
                     idx.at<int>(i, 0) = t.frameOf(i);
                     idx.at<int>(i, 1) = t.pointOf(i);
                 }
                 return toNumpy(idx); })
        .def_property_readonly("obs_uv", [](const Tracks& t) {
                 Mat uv(t.observations(), 2, CV_32F);
                 for (int i = 0; i < t.observations(); i++)
                 {
                     uv.at<float>(i, 0) = t.uv(i).x;
                     uv.at<float>(i, 1) = t.uv(i).y;
                 }
                 return toNumpy(uv); })
        .def("dense", [](const Tracks& t) { return toNumpy(t.dense()); },
             "F x P x 2 float32, NaN where unobserved.")
        .def("validate", &Tracks::validate, py::arg("what") = "");

    py::class_<Reconstruction> recCls(m, "Reconstruction",
        "Cameras and 3D points; points (P x 3 float64) row p belongs to track column p, NaN "
        "rows for rejected tracks. `points` is a view of the C++ matrix.");
    recCls.def(py::init<>())
        .def_readwrite("model", &Reconstruction::model)
        .def_readwrite("cameras", &Reconstruction::cameras, "list of Camera (copies)");
    AUGOCC_SIZE_PROP(recCls, Reconstruction, imageSize, "(width, height)");
    AUGOCC_MAT_PROP(recCls, Reconstruction, points, "P x 3 float64");
    recCls.def("findCamera", &Reconstruction::findCamera, py::arg("frame"))
        .def("camera", &Reconstruction::camera, py::arg("frame"),
             py::return_value_policy::copy, "Camera of a frame (raises when it has none).")
        .def("hasPoint", &Reconstruction::hasPoint, py::arg("p"))
        .def("validPointCount", &Reconstruction::validPointCount)
        .def("validate", &Reconstruction::validate, py::arg("what") = "");

    py::class_<Calibration> calib(m, "Calibration", "Known intrinsics (calibration.yml).");
    calib.def(py::init<>()).def_readwrite("distortion", &Calibration::distortion);
    AUGOCC_MATX_PROP(calib, Calibration, K, 3, 3, "intrinsics");
    AUGOCC_SIZE_PROP(calib, Calibration, imageSize, "(width, height)");

    py::enum_<TracksForm>(m, "TracksForm")
        .value("TRACKS_SMALLER", TRACKS_SMALLER)
        .value("TRACKS_DENSE", TRACKS_DENSE)
        .value("TRACKS_SPARSE", TRACKS_SPARSE)
        .export_values();
    m.def("readTracks", &readTracks, py::arg("path"), py::call_guard<py::gil_scoped_release>(),
          "Reads tracks.yml (raises augocc.error naming the file and key).");
    m.def("writeTracks", &writeTracks, py::arg("path"), py::arg("tracks"),
          py::arg("form") = TRACKS_SMALLER, py::call_guard<py::gil_scoped_release>(),
          "Writes tracks.yml atomically.");
    m.def("readReconstruction", &readReconstruction, py::arg("path"),
          py::call_guard<py::gil_scoped_release>(), "Reads reconstruction.yml.");
    m.def("writeReconstruction", &writeReconstruction, py::arg("path"), py::arg("rec"),
          py::call_guard<py::gil_scoped_release>(), "Writes reconstruction.yml atomically.");
    m.def("readCalibration", [](const String& path, std::pair<int, int> size) {
              return readCalibration(path, Size(size.first, size.second)); },
          py::arg("path"), py::arg("frameSize") = std::pair<int, int>(0, 0),
          "Reads OpenCV's calibration file for frames of frameSize.");
    m.def("readMasks", [](const String& dir, std::pair<int, int> size) {
              ObjectMasks masks;
              {
                  py::gil_scoped_release nogil;
                  masks = readMasks(dir, Size(size.first, size.second));
              }
              return masksToPy(masks);
          }, py::arg("dir"), py::arg("expectedSize") = std::pair<int, int>(0, 0),
          "Reads DIR/<object>/%04d.png: {object: {frame: uint8 array}}.");
    m.def("writeMasks", [](const String& dir, const py::dict& masks) {
              const ObjectMasks mk = masksFromPy(masks);
              py::gil_scoped_release nogil;
              writeMasks(dir, mk);
          }, py::arg("dir"), py::arg("masks"), "Writes {object: {frame: mask}} atomically.");

    py::class_<FrameSource, std::shared_ptr<FrameSource>>(m, "FrameSource",
        "Frames of a video, an image folder or a printf pattern.")
        .def_static("open", [](const String& input) {
                        return std::shared_ptr<FrameSource>(FrameSource::open(input)); },
                    py::arg("input"))
        .def("count", &FrameSource::count)
        .def("size", [](const FrameSource& s) { return sizeToPy(s.size()); })
        .def("fps", &FrameSource::fps)
        .def("position", &FrameSource::position)
        .def("seek", &FrameSource::seek, py::arg("index"))
        .def("read", [](FrameSource& s) -> py::object {
                 Mat f;
                 bool ok;
                 {
                     py::gil_scoped_release nogil;
                     ok = s.read(f);
                 }
                 return ok ? py::object(toNumpy(f)) : py::object(py::none());
             }, "The next frame (BGR uint8) or None at the end.");

    // ---- progress ------------------------------------------------------------------------------
    py::class_<Progress>(m, "Progress", "A progress report of a long stage.")
        .def_readonly("stage", &Progress::stage)
        .def_readonly("step", &Progress::step)
        .def_readonly("done", &Progress::done)
        .def_readonly("total", &Progress::total)
        .def_readonly("unit", &Progress::unit)
        .def_readonly("message", &Progress::message)
        .def("__repr__", [](const Progress& p) {
                 return format("<augocc.Progress %s/%s %lld/%lld %s>", p.stage.c_str(),
                               p.step.c_str(), (long long)p.done, (long long)p.total,
                               p.unit.c_str()); });

    // ---- mesh and scene ------------------------------------------------------------------------
    py::class_<Mesh> mesh(m, "Mesh", "A triangle mesh (vertices N x 3 float32, faces M x 3 "
                                     "int32).");
    mesh.def(py::init<>())
        .def_property("vertices", [](const Mesh& me) {
                          return toNumpy(Mat(me.vertices, true).reshape(1)); },
                      [](Mesh& me, const py::object& v) {
                          Mat a = fromNumpy(v, "vertices");
                          Mat f;
                          a.convertTo(f, CV_32F);
                          f.reshape(3, (int)(f.total() * f.channels() / 3)).copyTo(me.vertices);
                      })
        .def_property("faces", [](const Mesh& me) {
                          return toNumpy(Mat(me.faces, true).reshape(1)); },
                      [](Mesh& me, const py::object& v) {
                          Mat a = fromNumpy(v, "faces");
                          Mat f;
                          a.convertTo(f, CV_32S);
                          f.reshape(3, (int)(f.total() * f.channels() / 3)).copyTo(me.faces);
                      })
        .def("empty", &Mesh::empty)
        .def("computeNormals", &Mesh::computeNormals)
        .def("transform", [](Mesh& me, const py::object& M) {
                 me.transform(matxFromNumpy<4, 4>(M, "M")); }, py::arg("M"))
        .def_static("box", [](std::array<float, 3> a, std::array<float, 3> b) {
                        return Mesh::box(Vec3f(a[0], a[1], a[2]), Vec3f(b[0], b[1], b[2])); },
                    py::arg("minCorner"), py::arg("maxCorner"))
        .def_static("sphere", &Mesh::sphere, py::arg("radius"), py::arg("segments") = 32,
                    py::arg("rings") = 16)
        .def_static("dome", &Mesh::dome, py::arg("radius"), py::arg("segments") = 32,
                    py::arg("rings") = 12)
        .def_static("cylinder", &Mesh::cylinder, py::arg("radius"), py::arg("y0"),
                    py::arg("y1"), py::arg("segments") = 32);
    m.def("loadMeshes", &loadMeshes, py::arg("path"), "Meshes of a file (Assimp).");
    m.def("writeMeshPly", &writeMeshPly, py::arg("path"), py::arg("mesh"));

    py::class_<VirtualScene>(m, "VirtualScene", "A parsed scene file (scene.yml).")
        .def(py::init<>())
        .def_readwrite("path", &VirtualScene::path)
        .def_readwrite("sun", &VirtualScene::sun, "the `sun` node (SceneSun)")
        .def_property_readonly("objectNames", [](const VirtualScene& s) {
                                   std::vector<String> n;
                                   for (const SceneObject& o : s.objects)
                                       n.push_back(o.name);
                                   return n; });
    m.def("readScene", &readScene, py::arg("path"),
          "Reads and validates scene.yml with its meshes.");
    m.def("writeScene", &writeScene, py::arg("path"), py::arg("scene"));
    m.def("demoVirtualScene", &demoVirtualScene, py::arg("path"),
          "The demo's dome behind the building and tree in front of it.");

    // ---- clones ------------------------------------------------------------------------------
    py::class_<CloneSet, std::shared_ptr<CloneSet>>(m, "CloneSet",
        "The clones of the real objects: per object a voxel grid and patch voxels per key "
        "frame.")
        .def_static("load", [](const String& path) {
                        py::gil_scoped_release nogil;
                        return std::shared_ptr<CloneSet>(CloneSet::load(path)); },
                    py::arg("path"), "Loads a clones file (raises naming the file).")
        .def("save", &CloneSet::save, py::arg("path"), py::call_guard<py::gil_scoped_release>(),
             "Saves atomically (.yml.gz recommended).")
        .def("objectNames", &CloneSet::objectNames)
        .def("render", [](const CloneSet& c, const String& object, int frame,
                          const Camera& cam, std::pair<int, int> size, bool depth) -> py::object {
                 Mat matte, z;
                 {
                     py::gil_scoped_release nogil;
                     c.render(object, frame, cam, Size(size.first, size.second), matte,
                              depth ? _OutputArray(z) : _OutputArray(noArray()));
                 }
                 if (depth)
                     return py::make_tuple(toNumpy(matte), toNumpy(z));
                 return toNumpy(matte);
             }, py::arg("object"), py::arg("frame"), py::arg("camera"), py::arg("imageSize"),
             py::arg("depth") = false,
             "Matte (uint8 0/255) of one object in a frame; with depth=True (matte, depth "
             "float32, +inf off the clone).")
        .def("keyFrames", &CloneSet::keyFrames, py::arg("object"))
        .def("patchFrames", &CloneSet::patchFrames, py::arg("object"), py::arg("frame"))
        .def("voxelCount", &CloneSet::voxelCount, py::arg("object"))
        .def("patchVoxelCount", &CloneSet::patchVoxelCount, py::arg("object"),
             py::arg("keyFrame"))
        .def("gridSize", [](const CloneSet& c, const String& o) {
                 const Vec3i g = c.gridSize(o);
                 return py::make_tuple(g[0], g[1], g[2]); }, py::arg("object"))
        .def("voxelSize", &CloneSet::voxelSize, py::arg("object"))
        .def("gridPose", [](const CloneSet& c, const String& o) {
                 Matx33d R;
                 Vec3d origin;
                 c.gridPose(o, R, origin);
                 return py::make_tuple(matxToNumpy<3, 3>(R),
                                       py::make_tuple(origin[0], origin[1], origin[2])); },
             py::arg("object"), "(Rbox 3x3, origin)")
        .def("exportPly", &CloneSet::exportPly, py::arg("dir"),
             py::call_guard<py::gil_scoped_release>());

    py::class_<CloneBuilder::BoxParams> boxP(m, "CloneBuilderBoxParams");
    boxP.def(py::init<>())
        .def_readwrite("minPoints", &CloneBuilder::BoxParams::minPoints)
        .def_readwrite("trimFraction", &CloneBuilder::BoxParams::trimFraction)
        .def_readwrite("orientation", &CloneBuilder::BoxParams::orientation)
        .def_readwrite("maxEnlargeIterations", &CloneBuilder::BoxParams::maxEnlargeIterations);
    AUGOCC_VEC3_PROP(boxP, CloneBuilder::BoxParams, userRotation, "Rodrigues vector, radians");
    py::class_<CloneBuilder::PatchParams>(m, "CloneBuilderPatchParams")
        .def(py::init<>())
        .def_readwrite("raysPerPixel", &CloneBuilder::PatchParams::raysPerPixel)
        .def_readwrite("rule", &CloneBuilder::PatchParams::rule);
    py::class_<CloneBuilder::FreeSpaceParams>(m, "CloneBuilderFreeSpaceParams")
        .def(py::init<>())
        .def_readwrite("minViews", &CloneBuilder::FreeSpaceParams::minViews)
        .def_readwrite("edgeMargin", &CloneBuilder::FreeSpaceParams::edgeMargin)
        .def_readwrite("planarDeg", &CloneBuilder::FreeSpaceParams::planarDeg)
        .def_readwrite("marginVoxels", &CloneBuilder::FreeSpaceParams::marginVoxels)
        .def_readwrite("maxEdgeRatio", &CloneBuilder::FreeSpaceParams::maxEdgeRatio)
        .def_readwrite("maxReprojPx", &CloneBuilder::FreeSpaceParams::maxReprojPx)
        .def_readwrite("maxViews", &CloneBuilder::FreeSpaceParams::maxViews);
    py::class_<CloneBuilder::UnobservedParams>(m, "CloneBuilderUnobservedParams")
        .def(py::init<>())
        .def_readwrite("enabled", &CloneBuilder::UnobservedParams::enabled)
        .def_readwrite("views", &CloneBuilder::UnobservedParams::views)
        .def_readwrite("depthTolVoxels", &CloneBuilder::UnobservedParams::depthTolVoxels)
        .def_readwrite("keepNearSeen", &CloneBuilder::UnobservedParams::keepNearSeen)
        .def_readwrite("regrowFromUnseen", &CloneBuilder::UnobservedParams::regrowFromUnseen)
        .def_readwrite("maxTiltDeg", &CloneBuilder::UnobservedParams::maxTiltDeg);
    py::class_<CloneBuilder::PhotoParams>(m, "CloneBuilderPhotoParams")
        .def(py::init<>())
        .def_readwrite("threshold", &CloneBuilder::PhotoParams::threshold)
        .def_readwrite("minAgreement", &CloneBuilder::PhotoParams::minAgreement)
        .def_readwrite("minViews", &CloneBuilder::PhotoParams::minViews)
        .def_readwrite("rounds", &CloneBuilder::PhotoParams::rounds)
        .def_readwrite("patchStep", &CloneBuilder::PhotoParams::patchStep)
        .def_readwrite("maxViews", &CloneBuilder::PhotoParams::maxViews);
    py::class_<CloneBuilder::Params> cbP(m, "CloneBuilderParams",
        "CloneBuilder parameters (clone_builder.hpp); nested parts box, patches, freeSpace, "
        "unobserved, photo.");
    cbP.def(py::init<>())
        .def_readwrite("voxelPixels", &CloneBuilder::Params::voxelPixels)
        .def_readwrite("maxVoxels", &CloneBuilder::Params::maxVoxels)
        .def_readwrite("occlusionAware", &CloneBuilder::Params::occlusionAware)
        .def_readwrite("box", &CloneBuilder::Params::box)
        .def_readwrite("patches", &CloneBuilder::Params::patches)
        .def_readwrite("freeSpace", &CloneBuilder::Params::freeSpace)
        .def_readwrite("unobserved", &CloneBuilder::Params::unobserved)
        .def_readwrite("photo", &CloneBuilder::Params::photo);
    defProgress(cbP, &CloneBuilder::Params::progress);

    py::class_<CloneBuilder, std::shared_ptr<CloneBuilder>> cb(m, "CloneBuilder",
        "Builds clones of real objects from a reconstruction and key-frame silhouettes "
        "(CloneBuilder(voxelPixels=1.0, freeSpace=dict(minViews=0), progress=fn, ...)).");
    cb.def(py::init([](const py::kwargs& kw) {
               return std::shared_ptr<CloneBuilder>(
                   CloneBuilder::create(paramsFromKwargs<CloneBuilder::Params>(kw))); }))
        .def("getParams", &CloneBuilder::getParams)
        .def("setParams", &CloneBuilder::setParams, py::arg("params"))
        .def("build", [](const CloneBuilder& b, const Reconstruction& rec, const py::dict& masks,
                         const Tracks* tracks) {
                 const ObjectMasks mk = masksFromPy(masks);
                 py::gil_scoped_release nogil;
                 return std::shared_ptr<CloneSet>(b.build(rec, mk, tracks)); },
             py::arg("rec"), py::arg("keyFrameMasks"), py::arg("tracks") = nullptr,
             "One clone per object of {object: {frame: mask}}; with tracks, clustering by "
             "observation and free-space carving.")
        .def("addKeyFrame", [](const CloneBuilder& b, CloneSet& clones, const Reconstruction& rec,
                               const String& object, int frame, const py::object& mask) {
                 Mat mk = fromNumpy(mask, "mask");
                 py::gil_scoped_release nogil;
                 b.addKeyFrame(clones, rec, object, frame, mk); },
             py::arg("clones"), py::arg("rec"), py::arg("object"), py::arg("frame"),
             py::arg("mask"), "Adds one key frame to an existing clone.")
        .def("refine", [](const CloneBuilder& b, CloneSet& clones, const Reconstruction& rec,
                          const py::sequence& frames) {
                 const std::vector<Mat> fr = framesFromPy(frames, "frames");
                 py::gil_scoped_release nogil;
                 return b.refine(clones, rec, fr); },
             py::arg("clones"), py::arg("rec"), py::arg("frames"),
             "Photo-consistency carving over the frames (frames[f] is frame f, None where "
             "unused); returns the voxels carved.")
        .def("photoFrames", &CloneBuilder::photoFrames, py::arg("rec"),
             "The frames refine() compares (at most photo.maxViews, evenly spaced); the "
             "others may be None.");

    m.def("renderMattes", [](const CloneSet& clones, const Reconstruction& rec,
                             const py::object& progress) {
              ObjectMasks mattes;
              const ProgressCallback cb = progressFromPy(progress);
              {
                  py::gil_scoped_release nogil;
                  renderMattes(clones, rec, mattes, nullptr, cb);
              }
              return masksToPy(mattes);
          }, py::arg("clones"), py::arg("rec"), py::arg("progress") = py::none(),
          "Every object's matte in every frame of rec: {object: {frame: uint8}}.");
    m.def("writeMattes", [](const String& dir, const CloneSet& clones, const Reconstruction& rec,
                            const String& depthDir, const py::object& progress) {
              const ProgressCallback cb = progressFromPy(progress);
              py::gil_scoped_release nogil;
              writeMattes(dir, clones, rec, depthDir, cb);
          }, py::arg("dir"), py::arg("clones"), py::arg("rec"), py::arg("depthDir") = "",
          py::arg("progress") = py::none(), "Writes the mattes folder (as `augocc matte`).");

    // ---- tracker and sfm ---------------------------------------------------------------------
    py::class_<FeatureTracker::Params> ftP(m, "FeatureTrackerParams",
                                           "FeatureTracker parameters (feature_tracker.hpp).");
    ftP.def(py::init<>())
        .def_readwrite("maxTracks", &FeatureTracker::Params::maxTracks)
        .def_readwrite("quality", &FeatureTracker::Params::quality)
        .def_readwrite("minDistance", &FeatureTracker::Params::minDistance)
        .def_readwrite("blockSize", &FeatureTracker::Params::blockSize)
        .def_readwrite("levels", &FeatureTracker::Params::levels)
        .def_readwrite("fbThreshold", &FeatureTracker::Params::fbThreshold)
        .def_readwrite("redetectRatio", &FeatureTracker::Params::redetectRatio)
        .def_readwrite("minTrackLength", &FeatureTracker::Params::minTrackLength)
        .def_readwrite("border", &FeatureTracker::Params::border);
    AUGOCC_SIZE_PROP(ftP, FeatureTracker::Params, winSize, "Lucas-Kanade window (w, h)");
    AUGOCC_MAT_PROP(ftP, FeatureTracker::Params, exclusionMask, "uint8, > 127 = no features");
    defProgress(ftP, &FeatureTracker::Params::progress);

    py::class_<FeatureTracker, std::shared_ptr<FeatureTracker>>(m, "FeatureTracker",
        "Shi-Tomasi corners tracked by pyramidal Lucas-Kanade with a forward-backward check "
        "(FeatureTracker(maxTracks=1000, progress=fn, ...)).")
        .def(py::init([](const py::kwargs& kw) {
                 return std::shared_ptr<FeatureTracker>(
                     FeatureTracker::create(paramsFromKwargs<FeatureTracker::Params>(kw))); }))
        .def("getParams", &FeatureTracker::getParams)
        .def("setParams", &FeatureTracker::setParams, py::arg("params"))
        .def("track", [](const FeatureTracker& t, const py::object& frames) {
                 Tracks out;
                 if (py::isinstance<py::str>(frames))
                 {
                     const String input = frames.cast<std::string>();
                     py::gil_scoped_release nogil;
                     t.track(FrameSource::open(input), out);
                 }
                 else
                 {
                     const std::vector<Mat> fr = framesFromPy(frames, "frames");
                     py::gil_scoped_release nogil;
                     t.track(fr, out);
                 }
                 return out; },
             py::arg("frames"),
             "Tracks of a list of frames (BGR or grey uint8), or of an input path (video, "
             "image folder, printf pattern) read as `augocc track` reads it.");

    py::class_<SfmOptions> sfmO(m, "SfmOptions", "Options of recoverCameras() (camera_refiner.hpp).");
    sfmO.def(py::init<>())
        .def_readwrite("model", &SfmOptions::model)
        .def_readwrite("bundleAdjust", &SfmOptions::bundleAdjust)
        .def_readwrite("perFrameScale", &SfmOptions::perFrameScale)
        .def_readwrite("autoRatio", &SfmOptions::autoRatio)
        .def_readwrite("calibration", &SfmOptions::calibration)
        .def_readwrite("focal", &SfmOptions::focal)
        .def_readwrite("refineIntrinsics", &SfmOptions::refineIntrinsics)
        .def_readwrite("selfCalibrate", &SfmOptions::selfCalibrate)
        .def_readwrite("lensInlierPx", &SfmOptions::lensInlierPx)
        .def_readwrite("maxFocalRelStd", &SfmOptions::maxFocalRelStd)
        .def_readwrite("explainedRounds", &SfmOptions::explainedRounds);
    defProgress(sfmO, &SfmOptions::progress);

    py::class_<ReprojectionStats>(m, "ReprojectionStats")
        .def_readonly("rms", &ReprojectionStats::rms)
        .def_readonly("median", &ReprojectionStats::median)
        .def_readonly("p95", &ReprojectionStats::p95)
        .def_readonly("observations", &ReprojectionStats::observations);
    py::class_<SfmReport>(m, "SfmReport", "What recoverCameras() did.")
        .def_readonly("inlierTracks", &SfmReport::inlierTracks)
        .def_readonly("rejectedTracks", &SfmReport::rejectedTracks)
        .def_readonly("rescuedTracks", &SfmReport::rescuedTracks)
        .def_readonly("unmeasuredDepthTracks", &SfmReport::unmeasuredDepthTracks)
        .def_readonly("chosenModel", &SfmReport::chosenModel)
        .def_readonly("lensModel", &SfmReport::lensModel)
        .def_readonly("focal", &SfmReport::focal)
        .def_readonly("distortion", &SfmReport::distortion)
        .def_readonly("lensReason", &SfmReport::lensReason)
        .def_readonly("factorization", &SfmReport::factorization)
        .def_readonly("positionZoom", &SfmReport::positionZoom)
        .def_readonly("orthographic", &SfmReport::orthographic)
        .def_readonly("perspective", &SfmReport::perspective)
        .def_readonly("explained", &SfmReport::explained);

    m.def("recoverCameras", [](const Tracks& tracks, bool report, const py::kwargs& kw)
              -> py::object {
              const SfmOptions opt = paramsFromKwargs<SfmOptions>(kw);
              SfmReport rep;
              Reconstruction rec;
              {
                  py::gil_scoped_release nogil;
                  rec = recoverCameras(tracks, opt, &rep);
              }
              if (report)
                  return py::make_tuple(rec, rep);
              return py::cast(rec);
          }, py::arg("tracks"), py::kw_only(), py::arg("report") = false,
          "Cameras and points from tracks, as `augocc sfm` (SfmOptions as keywords: "
          "model='auto', selfCalibrate=True, progress=fn, ...). report=True returns "
          "(Reconstruction, SfmReport).");

    // ---- compositor --------------------------------------------------------------------------
    py::class_<Compositor::Params> coP(m, "CompositorParams", "Compositor parameters.");
    coP.def(py::init<>())
        .def_readwrite("supersample", &Compositor::Params::supersample)
        .def_readwrite("antialiasVirtual", &Compositor::Params::antialiasVirtual)
        .def_readwrite("cullBackFaces", &Compositor::Params::cullBackFaces)
        .def_readwrite("edgeRadius", &Compositor::Params::edgeRadius)
        .def_readwrite("edgeEps", &Compositor::Params::edgeEps)
        .def_readwrite("sun", &Compositor::Params::sun,
                       "Sun (resolveSun() of a scene): shading and shadows; disabled: the fixed "
                       "light")
        .def_readwrite("ground", &Compositor::Params::ground,
                       "the real ground (estimateGround()): receives the virtual shadows")
        .def_readwrite("shadowCatcher", &Compositor::Params::shadowCatcher,
                       "shadows of the virtual objects on the real ground and clones");
    AUGOCC_MATX_PROP(coP, Compositor::Params, lightRotation, 3, 3, "world to shading frame");

    py::class_<Compositor, std::shared_ptr<Compositor>>(m, "Compositor",
        "Inserts virtual objects into frames so that the real objects' clones hide them "
        "(Compositor(supersample=3, ...)). Use from one thread.")
        .def(py::init([](const py::kwargs& kw) {
                 return std::shared_ptr<Compositor>(
                     Compositor::create(paramsFromKwargs<Compositor::Params>(kw))); }))
        .def("getParams", &Compositor::getParams)
        .def("setParams", &Compositor::setParams, py::arg("params"))
        .def("setVirtualObjects", &Compositor::setVirtualObjects, py::arg("meshes"))
        .def("renderSize", [](const Compositor& c, std::pair<int, int> s) {
                 return sizeToPy(c.renderSize(Size(s.first, s.second))); }, py::arg("frameSize"))
        .def("composite", [](Compositor& c, const py::object& frame, int frameIndex,
                             const Camera& cam, const CloneSet& clones, bool layer, bool depth)
                 -> py::object {
                 Mat f = fromNumpy(frame, "frame");
                 Mat out, lay, z;
                 {
                     py::gil_scoped_release nogil;
                     c.composite(f, frameIndex, cam, clones, out,
                                 layer ? _OutputArray(lay) : _OutputArray(noArray()),
                                 depth ? _OutputArray(z) : _OutputArray(noArray()));
                 }
                 if (!layer && !depth)
                     return toNumpy(out);
                 py::list r;
                 r.append(toNumpy(out));
                 if (layer)
                     r.append(toNumpy(lay));
                 if (depth)
                     r.append(toNumpy(z));
                 return py::tuple(r); },
             py::arg("frame"), py::arg("frameIndex"), py::arg("camera"), py::arg("clones"),
             py::arg("virtualLayer") = false, py::arg("depth") = false,
             "The frame (BGR uint8) with the virtual objects inserted behind the clones; with "
             "virtualLayer / depth also the BGRA layer / float32 depth (a tuple).")
        .def("compositeDepth", [](Compositor& c, const py::object& frame, const Camera& cam,
                                  const py::object& occluderDepth) {
                 Mat f = fromNumpy(frame, "frame"), d = fromNumpy(occluderDepth, "depth");
                 Mat out;
                 {
                     py::gil_scoped_release nogil;
                     c.composite(f, cam, d, out);
                 }
                 return toNumpy(out); },
             py::arg("frame"), py::arg("camera"), py::arg("occluderDepth"),
             "Composite against a given occluder depth (float32, +inf where none).");

    py::class_<CompositeOptions> cOpt(m, "CompositeOptions", "Options of compositeSequence().");
    cOpt.def(py::init<>())
        .def_readwrite("firstFrame", &CompositeOptions::firstFrame)
        .def_readwrite("endFrame", &CompositeOptions::endFrame)
        .def_readwrite("supersample", &CompositeOptions::supersample)
        .def_readwrite("antialiasVirtual", &CompositeOptions::antialiasVirtual)
        .def_readwrite("mattesDir", &CompositeOptions::mattesDir)
        .def_readwrite("depthDir", &CompositeOptions::depthDir)
        .def_readwrite("virtualLayerDir", &CompositeOptions::virtualLayerDir)
        .def_readwrite("fps", &CompositeOptions::fps)
        .def_readwrite("lightFromGround", &CompositeOptions::lightFromGround)
        .def_readwrite("sun", &CompositeOptions::sun,
                       "the scene's sun (resolveSun()); the ground is estimateGround(rec)")
        .def_readwrite("reconstructionName", &CompositeOptions::reconstructionName);
    defProgress(cOpt, &CompositeOptions::progress);
    m.def("compositeSequence", [](const String& input, const Reconstruction& rec,
                                  const CloneSet& clones, const std::vector<Mesh>& meshes,
                                  const String& output, const py::kwargs& kw) {
              const CompositeOptions opt = paramsFromKwargs<CompositeOptions>(kw);
              py::gil_scoped_release nogil;
              return compositeSequence(input, rec, clones, meshes, output, opt); },
          py::arg("input"), py::arg("rec"), py::arg("clones"), py::arg("virtualObjects"),
          py::arg("output"),
          "Composites a sequence to a video or PNG folder, as `augocc composite` (options "
          "as keywords: firstFrame, endFrame, supersample, mattesDir, progress, ...).");
    py::class_<GroundFrame> gF(m, "GroundFrame",
        "The ground of a reconstruction (scene.hpp): unit axes up, right, back (world frame) "
        "and the plane up . X == height.");
    gF.def(py::init<>())
        .def_readwrite("height", &GroundFrame::height)
        .def_readwrite("fromPlane", &GroundFrame::fromPlane);
    AUGOCC_VEC3_PROP(gF, GroundFrame, up, "unit up, world frame");
    AUGOCC_VEC3_PROP(gF, GroundFrame, right, "unit, horizontal, right of the mean view direction");
    AUGOCC_VEC3_PROP(gF, GroundFrame, back, "unit, horizontal, towards the viewer");
    gF.def("toGround", [](const GroundFrame& g, const std::array<double, 3>& X) {
               const Vec3d v = g.toGround(Vec3d(X[0], X[1], X[2]));
               return py::make_tuple(v[0], v[1], v[2]); }, py::arg("X"),
           "World point to ground coordinates (right, up above the ground, back).")
        .def("fromGround", [](const GroundFrame& g, const std::array<double, 3>& X) {
               const Vec3d v = g.fromGround(Vec3d(X[0], X[1], X[2]));
               return py::make_tuple(v[0], v[1], v[2]); }, py::arg("g"),
           "Ground coordinates to a world point.")
        .def("rotation", [](const GroundFrame& g) { return matxToNumpy<3, 3>(g.rotation()); },
             "Rows (right, up, back): the Compositor's lightRotation that compositeSequence() "
             "and `augocc composite` use (CompositeOptions::lightFromGround).");
    m.def("estimateGround", &estimateGround, py::arg("rec"));

    // ---- the sun (lighting.hpp, scene.hpp, sun_estimation.hpp) ------------------------------
    py::class_<Sun> sunC(m, "Sun",
        "A sun and sky (lighting.hpp): direction towards the sun (world frame; zero: no sun), "
        "sky share of the light in [0, 1), penumbra in world units. Sun(direction=(x, y, z), "
        "sky=0.4, penumbra=0.1).");
    sunC.def(py::init([](const py::kwargs& kw) { return paramsFromKwargs<Sun>(kw); }))
        .def_readwrite("sky", &Sun::sky)
        .def_readwrite("penumbra", &Sun::penumbra);
    AUGOCC_VEC3_PROP(sunC, Sun, direction, "towards the sun, world frame (zero: disabled)");
    sunC.def("enabled", &Sun::enabled)
        .def("validate", [](const Sun& s, const String& what) { s.validate(what); },
             py::arg("what") = "Sun", "Raises naming `what` when the sun is not valid.")
        .def("__repr__", [](const Sun& s) {
                 return cv::format("augocc.Sun(direction=(%.6g, %.6g, %.6g), sky=%.6g, "
                                   "penumbra=%.6g)", s.direction[0], s.direction[1],
                                   s.direction[2], s.sky, s.penumbra); });

    py::class_<SceneSun> sceneSun(m, "SceneSun",
        "The `sun` node of a scene file as parsed (scene.hpp): form SUN_NONE, SUN_DIRECTION, "
        "SUN_AZIMUTH_ELEVATION or SUN_DATE_TIME and that form's fields.");
    sceneSun.def(py::init([](const py::kwargs& kw) { return paramsFromKwargs<SceneSun>(kw); }))
        .def_readwrite("form", &SceneSun::form)
        .def_readwrite("azimuthDeg", &SceneSun::azimuthDeg)
        .def_readwrite("elevationDeg", &SceneSun::elevationDeg)
        .def_readwrite("date", &SceneSun::date)
        .def_readwrite("time", &SceneSun::time)
        .def_readwrite("latitudeDeg", &SceneSun::latitudeDeg)
        .def_readwrite("longitudeDeg", &SceneSun::longitudeDeg)
        .def_readwrite("sky", &SceneSun::sky)
        .def_readwrite("penumbraPx", &SceneSun::penumbraPx);
    AUGOCC_VEC3_PROP(sceneSun, SceneSun, direction, "SUN_DIRECTION: world frame");
    AUGOCC_VEC3_PROP(sceneSun, SceneSun, north, "world frame; zero: the ground frame's -back");
    sceneSun.attr("SUN_NONE") = (int)SceneSun::SUN_NONE;
    sceneSun.attr("SUN_DIRECTION") = (int)SceneSun::SUN_DIRECTION;
    sceneSun.attr("SUN_AZIMUTH_ELEVATION") = (int)SceneSun::SUN_AZIMUTH_ELEVATION;
    sceneSun.attr("SUN_DATE_TIME") = (int)SceneSun::SUN_DATE_TIME;
    m.def("resolveSun", &resolveSun, py::arg("scene"), py::arg("rec"),
          "The scene's sun in the reconstruction's world (as `augocc composite` takes it); a "
          "disabled Sun when the scene has none.");
    m.def("sunDirection", [](const GroundFrame& g, double az, double el,
                             const std::array<double, 3>& north) {
              const Vec3d d = sunDirection(g, az, el, Vec3d(north[0], north[1], north[2]));
              return py::make_tuple(d[0], d[1], d[2]); },
          py::arg("ground"), py::arg("azimuthDeg"), py::arg("elevationDeg"),
          py::arg("north") = std::array<double, 3>{0, 0, 0},
          "Unit direction towards the sun from azimuth (clockwise from north) and elevation "
          "relative to a ground frame.");
    m.def("solarPosition", [](int year, int month, int day, double hourUtc, double lat,
                              double lon) {
              double az = 0, el = 0;
              solarPosition(year, month, day, hourUtc, lat, lon, az, el);
              return py::make_tuple(az, el); },
          py::arg("year"), py::arg("month"), py::arg("day"), py::arg("hourUtc"),
          py::arg("latitudeDeg"), py::arg("longitudeDeg"),
          "(azimuthDeg, elevationDeg) of the sun (NOAA's solar position).");
    m.def("demoSun", &demoSun, "The demo scene's sun node.");

    py::class_<SunEstimationParams> sunEstP(m, "SunEstimationParams",
                                        "Parameters of estimateSun() (sun_estimation.hpp).");
    sunEstP.def(py::init<>())
        .def_readwrite("maxSamplesPerFrame", &SunEstimationParams::maxSamplesPerFrame)
        .def_readwrite("edgeMarginPx", &SunEstimationParams::edgeMarginPx)
        .def_readwrite("normalStep", &SunEstimationParams::normalStep)
        .def_readwrite("sideBins", &SunEstimationParams::sideBins)
        .def_readwrite("coarseStepDeg", &SunEstimationParams::coarseStepDeg)
        .def_readwrite("finalStepDeg", &SunEstimationParams::finalStepDeg)
        .def_readwrite("minElevationDeg", &SunEstimationParams::minElevationDeg)
        .def_readwrite("maxElevationDeg", &SunEstimationParams::maxElevationDeg)
        .def_readwrite("coarsePenumbraFraction", &SunEstimationParams::coarsePenumbraFraction)
        .def_readwrite("finePenumbraFraction", &SunEstimationParams::finePenumbraFraction)
        .def_readwrite("skyInlierSigmas", &SunEstimationParams::skyInlierSigmas)
        .def_readwrite("jackknifeGroups", &SunEstimationParams::jackknifeGroups);
    py::class_<SunEstimate> sE(m, "SunEstimate", "What estimateSun() found.");
    sE.def_readonly("sky", &SunEstimate::sky)
        .def_readonly("azimuthDeg", &SunEstimate::azimuthDeg)
        .def_readonly("elevationDeg", &SunEstimate::elevationDeg)
        .def_readonly("angularSigmaDeg", &SunEstimate::angularSigmaDeg)
        .def_readonly("skySigma", &SunEstimate::skySigma)
        .def_readonly("rmsLog", &SunEstimate::rmsLog)
        .def_readonly("rmsLogNoSun", &SunEstimate::rmsLogNoSun)
        .def_readonly("groundSamples", &SunEstimate::groundSamples)
        .def_readonly("cloneSamples", &SunEstimate::cloneSamples)
        .def_readonly("frames", &SunEstimate::frames)
        .def_readonly("evaluations", &SunEstimate::evaluations)
        .def_property_readonly("direction", [](const SunEstimate& e) {
                                   return py::make_tuple(e.direction[0], e.direction[1],
                                                         e.direction[2]); },
                               "unit vector towards the sun, the reconstruction's world frame");
    m.def("sunEstimationFrames", &sunEstimationFrames, py::arg("rec"), py::arg("maxFrames"),
          "Up to maxFrames frame numbers evenly spaced over the cameras (as `augocc sun` "
          "picks them).");
    m.def("estimateSun", [](const py::sequence& frames, const std::vector<int>& frameNumbers,
                            const Reconstruction& rec, const CloneSet& clones,
                            const GroundFrame& ground, const py::kwargs& kw) {
              const SunEstimationParams p = paramsFromKwargs<SunEstimationParams>(kw);
              const std::vector<Mat> fr = framesFromPy(frames, "frames");
              py::gil_scoped_release nogil;
              return estimateSun(fr, frameNumbers, rec, clones, ground, p); },
          py::arg("frames"), py::arg("frameNumbers"), py::arg("rec"), py::arg("clones"),
          py::arg("ground"),
          "The sun's direction and sky share from frames (BGR uint8, frames[i] is frame "
          "frameNumbers[i]), as `augocc sun` (SunEstimationParams as keywords).");
    m.def("toSun", &toSun, py::arg("estimate"), py::arg("penumbra") = Sun().penumbra,
          "The estimate as a Sun (penumbra in world units).");
    m.def("placeScene", [](const VirtualScene& s, const Reconstruction& rec,
                           const CloneSet* clones) { return placeScene(s, rec, clones); },
          py::arg("scene"), py::arg("rec"), py::arg("clones") = nullptr,
          "The scene's meshes placed in the reconstruction's world (for Compositor).");

    // ---- synthesizer ---------------------------------------------------------------------------
    py::enum_<SceneSynthesizer::CameraPath>(m, "CameraPath")
        .value("PATH_ORBIT", SceneSynthesizer::PATH_ORBIT)
        .value("PATH_HANDHELD", SceneSynthesizer::PATH_HANDHELD)
        .export_values();
    py::class_<SceneSynthesizer::Params> ssP(m, "SceneSynthesizerParams",
                                             "SceneSynthesizer parameters.");
    ssP.def(py::init<>())
        .def_readwrite("frames", &SceneSynthesizer::Params::frames)
        .def_readwrite("model", &SceneSynthesizer::Params::model)
        .def_readwrite("distanceRatio", &SceneSynthesizer::Params::distanceRatio)
        .def_readwrite("orbitDegrees", &SceneSynthesizer::Params::orbitDegrees)
        .def_readwrite("elevationDegrees", &SceneSynthesizer::Params::elevationDegrees)
        .def_readwrite("numTracks", &SceneSynthesizer::Params::numTracks)
        .def_readwrite("noiseSigma", &SceneSynthesizer::Params::noiseSigma)
        .def_readwrite("partialFraction", &SceneSynthesizer::Params::partialFraction)
        .def_readwrite("outlierFraction", &SceneSynthesizer::Params::outlierFraction)
        .def_readwrite("numKeyFrames", &SceneSynthesizer::Params::numKeyFrames)
        .def_readwrite("seed", &SceneSynthesizer::Params::seed)
        .def_readwrite("frameSupersample", &SceneSynthesizer::Params::frameSupersample)
        .def_readwrite("distortion", &SceneSynthesizer::Params::distortion)
        .def_readwrite("path", &SceneSynthesizer::Params::path)
        .def_readwrite("exposureDrift", &SceneSynthesizer::Params::exposureDrift)
        .def_readwrite("whiteBalanceDrift", &SceneSynthesizer::Params::whiteBalanceDrift)
        .def_readwrite("videoBitrateMbps", &SceneSynthesizer::Params::videoBitrateMbps);
    AUGOCC_SIZE_PROP(ssP, SceneSynthesizer::Params, imageSize, "(width, height)");
    defProgress(ssP, &SceneSynthesizer::Params::progress);

    py::class_<SyntheticScene, std::shared_ptr<SyntheticScene>>(m, "SyntheticScene",
        "A synthesized sequence with its ground truth.")
        .def_property_readonly("frames", [](const SyntheticScene& s) {
                                   py::list l;
                                   for (const Mat& f : s.frames)
                                       l.append(toNumpy(f));
                                   return l; }, "BGR uint8 frames")
        .def_readonly("groundTruth", &SyntheticScene::groundTruth)
        .def_readonly("tracks", &SyntheticScene::tracks)
        .def_readonly("cleanTracks", &SyntheticScene::cleanTracks)
        .def_readonly("objectNames", &SyntheticScene::objectNames)
        .def_readonly("objectMeshes", &SyntheticScene::objectMeshes)
        .def_readonly("keyFrames", &SyntheticScene::keyFrames)
        .def_property_readonly("keyFrameMasks", [](const SyntheticScene& s) {
                                   return masksToPy(s.keyFrameMasks); })
        .def_property_readonly("wholeMasks", [](const SyntheticScene& s) {
                                   return masksToPy(s.wholeMasks); })
        .def_property_readonly("visibleMasks", [](const SyntheticScene& s) {
                                   return masksToPy(s.visibleMasks); })
        .def_property_readonly("depth", [](const SyntheticScene& s) {
                                   py::list l;
                                   for (const Mat& f : s.depth)
                                       l.append(toNumpy(f));
                                   return l; })
        .def_property_readonly("labels", [](const SyntheticScene& s) {
                                   py::list l;
                                   for (const Mat& f : s.labels)
                                       l.append(toNumpy(f));
                                   return l; });

    py::class_<SceneSynthesizer, std::shared_ptr<SceneSynthesizer>>(m, "SceneSynthesizer",
        "Renders (headless) a textured static scene with real objects and its ground truth "
        "(SceneSynthesizer(frames=60, imageSize=(640, 480), seed=1, ...)).")
        .def(py::init([](const py::kwargs& kw) {
                 return std::shared_ptr<SceneSynthesizer>(SceneSynthesizer::create(
                     paramsFromKwargs<SceneSynthesizer::Params>(kw))); }))
        .def("getParams", &SceneSynthesizer::getParams)
        .def("setParams", &SceneSynthesizer::setParams, py::arg("params"))
        .def("synthesize", [](const SceneSynthesizer& s) {
                 auto scene = std::make_shared<SyntheticScene>();
                 py::gil_scoped_release nogil;
                 s.synthesize(*scene);
                 return scene; }, "The whole sequence with its ground truth.")
        .def("write", [](const SceneSynthesizer& s, const String& dir) {
                 py::gil_scoped_release nogil;
                 s.write(dir); }, py::arg("dir"),
             "Writes the data set as `augocc synth` does, frame by frame (bounded memory).")
        .def("renderFrame", [](const SceneSynthesizer& s, int frame) {
                 Mat img;
                 {
                     py::gil_scoped_release nogil;
                     s.renderFrame(frame, img);
                 }
                 return toNumpy(img); }, py::arg("frame"))
        .def("renderWithVirtual", [](const SceneSynthesizer& s, int frame,
                                     const std::vector<Mesh>& meshes, int supersample) {
                 Mat img;
                 {
                     py::gil_scoped_release nogil;
                     s.renderWithVirtual(frame, meshes, img, supersample);
                 }
                 return toNumpy(img); },
             py::arg("frame"), py::arg("virtualObjects"), py::arg("supersample") = 1)
        .def("getCamera", &SceneSynthesizer::getCamera, py::arg("frame"))
        .def("getObjectNames", &SceneSynthesizer::getObjectNames);
    m.def("writeSyntheticScene", [](const String& dir, const SyntheticScene& scene,
                                    const SceneSynthesizer::Params& p, const py::object& prog) {
              const ProgressCallback cb = progressFromPy(prog);
              py::gil_scoped_release nogil;
              writeSyntheticScene(dir, scene, p, cb); },
          py::arg("dir"), py::arg("scene"), py::arg("params"), py::arg("progress") = py::none(),
          "Writes the data set as `augocc synth` does.");

    // ---- silhouette editor -------------------------------------------------------------------
    py::class_<SilhouetteEditor::Params> seP(m, "SilhouetteEditorParams");
    seP.def(py::init<>())
        .def_readwrite("weightNonEdge", &SilhouetteEditor::Params::weightNonEdge)
        .def_readwrite("weightGradientDirection",
                       &SilhouetteEditor::Params::weightGradientDirection)
        .def_readwrite("weightGradientMagnitude",
                       &SilhouetteEditor::Params::weightGradientMagnitude)
        .def_readwrite("gradientMagnitudeMax", &SilhouetteEditor::Params::gradientMagnitudeMax)
        .def_readwrite("cannyLow", &SilhouetteEditor::Params::cannyLow)
        .def_readwrite("cannyHigh", &SilhouetteEditor::Params::cannyHigh)
        .def_readwrite("clickSnapRadius", &SilhouetteEditor::Params::clickSnapRadius)
        .def_readwrite("searchMargin", &SilhouetteEditor::Params::searchMargin)
        .def_readwrite("outerEdgeBias", &SilhouetteEditor::Params::outerEdgeBias)
        .def_readwrite("outerEdgeBand", &SilhouetteEditor::Params::outerEdgeBand)
        .def_readwrite("outlineTolerance", &SilhouetteEditor::Params::outlineTolerance)
        .def_readwrite("snapSpacing", &SilhouetteEditor::Params::snapSpacing)
        .def_readwrite("snapRadius", &SilhouetteEditor::Params::snapRadius)
        .def_readwrite("snapDistancePenalty", &SilhouetteEditor::Params::snapDistancePenalty)
        .def_readwrite("minContourArea", &SilhouetteEditor::Params::minContourArea)
        .def_readwrite("refineBoundary", &SilhouetteEditor::Params::refineBoundary);

    auto pt = [](std::pair<int, int> p) { return Point(p.first, p.second); };
    auto ptList = [](const std::vector<Point>& v) {
        std::vector<std::pair<int, int>> r;
        for (const Point& p : v)
            r.emplace_back(p.x, p.y);
        return r;
    };
    py::class_<SilhouetteEditor, std::shared_ptr<SilhouetteEditor>> se(m, "SilhouetteEditor",
        "Headless contour editing (live wire, straight segments, undo) of one object's "
        "silhouette; points are (x, y) tuples.");
    se.attr("LIVE_WIRE") = (int)SilhouetteEditor::LIVE_WIRE;
    se.attr("STRAIGHT") = (int)SilhouetteEditor::STRAIGHT;
    se.def(py::init([](const py::kwargs& kw) {
               return std::shared_ptr<SilhouetteEditor>(SilhouetteEditor::create(
                   paramsFromKwargs<SilhouetteEditor::Params>(kw))); }))
        .def("getParams", &SilhouetteEditor::getParams)
        .def("setParams", &SilhouetteEditor::setParams, py::arg("params"))
        .def("setImage", [](SilhouetteEditor& e, const py::object& img) {
                 Mat m = fromNumpy(img, "image");
                 py::gil_scoped_release nogil;
                 e.setImage(m); }, py::arg("image"))
        .def("getImageSize", [](const SilhouetteEditor& e) { return sizeToPy(e.getImageSize()); })
        .def("setSegmentMode", &SilhouetteEditor::setSegmentMode, py::arg("mode"))
        .def("getSegmentMode", &SilhouetteEditor::getSegmentMode)
        .def("addPoint", [pt](SilhouetteEditor& e, std::pair<int, int> p) {
                 Point q;
                 {
                     py::gil_scoped_release nogil;
                     q = e.addPoint(pt(p));
                 }
                 return std::make_pair(q.x, q.y); }, py::arg("pt"),
             "Adds an anchor; returns it as placed (after the click snap).")
        .def("previewSegment", [pt](SilhouetteEditor& e, std::pair<int, int> p) {
                 std::vector<Point> path;
                 e.previewSegment(pt(p), path);
                 Mat m(path, true);
                 return toNumpy(m.reshape(1)); }, py::arg("pt"))
        .def("closeContour", &SilhouetteEditor::closeContour,
             py::call_guard<py::gil_scoped_release>())
        .def("removeLastPoint", &SilhouetteEditor::removeLastPoint)
        .def("findAnchor", [pt](const SilhouetteEditor& e, std::pair<int, int> p, double d)
                 -> py::object {
                 int c = -1, a = -1;
                 if (!e.findAnchor(pt(p), d, c, a))
                     return py::none();
                 return py::make_tuple(c, a); }, py::arg("pt"), py::arg("maxDistance"),
             "(contour, anchor) of the nearest anchor, or None.")
        .def("moveAnchor", [pt](SilhouetteEditor& e, int c, int a, std::pair<int, int> p) {
                 e.moveAnchor(c, a, pt(p)); }, py::arg("contour"), py::arg("anchor"),
             py::arg("pt"))
        .def("removeAnchor", &SilhouetteEditor::removeAnchor, py::arg("contour"),
             py::arg("anchor"))
        .def("insertAnchor", [pt](SilhouetteEditor& e, std::pair<int, int> p, double d) {
                 return e.insertAnchor(pt(p), d); }, py::arg("pt"), py::arg("maxDistance"))
        .def("removeContour", &SilhouetteEditor::removeContour, py::arg("contour"))
        .def("undo", &SilhouetteEditor::undo)
        .def("redo", &SilhouetteEditor::redo)
        .def("canUndo", &SilhouetteEditor::canUndo)
        .def("canRedo", &SilhouetteEditor::canRedo)
        .def("clearHistory", &SilhouetteEditor::clearHistory)
        .def("clear", &SilhouetteEditor::clear)
        .def("getContourCount", &SilhouetteEditor::getContourCount)
        .def("hasOpenContour", &SilhouetteEditor::hasOpenContour)
        .def("getAnchors", [ptList](const SilhouetteEditor& e, int c) {
                 return ptList(e.getAnchors(c)); }, py::arg("contour"))
        .def("getContour", [ptList](const SilhouetteEditor& e, int c) {
                 return ptList(e.getContour(c)); }, py::arg("contour"))
        .def("getAnchorCount", &SilhouetteEditor::getAnchorCount)
        .def("getMask", [](const SilhouetteEditor& e) {
                 Mat mk;
                 e.getMask(mk);
                 return toNumpy(mk); }, "uint8 mask, 255 inside.")
        .def("loadMask", [](SilhouetteEditor& e, const py::object& mask, bool snap) {
                 Mat mk = fromNumpy(mask, "mask");
                 py::gil_scoped_release nogil;
                 e.loadMask(mk, snap); }, py::arg("mask"), py::arg("snapToEdges") = false)
        .def("snapMask", [](SilhouetteEditor& e, const py::object& mask) {
                 Mat mk = fromNumpy(mask, "mask"), out;
                 {
                     py::gil_scoped_release nogil;
                     e.snapMask(mk, out);
                 }
                 return toNumpy(out); }, py::arg("proposed"))
        .def("drawOverlay", [pt](SilhouetteEditor& e, py::array canvas, std::pair<int, int> c) {
                 if (!(canvas.flags() & py::array::c_style) || !canvas.writeable())
                     throw py::value_error("augocc: drawOverlay: canvas must be a writeable "
                                           "C-contiguous array");
                 Mat m = fromNumpy(canvas, "canvas");
                 e.drawOverlay(m, pt(c)); }, py::arg("canvas"),
             py::arg("cursor") = std::make_pair(-1, -1), "Draws onto canvas in place.");

    // ---- perf support ----------------------------------------------------------------------
    m.def("_timeRenderCpp", [](const CloneSet& c, const String& object, int frame,
                               const Camera& cam, std::pair<int, int> size, int n) {
              py::gil_scoped_release nogil;
              const auto t0 = std::chrono::steady_clock::now();
              for (int i = 0; i < n; i++)
              {
                  Mat matte;  // a fresh output per call, as each Python call gets
                  c.render(object, frame, cam, Size(size.first, size.second), matte);
              }
              const auto t1 = std::chrono::steady_clock::now();
              return std::chrono::duration<double>(t1 - t0).count() / n;
          }, py::arg("clones"), py::arg("object"), py::arg("frame"), py::arg("camera"),
          py::arg("imageSize"), py::arg("n"),
          "Seconds per CloneSet::render call timed in C++ (perf/python_render.py).");
}
