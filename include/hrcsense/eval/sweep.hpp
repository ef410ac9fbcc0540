// SPDX-License-Identifier: Apache-2.0
// hrcsense — the evaluation harness's sweeps and result table (issue 18, "hrcsense eval"):
// `--sweep KEY=LIST | KEY=A:B[:STEP]` parsed into axes, the grid of sweep points they span,
// and results.csv written row by row so that an interrupted sweep continues where it stopped.
// Plain functions over strings; the configuration keys themselves are checked by load_config
// when a point runs (a misspelt key fails there, naming the key).
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace hrcsense::eval {

/// One `--sweep` argument: a configuration key and the values it takes, as `--set` text.
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};

/// Parses `KEY=V1,V2,...` (values as written, at least one, none empty) or `KEY=A:B[:STEP]`
/// (decimal numbers without exponents; A, A + STEP, ... up to B inclusive, STEP 1 by default,
/// > 0, A ≤ B, at most 10000 values; each written with as many decimals as the most precise of
/// A, B and STEP, trailing zeros dropped: `0.25:1:0.25` gives 0.25, 0.5, 0.75, 1). A key
/// without a dot is no configuration key. Throws std::invalid_argument naming the argument
/// and what is wrong.
SweepAxis parse_sweep(const std::string& argument);

/// One point of the grid: its settings as `--set` text (`KEY=VALUE`, in axis order).
struct SweepPoint {
  int64_t index = 0;
  std::vector<std::string> settings;
};

/// Every combination of the axes' values, the first axis outermost (the last one changes
/// fastest). No axes: one point without settings. Throws std::invalid_argument when a key is
/// swept twice.
std::vector<SweepPoint> sweep_grid(const std::vector<SweepAxis>& axes);

/// The settings of a point as one CSV field: `KEY=VALUE` joined by `;` (empty: none).
std::string settings_text(const SweepPoint& point);

/// One CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break; a line
/// break becomes a space, so that every row is one line (resume_results reads lines).
std::string csv_field(const std::string& text);

/// Splits one CSV line (no line break) into its fields, undoing csv_field's quoting. Throws
/// std::invalid_argument for an unterminated quote.
std::vector<std::string> split_csv_line(const std::string& line);

/// What results.csv already holds when a sweep starts.
struct ResumeState {
  bool existed = false;          ///< the file was there (with the expected header)
  int64_t rows = 0;              ///< complete rows kept
  bool dropped_partial = false;  ///< a last line without its line break (cut off) was removed
  std::set<std::string> done;    ///< row_key() of every complete row
};

/// The identity of a row: its sweep settings, scene and seed (the first `key_columns` fields
/// of the row joined, as row_key writes them).
std::string row_key(const std::vector<std::string>& key_fields);

/// Opens `path` for a resumed sweep: when absent, writes `header` (a CSV line) and returns
/// existed false. When present, its first line must equal `header` (else std::runtime_error
/// naming the file: another sweep's table); a last line without its line break is cut off
/// the file; the first `key_columns` fields of each row give the done set. A row with the
/// wrong field count is an error naming the file and line.
ResumeState resume_results(const std::string& path, const std::string& header, size_t key_columns);

}  // namespace hrcsense::eval
