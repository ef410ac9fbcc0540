// SPDX-License-Identifier: Apache-2.0
// hrcsense — the sweep runner behind `hrcsense eval` and its studies: every sweep point ×
// scene × seed as one unpaced run, the thesis's measures (docs/EVALUATION.md) appended to
// DIR/results.csv one complete line per row, so that an interrupted sweep continues where it
// stopped; DIR/results.md beside it.
#pragma once

#include "hrcsense/eval/sweep.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace hrcsense::eval {

/// One sweep to run.
/// How far a sweep has got, for a progress display.
struct SweepProgress {
  int64_t rows_done = 0;
  int64_t rows_total = 0;    ///< rows to run now (those already in results.csv not counted)
  int64_t frames_done = 0;   ///< source frames processed so far, over every row run now
  int64_t frames_total = 0;  ///< the same when every row is done; 0: unknown
  double elapsed_s = 0.0;    ///< since the first row started (steady clock)
  std::string current;       ///< the row being run: "<label>: <point> <scene file>"
  bool finished = false;     ///< the last report of the sweep
};

/// What a sweep tells its caller while it runs; either may be empty. The library itself writes
/// nothing to the terminal: `hrcsense eval` draws the progress bar and logs the notes.
struct SweepObserver {
  /// Every 200 ms while rows run, then once with finished set (on the calling thread).
  std::function<void(const SweepProgress&)> progress;
  /// A sentence for the log: resuming a results.csv, the files written, the study begun.
  std::function<void(const std::string&)> note;
};

struct SweepRequest {
  std::vector<std::string> scenes;          ///< configuration files, one run per point each
  std::vector<std::string> sets;            ///< `--set` text for every row, before the point's
  std::vector<eval::SweepPoint> points;     ///< the sweep points (at least one)
  int64_t seeds = 0;                        ///< source.seed 1..seeds per row; 0: each scene's own
  int64_t frames = -1;                      ///< source frames per row; -1: the source's length
  int jobs = 1;                             ///< rows at once; rates are marked `parallel` above 1
  std::string out_dir;                      ///< results.csv and results.md go here
  std::string label;                        ///< shown before the progress bar (a study's name)
  SweepObserver observer;                   ///< progress and notes (none by default)
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

/// Runs every row of `request` not already in out_dir/results.csv (noting that it resumes),
/// then writes results.md and returns the whole table. Every row's configuration is loaded
/// before the first one runs, so that a misspelt key fails at once. Throws (ConfigError for a
/// bad key or value, std::runtime_error naming the scene and settings of a row whose run
/// failed).
ResultTable run_sweep(const SweepRequest& request);

/// Reads a results.csv (header and rows, sorted by the `row` column); throws naming the file.
ResultTable read_results(const std::string& csv_path);

}  // namespace hrcsense::eval
