// augocc command line: shared helpers (argument checks, progress, error reporting).
// The CLI is a thin shell: each sub-command parses flags and calls the library.

#ifndef AUGOCC_CLI_COMMON_HPP
#define AUGOCC_CLI_COMMON_HPP

#include <chrono>
#include <set>
#include <string>
#include <vector>
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera_refiner.hpp"
#include "opencv2/augocc/progress.hpp"

namespace augocc_cli {

//! Options every sub-command shares.
struct Globals
{
    bool quiet = false;
};

//! Bad input or usage: exit status 2, message on stderr.
struct UsageError : std::runtime_error
{
    using std::runtime_error::runtime_error;
};

/** @brief Renders the library's Progress reports on stderr, with the time elapsed in the current
step and an estimate of the time left. On a terminal: one line redrawn in place (`\r`, at most
ten times a second). Otherwise (a log file, CI): plain lines, the first report of each stage,
then one every `kLogIntervalSeconds` at most, and each stage's last report, like ffmpeg or COLMAP
logs. --quiet: nothing. */
class ProgressPrinter
{
public:
    //! Seconds between two lines of a stage when stderr is not a terminal.
    static constexpr double kLogIntervalSeconds = 2.0;

    explicit ProgressPrinter(const Globals& g);
    ~ProgressPrinter();
    //! The callback to give the library (it refers to this printer).
    cv::augocc::ProgressCallback callback();
    //! One report.
    void report(const cv::augocc::Progress& p);
    //! One report of a stage without steps (the CLI's own loops).
    void report(const std::string& stage, long long done, long long total,
                const std::string& unit);
    //! Prints what is pending (the last report) and ends the terminal line.
    void finish();

private:
    typedef std::chrono::steady_clock Clock;
    void print(const cv::augocc::Progress& p);

    bool enabled_, tty_;
    std::string key_;           // stage + step of the last report
    Clock::time_point start_;   // of the current step
    Clock::time_point printed_; // last line printed
    cv::augocc::Progress last_;
    bool pending_ = false;      // last_ not printed yet
    size_t width_ = 0;          // of the terminal line drawn
};

//! Prints an informational line on stdout unless --quiet.
void info(const Globals& g, const std::string& line);

//! Throws UsageError naming the flag when the file does not exist.
void requireFile(const std::string& flag, const std::string& path);

//! Throws UsageError naming the flag when the known-intrinsics flags do not go together.
void checkIntrinsicsFlags(const std::string& calibration, double focal, bool refine);

/** @brief The known-intrinsics flags of `sfm` and `run` into SfmOptions: `--calibration FILE`
(read for frames of `frameSize`; a bad file throws cv::Exception naming it and the key, exit
status 2), `--focal PX` (positive), `--refine-intrinsics` (needs one of them). Throws UsageError
naming the flag on misuse. */
void setIntrinsicsOptions(const std::string& calibration, double focal, bool refine,
                          cv::Size frameSize, cv::augocc::SfmOptions& options);

//! The lens line of the sfm log: model, focal, coefficients and the reason.
std::string lensLine(const cv::augocc::SfmReport& report);

//! A size written WIDTHxHEIGHT (`--size 640x480`, `--max-window 1600x900`), both positive;
//! UsageError naming the flag otherwise.
cv::Size parseSize(const std::string& flag, const std::string& text);

//! One item of a frame list: frames first, first + step, ... before end.
struct FrameRange
{
    int first = 0;
    int end = -1;  //!< one past the last frame; -1: to the end of the input
    int step = 1;
};

/** @brief Parses frames as every sub-command writes them (README, "Command line"): a
comma-separated list of items, each a frame `a`, a half-open range `a:b` (frames a, a+1, ...,
b-1, as a Python slice), `a:` (a to the last frame), or a range with a step, `a:b:s` or `a::s`
(every s-th frame from a).
@param flag the flag, named in the messages (`--frames`).
@param text the flag's value.
@return the items in the order given.

Throws UsageError naming the flag and the item on anything else: an empty item, a part that is
not a non-negative integer, b <= a, s < 1.
*/
std::vector<FrameRange> parseFrameRanges(const std::string& flag, const std::string& text);

/** @brief One range of consecutive frames, as `composite --frames` and `run --frames` take it:
`a` (one frame), `a:b` (frames a..b-1, half-open) or `a:` (a to the last frame); parsed by
parseFrameRanges(). Throws UsageError naming the flag and `command` for a list or a step.
@param flag the flag (`--frames`). @param text its value. @param command the sub-command, named
in the message.
*/
FrameRange parseFrameSpan(const std::string& flag, const std::string& text,
                          const std::string& command);

/** @brief The frames of `ranges` in an input of `frameCount` frames, sorted, each once.
Throws UsageError naming `flag` when a frame of them is at or past `frameCount`.
@param flag the flag, named in the messages.
@param text the flag's value, quoted in the messages.
@param ranges from parseFrameRanges(flag, text).
@param frameCount frames in the input.
*/
std::set<int> listFrames(const std::string& flag, const std::string& text,
                         const std::vector<FrameRange>& ranges, int frameCount);

// Sub-command registration: one function per sub-command, each in its own cmd_<name>.cpp.
void registerSynth(CLI::App& app, Globals& g);
void registerTrack(CLI::App& app, Globals& g);
void registerSfm(CLI::App& app, Globals& g);
void registerClone(CLI::App& app, Globals& g);
void registerMatte(CLI::App& app, Globals& g);
void registerComposite(CLI::App& app, Globals& g);
void registerExportBlender(CLI::App& app, Globals& g);
void registerRun(CLI::App& app, Globals& g);
void registerDemo(CLI::App& app, Globals& g);
void registerAnnotate(CLI::App& app, Globals& g);
void registerPlace(CLI::App& app, Globals& g);
void registerPropagate(CLI::App& app, Globals& g);
void registerJoin(CLI::App& app, Globals& g);
void registerFarm(CLI::App& app, Globals& g);
void registerSun(CLI::App& app, Globals& g);

} // namespace augocc_cli

#endif
