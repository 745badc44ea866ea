// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Issue 15's camera figures of one recovered reconstruction against a synthesized shot's
// truth (perf/handheld_shots.sh): mean rotation error, focal error, distortion error at the
// image corners (measureLens, as test_sfm_lens.cpp), slide (measureSlide, as `augocc demo`),
// and how far the tracks reach towards the corners (what makes the lens identifiable there).
//
//   augocc_lens_figures RECONSTRUCTION GT_RECONSTRUCTION [TRACKS]

#include <opencv2/augocc.hpp>
#include "sfm_test_utils.hpp"

#include <algorithm>
#include <cstdio>
#include <vector>

using namespace cv;
using namespace cv::augocc;

namespace {

double median(std::vector<double> v)
{
    if (v.empty())
        return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

double mean(const std::vector<double>& v)
{
    double s = 0;
    for (double x : v)
        s += x;
    return v.empty() ? 0.0 : s / v.size();
}

// The reprojection error of observation i under `est`, or false when it has no camera or point.
bool residual(const Reconstruction& est, const Tracks& t, int i, Point2d& e)
{
    const int p = t.pointOf(i);
    const int ci = est.findCamera(t.frameOf(i));
    if (ci < 0 || !est.hasPoint(p))
        return false;
    e = est.cameras[ci].project(est.point(p)) - Point2d(t.uv(i));
    return true;
}

// Reach of the tracks: radius of each observation from the image centre c, as a fraction of the
// corner's radius (1 = the corner pixel).
void printReach(const Tracks& t, const Point2d& c)
{
    const double rc = cv::norm(c);
    std::vector<double> r;
    r.reserve(t.observations());
    for (int i = 0; i < t.observations(); i++)
        r.push_back(cv::norm(Point2d(t.uv(i)) - c) / rc);
    std::sort(r.begin(), r.end());
    auto frac = [&](double a) {
        return (double)(r.end() - std::lower_bound(r.begin(), r.end(), a)) / r.size();
    };
    std::printf("tracks: %d observations, radius / corner radius p99 %.3f, max %.3f; "
                "beyond 0.8: %.2f%%, beyond 0.9: %.2f%%\n", (int)r.size(),
                r[(size_t)(0.99 * (r.size() - 1))], r.back(), 100 * frac(0.8), 100 * frac(0.9));
}

// Residuals of the tracks under `est` by radius (tenths of the corner radius): the median
// length, and the median radial part (signed: + outwards), which shows a lens that does not fit
// where the tracks are.
void printResidualByRadius(const Reconstruction& est, const Tracks& t, const Point2d& c)
{
    const double rc = cv::norm(c);
    const int nb = 10;
    std::vector<std::vector<double>> len(nb), radial(nb);
    std::vector<double> all;
    for (int i = 0; i < t.observations(); i++)
    {
        Point2d e;
        if (!residual(est, t, i, e))
            continue;
        const Point2d q(t.uv(i));
        const double rq = cv::norm(q - c);
        const int b = std::min(nb - 1, (int)(nb * rq / rc));
        len[b].push_back(cv::norm(e));
        all.push_back(cv::norm(e));
        if (rq > 0)
            radial[b].push_back(e.dot(q - c) / rq);
    }
    const double thr = 3.16 * median(all);  // recoverCameras' unexplained observations
    std::printf("residual by radius (r / corner radius: count, median px, median radial "
                "px, %% beyond %.2f px):\n", thr);
    for (int b = 0; b < nb; b++)
    {
        const std::vector<double>& v = len[b];
        if (v.empty())
            continue;
        const double out = (double)std::count_if(v.begin(), v.end(),
                                                 [&](double x) { return x > thr; });
        std::printf("  %.1f-%.1f: %6d %.3f %+.3f %5.1f%%\n", 0.1 * b, 0.1 * (b + 1),
                    (int)v.size(), median(v), median(radial[b]), 100 * out / v.size());
    }
}

// Drift along the tracks (tracks of >= 30 observations): the mean residual of a track's last
// third minus that of its first third, its length and its parts along the image radius
// (outwards) and along the track's own displacement.
void printDrift(const Reconstruction& est, const Tracks& t, const Point2d& c)
{
    std::vector<double> mag, rad, mot;
    for (int p = 0; p < t.points(); p++)
    {
        const Range tr = t.track(p);
        const int n = tr.size();
        if (n < 30 || !est.hasPoint(p))
            continue;
        Point2d a(0, 0), b(0, 0), qa(0, 0), qb(0, 0);
        int na = 0, nb = 0;
        for (int k = 0; k < n; k++)
        {
            const int i = tr.start + k;
            Point2d e;
            if ((k >= n / 3 && k < n - n / 3) || !residual(est, t, i, e))
                continue;
            const Point2d q(t.uv(i));
            if (k < n / 3)
            {
                a += e;
                qa += q;
                na++;
            }
            else
            {
                b += e;
                qb += q;
                nb++;
            }
        }
        if (na < 5 || nb < 5)
            continue;
        const Point2d d = b * (1.0 / nb) - a * (1.0 / na);
        const Point2d qm = (qa * (1.0 / na) + qb * (1.0 / nb)) * 0.5 - c;
        const Point2d mv = qb * (1.0 / nb) - qa * (1.0 / na);
        mag.push_back(cv::norm(d));
        if (cv::norm(qm) > 1)
            rad.push_back(d.dot(qm) / cv::norm(qm));
        if (cv::norm(mv) > 1)
            mot.push_back(d.dot(mv) / cv::norm(mv));
    }
    std::printf("drift of %d tracks (last third - first third of the residual): median %.3f px; "
                "radial median %+.3f mean %+.3f; along the motion median %+.3f mean %+.3f px\n",
                (int)mag.size(), median(mag), median(rad), mean(rad), median(mot), mean(mot));
}

// Observations per cell of an 8 x 6 grid over the frame: where the tracks are.
void printGrid(const Tracks& t, Size s)
{
    const int gx = 8, gy = 6;
    std::vector<int> cnt(gx * gy, 0);
    for (int i = 0; i < t.observations(); i++)
    {
        const Point2f q = t.uv(i);
        const int cx = std::min(gx - 1, (int)(q.x * gx / s.width));
        const int cy = std::min(gy - 1, (int)(q.y * gy / s.height));
        cnt[cy * gx + cx]++;
    }
    std::printf("observations per cell (8 x 6 grid):\n");
    for (int y = 0; y < gy; y++)
    {
        for (int x = 0; x < gx; x++)
            std::printf(" %6d", cnt[y * gx + x]);
        std::printf("\n");
    }
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 3)
    {
        std::fprintf(stderr, "usage: %s RECONSTRUCTION GT_RECONSTRUCTION [TRACKS]\n", argv[0]);
        return 2;
    }
    try
    {
        const Reconstruction est = readReconstruction(argv[1]);
        const Reconstruction gt = readReconstruction(argv[2]);
        const Camera& ce = est.cameras.front();
        const opencv_test::LensFigures lf = opencv_test::measureLens(est, gt);
        const SlideStats sl = measureSlide(est, gt);
        String dist;
        for (double d : ce.distortion)
            dist += cv::format(" %.4f", d);
        std::printf("rotation %.4f deg, focal %.2f%% off (%.1f px, true %.1f), corners %.3f px, "
                    "slide median %.3f / p95 %.3f / worst %.2f px, distortion [%s ]\n",
                    lf.rotationDeg, lf.focalErrorPct, ce.K(0, 0), gt.camera(ce.frame).K(0, 0),
                    lf.cornerPx, sl.median, sl.p95, sl.max, dist.c_str());
        if (argc > 3)
        {
            const Tracks t = readTracks(argv[3]);
            const Size s = gt.imageSize;
            const Point2d c((s.width - 1) * 0.5, (s.height - 1) * 0.5);
            printReach(t, c);
            printResidualByRadius(est, t, c);
            printDrift(est, t, c);
            printGrid(t, s);
        }
    }
    catch (const cv::Exception& e)
    {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    }
    return 0;
}
