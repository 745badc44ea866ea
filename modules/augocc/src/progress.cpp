// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"

#include "progress_detail.hpp"

namespace cv {
namespace augocc {
namespace detail {

namespace {
thread_local const ProgressScope* tlsScope = nullptr;
} // namespace

ProgressScope::ProgressScope(const ProgressCallback& cb, const String& stage)
    : cb_(cb), stage_(stage), outer_(tlsScope)
{
    if (cb_)
        tlsScope = this;
}

ProgressScope::~ProgressScope()
{
    if (tlsScope == this)
        tlsScope = outer_;
}

const ProgressScope* ProgressScope::current()
{
    return tlsScope;
}

} // namespace detail
} // namespace augocc
} // namespace cv
