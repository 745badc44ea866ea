// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// RANSAC planes through reconstructed points and the ground plane of estimateGround().

#include "precomp.hpp"
#include "ground_plane.hpp"
#include "stats.hpp"

namespace cv {
namespace augocc {
namespace detail {

PlaneFit ransacPlane(const std::vector<Vec3d>& samples, const std::vector<Vec3d>& points,
                     double band, int trials, uint64 seed,
                     const std::function<bool(Vec3d& normal)>& orient)
{
    PlaneFit best;
    const int n = (int)samples.size();
    if (n < 3)
        return best;
    RNG rng(seed);
    for (int trial = 0; trial < trials; trial++)
    {
        const Vec3d& a = samples[rng.uniform(0, n)];
        const Vec3d& b = samples[rng.uniform(0, n)];
        const Vec3d& c = samples[rng.uniform(0, n)];
        Vec3d normal = (b - a).cross(c - a);
        const double len = cv::norm(normal);
        if (!(len > 0))
            continue;
        normal *= 1.0 / len;
        if (orient && !orient(normal))
            continue;
        const double offset = normal.dot(a);
        int count = 0;
        for (const Vec3d& p : points)
            count += std::abs(normal.dot(p) - offset) < band;
        if (count > best.inliers)
        {
            best.normal = normal;
            best.offset = offset;
            best.inliers = count;
        }
    }
    return best;
}

namespace {

// Eigenvector of the smallest eigenvalue of a symmetric 3x3.
Vec3d leastEigenvector(const Matx33d& S)
{
    Mat evals, evecs;
    cv::eigen(Mat(S), evals, evecs);  // descending
    return Vec3d(evecs.at<double>(2, 0), evecs.at<double>(2, 1), evecs.at<double>(2, 2));
}

} // namespace

bool fitGroundPlane(const std::vector<Vec3d>& pts, Vec3d& up, double& height)
{
    height = 0;
    if (pts.size() < 10)
        return false;
    std::vector<double> h(pts.size());
    for (size_t i = 0; i < pts.size(); i++)
        h[i] = up.dot(pts[i]);
    std::vector<double> hs = h;
    std::sort(hs.begin(), hs.end());
    const double hMedian = median(h);
    height = hs[(size_t)(0.02 * (hs.size() - 1))];
    // Spread of the scene along up: the inlier band is 1% of it.
    const double extent = std::max(hs.back() - hs.front(), 1e-12);
    const double kInlierFraction = 0.01;
    const double tol = kInlierFraction * extent;
    const double kMaxTiltDeg = 15.0;
    std::vector<Vec3d> low;
    for (size_t i = 0; i < pts.size(); i++)
        if (h[i] <= hMedian)
            low.push_back(pts[i]);
    // Deterministic RANSAC (fixed seed) over the lower half of the points; normals signed up.
    const int kIterations = 500;
    const PlaneFit best = ransacPlane(low, pts, tol, kIterations, 0x5eed, [&](Vec3d& n) {
        if (n.dot(up) < 0)
            n = -n;
        return !(n.dot(up) < std::cos(kMaxTiltDeg * CV_PI / 180));
    });
    // A plane holds the ground when it carries a tenth of the points (at least 10).
    const size_t kMinInliers = std::max<size_t>(10, pts.size() / 10);
    if ((size_t)best.inliers < kMinInliers)
        return false;
    // Least-squares refit on the inliers.
    Vec3d centroid(0, 0, 0);
    std::vector<Vec3d> in;
    for (const Vec3d& p : pts)
        if (std::abs(best.normal.dot(p) - best.offset) < tol)
            in.push_back(p);
    for (const Vec3d& p : in)
        centroid += p;
    centroid *= 1.0 / in.size();
    Matx33d C = Matx33d::zeros();
    for (const Vec3d& p : in)
        C += (p - centroid) * (p - centroid).t();
    Vec3d n = leastEigenvector(C);
    if (n.dot(up) < 0)
        n = -n;
    up = n;
    height = n.dot(centroid);
    return true;
}

} // namespace detail
} // namespace augocc
} // namespace cv
