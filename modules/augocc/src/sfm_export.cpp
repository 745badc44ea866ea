// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Exports of a reconstruction beyond the contract: COLMAP text model and a PLY point cloud.

#include "precomp.hpp"
#include "sfm_detail.hpp"
#include "atomic_write.hpp"

#include <filesystem>
#include <sstream>
#include <Eigen/Geometry>

namespace cv {
namespace augocc {

namespace {

Mat checkColors(InputArray colors, int rows, const char* what)
{
    if (colors.empty())
        return Mat();
    Mat c = colors.getMat();
    if (c.type() != CV_8UC3 || (int)c.total() != rows)
        CV_Error(Error::StsBadArg, cv::format("%s: colors must be %d x 1 CV_8UC3, got %d "
                 "elements of type %s", what, rows, (int)c.total(),
                 typeToString(c.type()).c_str()));
    return c.reshape(3, rows);
}

// Text is made in memory and written with checked I/O (atomic_write.hpp): an ofstream on a
// full disk says only that it failed, not why.
void startText(std::ostringstream& out)
{
    out.precision(17);
}

void writeText(const std::ostringstream& out, const String& tmp, const String& shown)
{
    const String text = out.str();
    detail::writeFileBytes(tmp, text.data(), text.size(), shown);
}

} // namespace

void writeColmapModel(const String& dir, const Reconstruction& rec, const Tracks& tracks,
                      InputArray colorsArg, double orthoDistanceRatio)
{
    rec.validate("reconstruction");
    tracks.validate("tracks");
    if (rec.points.rows != tracks.points())
        CV_Error(Error::StsBadSize, cv::format("reconstruction has %d points, tracks %d",
                 rec.points.rows, tracks.points()));
    if (!(orthoDistanceRatio > 1))
        CV_Error(Error::StsBadArg, "writeColmapModel: orthoDistanceRatio must be > 1");
    for (const Camera& cam : rec.cameras)
        if (cam.frame >= tracks.frames())
            CV_Error(Error::StsBadSize, cv::format("reconstruction has a camera of frame %d, "
                     "tracks %d frames", cam.frame, tracks.frames()));
    const Mat colors = checkColors(colorsArg, rec.points.rows, "writeColmapModel");
    // Lenses: COLMAP's OPENCV (k1, k2, p1, p2) and FULL_OPENCV (k3..k6 too) are OpenCV's own
    // model of the normalised point; thin prism and tilt terms have no COLMAP model.
    for (const Camera& cam : rec.cameras)
        for (size_t k = 8; k < cam.distortion.size(); k++)
            if (cam.distortion[k] != 0)
                CV_Error(Error::StsNotImplemented, cv::format("writeColmapModel: the camera of "
                         "frame %d has thin prism or tilt distortion (coefficient %d of %d is "
                         "not zero), which no COLMAP camera model expresses", cam.frame,
                         (int)k + 1, (int)cam.distortion.size()));
    detail::createDirectories(dir);
    const int P = rec.points.rows;
    Vec3d c;
    const double radius = detail::rmsRadius(rec.points, &c);
    const double D = orthoDistanceRatio * std::max(radius, 1e-9);

    // Pinhole equivalents (COLMAP pixel origin: +0.5).
    std::vector<Camera> cams;
    for (const Camera& cam : rec.cameras)
    {
        if (cam.model == PERSPECTIVE)
        {
            cams.push_back(cam);
            continue;
        }
        const Vec3d Rc = cam.R * c;
        const double f = cam.s * D;
        const Point2d pp = cam.principalPoint();
        cams.push_back(Camera::perspective(cam.R, Vec3d(cam.t[0], cam.t[1], D - Rc[2]),
                                           Matx33d(f, 0, pp.x, 0, f, pp.y, 0, 0, 1), cam.frame));
    }
    // POINT2D_IDX of track p in each image: order of the observed finite points.
    std::vector<std::vector<std::pair<int, int>>> pointTrack(P);  // (image id, point2d idx)
    std::vector<double> errSum(P, 0.0);

    writeAtomically(dir + "/images.txt", [&](const String& tmp) {
        std::ostringstream out;
        startText(out);
        out << "# Image list with two lines of data per image:\n"
               "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
               "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
               "# Written by augocc (frame i -> IMAGE_ID i + 1)\n";
        for (const Camera& cam : cams)
        {
            Eigen::Matrix3d R;
            for (int r = 0; r < 3; r++)
                for (int k = 0; k < 3; k++)
                    R(r, k) = cam.R(r, k);
            Eigen::Quaterniond q(R);
            q.normalize();
            const int id = cam.frame + 1;
            out << id << ' ' << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' '
                << cam.t[0] << ' ' << cam.t[1] << ' ' << cam.t[2] << ' ' << id << ' '
                << cv::format("%04d.png", cam.frame) << '\n';
            const Range obs = tracks.frame(cam.frame);
            int idx = 0;
            bool firstPt = true;
            for (int k = obs.start; k < obs.end; k++)
            {
                const int p = tracks.pointOf(tracks.byFrame(k));
                const Point2f o = tracks.uv(tracks.byFrame(k));
                const bool has3d = rec.hasPoint(p);
                if (!firstPt)
                    out << ' ';
                firstPt = false;
                out << o.x + 0.5 << ' ' << o.y + 0.5 << ' ' << (has3d ? p + 1 : -1);
                if (has3d)
                {
                    pointTrack[p].emplace_back(id, idx);
                    const Point2d q2 = cam.project(rec.point(p));
                    errSum[p] += std::hypot(q2.x - o.x, q2.y - o.y);
                }
                idx++;
            }
            out << '\n';
        }
        writeText(out, tmp, dir + "/images.txt");
    });
    writeAtomically(dir + "/cameras.txt", [&](const String& tmp) {
        std::ostringstream out;
        startText(out);
        out << "# Camera list with one line of data per camera:\n"
               "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
        if (rec.model == SCALED_ORTHOGRAPHIC)
            out << cv::format("# scaled_orthographic cameras approximated by PINHOLE at %g "
                              "x the scene's RMS radius\n", orthoDistanceRatio);
        for (const Camera& cam : cams)
        {
            const std::vector<double>& d = cam.distortion;
            const bool full = d.size() >= 8 && (d[4] != 0 || d[5] != 0 || d[6] != 0 ||
                                                d[7] != 0);
            const bool full5 = d.size() == 5 && d[4] != 0;
            const char* model = !cam.hasDistortion() ? "PINHOLE"
                                : (full || full5) ? "FULL_OPENCV" : "OPENCV";
            out << cam.frame + 1 << ' ' << model << ' ' << rec.imageSize.width << ' '
                << rec.imageSize.height << ' ' << cam.K(0, 0) << ' ' << cam.K(1, 1) << ' '
                << cam.K(0, 2) + 0.5 << ' ' << cam.K(1, 2) + 0.5;
            if (cam.hasDistortion())
            {
                const int n = (full || full5) ? 8 : 4;
                for (int k = 0; k < n; k++)
                    out << ' ' << (k < (int)d.size() ? d[k] : 0.0);
            }
            out << '\n';
        }
        writeText(out, tmp, dir + "/cameras.txt");
    });
    writeAtomically(dir + "/points3D.txt", [&](const String& tmp) {
        std::ostringstream out;
        startText(out);
        out << "# 3D point list with one line of data per point:\n"
               "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n";
        for (int p = 0; p < P; p++)
        {
            if (!rec.hasPoint(p) || pointTrack[p].empty())
                continue;
            const Vec3d X = rec.point(p);
            Vec3b bgr(128, 128, 128);
            if (!colors.empty())
                bgr = colors.at<Vec3b>(p);
            out << p + 1 << ' ' << X[0] << ' ' << X[1] << ' ' << X[2] << ' ' << (int)bgr[2]
                << ' ' << (int)bgr[1] << ' ' << (int)bgr[0] << ' '
                << errSum[p] / pointTrack[p].size();
            for (const auto& tr : pointTrack[p])
                out << ' ' << tr.first << ' ' << tr.second;
            out << '\n';
        }
        writeText(out, tmp, dir + "/points3D.txt");
    });
}

void writePointsPly(const String& path, const Reconstruction& rec, InputArray colorsArg)
{
    if (rec.points.empty() || rec.points.cols != 3 || rec.points.type() != CV_64F)
        CV_Error(Error::StsBadArg, "writePointsPly: reconstruction points must be P x 3 "
                 "CV_64F");
    const Mat colors = checkColors(colorsArg, rec.points.rows, "writePointsPly");
    const int n = rec.validPointCount();
    writeAtomically(path, [&](const String& tmp) {
        std::ostringstream out;
        startText(out);
        out << "ply\nformat ascii 1.0\ncomment augocc reconstruction points\n"
            << "element vertex " << n << "\nproperty double x\nproperty double y\n"
            << "property double z\n";
        if (!colors.empty())
            out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
        out << "end_header\n";
        for (int p = 0; p < rec.points.rows; p++)
        {
            if (!rec.hasPoint(p))
                continue;
            const Vec3d X = rec.point(p);
            out << X[0] << ' ' << X[1] << ' ' << X[2];
            if (!colors.empty())
            {
                const Vec3b bgr = colors.at<Vec3b>(p);
                out << ' ' << (int)bgr[2] << ' ' << (int)bgr[1] << ' ' << (int)bgr[0];
            }
            out << '\n';
        }
        writeText(out, tmp, path);
    });
}

} // namespace augocc
} // namespace cv
