// SPDX-License-Identifier: Apache-2.0
// hrcsense — the evaluation harness's metrics (issue 18, "hrcsense eval"): the thesis's
// instability value, MSE and average distance error (its Tables 4.1-4.4), and the latency and
// Z_d coverage beside them, as plain functions over one run's per-frame results. They read
// the simulator's ground truth where it exists and the run itself (its median point) where
// it does not (the recordings). Standard library only: points are metres, base frame.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace hrcsense::eval {

/// The thesis's results in one minute: ≈12 Hz for 60 s; per_thesis_minute() scales to it.
constexpr int64_t kThesisMinuteResults = 740;
/// The thesis's mis-recognition threshold, m: a closest point farther than this from the
/// reference is mis-recognised.
constexpr double kThesisMisrecognitionM = 1.0;
/// The stricter threshold reported beside the thesis's, m: 1 m hides errors that matter to
/// a stop distance of 0.5 m.
constexpr double kStrictMisrecognitionM = 0.1;

/// One frame's result as the evaluation sees it. A sample with `measured` true and a
/// non-finite distance_m or closest_base is a failed measurement: it counts as mis-recognised
/// by the truth rule and is skipped by the error, coverage and latency statistics.
struct EvalSample {
  bool measured = false;                  ///< a closest point was found
  std::array<double, 3> closest_base{};   ///< the measured closest point, m, base frame
  double distance_m = std::numeric_limits<double>::quiet_NaN();  ///< measured closest distance, m; NaN: none
  bool has_truth = false;                 ///< the simulator knows the true closest point
  std::array<double, 3> truth_closest_base{};  ///< the true closest point, m, base frame
  double truth_distance_m = std::numeric_limits<double>::quiet_NaN();  ///< the true closest distance, m
  double distance_uncertainty_m = std::numeric_limits<double>::quiet_NaN();  ///< Z_d, m; NaN: unknown
  /// S_p of the frame, m; NaN: none. Carried for the harness's tables; no metric here reads it.
  double protective_distance_m = std::numeric_limits<double>::quiet_NaN();
  double latency_us = std::numeric_limits<double>::quiet_NaN();  ///< processing latency, µs; NaN: unknown
  int64_t foreground_points = 0;          ///< points of the foreground cloud the search ran on
};

/// The thesis's instability value: how many of the counted frames were mis-recognised.
struct InstabilityCount {
  int64_t frames = 0;          ///< frames counted (the denominator)
  int64_t mis_recognised = 0;  ///< of those, mis-recognised
  /// mis_recognised per 1000 counted frames; 0 when no frame counted.
  double per_1000_frames() const;
  /// mis_recognised scaled to the thesis's one minute, mis_recognised · kThesisMinuteResults /
  /// frames (the number its tables print); 0 when no frame counted.
  double per_thesis_minute() const;
};

/// Instability against ground truth. Counted: the frames with truth (a frame without truth
/// is in neither count). Mis-recognised: a frame whose measured closest point is strictly
/// farther than `threshold_m` (m) from its true closest point, a frame with truth and no
/// measurement (a miss), and a failed measurement (non-finite distance or point). A
/// non-finite truth point fails the comparison too, so a broken ground truth shows as
/// mis-recognition rather than hiding.
InstabilityCount instability_vs_truth(const std::vector<EvalSample>& samples, double threshold_m);

/// Instability without ground truth (the recordings). The reference is the run's
/// component-wise median closest point over the finite measured frames (for an even count,
/// the mean of the two middle values, per component). Counted: the measured frames.
/// Mis-recognised: strictly farther than `threshold_m` (m) from the median point, and every
/// failed measurement (which is left out of the median).
InstabilityCount instability_vs_median(const std::vector<EvalSample>& samples, double threshold_m);

/// The closest points, in order, of the frames that are measured, have truth and are not
/// mis-recognised by the rule of instability_vs_truth: the input of the MSE. Frames without
/// truth are left out, as they cannot be judged.
std::vector<std::array<double, 3>> stable_points_vs_truth(const std::vector<EvalSample>& samples,
                                                           double threshold_m);

/// The closest points, in order, of the measured frames that are not mis-recognised by the
/// rule of instability_vs_median (median point of the same samples).
std::vector<std::array<double, 3>> stable_points_vs_median(const std::vector<EvalSample>& samples,
                                                            double threshold_m);

/// The mean squared Euclidean distance (m²) of `points` (m) from their mean point, over the
/// whole run. NaN for no points; any non-finite coordinate makes it NaN.
double mse_whole_run(const std::vector<std::array<double, 3>>& points);

/// The thesis's MSE (m²): 5 windows of 10 consecutive points, each window's MSE about its own
/// mean, averaged over the 5. With n points, window k (k = 0..4) starts at floor(k·(n − 10) /
/// 4), so the windows are spread evenly: they tile a run of 50 exactly and overlap below 50.
/// Slow drift between windows does not count, unlike mse_whole_run. NaN for fewer than 10.
double mse_thesis_windows(const std::vector<std::array<double, 3>>& points);

/// The thesis's average distance error and its spread, over the frames that are measured and
/// have truth, with finite distance_m and truth_distance_m. abs = |distance_m −
/// truth_distance_m|. Percentiles follow the nearest-rank rule on the sorted values: the one
/// at index ceil(q·n) − 1, clamped to [0, n − 1]; the median is that rule's q = 0.5 (a value
/// of the run, never the mean of the two middle ones).
struct DistanceError {
  int64_t frames = 0;  ///< frames in the statistics; 0: every other field NaN
  double mean_abs_m = std::numeric_limits<double>::quiet_NaN();    ///< mean abs, m
  double median_abs_m = std::numeric_limits<double>::quiet_NaN();  ///< nearest-rank q = 0.5 of abs, m
  double p95_abs_m = std::numeric_limits<double>::quiet_NaN();     ///< nearest-rank q = 0.95 of abs, m
  double max_abs_m = std::numeric_limits<double>::quiet_NaN();     ///< largest abs, m
  /// Share of the frames measured strictly farther than true (distance_m > truth_distance_m):
  /// the unsafe side, as a farther person gets less protection.
  double unsafe_share = std::numeric_limits<double>::quiet_NaN();
};

/// The distance error of `samples` (DistanceError says which frames count). Failed
/// measurements are skipped here; instability_vs_truth counts them.
DistanceError distance_error(const std::vector<EvalSample>& samples);

/// Nearest-rank percentiles (the rule of DistanceError) of a set of values.
struct Percentiles {
  int64_t count = 0;  ///< values counted; 0: p50 and p99 NaN
  double p50 = std::numeric_limits<double>::quiet_NaN();  ///< nearest-rank q = 0.5
  double p99 = std::numeric_limits<double>::quiet_NaN();  ///< nearest-rank q = 0.99
};

/// p50 and p99 of the finite latency_us values (µs) of all samples, measured or not: a frame
/// that found nothing took its time too. NaN and infinite latencies are skipped.
Percentiles latency_percentiles(const std::vector<EvalSample>& samples);

/// How often a bound held: covered of frames.
struct Coverage {
  int64_t frames = 0;   ///< frames counted
  int64_t covered = 0;  ///< of those, the bound held
  /// covered / frames; NaN when no frame counted (no evidence is not 0 % or 100 %).
  double share() const;
};

/// Whether Z_d covers the measurement's error on the unsafe side: over the frames that are
/// measured, have truth and finite distance_m, truth_distance_m and distance_uncertainty_m,
/// covered when distance_m − distance_uncertainty_m ≤ truth_distance_m. Failed measurements
/// are skipped: their verdict is a stop whatever Z_d says, and instability_vs_truth counts
/// them.
Coverage uncertainty_coverage(const std::vector<EvalSample>& samples);

}  // namespace hrcsense::eval
