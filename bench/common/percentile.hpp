// SPDX-License-Identifier: Apache-2.0
// Benchmarks' percentile of a sample: the value at the rounded rank p·(n − 1) of the sorted
// values (p in 0..1; 0 for no values), so p = 0.5 of an odd count is the median.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace hrcsense::bench {

inline double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto index = static_cast<size_t>(std::llround(p * static_cast<double>(values.size() - 1)));
  return values[index];
}

}  // namespace hrcsense::bench
