// SPDX-License-Identifier: Apache-2.0
// The evaluation harness's metrics (eval/metrics.hpp) on short hand-made runs whose expected
// values are worked by hand beside each check: instability against truth and against the
// median, the MSE over the whole run and the thesis's windows, the distance error, latency
// percentiles and Z_d coverage, with their edge cases (empty runs, the strict threshold,
// misses, failed measurements, even counts, nearest ranks). Coordinates are small binary
// fractions, so most results are exact.

#include "hrcsense/eval/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hrcsense::eval {
namespace {

using Point = std::array<double, 3>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A simulated frame: measured at `measured`, truly at `truth`. The distances are not what the
// point rules read, so any finite value does.
EvalSample truth_frame(Point measured, Point truth) {
  EvalSample s;
  s.measured = true;
  s.closest_base = measured;
  s.distance_m = 1.0;
  s.has_truth = true;
  s.truth_closest_base = truth;
  s.truth_distance_m = 1.0;
  return s;
}

// A simulated frame in which nothing was found although the truth has a closest point.
EvalSample missed_frame(Point truth) {
  EvalSample s;
  s.has_truth = true;
  s.truth_closest_base = truth;
  s.truth_distance_m = 1.0;
  return s;
}

// A recorded frame: measured, no truth.
EvalSample recorded_frame(Point measured) {
  EvalSample s;
  s.measured = true;
  s.closest_base = measured;
  s.distance_m = 1.0;
  return s;
}

// A simulated frame as the distance statistics see it.
EvalSample distance_frame(double distance_m, double truth_distance_m, double uncertainty_m = kNaN) {
  EvalSample s;
  s.measured = true;
  s.distance_m = distance_m;
  s.has_truth = true;
  s.truth_distance_m = truth_distance_m;
  s.distance_uncertainty_m = uncertainty_m;
  return s;
}

EvalSample latency_frame(double latency_us) {
  EvalSample s;  // not measured: a frame that found nothing has a latency too
  s.latency_us = latency_us;
  return s;
}

// --- instability against truth ---

TEST(InstabilityVsTruth, CountsFarPointsMissesAndFailedMeasurements) {
  EvalSample failed = truth_frame({1.0, 0.0, 0.0}, {1.0, 0.0, 0.0});
  failed.distance_m = kNaN;  // measured = true, but the distance is NaN
  const std::vector<EvalSample> run = {
      truth_frame({1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}),   // 0 m: recognised
      truth_frame({1.5, 0.0, 0.0}, {1.0, 0.0, 0.0}),   // 0.5 m, not > 0.5: recognised
      truth_frame({1.75, 1.0, 0.0}, {1.0, 0.0, 0.0}),  // √(0.75² + 1²) = √1.5625 = 1.25 m > 0.5: mis
      missed_frame({1.0, 0.0, 0.0}),                   // a miss: mis
      recorded_frame({9.0, 9.0, 9.0}),                 // no truth: not counted at all
      failed,                                          // failed measurement: mis
  };
  const InstabilityCount c = instability_vs_truth(run, 0.5);
  EXPECT_EQ(c.frames, 5);          // 6 frames − 1 without truth
  EXPECT_EQ(c.mis_recognised, 3);  // the 1.25 m frame, the miss, the failed one
  EXPECT_DOUBLE_EQ(c.per_1000_frames(), 600.0);    // 3 · 1000 / 5
  EXPECT_DOUBLE_EQ(c.per_thesis_minute(), 444.0);  // 3 · 740 / 5 = 2220 / 5
}

TEST(InstabilityVsTruth, ThresholdIsStrictlyGreater) {
  // Exactly 1 m off ((1, 0, 0) from the origin): not farther than the thesis's 1 m.
  const std::vector<EvalSample> at = {truth_frame({1.0, 0.0, 0.0}, {0.0, 0.0, 0.0})};
  EXPECT_EQ(instability_vs_truth(at, kThesisMisrecognitionM).mis_recognised, 0);
  // 1.25 m off: farther.
  const std::vector<EvalSample> beyond = {truth_frame({1.25, 0.0, 0.0}, {0.0, 0.0, 0.0})};
  EXPECT_EQ(instability_vs_truth(beyond, kThesisMisrecognitionM).mis_recognised, 1);
}

TEST(InstabilityVsTruth, StrictRuleCountsWhatTheThesisRuleLetsThrough) {
  // 0.25 m off: within the thesis's 1 m, beyond the strict 0.1 m.
  const std::vector<EvalSample> run = {
      truth_frame({0.25, 0.0, 0.0}, {0.0, 0.0, 0.0}),
      truth_frame({0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}),
  };
  EXPECT_EQ(instability_vs_truth(run, kThesisMisrecognitionM).mis_recognised, 0);
  EXPECT_EQ(instability_vs_truth(run, kStrictMisrecognitionM).mis_recognised, 1);
}

TEST(InstabilityVsTruth, NonFinitePointsAreMisRecognised) {
  EvalSample nan_point = truth_frame({kNaN, 0.0, 0.0}, {0.0, 0.0, 0.0});  // finite distance, NaN point
  EvalSample inf_distance = truth_frame({0.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  inf_distance.distance_m = kInf;
  const EvalSample nan_truth = truth_frame({0.0, 0.0, 0.0}, {0.0, kNaN, 0.0});  // broken truth shows
  const InstabilityCount c = instability_vs_truth({nan_point, inf_distance, nan_truth}, 1.0);
  EXPECT_EQ(c.frames, 3);
  EXPECT_EQ(c.mis_recognised, 3);
}

TEST(InstabilityVsTruth, EmptyAndTruthlessRunsCountNothing) {
  const InstabilityCount empty = instability_vs_truth({}, 1.0);
  EXPECT_EQ(empty.frames, 0);
  EXPECT_EQ(empty.mis_recognised, 0);
  EXPECT_EQ(empty.per_1000_frames(), 0.0);    // 0 frames: 0, not NaN
  EXPECT_EQ(empty.per_thesis_minute(), 0.0);
  const InstabilityCount truthless = instability_vs_truth({recorded_frame({5.0, 0.0, 0.0})}, 1.0);
  EXPECT_EQ(truthless.frames, 0);
  EXPECT_EQ(truthless.mis_recognised, 0);
}

// --- instability against the median ---

TEST(InstabilityVsMedian, EvenCountTakesTheMeanOfTheMiddleValuesPerComponent) {
  const std::vector<EvalSample> run = {
      recorded_frame({0.0, 0.0, 0.0}),
      recorded_frame({1.0, 2.0, 0.0}),
      missed_frame({0.0, 0.0, 0.0}),  // not measured: not counted, not in the median
      recorded_frame({2.0, 0.0, 0.0}),
      recorded_frame({9.0, 4.0, 0.0}),
  };
  // x sorted 0, 1, 2, 9: (1 + 2) / 2 = 1.5; y sorted 0, 0, 2, 4: (0 + 2) / 2 = 1; z 0.
  // Median point (1.5, 1, 0), none of the points. Distances from it, threshold 1.25:
  //   (0, 0, 0): √(1.5² + 1²) = √3.25 ≈ 1.80 > 1.25: mis
  //   (1, 2, 0): √(0.5² + 1²) = √1.25 ≈ 1.12: stable
  //   (2, 0, 0): √(0.5² + 1²) = √1.25 ≈ 1.12: stable
  //   (9, 4, 0): √(7.5² + 3²) = √65.25 ≈ 8.08: mis
  // (The lower middle values, (1, 0, 0), would make (0, 0, 0) 1 m off and stable.)
  const InstabilityCount c = instability_vs_median(run, 1.25);
  EXPECT_EQ(c.frames, 4);
  EXPECT_EQ(c.mis_recognised, 2);
  EXPECT_DOUBLE_EQ(c.per_1000_frames(), 500.0);    // 2 · 1000 / 4
  EXPECT_DOUBLE_EQ(c.per_thesis_minute(), 370.0);  // 2 · 740 / 4
  const std::vector<Point> stable = stable_points_vs_median(run, 1.25);
  const std::vector<Point> expected = {{1.0, 2.0, 0.0}, {2.0, 0.0, 0.0}};
  EXPECT_EQ(stable, expected);
}

TEST(InstabilityVsMedian, OddCountAndTheStrictBoundary) {
  const std::vector<EvalSample> run = {
      recorded_frame({0.0, 0.0, 0.0}),
      recorded_frame({3.0, 0.0, 0.0}),
      recorded_frame({1.0, 0.0, 0.0}),
  };
  // x sorted 0, 1, 3: median 1 → point (1, 0, 0). Distances 1, 2, 0; threshold 1: only the 2 m
  // one is strictly farther.
  const InstabilityCount c = instability_vs_median(run, 1.0);
  EXPECT_EQ(c.frames, 3);
  EXPECT_EQ(c.mis_recognised, 1);
  EXPECT_DOUBLE_EQ(c.per_thesis_minute(), 740.0 / 3.0);  // 1 · 740 / 3 ≈ 246.67
  EXPECT_DOUBLE_EQ(c.per_1000_frames(), 1000.0 / 3.0);   // 1 · 1000 / 3
}

TEST(InstabilityVsMedian, FailedMeasurementsCountButStayOutOfTheMedian) {
  EvalSample nan_distance = recorded_frame({100.0, 0.0, 0.0});
  nan_distance.distance_m = kNaN;
  const EvalSample nan_point = recorded_frame({kNaN, 0.0, 0.0});
  const std::vector<EvalSample> run = {
      recorded_frame({0.0, 0.0, 0.0}), recorded_frame({0.0, 0.0, 0.0}), recorded_frame({4.0, 0.0, 0.0}),
      nan_distance, nan_point,
  };
  // Median over the 3 finite points: x 0, 0, 4 → 0, point (0, 0, 0). Threshold 1: (4, 0, 0) is
  // 4 m off: mis; both failed frames: mis. 3 of 5. (Had x = 100 joined the median, x 0, 0, 4,
  // 100 → 2, and the two origin points would be 2 m off as well.)
  const InstabilityCount c = instability_vs_median(run, 1.0);
  EXPECT_EQ(c.frames, 5);
  EXPECT_EQ(c.mis_recognised, 3);
  const std::vector<Point> expected = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  EXPECT_EQ(stable_points_vs_median(run, 1.0), expected);
}

TEST(InstabilityVsMedian, EmptyAndAllFailedRuns) {
  const InstabilityCount empty = instability_vs_median({}, 1.0);
  EXPECT_EQ(empty.frames, 0);
  EXPECT_EQ(empty.mis_recognised, 0);
  EXPECT_EQ(empty.per_thesis_minute(), 0.0);
  EXPECT_TRUE(stable_points_vs_median({}, 1.0).empty());
  // Only failed measurements: no median; both counted, both mis-recognised.
  EvalSample failed = recorded_frame({0.0, 0.0, 0.0});
  failed.distance_m = kNaN;
  const InstabilityCount all_failed = instability_vs_median({failed, failed}, 1.0);
  EXPECT_EQ(all_failed.frames, 2);
  EXPECT_EQ(all_failed.mis_recognised, 2);
}

// --- stable points against truth ---

TEST(StablePointsVsTruth, KeepsMeasuredFramesWithinTheThresholdInOrder) {
  const std::vector<EvalSample> run = {
      truth_frame({1.5, 0.0, 0.0}, {1.0, 0.0, 0.0}),   // 0.5 m, not > 0.5: kept
      recorded_frame({1.0, 0.0, 0.0}),                 // no truth: cannot be judged, left out
      truth_frame({3.0, 0.0, 0.0}, {1.0, 0.0, 0.0}),   // 2 m: left out
      missed_frame({1.0, 0.0, 0.0}),                   // no point: left out
      truth_frame({1.0, 0.25, 0.0}, {1.0, 0.0, 0.0}),  // 0.25 m: kept
  };
  const std::vector<Point> expected = {{1.5, 0.0, 0.0}, {1.0, 0.25, 0.0}};
  EXPECT_EQ(stable_points_vs_truth(run, 0.5), expected);
  EXPECT_TRUE(stable_points_vs_truth({}, 0.5).empty());
}

// --- MSE ---

TEST(MseWholeRun, MeanSquaredDistanceFromTheMeanPoint) {
  // Mean (0, 0, 0); each point is √3 from it: 3 m² each, mean 3.
  EXPECT_DOUBLE_EQ(mse_whole_run({{1.0, 1.0, 1.0}, {-1.0, -1.0, -1.0}}), 3.0);
  // Mean (2, 0, 0); squared distances 4, 0, 4: 8 / 3.
  EXPECT_DOUBLE_EQ(mse_whole_run({{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {4.0, 0.0, 0.0}}), 8.0 / 3.0);
  EXPECT_EQ(mse_whole_run({{5.0, 6.0, 7.0}}), 0.0);  // one point is its own mean
  EXPECT_TRUE(std::isnan(mse_whole_run({})));
}

// Window k (indices 10k .. 10k + 9) of a 50-point run alternates x = 10k + (k + 1) and
// 10k − (k + 1): mean 10k, every point (k + 1) from it.
std::vector<Point> fifty_point_run() {
  std::vector<Point> points;
  for (int k = 0; k < 5; ++k) {
    for (int i = 0; i < 10; ++i) {
      const double offset = (i % 2 == 0 ? 1.0 : -1.0) * (k + 1);
      points.push_back({10.0 * k + offset, 0.0, 0.0});
    }
  }
  return points;
}

TEST(MseThesisWindows, FiftyPointsTileTheRun) {
  const std::vector<Point> points = fifty_point_run();
  ASSERT_EQ(points.size(), 50U);
  // Starts floor(k · 40 / 4) = 0, 10, 20, 30, 40. Window MSEs (k + 1)² = 1, 4, 9, 16, 25:
  // (1 + 4 + 9 + 16 + 25) / 5 = 55 / 5 = 11.
  EXPECT_DOUBLE_EQ(mse_thesis_windows(points), 11.0);
  // The whole run's mean x is (0 + 10 + 20 + 30 + 40) / 5 = 20; a pair 10k − 20 ± (k + 1)
  // averages (10k − 20)² + (k + 1)²: 401, 104, 9, 116, 425 → 1055 / 5 = 211. The windows
  // ignore the drift between them.
  EXPECT_DOUBLE_EQ(mse_whole_run(points), 211.0);
}

TEST(MseThesisWindows, BelowFiftyTheWindowsOverlapFromTheFloor) {
  // 12 points, all at the origin but index 10 at (10, 0, 0).
  std::vector<Point> points(12, Point{0.0, 0.0, 0.0});
  points[10] = {10.0, 0.0, 0.0};
  // Starts floor(k · 2 / 4) = 0, 0, 1, 1, 2. Window at 0 (indices 0..9): all 0, MSE 0. Windows
  // at 1 (1..10) and 2 (2..11) hold the outlier: mean x 10 / 10 = 1, squared distances
  // 9 · 1² + 9² = 90, MSE 90 / 10 = 9. (0 + 0 + 9 + 9 + 9) / 5 = 27 / 5 = 5.4. (Rounded
  // starts 0, 1, 1, 2, 2 would give 36 / 5 = 7.2.)
  EXPECT_DOUBLE_EQ(mse_thesis_windows(points), 5.4);
}

TEST(MseThesisWindows, TenPointsAreOneWindowFiveTimesAndFewerAreNaN) {
  std::vector<Point> points;
  for (int i = 0; i < 10; ++i) points.push_back({static_cast<double>(i), 0.0, 0.0});
  // x = 0..9, mean 4.5: squared distances 4.5², 3.5², 2.5², 1.5², 0.5², each twice:
  // 2 · (20.25 + 12.25 + 6.25 + 2.25 + 0.25) = 82.5, / 10 = 8.25. All 5 windows start at 0.
  EXPECT_DOUBLE_EQ(mse_thesis_windows(points), 8.25);
  points.pop_back();  // 9 points: no window fits
  EXPECT_TRUE(std::isnan(mse_thesis_windows(points)));
  EXPECT_TRUE(std::isnan(mse_thesis_windows({})));
}

// --- distance error ---

TEST(DistanceError, HandComputed) {
  EvalSample unmeasured = distance_frame(kNaN, 2.0);
  unmeasured.measured = false;
  EvalSample truthless = distance_frame(9.0, kNaN);
  truthless.has_truth = false;
  const std::vector<EvalSample> run = {
      distance_frame(2.5, 2.0),   // +0.5, farther: unsafe
      distance_frame(1.75, 2.0),  // −0.25
      unmeasured,                 // skipped
      distance_frame(3.0, 2.0),   // +1, unsafe
      distance_frame(0.0, 2.0),   // −2
      truthless,                  // skipped
      distance_frame(kNaN, 2.0),  // measured, NaN distance: skipped
      distance_frame(2.0, 2.0),   // 0: equal is not unsafe
  };
  const DistanceError e = distance_error(run);
  EXPECT_EQ(e.frames, 5);
  // abs sorted 0, 0.25, 0.5, 1, 2; sum 3.75.
  EXPECT_DOUBLE_EQ(e.mean_abs_m, 0.75);    // 3.75 / 5
  EXPECT_DOUBLE_EQ(e.median_abs_m, 0.5);   // index ceil(0.5 · 5) − 1 = 2
  EXPECT_DOUBLE_EQ(e.p95_abs_m, 2.0);      // index ceil(0.95 · 5) − 1 = ceil(4.75) − 1 = 4
  EXPECT_DOUBLE_EQ(e.max_abs_m, 2.0);
  EXPECT_DOUBLE_EQ(e.unsafe_share, 0.4);   // 2.5 and 3.0: 2 / 5
}

TEST(DistanceError, EvenCountMedianIsANearestRankValue) {
  const std::vector<EvalSample> run = {
      distance_frame(4.0, 0.0), distance_frame(1.0, 0.0), distance_frame(3.0, 0.0), distance_frame(2.0, 0.0),
  };
  const DistanceError e = distance_error(run);
  EXPECT_EQ(e.frames, 4);
  EXPECT_DOUBLE_EQ(e.median_abs_m, 2.0);  // sorted 1, 2, 3, 4: index ceil(0.5 · 4) − 1 = 1; not 2.5
  EXPECT_DOUBLE_EQ(e.mean_abs_m, 2.5);    // 10 / 4
  EXPECT_DOUBLE_EQ(e.p95_abs_m, 4.0);     // index ceil(3.8) − 1 = 3
  EXPECT_DOUBLE_EQ(e.unsafe_share, 1.0);  // 4 / 4 farther than 0
}

TEST(DistanceError, TwentyValuesNearestRank) {
  std::vector<EvalSample> run;
  for (int i = 20; i >= 1; --i) run.push_back(distance_frame(10.0 + 0.25 * i, 10.0));  // abs 0.25 · i, reversed
  const DistanceError e = distance_error(run);
  EXPECT_EQ(e.frames, 20);
  EXPECT_DOUBLE_EQ(e.mean_abs_m, 2.625);   // 0.25 · (1 + … + 20) / 20 = 0.25 · 210 / 20 = 52.5 / 20
  EXPECT_DOUBLE_EQ(e.median_abs_m, 2.5);   // index ceil(0.5 · 20) − 1 = 9: the 10th, 0.25 · 10
  EXPECT_DOUBLE_EQ(e.p95_abs_m, 4.75);     // index ceil(0.95 · 20) − 1 = 18: the 19th, 0.25 · 19
  EXPECT_DOUBLE_EQ(e.max_abs_m, 5.0);      // 0.25 · 20
  EXPECT_DOUBLE_EQ(e.unsafe_share, 1.0);   // all measured farther
}

TEST(DistanceError, NoFramesGiveZeroAndNaN) {
  const DistanceError e = distance_error({distance_frame(kNaN, 1.0)});
  EXPECT_EQ(e.frames, 0);
  EXPECT_TRUE(std::isnan(e.mean_abs_m));
  EXPECT_TRUE(std::isnan(e.median_abs_m));
  EXPECT_TRUE(std::isnan(e.p95_abs_m));
  EXPECT_TRUE(std::isnan(e.max_abs_m));
  EXPECT_TRUE(std::isnan(e.unsafe_share));
  EXPECT_EQ(distance_error({}).frames, 0);
}

// --- latency ---

TEST(LatencyPercentiles, TwentyValuesSkippingNonFinite) {
  // 100 · i µs for i = 1..20, out of order, with NaN and ∞ between them.
  std::vector<EvalSample> run;
  for (const int i : {7, 20, 1, 13, 2, 19, 8, 14, 3, 18, 9, 15, 4, 17, 10, 16, 5, 11, 6, 12}) {
    run.push_back(latency_frame(100.0 * i));
  }
  run.push_back(latency_frame(kNaN));
  run.push_back(latency_frame(kInf));
  const Percentiles p = latency_percentiles(run);
  EXPECT_EQ(p.count, 20);
  EXPECT_DOUBLE_EQ(p.p50, 1000.0);  // index ceil(0.5 · 20) − 1 = 9: the 10th, 100 · 10
  EXPECT_DOUBLE_EQ(p.p99, 2000.0);  // index ceil(0.99 · 20) − 1 = ceil(19.8) − 1 = 19: the 20th
}

TEST(LatencyPercentiles, HundredValuesP99IsThe99th) {
  std::vector<EvalSample> run;
  for (int i = 1; i <= 100; ++i) run.push_back(latency_frame(i));
  const Percentiles p = latency_percentiles(run);
  EXPECT_EQ(p.count, 100);
  EXPECT_DOUBLE_EQ(p.p50, 50.0);  // index ceil(50) − 1 = 49: the 50th
  EXPECT_DOUBLE_EQ(p.p99, 99.0);  // index ceil(99) − 1 = 98: the 99th, not the maximum
}

TEST(LatencyPercentiles, NoFiniteValues) {
  const Percentiles p = latency_percentiles({latency_frame(kNaN)});
  EXPECT_EQ(p.count, 0);
  EXPECT_TRUE(std::isnan(p.p50));
  EXPECT_TRUE(std::isnan(p.p99));
  EXPECT_EQ(latency_percentiles({}).count, 0);
}

// --- Z_d coverage ---

TEST(UncertaintyCoverage, HandComputed) {
  EvalSample unmeasured = distance_frame(2.5, 2.0, 0.25);
  unmeasured.measured = false;
  EvalSample truthless = distance_frame(2.5, 2.0, 0.25);
  truthless.has_truth = false;
  const std::vector<EvalSample> run = {
      distance_frame(2.25, 2.0, 0.25),  // 2.25 − 0.25 = 2.0 ≤ 2.0: covered (the boundary)
      distance_frame(2.5, 2.0, 0.25),   // 2.5 − 0.25 = 2.25 > 2.0: not covered
      distance_frame(1.5, 2.0, 0.0),    // 1.5 ≤ 2.0: nearer than true is covered
      distance_frame(2.5, 2.0, kNaN),   // Z_d unknown: skipped
      distance_frame(kNaN, 2.0, 0.25),  // failed measurement: skipped
      unmeasured,                       // skipped
      truthless,                        // skipped
  };
  const Coverage c = uncertainty_coverage(run);
  EXPECT_EQ(c.frames, 3);
  EXPECT_EQ(c.covered, 2);
  EXPECT_DOUBLE_EQ(c.share(), 2.0 / 3.0);
}

TEST(UncertaintyCoverage, NoFramesIsNaN) {
  const Coverage c = uncertainty_coverage({});
  EXPECT_EQ(c.frames, 0);
  EXPECT_EQ(c.covered, 0);
  EXPECT_TRUE(std::isnan(c.share()));
}

}  // namespace
}  // namespace hrcsense::eval
