// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Reporting Progress (opencv2/augocc/progress.hpp) from inside the library.

#ifndef OPENCV_AUGOCC_PROGRESS_DETAIL_HPP
#define OPENCV_AUGOCC_PROGRESS_DETAIL_HPP

#include "opencv2/augocc/progress.hpp"

namespace cv {
namespace augocc {
namespace detail {

//! Calls `cb` (if set) with one report.
inline void reportProgress(const ProgressCallback& cb, const String& stage, const String& step,
                           int64 done, int64 total, const String& unit,
                           const String& message = String())
{
    if (!cb)
        return;
    Progress p;
    p.stage = stage;
    p.step = step;
    p.done = done;
    p.total = total;
    p.unit = unit;
    p.message = message;
    cb(p);
}

/** @brief The callback of the stage running on this thread, for code deep inside it (the Ceres
solves of recoverCameras()) that has no options of its own to carry one. A scope sets it for its
lifetime (nested scopes restore the outer one); current() is null outside any scope. */
class ProgressScope
{
public:
    ProgressScope(const ProgressCallback& cb, const String& stage);
    ~ProgressScope();
    //! The innermost scope of this thread with a callback set, or null.
    static const ProgressScope* current();
    void report(const String& step, int64 done, int64 total, const String& unit,
                const String& message = String()) const
    {
        reportProgress(cb_, stage_, step, done, total, unit, message);
    }

private:
    ProgressScope(const ProgressScope&) = delete;
    ProgressScope& operator=(const ProgressScope&) = delete;
    ProgressCallback cb_;
    String stage_;
    const ProgressScope* outer_;
};

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
