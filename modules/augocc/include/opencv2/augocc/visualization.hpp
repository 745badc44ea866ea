// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_VISUALIZATION_HPP
#define OPENCV_AUGOCC_VISUALIZATION_HPP

#include <vector>
#include <opencv2/core.hpp>

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Lays images out on a grid with a caption under each: a contact sheet for reports.

Every image is scaled to `thumbWidth` pixels wide (aspect kept; INTER_AREA); grey or BGRA images
are converted to BGR. Cells of a row share the height of its tallest thumbnail; the background is
dark grey, captions white.
@param images the images (CV_8UC1, CV_8UC3 or CV_8UC4), at least one, none empty.
@param captions one per image, or empty for none.
@param columns images per row (>= 1).
@param thumbWidth width of each thumbnail in pixels (>= 16).
@return the sheet, BGR CV_8UC3.
*/
CV_EXPORTS Mat makeContactSheet(const std::vector<Mat>& images, const std::vector<String>& captions,
                                int columns, int thumbWidth);

/** @brief Draws the outline of a binary mask over an image.
@param image BGR CV_8UC3 image, modified in place.
@param mask CV_8U mask of the same size, > 127 = inside.
@param colour outline colour (BGR).
@param thickness line thickness in pixels (>= 1).
*/
CV_EXPORTS void drawMaskOutlines(InputOutputArray image, const Mat& mask, Scalar colour,
                                 int thickness = 2);

//! @}

} // namespace augocc
} // namespace cv

#endif
