// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — run-time choice of the instruction set (see isa.hpp).
#include "isa.hpp"

#include "hrcsense/filters.hpp"

#include <atomic>

namespace hrcsense {
namespace {

// A test hook rather than configuration: both paths give the same bits, so only tests (and
// someone chasing a suspected CPU fault) have a reason to force the portable one.
std::atomic<bool> portable_forced{false};

bool cpu_has_avx2() {
#if HRCSENSE_FILTERS_X86
  static const bool has = __builtin_cpu_supports("avx2") != 0;
  return has;
#else
  return false;
#endif
}

}  // namespace

void set_filter_isa(FilterIsa isa) { portable_forced.store(isa == FilterIsa::portable, std::memory_order_relaxed); }

const char* filter_isa_name() {
  if (filters_detail::use_avx2()) return "avx2";
#if defined(__SSE2__)
  return "sse2";
#else
  return "scalar";
#endif
}

bool filters_detail::use_avx2() { return cpu_has_avx2() && !portable_forced.load(std::memory_order_relaxed); }

}  // namespace hrcsense
