// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The sun from the footage (sun_estimation.hpp): samples of the ground and of the clones with
// their normals and brightness, shadow maps of the clones from candidate suns (shadow.hpp), and
// the light model of lighting.hpp fitted in log brightness with one albedo per surface group.

#include "precomp.hpp"
#include "opencv2/augocc/sun_estimation.hpp"
#include "shadow.hpp"

namespace cv {
namespace augocc {

namespace {

struct Sample
{
    Vec3f X;       // world point
    Vec3f n;       // unit normal, world
    float logI;    // log brightness
    int region;    // albedo group
    int group;     // jackknife group (-1: none)
    int slot;      // index of the frame (its shadow maps)
    bool onClone;  // receiver on a clone (the voxel depth bias)
};

const double kMinBrightness = 4.0 / 255, kMaxBrightness = 250.0 / 255;

// Unit direction of azimuth / elevation (degrees) relative to the ground (sunDirection()).
Vec3d dirOf(const GroundFrame& g, double az, double el)
{
    return sunDirection(g, az, el);
}

void azElOf(const GroundFrame& g, const Vec3d& L, double& az, double& el)
{
    const Vec3d up = g.up / cv::norm(g.up);
    Vec3d N = -g.back - up * up.dot(-g.back);
    N /= cv::norm(N);
    const Vec3d E = N.cross(up);
    el = std::asin(std::max(-1.0, std::min(1.0, up.dot(L)))) * 180 / CV_PI;
    double a = std::atan2(L.dot(E), L.dot(N)) * 180 / CV_PI;
    if (a < 0)
        a += 360;
    az = a >= 360 ? 0 : a;
}

double angleDeg(const Vec3d& a, const Vec3d& b)
{
    return std::atan2(cv::norm(a.cross(b)), a.dot(b)) * 180 / CV_PI;
}

class Problem
{
public:
    Problem(const std::vector<Mat>& frames, const std::vector<int>& frameNumbers,
            const Reconstruction& rec, const CloneSet& clones, const GroundFrame& ground,
            const SunEstimationParams& p)
        : rec_(rec), clones_(clones), ground_(ground), p_(p), frameNumbers_(frameNumbers)
    {
        up_ = ground.up / cv::norm(ground.up);
        names_ = clones.objectNames();
        // The casters' bounds (every clone's grid box), as the compositor lays its map out.
        double voxel = 0;
        Vec3d lo = Vec3d::all(1e300), hi = -lo;
        for (const String& name : names_)
        {
            Matx33d Rb;
            Vec3d o;
            clones.gridPose(name, Rb, o);
            const Vec3i n = clones.gridSize(name);
            const double v = clones.voxelSize(name);
            voxel = std::max(voxel, v);
            for (int c = 0; c < 8; c++)
            {
                const Vec3d X = o + Rb * Vec3d((c & 1) ? n[0] * v : 0, (c & 2) ? n[1] * v : 0,
                                               (c & 4) ? n[2] * v : 0);
                corners_.push_back(X);
                for (int k = 0; k < 3; k++)
                {
                    lo[k] = std::min(lo[k], X[k]);
                    hi[k] = std::max(hi[k], X[k]);
                }
            }
        }
        extent_ = corners_.empty() ? 1.0 : cv::norm(hi - lo);
        centre_ = 0.5 * (lo + hi);
        extraBias_ = 1.5 * voxel;
        for (size_t i = 0; i < frames.size(); i++)
            gather(frames[i], frameNumbers[i], (int)i);
    }

    const std::vector<Sample>& samples() const { return samples_; }
    int regions() const { return regionCount_; }
    double extent() const { return extent_; }

    /* Per sample t = V max(0, n . L) under sun L with the given penumbra (world units). */
    void shading(const Vec3d& L, double penumbra, std::vector<float>& t) const
    {
        Sun sun;
        sun.direction = L;
        sun.sky = 0.5;
        sun.penumbra = penumbra;
        std::vector<detail::ShadowMap> maps(frameNumbers_.size());
        for (size_t k = 0; k < maps.size(); k++)
        {
            detail::ShadowMap& m = maps[k];
            m.layout(sun, corners_);
            m.extraBias = extraBias_;
            Mat matte, depth;
            for (const String& name : names_)
            {
                clones_.render(name, frameNumbers_[k], m.cam, m.size(), matte, depth);
                m.addDepth(depth);
            }
            m.finish();
        }
        t.resize(samples_.size());
        parallel_for_(Range(0, (int)samples_.size()), [&](const Range& r) {
            for (int i = r.start; i < r.end; i++)
            {
                const Sample& s = samples_[i];
                const Vec3d n(s.n);
                const double c = std::max(0.0, n.dot(L));
                t[i] = c > 0 ? (float)(c * maps[s.slot].visibility(Vec3d(s.X), n)) : 0.f;
            }
        });
    }

    /* Sum of squared log residuals over the samples not in group `skip`, albedos eliminated,
    for sky share `sky`. */
    double rss(const std::vector<float>& t, double sky, int skip, int* count = nullptr,
               const std::vector<uchar>* keep = nullptr) const
    {
        std::vector<double> sum(regionCount_, 0.0), sum2(regionCount_, 0.0);
        std::vector<int> n(regionCount_, 0);
        const float s = (float)sky;
        for (size_t i = 0; i < samples_.size(); i++)
        {
            const Sample& sm = samples_[i];
            if ((skip >= 0 && sm.group == skip) || (keep && !(*keep)[i]))
                continue;
            const double d = sm.logI - std::log(s + (1 - s) * t[i]);
            sum[sm.region] += d;
            sum2[sm.region] += d * d;
            n[sm.region]++;
        }
        double r = 0;
        int total = 0;
        for (int k = 0; k < regionCount_; k++)
            if (n[k] > 0)
            {
                r += std::max(0.0, sum2[k] - sum[k] * sum[k] / n[k]);
                total += n[k];
            }
        if (count)
            *count = total;
        return r;
    }

    // Sky share minimising rss() (golden-section search on [0.01, 0.99]).
    double bestSky(const std::vector<float>& t, int skip, double& best,
                   const std::vector<uchar>* keep = nullptr) const
    {
        double a = 0.01, b = 0.99;
        const double g = (std::sqrt(5.0) - 1) / 2;
        double x1 = b - g * (b - a), x2 = a + g * (b - a);
        double f1 = rss(t, x1, skip, nullptr, keep), f2 = rss(t, x2, skip, nullptr, keep);
        while (b - a > 1e-4)
        {
            if (f1 < f2)
            {
                b = x2;
                x2 = x1;
                f2 = f1;
                x1 = b - g * (b - a);
                f1 = rss(t, x1, skip, nullptr, keep);
            }
            else
            {
                a = x1;
                x1 = x2;
                f1 = f2;
                x2 = a + g * (b - a);
                f2 = rss(t, x2, skip, nullptr, keep);
            }
        }
        const double x = 0.5 * (a + b);
        best = rss(t, x, skip, nullptr, keep);
        return x;
    }

    /* The samples whose residual under (t, sky) lies within k RMS of their group's mean: what
    the model explains, without the pixels the clones' shadows do not (a visual hull is larger
    than its object, so its predicted shadow covers some lit ground). */
    std::vector<uchar> inliers(const std::vector<float>& t, double sky, double k) const
    {
        std::vector<double> sum(regionCount_, 0.0), sum2(regionCount_, 0.0);
        std::vector<int> n(regionCount_, 0);
        std::vector<double> d(samples_.size());
        const float s = (float)sky;
        for (size_t i = 0; i < samples_.size(); i++)
        {
            d[i] = samples_[i].logI - std::log(s + (1 - s) * t[i]);
            sum[samples_[i].region] += d[i];
            sum2[samples_[i].region] += d[i] * d[i];
            n[samples_[i].region]++;
        }
        double tot = 0;
        int cnt = 0;
        for (int r = 0; r < regionCount_; r++)
            if (n[r] > 0)
            {
                tot += std::max(0.0, sum2[r] - sum[r] * sum[r] / n[r]);
                cnt += n[r];
                sum[r] /= n[r];
            }
        const double lim = k * std::sqrt(tot / std::max(1, cnt));
        std::vector<uchar> keep(samples_.size());
        for (size_t i = 0; i < samples_.size(); i++)
            keep[i] = std::abs(d[i] - sum[samples_[i].region]) <= lim;
        return keep;
    }

private:
    void gather(const Mat& frameIn, int frame, int slot)
    {
        const Camera& cam = rec_.camera(frame);
        const Size sz = frameIn.size();
        Mat grey;
        if (frameIn.channels() == 3)
        {
            // Mean of the channels (the model holds per channel; the mean of three is one).
            Mat f;
            frameIn.convertTo(f, CV_32FC3, 1.0 / 255);
            cv::transform(f, grey, Matx13f(1.f / 3, 1.f / 3, 1.f / 3));
        }
        else
            frameIn.convertTo(grey, CV_32F, 1.0 / 255);
        const float inf = std::numeric_limits<float>::infinity();
        // The nearest clone per pixel and its object.
        Mat z(sz, CV_32F, Scalar(inf)), label(sz, CV_8U, Scalar(255)), matte, depth;
        for (size_t k = 0; k < names_.size(); k++)
        {
            clones_.render(names_[k], frame, cam, sz, matte, depth);
            Mat nearer = depth < z;
            depth.copyTo(z, nearer);
            label.setTo(Scalar((double)k + 1), nearer);
        }
        // Normals of the clones from their depth alone, smoothed per object over the staircase
        // of voxel-centre depths (a box of 4 normal steps), then unit.
        Mat pts, nrm;
        detail::surfaceFromDepth(cam, z, pts, nrm, p_.normalStep);
        Mat smooth(sz, CV_32FC3, Scalar::all(0));
        const int win = 4 * p_.normalStep + 1;
        for (size_t k = 0; k < names_.size(); k++)
        {
            Mat mk = label == (int)(k + 1), part(sz, CV_32FC3, Scalar::all(0)), blurred;
            nrm.copyTo(part, mk);
            cv::boxFilter(part, blurred, CV_32F, Size(win, win), Point(-1, -1), false,
                          BORDER_CONSTANT);
            blurred.copyTo(smooth, mk);
        }
        // The ground where no clone is nearer: label 0.
        for (int y = 0; y < sz.height; y++)
            for (int x = 0; x < sz.width; x++)
            {
                const Ray ray = cam.backproject(Point2d(x, y));
                const double dn = up_.dot(ray.direction);
                if (std::abs(dn) < 1e-12)
                    continue;
                const double lambda = (ground_.height - up_.dot(ray.origin)) / dn;
                const Vec3d X = ray.at(lambda);
                const double zg = cam.depth(X);
                if (zg > 0 && zg < z.at<float>(y, x))
                {
                    z.at<float>(y, x) = (float)zg;
                    label.at<uchar>(y, x) = 0;
                    pts.at<Vec3f>(y, x) = Vec3f(X);
                }
            }
        // Away from surface changes: the label constant over the margin's square.
        const int m = std::max(0, cvRound(p_.edgeMarginPx));
        Mat lmin, lmax;
        const Mat kernel = Mat::ones(2 * m + 1, 2 * m + 1, CV_8U);
        cv::erode(label, lmin, kernel, Point(-1, -1), 1, BORDER_REPLICATE);
        cv::dilate(label, lmax, kernel, Point(-1, -1), 1, BORDER_REPLICATE);
        const int stride =
            std::max(1, (int)std::ceil(std::sqrt((double)sz.area() / p_.maxSamplesPerFrame)));
        const Matx33d Rg = ground_.rotation();
        const Vec3d view = cam.viewDirection();
        const int nb = p_.sideBins;
        for (int y = m; y < sz.height - m; y += stride)
            for (int x = m; x < sz.width - m; x += stride)
            {
                const int l = label.at<uchar>(y, x);
                if (l == 255 || lmin.at<uchar>(y, x) != lmax.at<uchar>(y, x))
                    continue;
                const float I = grey.at<float>(y, x);
                if (!(I >= kMinBrightness && I <= kMaxBrightness))
                    continue;
                Sample s;
                s.X = pts.at<Vec3f>(y, x);
                s.logI = std::log(I);
                s.slot = slot;
                s.onClone = l > 0;
                Vec3d n = up_;
                s.region = 0;
                if (l > 0)
                {
                    n = Vec3d(smooth.at<Vec3f>(y, x));
                    const double nn = cv::norm(n);
                    if (!(nn > 1e-6))
                        continue;
                    n /= nn;
                    // Grazing views: the depth's normal is unreliable.
                    if (std::abs(n.dot(view)) < 0.2)
                        continue;
                    const Vec3d g = Rg * n;  // (right, up, back)
                    int bin;
                    if (g[1] > 0.8)
                        bin = 0;
                    else if (g[1] < -0.5)
                        continue;
                    else
                    {
                        double a = std::atan2(g[2], g[0]) / (2 * CV_PI);
                        a -= std::floor(a);
                        bin = 1 + std::min(nb - 1, (int)(a * nb));
                    }
                    s.region = 1 + (l - 1) * (nb + 1) + bin;
                }
                s.n = Vec3f(n);
                if (!std::isfinite(s.X[0]))
                    continue;
                s.group = -1;
                if (p_.jackknifeGroups > 0)
                {
                    const Vec3d h = Rg * (Vec3d(s.X) - centre_);
                    double a = std::atan2(h[2], h[0]) / (2 * CV_PI);
                    a -= std::floor(a);
                    s.group = std::min(p_.jackknifeGroups - 1, (int)(a * p_.jackknifeGroups));
                }
                samples_.push_back(s);
            }
        regionCount_ = 1 + (int)names_.size() * (nb + 1);
    }

    const Reconstruction& rec_;
    const CloneSet& clones_;
    GroundFrame ground_;
    SunEstimationParams p_;
    std::vector<int> frameNumbers_;
    std::vector<String> names_;
    std::vector<Vec3d> corners_;
    std::vector<Sample> samples_;
    Vec3d up_, centre_;
    double extent_ = 1, extraBias_ = 0;
    int regionCount_ = 1;
};

struct Fit
{
    Vec3d L;
    double sky = 0.5;
    double cost = std::numeric_limits<double>::infinity();
};

class Search
{
public:
    Search(const Problem& pr, const GroundFrame& g, const SunEstimationParams& p)
        : pr_(pr), g_(g), p_(p)
    {
        up_ = g.up / cv::norm(g.up);
    }

    Fit evaluate(const Vec3d& L, double penumbra, int skip)
    {
        Fit f;
        f.L = L;
        pr_.shading(L, penumbra, t_);
        f.sky = pr_.bestSky(t_, skip, f.cost);
        evaluations++;
        return f;
    }

    bool allowed(const Vec3d& L) const
    {
        const double el = std::asin(std::max(-1.0, std::min(1.0, up_.dot(L)))) * 180 / CV_PI;
        return el >= p_.minElevationDeg && el <= p_.maxElevationDeg;
    }

    // Compass search on the sphere from `start`: steps along two tangent axes, halved down to
    // `stop` degrees.
    Fit refine(Fit best, double step, double stop, double penumbra, int skip)
    {
        best = evaluate(best.L, penumbra, skip);
        while (step >= stop - 1e-9)
        {
            Vec3d e1 = up_.cross(best.L);
            if (cv::norm(e1) < 1e-9)
                e1 = g_.right;
            e1 /= cv::norm(e1);
            const Vec3d e2 = best.L.cross(e1);
            bool moved = false;
            const double h = std::tan(step * CV_PI / 180);
            const Vec3d cand[4] = {best.L + h * e1, best.L - h * e1, best.L + h * e2,
                                   best.L - h * e2};
            Fit top = best;
            for (const Vec3d& c : cand)
            {
                const Vec3d L = c / cv::norm(c);
                if (!allowed(L))
                    continue;
                const Fit f = evaluate(L, penumbra, skip);
                if (f.cost < top.cost)
                {
                    top = f;
                    moved = true;
                }
            }
            if (moved)
                best = top;
            else
                step *= 0.5;
        }
        return best;
    }

    int evaluations = 0;

private:
    const Problem& pr_;
    GroundFrame g_;
    SunEstimationParams p_;
    Vec3d up_;
    std::vector<float> t_;
};

void checkParams(const SunEstimationParams& p)
{
    if (p.maxSamplesPerFrame < 100)
        CV_Error(Error::StsBadArg, "estimateSun: maxSamplesPerFrame must be >= 100");
    if (!(p.edgeMarginPx >= 0) || p.normalStep < 1 || p.sideBins < 1)
        CV_Error(Error::StsBadArg, "estimateSun: edgeMarginPx >= 0, normalStep >= 1 and "
                                   "sideBins >= 1 expected");
    if (!(p.coarseStepDeg >= 1 && p.coarseStepDeg <= 45) ||
        !(p.finalStepDeg > 0 && p.finalStepDeg <= p.coarseStepDeg))
        CV_Error(Error::StsBadArg, "estimateSun: coarseStepDeg in [1, 45] and finalStepDeg in "
                                   "(0, coarseStepDeg] expected");
    if (!(p.minElevationDeg >= 0 && p.minElevationDeg < p.maxElevationDeg &&
          p.maxElevationDeg <= 90))
        CV_Error(Error::StsBadArg, "estimateSun: 0 <= minElevationDeg < maxElevationDeg <= 90 "
                                   "expected");
    if (!(p.coarsePenumbraFraction > 0) || !(p.finePenumbraFraction > 0))
        CV_Error(Error::StsBadArg, "estimateSun: penumbra fractions must be positive");
    if (!(p.skyInlierSigmas >= 0))
        CV_Error(Error::StsBadArg, "estimateSun: skyInlierSigmas must be >= 0");
    if (p.jackknifeGroups != 0 && p.jackknifeGroups < 3)
        CV_Error(Error::StsBadArg, "estimateSun: jackknifeGroups must be 0 or >= 3");
}

} // namespace

std::vector<int> sunEstimationFrames(const Reconstruction& rec, int maxFrames)
{
    std::vector<int> out;
    const int n = (int)rec.cameras.size();
    if (n == 0 || maxFrames <= 0)
        return out;
    const int k = std::min(n, maxFrames);
    for (int i = 0; i < k; i++)
    {
        const int idx = k == 1 ? n / 2 : (int)std::lround((double)i * (n - 1) / (k - 1));
        const int f = rec.cameras[idx].frame;
        if (out.empty() || out.back() != f)
            out.push_back(f);
    }
    return out;
}

SunEstimate estimateSun(const std::vector<Mat>& frames, const std::vector<int>& frameNumbers,
                        const Reconstruction& rec, const CloneSet& clones,
                        const GroundFrame& ground, const SunEstimationParams& params)
{
    checkParams(params);
    if (frames.size() != frameNumbers.size() || frames.empty())
        CV_Error(Error::StsBadArg, cv::format("estimateSun: %d frames for %d frame numbers",
                                              (int)frames.size(), (int)frameNumbers.size()));
    for (size_t i = 0; i < frames.size(); i++)
    {
        if (rec.findCamera(frameNumbers[i]) < 0)
            CV_Error(Error::StsBadArg, cv::format("estimateSun: frame %d has no camera",
                                                  frameNumbers[i]));
        if (frames[i].depth() != CV_8U ||
            (frames[i].channels() != 1 && frames[i].channels() != 3))
            CV_Error(Error::StsBadArg, cv::format("estimateSun: frame %d is not 8-bit grey or "
                                                  "BGR", frameNumbers[i]));
        if (frames[i].size() != rec.imageSize)
            CV_Error(Error::StsBadArg, cv::format("estimateSun: frame %d is %dx%d, the "
                                                  "reconstruction's frames %dx%d",
                                                  frameNumbers[i], frames[i].cols,
                                                  frames[i].rows, rec.imageSize.width,
                                                  rec.imageSize.height));
    }
    if (clones.objectNames().empty())
        CV_Error(Error::StsBadArg, "estimateSun: no clones (their shadows are the evidence)");
    const Problem pr(frames, frameNumbers, rec, clones, ground, params);
    if (pr.samples().size() < 200)
        CV_Error(Error::StsBadArg, cv::format("estimateSun: only %d usable pixels (ground and "
                                              "clones seen, neither black nor saturated)",
                                              (int)pr.samples().size()));
    Search search(pr, ground, params);
    const double coarsePen = params.coarsePenumbraFraction * pr.extent();
    const double finePen = params.finePenumbraFraction * pr.extent();
    // Coarse grid: elevation rings, azimuth spaced by the same arc on the sky.
    std::vector<Fit> grid;
    const double step = params.coarseStepDeg;
    for (double el = params.minElevationDeg + 0.5 * step; el < params.maxElevationDeg;
         el += step)
    {
        const int na = std::max(1, (int)std::ceil(360 * std::cos(el * CV_PI / 180) / step));
        for (int i = 0; i < na; i++)
            grid.push_back(search.evaluate(dirOf(ground, 360.0 * i / na, el), coarsePen, -1));
    }
    std::sort(grid.begin(), grid.end(),
              [](const Fit& a, const Fit& b) { return a.cost < b.cost; });
    // Refine the best few coarse minima (smooth shadows), then the best at the fine penumbra.
    Fit best;
    const int starts = std::min<int>(3, (int)grid.size());
    for (int i = 0; i < starts; i++)
    {
        const Fit f = search.refine(grid[i], step / 2, 1.0, coarsePen, -1);
        if (f.cost < best.cost)
            best = f;
    }
    best = search.refine(best, 1.0, params.finalStepDeg, finePen, -1);

    SunEstimate e;
    e.direction = best.L;
    e.sky = best.sky;
    if (params.skyInlierSigmas > 0)
    {
        // The sky share again over the samples the fit explains (SunEstimationParams).
        std::vector<float> t;
        pr.shading(best.L, finePen, t);
        const std::vector<uchar> keep = pr.inliers(t, best.sky, params.skyInlierSigmas);
        double c;
        e.sky = pr.bestSky(t, -1, c, &keep);
    }
    azElOf(ground, best.L, e.azimuthDeg, e.elevationDeg);
    {
        std::vector<float> t;
        pr.shading(best.L, finePen, t);
        int count = 0;
        const double r = pr.rss(t, best.sky, -1, &count);
        e.rmsLog = std::sqrt(r / std::max(1, count));
        std::fill(t.begin(), t.end(), 0.f);
        e.rmsLogNoSun = std::sqrt(pr.rss(t, 0.5, -1) / std::max(1, count));
    }
    for (const Sample& s : pr.samples())
        (s.onClone ? e.cloneSamples : e.groundSamples)++;
    e.frames = (int)frames.size();
    if (params.jackknifeGroups > 0)
    {
        // Delete-one-group jackknife: var = (K - 1) / K * sum (theta_k - theta)^2 over the
        // groups that hold samples, each re-fitted from the estimate.
        std::vector<int> present(params.jackknifeGroups, 0);
        for (const Sample& s : pr.samples())
            if (s.group >= 0)
                present[s.group]++;
        double a2 = 0, s2 = 0;
        int K = 0;
        for (int g = 0; g < params.jackknifeGroups; g++)
        {
            if (present[g] == 0)
                continue;
            const Fit f = search.refine(best, 2.0, params.finalStepDeg * 2, finePen, g);
            const double a = angleDeg(f.L, best.L);
            a2 += a * a;
            s2 += (f.sky - best.sky) * (f.sky - best.sky);
            K++;
        }
        if (K >= 2)
        {
            // The compass search's resolution added in quadrature: a uniform error of +-step/2
            // along each of its two axes (the jackknife's re-fits move in those steps, so a
            // spread below one step reads as zero).
            const double q = 2 * params.finalStepDeg * params.finalStepDeg / 12;
            e.angularSigmaDeg = std::sqrt((K - 1.0) / K * a2 + q);
            e.skySigma = std::sqrt((K - 1.0) / K * s2);
        }
    }
    e.evaluations = search.evaluations;
    return e;
}

Sun toSun(const SunEstimate& estimate, double penumbra)
{
    Sun s;
    s.direction = estimate.direction;
    s.sky = estimate.sky;
    s.penumbra = penumbra;
    s.validate("toSun");
    return s;
}

} // namespace augocc
} // namespace cv
