// augocc command line: shared helpers.

#include "cli_common.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <unistd.h>

namespace augocc_cli {

Progress::Progress(const Globals& g, const std::string& stage, int total)
    : enabled_(!g.quiet && isatty(fileno(stderr))), stage_(stage), total_(total),
      start_(std::chrono::steady_clock::now())
{
    update(0);
}

void Progress::update(int done)
{
    if (!enabled_)
        return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done > 0 ? elapsed * (total_ - done) / done : 0.0;
    std::fprintf(stderr, "\r%-10s %5d/%-5d  %6.1f s elapsed  ETA %6.1f s", stage_.c_str(), done,
                 total_, elapsed, eta);
    std::fflush(stderr);
}

void Progress::finish()
{
    if (!enabled_)
        return;
    update(total_);
    std::fprintf(stderr, "\n");
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

} // namespace augocc_cli
