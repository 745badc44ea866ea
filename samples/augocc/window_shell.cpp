// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "window_shell.hpp"

#include <algorithm>
#include <cstdlib>
#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>

namespace augocc_cli {

void requireDisplay(const std::string& command)
{
    if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY"))
        throw UsageError(command + " opens a window and needs a display: set DISPLAY (or run "
                         "it under xvfb-run)");
}

void logWindowImageRect(const Globals& g, const std::string& command, const std::string& window)
{
    const cv::Rect r = cv::getWindowImageRect(window);
    info(g, cv::format("%s: window image rect %d %d %d %d", command.c_str(), r.x, r.y, r.width,
                       r.height));
}

void drawHelpOverlay(cv::Mat& view, const char* const (*rows)[2], int n, int valueColumn)
{
    const int lineH = 17;
    // As wide as the widest row (a fixed 560 px cut annotate's longest line).
    int width = 0;
    for (int i = 0; i < n; ++i)
    {
        int base = 0;
        const cv::Size key = cv::getTextSize(rows[i][0], cv::FONT_HERSHEY_SIMPLEX, 0.42, 1, &base);
        const cv::Size val = cv::getTextSize(rows[i][1], cv::FONT_HERSHEY_SIMPLEX, 0.42, 1, &base);
        width = std::max(width, std::max(key.width, valueColumn + val.width));
    }
    const cv::Rect box = cv::Rect(8, 8, std::min(view.cols - 16, width + 16), n * lineH + 14) &
                         cv::Rect(cv::Point(), view.size());
    cv::Mat roi = view(box);
    const cv::Mat dark(roi.size(), roi.type(), cv::Scalar(20, 20, 20));
    cv::addWeighted(roi, 0.25, dark, 0.75, 0, roi);
    for (int i = 0; i < n; ++i)
    {
        const cv::Point at(box.x + 8, box.y + 18 + i * lineH);
        cv::putText(view, rows[i][0], at, cv::FONT_HERSHEY_SIMPLEX, 0.42,
                    cv::Scalar(150, 220, 255), 1, cv::LINE_AA);
        cv::putText(view, rows[i][1], at + cv::Point(valueColumn, 0), cv::FONT_HERSHEY_SIMPLEX,
                    0.42, cv::Scalar(240, 240, 240), 1, cv::LINE_AA);
    }
}

} // namespace augocc_cli
