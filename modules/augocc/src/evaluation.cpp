// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Scores against a ground truth: a composite against the rendered truth, a reconstruction aligned
// with a reference one.

#include "precomp.hpp"

namespace cv {
namespace augocc {

// ---------------------------------------------------------------------------------------------
// Scores

namespace {

Mat binary(InputArray a, const char* what, Size size)
{
    Mat m = a.getMat();
    if (m.type() != CV_8UC1 || m.size() != size)
        CV_Error(Error::StsBadArg, String("scoreComposite: ") + what + " must be CV_8U of the "
                 "composite's size");
    return m > 127;
}

// Inner boundary: pixels of the mask with a 4-neighbour outside it.
Mat innerBoundary(const Mat& mask)
{
    Mat eroded;
    cv::erode(mask, eroded, getStructuringElement(MORPH_CROSS, Size(3, 3)), Point(-1, -1), 1,
              BORDER_CONSTANT, Scalar(0));
    return mask & ~eroded;
}

} // namespace

CompositeScore scoreComposite(InputArray compositeArr, InputArray truthArr, InputArray visibleArr,
                              InputArray visibleTruthArr, InputArray silhouetteArr,
                              int greyTolerance, int bandRadius)
{
    Mat comp = compositeArr.getMat(), truth = truthArr.getMat();
    CV_CheckTypeEQ(comp.type(), CV_8UC3, "composite");
    CV_CheckTypeEQ(truth.type(), CV_8UC3, "ground truth");
    CV_CheckEQ(comp.size(), truth.size(), "composite and ground truth sizes");
    const Size sz = comp.size();
    const Mat vis = binary(visibleArr, "visible", sz);
    const Mat visT = binary(visibleTruthArr, "visibleTruth", sz);
    const Mat sil = binary(silhouetteArr, "silhouette", sz);
    CompositeScore s;

    Mat g1, g2, diff;
    cv::cvtColor(comp, g1, COLOR_BGR2GRAY);
    cv::cvtColor(truth, g2, COLOR_BGR2GRAY);
    cv::absdiff(g1, g2, diff);
    s.fractionWithin = (double)cv::countNonZero(diff <= greyTolerance) / (double)sz.area();

    // Occlusion boundaries: visible boundary away from the silhouette's own boundary.
    Mat silEdge;
    cv::dilate(innerBoundary(sil), silEdge, Mat(), Point(-1, -1), 1);
    const Mat bT = innerBoundary(visT) & ~silEdge;
    const Mat b = innerBoundary(vis) & ~silEdge;
    s.boundaryPixels = cv::countNonZero(bT);
    const int nb = cv::countNonZero(b);
    auto meanDistTo = [&](const Mat& from, const Mat& toMask) {
        Mat dist;
        const Mat toEdge = innerBoundary(toMask);
        if (cv::countNonZero(toEdge) == 0)
            return std::sqrt((double)sz.area());  // nothing to match: as far as it gets
        cv::distanceTransform(~toEdge, dist, DIST_L2, DIST_MASK_PRECISE);
        return cv::mean(dist, from)[0];
    };
    if (s.boundaryPixels == 0 && nb == 0)
        s.boundaryDistance = 0;
    else
    {
        double sum = 0, n = 0;
        if (nb > 0)
        {
            sum += meanDistTo(b, visT) * nb;
            n += nb;
        }
        if (s.boundaryPixels > 0)
        {
            sum += meanDistTo(bT, vis) * s.boundaryPixels;
            n += s.boundaryPixels;
        }
        s.boundaryDistance = sum / n;
    }

    // Band around the true occlusion boundary.
    Mat band;
    const int r = std::max(0, bandRadius);
    cv::dilate(bT, band, getStructuringElement(MORPH_ELLIPSE, Size(2 * r + 1, 2 * r + 1)));
    s.bandPixels = cv::countNonZero(band);
    if (s.bandPixels > 0)
    {
        Mat cdiff;
        cv::absdiff(comp, truth, cdiff);
        const Scalar m = cv::mean(cdiff, band);
        s.bandError = (m[0] + m[1] + m[2]) / 3.0;
    }
    return s;
}

// ---------------------------------------------------------------------------------------------
// Alignment with a reference reconstruction

Matx44d alignReconstructions(const Reconstruction& rec, const Reconstruction& ref)
{
    std::vector<std::pair<const Camera*, const Camera*> > pairs;
    for (const Camera& c : rec.cameras)
    {
        const int j = ref.findCamera(c.frame);
        if (j >= 0)
            pairs.push_back({&c, &ref.cameras[j]});
    }
    if (pairs.size() < 3)
        CV_Error(Error::StsBadArg, "alignReconstructions: fewer than three common frames");
    // X_rec = sigma * Q * X_ref + T  (Q: R_rec Q = R_ref for every frame).
    Matx33d S = Matx33d::zeros();
    for (const auto& p : pairs)
        S += p.first->R.t() * p.second->R;
    Mat w, u, vt;
    cv::SVDecomp(Mat(S), w, u, vt);
    Mat Qm = u * vt;
    if (cv::determinant(Qm) < 0)
    {
        Mat D = Mat::eye(3, 3, CV_64F);
        D.at<double>(2, 2) = -1;
        Qm = u * D * vt;
    }
    const Matx33d Q((double*)Qm.ptr<double>());
    double sigma = 0;
    Vec3d T;
    if (rec.model == SCALED_ORTHOGRAPHIC)
    {
        // s_rec * sigma = s_ref; (R_rec T)_xy = (s_ref / s_rec) t_ref_xy / sigma ... in rec units:
        // s_rec (R_rec T + t_rec)_xy = s_ref t_ref_xy.
        for (const auto& p : pairs)
            sigma += p.second->s / p.first->s;
        sigma /= pairs.size();
        Mat A((int)pairs.size() * 2, 3, CV_64F), b((int)pairs.size() * 2, 1, CV_64F);
        for (size_t i = 0; i < pairs.size(); i++)
        {
            const Camera& c = *pairs[i].first;
            const Camera& r = *pairs[i].second;
            for (int k = 0; k < 2; k++)
            {
                for (int j = 0; j < 3; j++)
                    A.at<double>(2 * (int)i + k, j) = c.R(k, j);
                b.at<double>(2 * (int)i + k) = r.s / c.s * r.t[k] - c.t[k];
            }
        }
        Mat x;
        cv::solve(A, b, x, DECOMP_SVD);
        T = Vec3d(x.at<double>(0), x.at<double>(1), x.at<double>(2));
    }
    else
    {
        // R_rec T - sigma t_ref = -t_rec, 3 equations per frame, unknowns (T, sigma).
        Mat A((int)pairs.size() * 3, 4, CV_64F), b((int)pairs.size() * 3, 1, CV_64F);
        for (size_t i = 0; i < pairs.size(); i++)
        {
            const Camera& c = *pairs[i].first;
            const Camera& r = *pairs[i].second;
            for (int k = 0; k < 3; k++)
            {
                for (int j = 0; j < 3; j++)
                    A.at<double>(3 * (int)i + k, j) = c.R(k, j);
                A.at<double>(3 * (int)i + k, 3) = -r.t[k];
                b.at<double>(3 * (int)i + k) = -c.t[k];
            }
        }
        Mat x;
        cv::solve(A, b, x, DECOMP_SVD);
        T = Vec3d(x.at<double>(0), x.at<double>(1), x.at<double>(2));
        sigma = x.at<double>(3);
    }
    if (!(sigma > 0))
        CV_Error(Error::StsBadArg, "alignReconstructions: degenerate scale");
    // Invert: X_ref = Q^T (X_rec - T) / sigma.
    const Matx33d A = Q.t() * (1.0 / sigma);
    const Vec3d t = -(A * T);
    return Matx44d(A(0, 0), A(0, 1), A(0, 2), t[0], A(1, 0), A(1, 1), A(1, 2), t[1],
                   A(2, 0), A(2, 1), A(2, 2), t[2], 0, 0, 0, 1);
}


SlideStats measureSlide(const Reconstruction& recovered, const Reconstruction& truth,
                        int gridSteps, double margin)
{
    CV_Assert(gridSteps >= 2);
    std::vector<double> axes[3];
    for (int p = 0; p < recovered.points.rows; p++)
        if (recovered.hasPoint(p))
        {
            const Vec3d X = recovered.point(p);
            for (int a = 0; a < 3; a++)
                axes[a].push_back(X[a]);
        }
    if (axes[0].empty())
        CV_Error(Error::StsBadArg, "measureSlide: the recovered reconstruction has no point");
    Vec3d lo, hi;
    for (int a = 0; a < 3; a++)
    {
        std::sort(axes[a].begin(), axes[a].end());
        const size_t n = axes[a].size();
        lo[a] = axes[a][(size_t)(0.02 * (n - 1))];
        hi[a] = axes[a][(size_t)(0.98 * (n - 1))];
        const double ext = hi[a] - lo[a];
        lo[a] -= margin * ext;
        hi[a] += margin * ext;
    }
    std::vector<std::pair<const Camera*, const Camera*> > pairs;
    for (const Camera& c : recovered.cameras)
    {
        const int t = truth.findCamera(c.frame);
        if (t >= 0)
            pairs.push_back(std::make_pair(&c, &truth.cameras[t]));
    }
    if (pairs.size() < 2)
        CV_Error(Error::StsBadArg, "measureSlide: the reconstructions share fewer than two frames");
    const Size size = truth.imageSize;
    const int n = gridSteps;
    std::vector<std::vector<double> > slides(n * n * n);
    parallel_for_(Range(0, n * n * n), [&](const Range& r) {
        for (int g = r.start; g < r.end; g++)
        {
            const Vec3d t((g % n) / (n - 1.0), ((g / n) % n) / (n - 1.0), (g / (n * n)) / (n - 1.0));
            const Vec3d X(lo[0] + t[0] * (hi[0] - lo[0]), lo[1] + t[1] * (hi[1] - lo[1]),
                          lo[2] + t[2] * (hi[2] - lo[2]));
            std::vector<const Camera*> cams;
            std::vector<Point2d> px;
            for (const auto& pr : pairs)
            {
                if (pr.first->model == PERSPECTIVE && !(pr.first->depth(X) > 0))
                    continue;
                const Point2d u = pr.first->project(X);
                if (u.x < -0.5 || u.y < -0.5 || u.x > size.width - 0.5 || u.y > size.height - 0.5)
                    continue;
                cams.push_back(pr.second);
                px.push_back(u);
            }
            if (cams.size() < 2)
                continue;
            // Linear start: each pixel's ray through the true camera, the point nearest to all
            // rays (least squares).
            Matx33d A = Matx33d::zeros();
            Vec3d b(0, 0, 0);
            for (size_t i = 0; i < cams.size(); i++)
            {
                const Ray ray = cams[i]->backproject(px[i]);
                const Matx33d P = Matx33d::eye() - ray.direction * ray.direction.t();
                A += P;
                b += P * ray.origin;
            }
            Vec3d Y;
            if (!cv::solve(A, b, Y, DECOMP_SVD))
                continue;
            // Gauss-Newton on the pixel error, central-difference Jacobian.
            for (int it = 0; it < 10; it++)
            {
                Matx33d H = Matx33d::zeros();
                Vec3d gvec(0, 0, 0);
                const double h = 1e-6 * std::max(1.0, cv::norm(Y));
                for (size_t i = 0; i < cams.size(); i++)
                {
                    const Point2d e = cams[i]->project(Y) - px[i];
                    Matx23d J;
                    for (int a = 0; a < 3; a++)
                    {
                        Vec3d d(0, 0, 0);
                        d[a] = h;
                        const Point2d dp = (cams[i]->project(Y + d) - cams[i]->project(Y - d)) *
                                           (0.5 / h);
                        J(0, a) = dp.x;
                        J(1, a) = dp.y;
                    }
                    H += J.t() * J;
                    gvec += J.t() * Vec2d(e.x, e.y);
                }
                Vec3d step;
                if (!cv::solve(H, -gvec, step, DECOMP_SVD))
                    break;
                Y += step;
                if (cv::norm(step) < 1e-12 * std::max(1.0, cv::norm(Y)))
                    break;
            }
            for (size_t i = 0; i < cams.size(); i++)
                slides[g].push_back(cv::norm(cams[i]->project(Y) - px[i]));
        }
    });
    SlideStats st;
    std::vector<double> all;
    for (const auto& s : slides)
    {
        if (s.empty())
            continue;
        st.points++;
        all.insert(all.end(), s.begin(), s.end());
    }
    st.observations = (int)all.size();
    if (all.empty())
        return st;
    std::sort(all.begin(), all.end());
    st.median = all[all.size() / 2];
    st.p95 = all[(size_t)(0.95 * (all.size() - 1))];
    st.max = all.back();
    return st;
}

ShadowScore scoreShadows(InputArray referenceArr, InputArray compositeArr, InputArray truthArr,
                         InputArray maskArr, int greyTolerance)
{
    const Mat ref = referenceArr.getMat(), comp = compositeArr.getMat(), truth = truthArr.getMat();
    const Mat mask = maskArr.getMat();
    CV_CheckTypeEQ(ref.type(), CV_8UC3, "scoreShadows: reference");
    CV_CheckTypeEQ(comp.type(), CV_8UC3, "scoreShadows: composite");
    CV_CheckTypeEQ(truth.type(), CV_8UC3, "scoreShadows: truth");
    CV_CheckTypeEQ(mask.type(), CV_8UC1, "scoreShadows: mask");
    CV_CheckEQ(comp.size(), ref.size(), "scoreShadows: composite size");
    CV_CheckEQ(truth.size(), ref.size(), "scoreShadows: truth size");
    CV_CheckEQ(mask.size(), ref.size(), "scoreShadows: mask size");
    Mat gr, gc, gt;
    cv::cvtColor(ref, gr, COLOR_BGR2GRAY);
    cv::cvtColor(comp, gc, COLOR_BGR2GRAY);
    cv::cvtColor(truth, gt, COLOR_BGR2GRAY);
    gr.convertTo(gr, CV_32F);
    gc.convertTo(gc, CV_32F);
    gt.convertTo(gt, CV_32F);
    const Mat in = mask > 0;
    const Mat band = ((cv::abs(gc - gr) > greyTolerance) | (cv::abs(gt - gr) > greyTolerance)) & in;
    ShadowScore sc;
    sc.bandPixels = cv::countNonZero(band);
    if (sc.bandPixels > 0)
        sc.fractionWithin = (double)cv::countNonZero((cv::abs(gc - gt) <= greyTolerance) & band) /
                            sc.bandPixels;
    // Shadow regions and their boundaries, away from the pixels left out.
    const Mat limit = gr * (1 - kShadowDepth);
    const Mat sc0 = (gc < limit) & in, st0 = (gt < limit) & in;
    Mat out, nearOut;
    cv::bitwise_not(in, out);
    cv::dilate(out, nearOut, getStructuringElement(MORPH_RECT, Size(5, 5)));
    auto boundary = [&](const Mat& s) {
        Mat e;
        cv::erode(s, e, getStructuringElement(MORPH_RECT, Size(3, 3)), Point(-1, -1), 1,
                  BORDER_REPLICATE);
        return (s & ~e) & ~nearOut;
    };
    const Mat bc = boundary(sc0), bt = boundary(st0);
    const int nc = cv::countNonZero(bc), nt = cv::countNonZero(bt);
    sc.boundaryPixels = nc + nt;
    if (nc + nt == 0)
        return sc;
    // Distances to the other image's boundary; where it has none (its shadow there is fainter
    // than kShadowDepth), to its pixels that differ from the reference by more than the
    // tolerance; where it has neither, as far as it gets in the image.
    const Mat faintC = (cv::abs(gc - gr) > greyTolerance) & in;
    const Mat faintT = (cv::abs(gt - gr) > greyTolerance) & in;
    auto meanTo = [&](const Mat& from, const Mat& edge, const Mat& faint) {
        const Mat to = cv::countNonZero(edge) > 0 ? edge : faint;
        if (cv::countNonZero(to) == 0)
            return (double)std::max(ref.cols, ref.rows);
        Mat d;
        cv::distanceTransform(~to, d, DIST_L2, DIST_MASK_PRECISE);
        return cv::mean(d, from)[0];
    };
    double sum = 0;
    if (nc > 0)
        sum += nc * meanTo(bc, bt, faintT);
    if (nt > 0)
        sum += nt * meanTo(bt, bc, faintC);
    sc.boundaryDistance = sum / (nc + nt);
    return sc;
}

} // namespace augocc
} // namespace cv
