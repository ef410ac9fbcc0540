// SPDX-License-Identifier: Apache-2.0
// hrcsense — the sweep runner behind `hrcsense eval` and its studies: every sweep point ×
// scene × seed as one unpaced run, the thesis's measures (docs/EVALUATION.md) appended to
// DIR/results.csv one complete line per row, so that an interrupted sweep continues where it
// stopped; DIR/results.md beside it.
#pragma once

#include "hrcsense/eval/sweep.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::eval {

/// One sweep to run.
struct SweepRequest {
  std::vector<std::string> scenes;          ///< configuration files, one run per point each
  std::vector<std::string> sets;            ///< `--set` text for every row, before the point's
  std::vector<eval::SweepPoint> points;     ///< the sweep points (at least one)
  int64_t seeds = 0;                        ///< source.seed 1..seeds per row; 0: each scene's own
  int64_t frames = -1;                      ///< source frames per row; -1: the source's length
  int jobs = 1;                             ///< rows at once; rates are marked `parallel` above 1
  std::string out_dir;                      ///< results.csv and results.md go here
  std::string label;                        ///< shown before the progress bar (a study's name)
};

/// results.csv read back: its columns and its rows in row order.
struct ResultTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  /// The index of column `name`; throws std::out_of_range naming it when there is none.
  size_t column(const std::string& name) const;
  /// Row `row`'s cell of column `name` as text.
  const std::string& text(size_t row, const std::string& name) const;
  /// The same as a number; NaN when the cell is empty (a measure without frames).
  double number(size_t row, const std::string& name) const;
};

/// Runs every row of `request` not already in out_dir/results.csv (logging that it resumes),
/// then writes results.md and returns the whole table. Every row's configuration is loaded
/// before the first one runs, so that a misspelt key fails at once. Throws (ConfigError for a
/// bad key or value, std::runtime_error naming the scene and settings of a row whose run
/// failed).
ResultTable run_sweep(const SweepRequest& request);

/// Reads a results.csv (header and rows, sorted by the `row` column); throws naming the file.
ResultTable read_results(const std::string& csv_path);

}  // namespace hrcsense::eval
