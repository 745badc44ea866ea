// augocc command line: shared helpers.

#include "cli_common.hpp"

#include <cctype>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <unistd.h>

namespace augocc_cli {

ProgressPrinter::ProgressPrinter(const Globals& g)
    : enabled_(!g.quiet), tty_(isatty(fileno(stderr)) != 0), start_(Clock::now()),
      printed_(start_)
{
}

ProgressPrinter::~ProgressPrinter()
{
    finish();
}

cv::augocc::ProgressCallback ProgressPrinter::callback()
{
    return [this](const cv::augocc::Progress& p) { report(p); };
}

void ProgressPrinter::report(const std::string& stage, long long done, long long total,
                             const std::string& unit)
{
    cv::augocc::Progress p;
    p.stage = stage;
    p.done = done;
    p.total = total;
    p.unit = unit;
    report(p);
}

void ProgressPrinter::report(const cv::augocc::Progress& p)
{
    if (!enabled_)
        return;
    const Clock::time_point now = Clock::now();
    const std::string key = p.stage + "/" + p.step;
    const bool newStage = p.stage != last_.stage;
    if (key != key_)
    {
        // The previous stage's last state, then the new step from its start (a new step of
        // the same stage does not print: sfm has a step per bundle adjustment).
        if (pending_ && newStage)
            print(last_);
        if (tty_ && newStage && width_ > 0)
        {
            std::fputc('\n', stderr);
            width_ = 0;
        }
        key_ = key;
        start_ = now;
    }
    last_ = p;
    pending_ = true;
    const double since = std::chrono::duration<double>(now - printed_).count();
    const bool finished = p.total > 0 && p.done >= p.total;
    if (tty_ ? (since >= 0.1 || finished || newStage)
             : (newStage || since >= kLogIntervalSeconds))
        print(p);
}

void ProgressPrinter::print(const cv::augocc::Progress& p)
{
    const Clock::time_point now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    std::string line = p.stage;
    if (!p.step.empty())
        line += ": " + p.step;
    line = cv::format("%-32s", line.c_str());
    if (p.total > 0)
    {
        line += cv::format(" %lld/%lld %s (%3.0f%%)", (long long)p.done, (long long)p.total,
                           p.unit.c_str(), 100.0 * (double)p.done / (double)p.total);
        if (p.done > 0 && p.done < p.total)
            line += cv::format("  %.1f s, about %.1f s left", elapsed,
                               elapsed * (double)(p.total - p.done) / (double)p.done);
        else
            line += cv::format("  %.1f s", elapsed);
    }
    else
        line += cv::format(" %lld %s  %.1f s", (long long)p.done, p.unit.c_str(), elapsed);
    if (!p.message.empty())
        line += "  " + p.message;
    if (tty_)
    {
        const size_t w = line.size();
        if (w < width_)
            line += std::string(width_ - w, ' ');
        width_ = w;
        std::fprintf(stderr, "\r%s", line.c_str());
    }
    else
        std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
    printed_ = now;
    pending_ = false;
}

void ProgressPrinter::finish()
{
    if (!enabled_)
        return;
    if (pending_)
        print(last_);
    if (tty_ && width_ > 0)
        std::fputc('\n', stderr);
    width_ = 0;
    key_.clear();
    last_ = cv::augocc::Progress();
}

void info(const Globals& g, const std::string& line)
{
    if (!g.quiet)
        std::cout << line << std::endl;
}

void requireFile(const std::string& flag, const std::string& path)
{
    if (!std::filesystem::exists(path))
        throw UsageError(flag + " " + path + ": no such file or folder");
}

void checkIntrinsicsFlags(const std::string& calibration, double focal, bool refine)
{
    if (!calibration.empty())
        requireFile("--calibration", calibration);
    if (!calibration.empty() && focal != 0)
        throw UsageError("--focal: give --calibration or --focal, not both");
    if (focal != 0 && !(focal > 0 && std::isfinite(focal)))
        throw UsageError(cv::format("--focal %g: must be a positive number of pixels", focal));
    if (refine && calibration.empty() && focal == 0)
        throw UsageError("--refine-intrinsics: needs --calibration or --focal");
}

void setIntrinsicsOptions(const std::string& calibration, double focal, bool refine,
                          cv::Size frameSize, cv::augocc::SfmOptions& options)
{
    checkIntrinsicsFlags(calibration, focal, refine);
    if (!calibration.empty())
        options.calibration = cv::augocc::readCalibration(calibration, frameSize);
    options.focal = focal;
    options.refineIntrinsics = refine;
}

std::string lensLine(const cv::augocc::SfmReport& r)
{
    std::string k;
    for (size_t i = 0; i < r.distortion.size(); i++)
        k += cv::format("%s%.5g", i ? ", " : "", r.distortion[i]);
    return "  lens: " + r.lensModel + (r.focal > 0 ? cv::format(", focal %.2f px", r.focal)
                                                     : std::string()) +
           (k.empty() ? std::string() : ", distortion [" + k + "]") + ": " + r.lensReason;
}

namespace {

// `part` of a frame list item as a non-negative integer (below INT_MAX, so that a + 1 exists).
int parseFrameNumber(const std::string& where, const std::string& part)
{
    long v = -1;
    size_t used = 0;
    if (!part.empty() && std::isdigit((unsigned char)part[0]))
    {
        try
        {
            v = std::stol(part, &used);
        }
        catch (const std::exception&)
        {
            used = 0;
        }
    }
    if (part.empty() || used != part.size() || v < 0 || v >= INT_MAX)
        throw UsageError(where + ": '" + part + "' is not a frame index (a non-negative "
                         "integer)");
    return (int)v;
}

} // namespace

std::vector<FrameRange> parseFrameRanges(const std::string& flag, const std::string& text)
{
    std::vector<FrameRange> ranges;
    size_t start = 0;
    while (start <= text.size())
    {
        size_t comma = text.find(',', start);
        if (comma == std::string::npos)
            comma = text.size();
        const std::string item = text.substr(start, comma - start);
        start = comma + 1;
        const std::string where = flag + " " + text + ": '" + item + "'";
        std::vector<std::string> parts;
        for (size_t from = 0;;)
        {
            const size_t colon = item.find(':', from);
            parts.push_back(item.substr(from, colon == std::string::npos ? std::string::npos
                                                                         : colon - from));
            if (colon == std::string::npos)
                break;
            from = colon + 1;
        }
        if (item.empty() || parts.size() > 3)
            throw UsageError(where + " is not a frame a, a range a:b (frames a..b-1), a: or "
                             "a:b:step");
        FrameRange r;
        r.first = parseFrameNumber(where, parts[0]);
        if (parts.size() == 1)
            r.end = r.first + 1;
        else if (!parts[1].empty())
        {
            r.end = parseFrameNumber(where, parts[1]);
            if (r.end <= r.first)
                throw UsageError(where + " is empty: a:b is frames a..b-1, b must be greater "
                                 "than a");
        }
        if (parts.size() == 3)
        {
            r.step = parseFrameNumber(where, parts[2]);
            if (r.step < 1)
                throw UsageError(where + ": the step must be at least 1");
        }
        ranges.push_back(r);
    }
    return ranges;
}

cv::Size parseSize(const std::string& flag, const std::string& text)
{
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 ||
        (x != 'x' && x != 'X') || w <= 0 || h <= 0)
        throw UsageError(flag + " " + text + ": expected WIDTHxHEIGHT, e.g. 640x480");
    return cv::Size(w, h);
}

FrameRange parseFrameSpan(const std::string& flag, const std::string& text,
                          const std::string& command)
{
    const std::vector<FrameRange> r = parseFrameRanges(flag, text);
    if (r.size() != 1 || r[0].step != 1)
        throw UsageError(flag + " " + text + ": " + command + " takes one range of consecutive "
                         "frames (a, a:b or a:)");
    return r[0];
}

std::set<int> listFrames(const std::string& flag, const std::string& text,
                         const std::vector<FrameRange>& ranges, int frameCount)
{
    std::set<int> frames;
    for (const FrameRange& r : ranges)
    {
        const int last = r.end < 0 ? std::max(frameCount - 1, r.first) : r.end - 1;
        if (last >= frameCount)
            throw UsageError(flag + " " + text + ": frame " + std::to_string(last) + " is "
                             "beyond the last frame " + std::to_string(frameCount - 1));
        for (long long f = r.first; f <= last; f += r.step)
            frames.insert((int)f);
    }
    return frames;
}

} // namespace augocc_cli
