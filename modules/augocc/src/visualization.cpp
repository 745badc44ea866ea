// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "opencv2/augocc/visualization.hpp"

namespace cv {
namespace augocc {

namespace {

const int kCaptionHeight = 22;          // pixels under each thumbnail for its caption
const int kGap = 4;                     // pixels between cells
const Scalar kBackground(40, 40, 40);
const Scalar kCaptionColour(255, 255, 255);

Mat toBgr(const Mat& img)
{
    Mat out;
    if (img.channels() == 1)
        cv::cvtColor(img, out, COLOR_GRAY2BGR);
    else if (img.channels() == 4)
        cv::cvtColor(img, out, COLOR_BGRA2BGR);
    else
        out = img;
    if (out.depth() != CV_8U)
        CV_Error(Error::StsUnsupportedFormat, "makeContactSheet: images must be 8-bit");
    return out;
}

} // namespace

Mat makeContactSheet(const std::vector<Mat>& images, const std::vector<String>& captions,
                     int columns, int thumbWidth)
{
    if (images.empty())
        CV_Error(Error::StsBadArg, "makeContactSheet: no image");
    if (!captions.empty() && captions.size() != images.size())
        CV_Error(Error::StsBadArg, cv::format("makeContactSheet: %d captions for %d images",
                 (int)captions.size(), (int)images.size()));
    CV_CheckGE(columns, 1, "makeContactSheet: columns");
    CV_CheckGE(thumbWidth, 16, "makeContactSheet: thumbWidth");
    std::vector<Mat> thumbs(images.size());
    for (size_t i = 0; i < images.size(); i++)
    {
        if (images[i].empty())
            CV_Error(Error::StsBadArg, cv::format("makeContactSheet: image %d is empty", (int)i));
        const Mat bgr = toBgr(images[i]);
        const int h = std::max(1, cvRound((double)bgr.rows * thumbWidth / bgr.cols));
        cv::resize(bgr, thumbs[i], Size(thumbWidth, h), 0, 0, INTER_AREA);
    }
    const int n = (int)images.size();
    const int cols = std::min(columns, n);
    const int rows = (n + cols - 1) / cols;
    const int caption = captions.empty() ? 0 : kCaptionHeight;
    std::vector<int> rowHeight(rows, 0);
    for (int i = 0; i < n; i++)
        rowHeight[i / cols] = std::max(rowHeight[i / cols], thumbs[i].rows + caption);
    int height = kGap;
    for (int h : rowHeight)
        height += h + kGap;
    const int width = kGap + cols * (thumbWidth + kGap);
    Mat sheet(height, width, CV_8UC3, kBackground);
    int y = kGap;
    for (int r = 0; r < rows; r++)
    {
        for (int c = 0; c < cols && r * cols + c < n; c++)
        {
            const int i = r * cols + c;
            const int x = kGap + c * (thumbWidth + kGap);
            thumbs[i].copyTo(sheet(Rect(x, y, thumbWidth, thumbs[i].rows)));
            if (caption)
            {
                const double fontScale = 0.45;
                int baseline = 0;
                String text = captions[i];
                // Shorten the caption until it fits the cell.
                while (text.size() > 1 &&
                       cv::getTextSize(text, FONT_HERSHEY_SIMPLEX, fontScale, 1, &baseline).width >
                           thumbWidth - 4)
                    text.pop_back();
                cv::putText(sheet, text, Point(x + 2, y + thumbs[i].rows + kCaptionHeight - 7),
                            FONT_HERSHEY_SIMPLEX, fontScale, kCaptionColour, 1, LINE_AA);
            }
        }
        y += rowHeight[r] + kGap;
    }
    return sheet;
}

void drawMaskOutlines(InputOutputArray image, const Mat& mask, Scalar colour, int thickness)
{
    Mat img = image.getMat();
    CV_CheckTypeEQ(img.type(), CV_8UC3, "drawMaskOutlines: image must be BGR CV_8UC3");
    CV_CheckTypeEQ(mask.type(), CV_8UC1, "drawMaskOutlines: mask must be CV_8UC1");
    if (mask.size() != img.size())
        CV_Error(Error::StsBadSize, cv::format("drawMaskOutlines: mask %dx%d, image %dx%d",
                 mask.cols, mask.rows, img.cols, img.rows));
    CV_CheckGE(thickness, 1, "drawMaskOutlines: thickness");
    Mat bin;
    cv::compare(mask, 127, bin, CMP_GT);
    std::vector<std::vector<Point>> contours;
    cv::findContours(bin, contours, RETR_LIST, CHAIN_APPROX_SIMPLE);
    cv::drawContours(img, contours, -1, colour, thickness, LINE_AA);
}

} // namespace augocc
} // namespace cv
