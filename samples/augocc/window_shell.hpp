// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.
//
// What the interactive windows (annotate, place) share: the display check, the window
// rectangle line that tests and scripts read, and the keyboard help overlay.
#ifndef AUGOCC_CLI_WINDOW_SHELL_HPP
#define AUGOCC_CLI_WINDOW_SHELL_HPP

#include <string>
#include <opencv2/core.hpp>
#include "cli_common.hpp"

namespace augocc_cli {

/** @brief Throws UsageError when no display is set: Qt aborts the process when it cannot reach
one, so the command says so first.
@param command the sub-command, named in the message ("annotate"). */
void requireDisplay(const std::string& command);

/** @brief Logs "<command>: window image rect x y w h": where the frame lies on the screen
(getWindowImageRect), for tests and scripts that drive the window with xdotool. */
void logWindowImageRect(const Globals& g, const std::string& command, const std::string& window);

/** @brief Draws the keyboard help over `view`: a darkened box at its top-left, one row per
entry, the key in one colour and its meaning `valueColumn` pixels to the right.
@param rows `n` pairs (key, meaning). */
void drawHelpOverlay(cv::Mat& view, const char* const (*rows)[2], int n, int valueColumn);

} // namespace augocc_cli

#endif
