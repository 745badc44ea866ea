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

} // namespace augocc
} // namespace cv
