// SPDX-License-Identifier: Apache-2.0
// hrcsense — the evaluation harness's metrics (eval/metrics.hpp): instability, MSE, distance
// error, latency percentiles and Z_d coverage over one run's samples.

#include "hrcsense/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace hrcsense::eval {
namespace {

using Point = std::array<double, 3>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool is_finite(const Point& p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

// A measurement the metrics can use; a measured frame failing this is a failed measurement.
bool finite_measurement(const EvalSample& s) {
  return s.measured && std::isfinite(s.distance_m) && is_finite(s.closest_base);
}

double distance(const Point& a, const Point& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// `<=`, not `!(>)`: a NaN distance (a non-finite truth point) is not within, so mis-recognised.
bool within(const Point& p, const Point& reference, double threshold_m) {
  return distance(p, reference) <= threshold_m;
}

// The truth rule of one frame with truth: stable when measured, finite and within threshold.
bool stable_vs_truth(const EvalSample& s, double threshold_m) {
  return finite_measurement(s) && within(s.closest_base, s.truth_closest_base, threshold_m);
}

double median_of(std::vector<double>& values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Component-wise median of the finite measured closest points; NaN when there are none (every
// measured frame then failed, and NaN makes each of them mis-recognised).
Point median_point(const std::vector<EvalSample>& samples) {
  Point median{kNaN, kNaN, kNaN};
  std::vector<double> values;
  values.reserve(samples.size());
  for (size_t axis = 0; axis < 3; ++axis) {
    values.clear();
    for (const EvalSample& s : samples) {
      if (finite_measurement(s)) values.push_back(s.closest_base[axis]);
    }
    if (!values.empty()) median[axis] = median_of(values);
  }
  return median;
}

// The nearest-rank value of sorted, non-empty `values` for q = percent / 100: index
// ceil(q·n) − 1, clamped. Integer arithmetic, as in floating point 0.07·100 rounds up to rank 8.
double nearest_rank(const std::vector<double>& sorted, int64_t percent) {
  const auto n = static_cast<int64_t>(sorted.size());
  const int64_t rank = (percent * n + 99) / 100;  // ceil(percent·n / 100)
  const int64_t index = std::clamp<int64_t>(rank - 1, 0, n - 1);
  return sorted[static_cast<size_t>(index)];
}

double window_mse(const std::vector<Point>& points, size_t begin, size_t end) {
  Point mean{0.0, 0.0, 0.0};
  for (size_t i = begin; i < end; ++i) {
    for (size_t axis = 0; axis < 3; ++axis) mean[axis] += points[i][axis];
  }
  const auto count = static_cast<double>(end - begin);
  for (double& m : mean) m /= count;
  double sum_m2 = 0.0;
  for (size_t i = begin; i < end; ++i) {
    const double d = distance(points[i], mean);
    sum_m2 += d * d;
  }
  return sum_m2 / count;
}

}  // namespace

double InstabilityCount::per_1000_frames() const {
  return frames == 0 ? 0.0 : static_cast<double>(mis_recognised) * 1000.0 / static_cast<double>(frames);
}

double InstabilityCount::per_thesis_minute() const {
  return frames == 0 ? 0.0
                     : static_cast<double>(mis_recognised) * static_cast<double>(kThesisMinuteResults) /
                           static_cast<double>(frames);
}

InstabilityCount instability_vs_truth(const std::vector<EvalSample>& samples, double threshold_m) {
  InstabilityCount count;
  for (const EvalSample& s : samples) {
    if (!s.has_truth) continue;
    ++count.frames;
    if (!stable_vs_truth(s, threshold_m)) ++count.mis_recognised;
  }
  return count;
}

InstabilityCount instability_vs_median(const std::vector<EvalSample>& samples, double threshold_m) {
  const Point median = median_point(samples);
  InstabilityCount count;
  for (const EvalSample& s : samples) {
    if (!s.measured) continue;
    ++count.frames;
    if (!finite_measurement(s) || !within(s.closest_base, median, threshold_m)) ++count.mis_recognised;
  }
  return count;
}

std::vector<Point> stable_points_vs_truth(const std::vector<EvalSample>& samples, double threshold_m) {
  std::vector<Point> points;
  for (const EvalSample& s : samples) {
    if (s.has_truth && stable_vs_truth(s, threshold_m)) points.push_back(s.closest_base);
  }
  return points;
}

std::vector<Point> stable_points_vs_median(const std::vector<EvalSample>& samples, double threshold_m) {
  const Point median = median_point(samples);
  std::vector<Point> points;
  for (const EvalSample& s : samples) {
    if (finite_measurement(s) && within(s.closest_base, median, threshold_m)) points.push_back(s.closest_base);
  }
  return points;
}

double mse_whole_run(const std::vector<Point>& points) {
  return points.empty() ? kNaN : window_mse(points, 0, points.size());
}

double mse_thesis_windows(const std::vector<Point>& points) {
  constexpr size_t kWindows = 5;
  constexpr size_t kWindowPoints = 10;
  const size_t n = points.size();
  if (n < kWindowPoints) return kNaN;
  double sum = 0.0;
  for (size_t k = 0; k < kWindows; ++k) {
    const size_t begin = k * (n - kWindowPoints) / (kWindows - 1);  // floor: integer division
    sum += window_mse(points, begin, begin + kWindowPoints);
  }
  return sum / static_cast<double>(kWindows);
}

DistanceError distance_error(const std::vector<EvalSample>& samples) {
  std::vector<double> abs_m;
  int64_t unsafe = 0;
  for (const EvalSample& s : samples) {
    if (!s.measured || !s.has_truth || !std::isfinite(s.distance_m) || !std::isfinite(s.truth_distance_m)) continue;
    abs_m.push_back(std::abs(s.distance_m - s.truth_distance_m));
    if (s.distance_m > s.truth_distance_m) ++unsafe;
  }
  DistanceError e;
  e.frames = static_cast<int64_t>(abs_m.size());
  if (abs_m.empty()) return e;
  std::sort(abs_m.begin(), abs_m.end());
  double sum_m = 0.0;
  for (const double a : abs_m) sum_m += a;
  const auto n = static_cast<double>(abs_m.size());
  e.mean_abs_m = sum_m / n;
  e.median_abs_m = nearest_rank(abs_m, 50);
  e.p95_abs_m = nearest_rank(abs_m, 95);
  e.max_abs_m = abs_m.back();
  e.unsafe_share = static_cast<double>(unsafe) / n;
  return e;
}

Percentiles latency_percentiles(const std::vector<EvalSample>& samples) {
  std::vector<double> latency_us;
  for (const EvalSample& s : samples) {
    if (std::isfinite(s.latency_us)) latency_us.push_back(s.latency_us);
  }
  Percentiles p;
  p.count = static_cast<int64_t>(latency_us.size());
  if (latency_us.empty()) return p;
  std::sort(latency_us.begin(), latency_us.end());
  p.p50 = nearest_rank(latency_us, 50);
  p.p99 = nearest_rank(latency_us, 99);
  return p;
}

double Coverage::share() const {
  return frames == 0 ? kNaN : static_cast<double>(covered) / static_cast<double>(frames);
}

Coverage uncertainty_coverage(const std::vector<EvalSample>& samples) {
  Coverage c;
  for (const EvalSample& s : samples) {
    if (!s.measured || !s.has_truth || !std::isfinite(s.distance_m) || !std::isfinite(s.truth_distance_m) ||
        !std::isfinite(s.distance_uncertainty_m)) {
      continue;
    }
    ++c.frames;
    if (s.distance_m - s.distance_uncertainty_m <= s.truth_distance_m) ++c.covered;
  }
  return c;
}

}  // namespace hrcsense::eval
