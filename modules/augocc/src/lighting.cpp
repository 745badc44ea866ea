// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// The sun (lighting.hpp): validation and the solar position of a date, time and place.

#include "precomp.hpp"
#include "opencv2/augocc/lighting.hpp"

namespace cv {
namespace augocc {

void Sun::validate(const String& what) const
{
    for (int k = 0; k < 3; k++)
        if (!std::isfinite(direction[k]))
            CV_Error(Error::StsBadArg, what + ": direction is not finite");
    if (!(sky >= 0 && sky < 1))
        CV_Error(Error::StsBadArg, cv::format("%s: sky must be in [0, 1), got %g", what.c_str(),
                                              sky));
    if (!(penumbra > 0) || !std::isfinite(penumbra))
        CV_Error(Error::StsBadArg, cv::format("%s: penumbra must be positive, got %g",
                                              what.c_str(), penumbra));
}

void solarPosition(int year, int month, int day, double hourUtc, double latitudeDeg,
                   double longitudeDeg, double& azimuthDeg, double& elevationDeg)
{
    if (month < 1 || month > 12)
        CV_Error(Error::StsOutOfRange, cv::format("solarPosition: month %d", month));
    static const int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    const int monthDays = kDays[month - 1] + (month == 2 && leap ? 1 : 0);
    if (day < 1 || day > monthDays)
        CV_Error(Error::StsOutOfRange, cv::format("solarPosition: day %d of month %d", day,
                                                  month));
    if (!(hourUtc >= 0 && hourUtc < 24))
        CV_Error(Error::StsOutOfRange, cv::format("solarPosition: hour %g (UTC, [0, 24))",
                                                  hourUtc));
    if (!(std::abs(latitudeDeg) <= 90))
        CV_Error(Error::StsOutOfRange, cv::format("solarPosition: latitude %g", latitudeDeg));
    if (!(std::abs(longitudeDeg) <= 180))
        CV_Error(Error::StsOutOfRange, cv::format("solarPosition: longitude %g", longitudeDeg));
    int doy = day;
    for (int m = 1; m < month; m++)
        doy += kDays[m - 1] + (m == 2 && leap ? 1 : 0);
    // NOAA Global Monitoring Division, "General Solar Position Calculations": fractional year
    // gamma (radians), equation of time (minutes) and declination (radians) by Spencer's series.
    const double g = 2 * CV_PI / (leap ? 366 : 365) * (doy - 1 + (hourUtc - 12) / 24);
    const double eqTime = 229.18 * (0.000075 + 0.001868 * std::cos(g) - 0.032077 * std::sin(g) -
                                    0.014615 * std::cos(2 * g) - 0.040849 * std::sin(2 * g));
    const double decl = 0.006918 - 0.399912 * std::cos(g) + 0.070257 * std::sin(g) -
                        0.006758 * std::cos(2 * g) + 0.000907 * std::sin(2 * g) -
                        0.002697 * std::cos(3 * g) + 0.00148 * std::sin(3 * g);
    // True solar time (minutes) at the longitude, hour angle (degrees, positive afternoon).
    const double tst = hourUtc * 60 + eqTime + 4 * longitudeDeg;
    const double ha = (tst / 4 - 180) * CV_PI / 180;
    const double lat = latitudeDeg * CV_PI / 180;
    // The sun in local east-north-up coordinates (the same zenith and azimuth as NOAA's cosine
    // formulas, without their quadrant ambiguity).
    const double e = -std::cos(decl) * std::sin(ha);
    const double n = std::sin(decl) * std::cos(lat) - std::cos(decl) * std::cos(ha) * std::sin(lat);
    const double u = std::sin(decl) * std::sin(lat) + std::cos(decl) * std::cos(ha) * std::cos(lat);
    elevationDeg = std::asin(std::max(-1.0, std::min(1.0, u))) * 180 / CV_PI;
    double az = std::atan2(e, n) * 180 / CV_PI;
    if (az < 0)
        az += 360;
    azimuthDeg = az >= 360 ? 0 : az;
}

} // namespace augocc
} // namespace cv
