// augocc command line: shared helpers (argument checks, progress, error reporting).
// The CLI is a thin shell: each sub-command parses flags and calls the library.

#ifndef AUGOCC_CLI_COMMON_HPP
#define AUGOCC_CLI_COMMON_HPP

#include <chrono>
#include <string>
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

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

/** @brief One progress line on stderr (done/total, elapsed, ETA), redrawn in place, shown only
when stderr is a terminal and --quiet is not given. */
class Progress
{
public:
    Progress(const Globals& g, const std::string& stage, int total);
    void update(int done);
    void finish();

private:
    bool enabled_;
    std::string stage_;
    int total_;
    std::chrono::steady_clock::time_point start_;
};

//! Prints an informational line on stdout unless --quiet.
void info(const Globals& g, const std::string& line);

//! Throws UsageError naming the flag when the file does not exist.
void requireFile(const std::string& flag, const std::string& path);

// Sub-command registration: one function per sub-command, each in its own cmd_<name>.cpp.
void registerSynth(CLI::App& app, Globals& g);
void registerTrack(CLI::App& app, Globals& g);
void registerSfm(CLI::App& app, Globals& g);
void registerClone(CLI::App& app, Globals& g);
void registerMatte(CLI::App& app, Globals& g);
void registerComposite(CLI::App& app, Globals& g);
void registerRun(CLI::App& app, Globals& g);
void registerDemo(CLI::App& app, Globals& g);
void registerAnnotate(CLI::App& app, Globals& g);
void registerPropagate(CLI::App& app, Globals& g);

} // namespace augocc_cli

#endif
