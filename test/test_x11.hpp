// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Driving augocc's highgui windows in tests: a private Xvfb display, the tool as a child process
// (its log read for the "window image rect" line), xdotool for the mouse and the keys, ffmpeg
// x11grab for screenshots. Used by the end-to-end tests of `annotate` and `place`.

#ifndef OPENCV_AUGOCC_TEST_X11_HPP
#define OPENCV_AUGOCC_TEST_X11_HPP

#include "test_common.hpp"

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace opencv_test {
namespace x11 {

using cv::Point;
using cv::Rect;
using cv::format;
namespace fs = std::filesystem;

inline bool haveTool(const std::string& name)
{
    return runCommand("command -v " + name + " >/dev/null") == 0;
}

// A child process killed (TERM, then KILL) when the guard goes out of scope.
struct Child
{
    pid_t pid = -1;
    ~Child() { stop(); }
    void stop()
    {
        if (pid <= 0)
            return;
        ::kill(pid, SIGTERM);
        for (int i = 0; i < 50; ++i)
        {
            if (::waitpid(pid, nullptr, WNOHANG) == pid)
            {
                pid = -1;
                return;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        ::kill(pid, SIGKILL);
        ::waitpid(pid, nullptr, 0);
        pid = -1;
    }
    // Exit status, or -1 on timeout or abnormal end.
    int wait(double timeoutS)
    {
        const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutS);
        while (std::chrono::steady_clock::now() < end)
        {
            int status = 0;
            if (::waitpid(pid, &status, WNOHANG) == pid)
            {
                pid = -1;
                return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        return -1;
    }
};

// Starts argv with extra environment, stdout+stderr into logPath.
inline pid_t spawn(const std::vector<std::string>& argv, const std::vector<std::string>& env,
            const std::string& logPath)
{
    const pid_t pid = ::fork();
    if (pid != 0)
        return pid;
    const int fd = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0)
    {
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        ::close(fd);
    }
    for (const std::string& e : env)
        ::putenv(::strdup(e.c_str()));
    std::vector<char*> args;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(127);
}

// A display number nobody uses: from the pid, skipping numbers with a lock or socket.
inline int freeDisplay()
{
    for (int i = 0; i < 400; ++i)
    {
        const int n = 100 + (int(::getpid()) + i) % 400;
        if (!fs::exists(format("/tmp/.X%d-lock", n)) &&
            !fs::exists(format("/tmp/.X11-unix/X%d", n)))
            return n;
    }
    return -1;
}

inline std::string readFile(const std::string& path)
{
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

inline void sleepMs(int ms)
{
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));
}

class Xdo
{
public:
    explicit Xdo(const std::string& display) : display_(display) {}
    void run(const std::string& args)
    {
        std::string out;
        const int rc = runCommand("DISPLAY=" + display_ + " timeout 10 xdotool " + args, &out);
        EXPECT_EQ(0, rc) << "xdotool " << args << ": " << out;
    }
    // --sync waits for the pointer to move, so it is not used for the position it is at.
    void moveTo(Point screen)
    {
        if (screen == pointer_)
            return;
        run(format("mousemove --sync %d %d", screen.x, screen.y));
        pointer_ = screen;
        sleepMs(60);
    }
    void click(Point screen)
    {
        moveTo(screen);
        run("click 1");
        sleepMs(250);  // one live-wire segment plus a redraw
    }
    void key(const std::string& k)
    {
        run("key " + k);
        sleepMs(250);
    }

private:
    std::string display_;
    Point pointer_ = Point(-1, -1);
};

inline void grab(const std::string& display, const Rect& r, const std::string& path)
{
    std::string out;
    const int rc = runCommand(format("timeout 20 ffmpeg -loglevel error -y -f x11grab "
                                     "-video_size %dx%d -i %s+%d,%d -frames:v 1 '%s'",
                                     r.width, r.height, display.c_str(), r.x, r.y, path.c_str()),
                              &out);
    EXPECT_EQ(0, rc) << "ffmpeg x11grab: " << out;
}

/** Waits for the "<tag> window image rect x y w h" line in a child's log.
@return false (with the log in `why`) when the child ends or the timeout passes first. */
inline bool waitForWindowRect(Child& tool, const std::string& log, double timeoutS, Rect& rect,
                              std::string& why)
{
    const auto t0 = std::chrono::steady_clock::now();
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() <
           timeoutS)
    {
        const std::string text = readFile(log);
        const size_t at = text.find("window image rect ");
        if (at != std::string::npos && text.find('\n', at) != std::string::npos)
        {
            std::istringstream is(text.substr(at + 18));
            is >> rect.x >> rect.y >> rect.width >> rect.height;
            return true;
        }
        int status;
        if (::waitpid(tool.pid, &status, WNOHANG) == tool.pid)
        {
            tool.pid = -1;
            why = "the tool ended early:\n" + text;
            return false;
        }
        sleepMs(100);
    }
    why = format("no window within %.0f s:\n", timeoutS) + readFile(log);
    return false;
}

/** Why an end-to-end window test cannot run here, empty when it can: Xvfb or xdotool missing,
the augocc binary `bin` not built, or screenshots asked for (`shots`, the value of the variable
`shotsVar`) without ffmpeg to grab them. */
inline std::string windowTestSkipReason(const std::string& bin, const std::string& shots,
                                        const std::string& shotsVar)
{
    if (!haveTool("Xvfb") || !haveTool("xdotool"))
        return "Xvfb or xdotool not installed (scripts/setup.sh installs xvfb xdotool)";
    if (!fs::exists(bin))
        return "augocc binary not built: " + bin;
    if (!shots.empty() && !haveTool("ffmpeg"))
        return shotsVar + " set but ffmpeg missing";
    return std::string();
}

/** Starts Xvfb on a free display number; waits for its socket.
@param screen the screen, WIDTHxHEIGHTxDEPTH.
@return the display (":N"), empty on failure (with the reason in `why`). */
inline std::string startXvfb(Child& xvfb, const std::string& dir, std::string& why,
                             const std::string& screen = "1024x768x24")
{
    const int dispNum = freeDisplay();
    if (dispNum < 0)
    {
        why = "no free X display number";
        return std::string();
    }
    const std::string display = format(":%d", dispNum);
    xvfb.pid = spawn({"Xvfb", display, "-screen", "0", screen, "-nolisten", "tcp"}, {},
                     dir + "/xvfb.log");
    const std::string socket = format("/tmp/.X11-unix/X%d", dispNum);
    for (int i = 0; i < 200 && !fs::exists(socket); ++i)
        sleepMs(50);
    if (!fs::exists(socket))
    {
        why = "Xvfb did not start: " + readFile(dir + "/xvfb.log");
        return std::string();
    }
    return display;
}

} // namespace x11
} // namespace opencv_test

#endif
