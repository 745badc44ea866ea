// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_clone_scenes.hpp"

namespace opencv_test {

Camera orbitCamera(CameraModel model, double azimuthDeg, double elevationDeg, double dist,
                   const Vec3d& target, Size size, double pixelsPerUnit, int frame)
{
    const double a = azimuthDeg * CV_PI / 180, e = elevationDeg * CV_PI / 180;
    const Vec3d C = target + Vec3d(dist * std::cos(e) * std::sin(a), dist * std::sin(e),
                                   dist * std::cos(e) * std::cos(a));
    Vec3d f = target - C;
    f /= cv::norm(f);
    Vec3d x = f.cross(Vec3d(0, 1, 0));
    x /= cv::norm(x);
    const Vec3d y = f.cross(x);
    const Matx33d R(x[0], x[1], x[2], y[0], y[1], y[2], f[0], f[1], f[2]);
    const Vec3d t = -(R * C);
    const Point2d pp(size.width / 2.0 - 0.5, size.height / 2.0 - 0.5);
    if (model == SCALED_ORTHOGRAPHIC)
        return Camera::orthographic(R, t, pixelsPerUnit, pp, frame);
    const double fpx = pixelsPerUnit * dist;
    return Camera::perspective(R, t, Matx33d(fpx, 0, pp.x, 0, fpx, pp.y, 0, 0, 1), frame);
}

std::vector<Point2f> boxHull(const std::pair<Vec3d, Vec3d>& b, const Camera& cam)
{
    std::vector<Point2f> c, hull;
    for (int q = 0; q < 8; q++)
    {
        const Vec3d X(q & 1 ? b.second[0] : b.first[0], q & 2 ? b.second[1] : b.first[1],
                      q & 4 ? b.second[2] : b.first[2]);
        const Point2d uv = cam.project(X);
        c.push_back(Point2f((float)uv.x, (float)uv.y));
    }
    convexHull(c, hull);
    return hull;
}

Mat silhouetteOf(const AnalyticObject& o, const Camera& cam, Size size)
{
    Mat m(size, CV_8U, Scalar(0));
    for (const auto& b : o.boxes)
    {
        const std::vector<Point2f> hull = boxHull(b, cam);
        const Rect r = boundingRect(hull) & Rect(Point(0, 0), size);
        for (int y = r.y; y < r.y + r.height; y++)
            for (int x = r.x; x < r.x + r.width; x++)
                if (pointPolygonTest(hull, Point2f((float)x, (float)y), false) >= 0)
                    m.at<uchar>(y, x) = 255;
    }
    return m;
}

AnalyticScene makeScene(CameraModel model, const std::vector<AnalyticObject>& objects, int frames,
                        int numKeys, double orbitDeg, Size size)
{
    AnalyticScene s;
    s.objects = objects;
    s.rec.model = model;
    s.rec.imageSize = size;
    const Vec3d target(1.5, 1.0, 0.0);
    for (int f = 0; f < frames; f++)
    {
        const double az = -orbitDeg / 2 + orbitDeg * f / (frames - 1);
        s.rec.cameras.push_back(orbitCamera(model, az, 25, 40, target, size, 45, f));
    }
    for (int k = 0; k < numKeys; k++)
        s.keyFrames.push_back(cvRound((double)k * (frames - 1) / (numKeys - 1)));
    RNG rng(11);
    std::vector<Vec3d> pts;
    for (int f = 0; f < frames; f++)
    {
        Mat covered(size, CV_8U, Scalar(0));
        for (const AnalyticObject& o : objects)
        {
            const Mat w = silhouetteOf(o, s.rec.cameras[f], size);
            s.whole[o.name][f] = w;
            s.visible[o.name][f] = w & ~covered;
            covered |= w;
        }
    }
    for (int k : s.keyFrames)
        for (const AnalyticObject& o : objects)
            s.keyMasks[o.name][k] = s.visible[o.name][k];
    // Points on the objects' faces, plus ground points.
    for (const AnalyticObject& o : objects)
        for (const auto& b : o.boxes)
            for (int q = 0; q < 60; q++)
            {
                Vec3d X(rng.uniform(b.first[0], b.second[0]), rng.uniform(b.first[1], b.second[1]),
                        rng.uniform(b.first[2], b.second[2]));
                const int axis = rng.uniform(0, 3);
                X[axis] = rng.uniform(0, 2) ? b.second[axis] : b.first[axis];
                pts.push_back(X);
            }
    for (int q = 0; q < 80; q++)
        pts.push_back(Vec3d(rng.uniform(-6.0, 9.0), 0.0, rng.uniform(-6.0, 6.0)));
    s.rec.points = Mat((int)pts.size(), 3, CV_64F);
    for (size_t q = 0; q < pts.size(); q++)
        for (int a = 0; a < 3; a++)
            s.rec.points.at<double>((int)q, a) = pts[q][a];
    return s;
}

std::vector<AnalyticObject> towerAndEll()
{
    AnalyticObject tower{"tower", {{Vec3d(-1, 0, -1), Vec3d(1, 3, 1)}}};
    AnalyticObject ell{"ell", {{Vec3d(2.5, 0, -1), Vec3d(5.5, 1.5, 0)},
                               {Vec3d(4.5, 0, -1), Vec3d(5.5, 1.5, 2)}}};
    return {tower, ell};
}

// front hides part of back in every frame (listed front to back).
std::vector<AnalyticObject> frontAndBack()
{
    AnalyticObject front{"front", {{Vec3d(0.7, 0, 1.5), Vec3d(2.3, 3.0, 3)}}};
    AnalyticObject back{"back", {{Vec3d(0, 0, -4), Vec3d(3, 3, -2)}}};
    return {front, back};
}

// Mean distance (px) from the boundary pixels of `a` to the boundary of `b`.
double meanBoundaryDistance(const Mat& a, const Mat& b)
{
    Mat ea, eb;
    erode(a, ea, Mat());
    erode(b, eb, Mat());
    Mat ba = a & ~ea, bb = b & ~eb;
    Mat dt;
    distanceTransform(~bb, dt, DIST_L2, DIST_MASK_PRECISE);
    std::vector<Point> pts;
    findNonZero(ba, pts);
    if (pts.empty())
        return 0;
    double s = 0;
    for (const Point& p : pts)
        s += dt.at<float>(p);
    return s / pts.size();
}

Figures measure(const CloneSet& clones, const AnalyticScene& s, const String& object,
                const ObjectMasks& nonKeyRef)
{
    Figures fig;
    double sumIoU = 0, sumB = 0;
    int n = 0;
    for (const Camera& cam : s.rec.cameras)
    {
        Mat matte;
        clones.render(object, cam.frame, cam, s.rec.imageSize, matte);
        const bool key = std::find(s.keyFrames.begin(), s.keyFrames.end(), cam.frame) !=
                         s.keyFrames.end();
        if (key)
        {
            // Against the key-frame silhouette, outside the pixels of nearer objects (objects are
            // listed front to back): there the clone is unknown by design (occlusion-aware
            // carving) and the nearer object's clone is in front anyway.
            const Mat& sil = s.keyMasks.at(object).at(cam.frame);
            Mat nearer(sil.size(), CV_8U, Scalar(0));
            for (const AnalyticObject& o : s.objects)
            {
                if (o.name == object)
                    break;
                nearer |= s.keyMasks.at(o.name).at(cam.frame);
            }
            fig.keyMin = std::min(fig.keyMin, maskIoU(matte & ~nearer, sil));
            continue;
        }
        const Mat& ref = nonKeyRef.at(object).at(cam.frame);
        const double iou = maskIoU(matte, ref);
        sumIoU += iou;
        sumB += meanBoundaryDistance(matte, ref);
        fig.nonKeyMin = std::min(fig.nonKeyMin, iou);
        n++;
    }
    fig.nonKeyMean = sumIoU / std::max(n, 1);
    fig.boundaryMean = sumB / std::max(n, 1);
    return fig;
}

SynthFigures measureSynth(const CloneSet& clones, const SyntheticScene& s, const String& object)
{
    SynthFigures fig;
    const Reconstruction& rec = s.groundTruth;
    int n = 0, nk = 0;
    for (const Camera& cam : rec.cameras)
    {
        Mat matte;
        clones.render(object, cam.frame, cam, rec.imageSize, matte);
        const Mat& whole = s.wholeMasks.at(object).at(cam.frame);
        const bool key = std::count(s.keyFrames.begin(), s.keyFrames.end(), cam.frame) > 0;
        if (key)
        {
            // Against the key-frame (visible) silhouette, outside the pixels where other objects
            // are seen (there, this clone is unknown by design and the other clone decides).
            const Mat& sil = s.keyFrameMasks.at(object).at(cam.frame);
            Mat others(sil.size(), CV_8U, Scalar(0));
            for (const auto& o : s.visibleMasks)
                if (o.first != object)
                    others |= o.second.at(cam.frame);
            fig.keyMin = std::min(fig.keyMin, maskIoU(matte & ~others, sil));
            fig.hiddenFraction += 1.0 - (double)countNonZero(sil) / std::max(1, countNonZero(whole));
            nk++;
            continue;
        }
        const double iou = maskIoU(matte, whole);
        fig.nonKeyMean += iou;
        fig.nonKeyMin = std::min(fig.nonKeyMin, iou);
        fig.boundary += meanBoundaryDistance(matte, whole);
        // Where another object is seen in front, this clone's matte decides nothing (the other
        // clone is nearer): IoU outside those pixels, and recall of the whole silhouette.
        Mat front(whole.size(), CV_8U, Scalar(0));
        for (const auto& o : s.visibleMasks)
            if (o.first != object)
                front |= o.second.at(cam.frame) & ~s.visibleMasks.at(object).at(cam.frame);
        const double visIoU = maskIoU(matte & ~front, whole & ~front);
        fig.visibleMean += visIoU;
        fig.visibleMin = std::min(fig.visibleMin, visIoU);
        fig.recall += (double)countNonZero(matte & whole) / std::max(1, countNonZero(whole));
        n++;
    }
    fig.nonKeyMean /= std::max(n, 1);
    fig.boundary /= std::max(n, 1);
    fig.visibleMean /= std::max(n, 1);
    fig.recall /= std::max(n, 1);
    fig.hiddenFraction /= std::max(nk, 1);
    return fig;
}

DepthFigures measureDepth(const CloneSet& clones, const SyntheticScene& s, const String& name,
                          const String& debugPng)
{
    DepthFigures fig;
    int64 n = 0;
    const double h = clones.voxelSize(name);
    for (const Camera& cam : s.groundTruth.cameras)
    {
        Mat mt, dp;
        clones.render(name, cam.frame, cam, s.groundTruth.imageSize, mt, dp);
        const Mat& vis = s.visibleMasks.at(name).at(cam.frame);
        const Mat& gt = s.depth[cam.frame];
        Mat dbg;
        if (!debugPng.empty() && cam.frame == 30)
            dbg = s.frames[cam.frame] / 3;
        for (int y = 0; y < dp.rows; y++)
            for (int x = 0; x < dp.cols; x++)
                if (vis.at<uchar>(y, x) && mt.at<uchar>(y, x))
                {
                    const double dz = (gt.at<float>(y, x) - dp.at<float>(y, x)) / h;
                    fig.meanAbs += std::abs(dz);
                    fig.front += dz > 3;
                    n++;
                    if (!dbg.empty())  // yellow: clone in front, blue: behind, 4 levels a voxel
                    {
                        const int c = (int)std::min(255.0, std::abs(dz) * 4);
                        dbg.at<Vec3b>(y, x) = dz > 0 ? Vec3b(0, (uchar)c, (uchar)std::max(60, c))
                                                     : Vec3b((uchar)std::max(60, c), (uchar)c, 0);
                    }
                }
        if (!dbg.empty())
            imwrite(debugPng, dbg);
    }
    fig.meanAbs /= std::max<int64>(n, 1);
    fig.front /= std::max<int64>(n, 1);
    return fig;
}

void printPhoto(const char* tag, const String& name, const SynthFigures& f, const DepthFigures& d)
{
    std::cout << tag << " " << name << ": key min IoU " << f.keyMin << ", non-key mean IoU "
              << f.nonKeyMean << " worst " << f.nonKeyMin << ", boundary " << f.boundary
              << " px, recall " << f.recall << ", depth: mean |dz| " << d.meanAbs
              << " voxels, " << d.front * 100 << "% of pixels > 3 voxels in front" << std::endl;
}

} // namespace opencv_test
