// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_TEST_SILHOUETTE_SCENE_HPP
#define OPENCV_AUGOCC_TEST_SILHOUETTE_SCENE_HPP

// A drawn test frame for the silhouette tools: a textured box-shaped building (facades with
// window grids, a roof) standing on a textured ground, seen by a scaled-orthographic camera from
// above, with its exact silhouette. Independent of the SceneSynthesizer so that the editor's
// tests need no OpenGL.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include "opencv2/augocc/camera.hpp"

namespace opencv_test {

struct SilhouetteScene
{
    cv::Mat image;  //!< BGR frame
    cv::Mat mask;   //!< CV_8U true silhouette of the building (255)
};

//! Camera looking at the origin from azimuth/elevation (degrees), y up in the world.
inline cv::augocc::Camera orbitCamera(double azimuthDeg, double elevationDeg, double scale,
                                      cv::Size size)
{
    const double a = azimuthDeg * CV_PI / 180, e = elevationDeg * CV_PI / 180;
    const cv::Vec3d f = -cv::Vec3d(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
    const cv::Vec3d right = cv::normalize(f.cross(cv::Vec3d(0, 1, 0)));
    const cv::Vec3d down = f.cross(right);
    const cv::Matx33d R(right[0], right[1], right[2], down[0], down[1], down[2], f[0], f[1], f[2]);
    const cv::Vec3d t(0, 0, 100);  // far in front of the camera plane
    return cv::augocc::Camera::orthographic(R, t, scale,
                                            cv::Point2d(size.width / 2.0, size.height / 2.0));
}

/** @brief Draws the box building [-w/2, w/2] x [0, h] x [-d/2, d/2] seen by `cam`.
@param cam camera.
@param size frame size.
@param seed texture seed.
@param boxSize (w, h, d) of the building in world units.
*/
inline SilhouetteScene drawBoxScene(const cv::augocc::Camera& cam, cv::Size size, uint64 seed,
                                    cv::Vec3d boxSize = cv::Vec3d(4, 5, 3))
{
    using namespace cv;
    RNG rng(seed);
    SilhouetteScene s;
    // Ground: smooth colour blobs plus fine grain, so the outline has clutter around it.
    Mat blobs(size.height / 8 + 1, size.width / 8 + 1, CV_8UC3);
    rng.fill(blobs, RNG::UNIFORM, Scalar(60, 80, 60), Scalar(140, 160, 130));
    resize(blobs, s.image, size, 0, 0, INTER_CUBIC);
    Mat grain(size, CV_16SC3);
    rng.fill(grain, RNG::NORMAL, Scalar::all(0), Scalar::all(6));
    add(s.image, grain, s.image, noArray(), CV_8U);
    s.mask = Mat::zeros(size, CV_8U);

    const double w = boxSize[0] / 2, h = boxSize[1], d = boxSize[2] / 2;
    // Faces: 4 corner points (counter-clockwise seen from outside) and an outward normal.
    struct Face { Vec3d p[4]; Vec3d n; Scalar colour; };
    const Face faces[] = {
        {{Vec3d(-w, 0, d), Vec3d(w, 0, d), Vec3d(w, h, d), Vec3d(-w, h, d)}, Vec3d(0, 0, 1),
         Scalar(70, 110, 190)},
        {{Vec3d(w, 0, d), Vec3d(w, 0, -d), Vec3d(w, h, -d), Vec3d(w, h, d)}, Vec3d(1, 0, 0),
         Scalar(50, 80, 150)},
        {{Vec3d(w, 0, -d), Vec3d(-w, 0, -d), Vec3d(-w, h, -d), Vec3d(w, h, -d)}, Vec3d(0, 0, -1),
         Scalar(60, 95, 170)},
        {{Vec3d(-w, 0, -d), Vec3d(-w, 0, d), Vec3d(-w, h, d), Vec3d(-w, h, -d)}, Vec3d(-1, 0, 0),
         Scalar(45, 75, 140)},
        {{Vec3d(-w, h, d), Vec3d(w, h, d), Vec3d(w, h, -d), Vec3d(-w, h, -d)}, Vec3d(0, 1, 0),
         Scalar(150, 150, 155)},
    };
    auto proj = [&](const Vec3d& X) {
        const Point2d p = cam.project(X);
        // 4 fractional bits for fillConvexPoly's sub-pixel rasterization.
        return Point(cvRound(p.x * 16), cvRound(p.y * 16));
    };
    const Vec3d view = cam.viewDirection();
    for (const Face& f : faces)
    {
        if (f.n.dot(view) >= 0)
            continue;  // back face
        Point poly[4];
        for (int i = 0; i < 4; ++i)
            poly[i] = proj(f.p[i]);
        const Scalar col = f.colour + Scalar::all(rng.uniform(-10, 10));
        fillConvexPoly(s.image, poly, 4, col, LINE_8, 4);
        fillConvexPoly(s.mask, poly, 4, Scalar::all(255), LINE_8, 4);
        if (f.n[1] > 0)
            continue;  // no windows on the roof
        // Window grid in face coordinates (u along the bottom edge, v up), kept off the edges.
        const Vec3d du = f.p[1] - f.p[0], dv = f.p[3] - f.p[0];
        const int cols = 4, rows = 6;
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c)
            {
                const double u0 = 0.12 + 0.8 * c / cols, v0 = 0.08 + 0.85 * r / rows;
                const double u1 = u0 + 0.45 / cols, v1 = v0 + 0.5 / rows;
                Point q[4] = {proj(f.p[0] + u0 * du + v0 * dv), proj(f.p[0] + u1 * du + v0 * dv),
                              proj(f.p[0] + u1 * du + v1 * dv), proj(f.p[0] + u0 * du + v1 * dv)};
                fillConvexPoly(s.image, q, 4, Scalar(60, 50, 40) + Scalar::all(rng.uniform(0, 30)),
                               LINE_8, 4);
            }
    }
    Mat noise(size, CV_16SC3);
    rng.fill(noise, RNG::NORMAL, Scalar::all(0), Scalar::all(3));
    add(s.image, noise, s.image, noArray(), CV_8U);
    return s;
}

//! The default test view: a building filling about a fifth of the frame.
inline SilhouetteScene makeBoxScene(cv::Size size, uint64 seed)
{
    const double azimuth = 25 + 10 * double(seed % 4), elevation = 20 + 5 * double(seed % 3);
    const double scale = size.height / 14.0;
    return drawBoxScene(orbitCamera(azimuth, elevation, scale, size), size, seed);
}

} // namespace opencv_test

#endif
