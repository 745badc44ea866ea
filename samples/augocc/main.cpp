// augocc: put virtual 3D objects into a video of a static scene so that real objects hide them.
// Usage: augocc <sub-command> --help

#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "cli_common.hpp"

using namespace augocc_cli;

int main(int argc, char** argv)
{
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_WARNING);
    CLI::App app{"augocc: virtual objects in real video, hidden by the real objects in front "
                 "of them (Ong, Teh & Tan 1998)"};
    app.require_subcommand(1);
    Globals g;
    app.add_flag("--quiet,-q", g.quiet, "print nothing but errors");
    // Runs before the sub-command (CLI11 runs option callbacks while parsing); every stage's
    // results are the same at any thread count.
    app.add_option_function<int>(
           "--threads", [](int n) { cv::setNumThreads(n); },
           "worker threads (default: all cores); outputs do not depend on it")
        ->check(CLI::Range(1, 1024));
    // Sub-commands, in pipeline order (one cmd_<name>.cpp each).
    registerSynth(app, g);
    registerTrack(app, g);
    registerSfm(app, g);
    registerClone(app, g);
    registerMatte(app, g);
    registerComposite(app, g);
    registerExportBlender(app, g);
    registerRun(app, g);
    registerDemo(app, g);
    registerAnnotate(app, g);
    registerSun(app, g);
    registerPlace(app, g);
    registerPropagate(app, g);
    registerJoin(app, g);
    registerFarm(app, g);

    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        const int rc = app.exit(e);
        return rc == 0 ? 0 : 2;
    }
    catch (const UsageError& e)
    {
        std::cerr << "augocc: " << e.what() << std::endl;
        return 2;
    }
    catch (const cv::Exception& e)
    {
        // Library errors on bad input carry the file and the problem in err.
        const bool internal = e.code == cv::Error::StsInternal || e.code == cv::Error::StsNoMem ||
                              e.code == cv::Error::StsAssert;
        std::cerr << "augocc: " << (e.err.empty() ? e.msg : e.err) << std::endl;
        return internal ? 1 : 2;
    }
    catch (const std::filesystem::filesystem_error& e)
    {
        // A folder that cannot be made or listed (read-only, permissions, full): the user's
        // paths, not augocc's own failure. The library reports these itself; this is the net.
        std::cerr << "augocc: " << (e.path1().empty() ? std::string() : e.path1().string() + ": ")
                  << e.code().message() << std::endl;
        return 2;
    }
    catch (const std::exception& e)
    {
        std::cerr << "augocc: internal error: " << e.what() << std::endl;
        return 1;
    }
    return 0;
}
