// SPDX-License-Identifier: Apache-2.0
// hrcsense — the golden comparison behind `hrcsense verify-filters`: every case of a golden set
// made by the real RealSense SDK (the data/sdk_filter_goldens format: cases.json, its inputs and
// the SDK's outputs) run through hrcsense's filters and compared value for value, bit for bit.
// The result is a plain report; the tool prints it, tests assert on it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense::eval {

/// Where a case's outputs first differ from the SDK's: the first differing value of the first
/// golden output (in cases.json's order) that differs.
struct GoldenMismatch {
  std::string output;       ///< the golden output's file, as cases.json names it
  int64_t frame_index = 0;  ///< the input frame it is the output of (0-based)
  int x = 0;                ///< column in that output, pixels
  int y = 0;                ///< row in that output, pixels
  double ours = 0.0;        ///< hrcsense's value (depth counts, or disparity)
  double sdk = 0.0;         ///< the SDK's value
};

/// One case of a golden set, compared.
struct GoldenCaseResult {
  std::string name;                ///< as in cases.json; "<unnamed>" when it has none
  size_t outputs_checked = 0;      ///< golden outputs compared with ours
  size_t values_differing = 0;     ///< values, over all its outputs, that differ bit for bit
  double largest_difference = 0.0; ///< the largest absolute difference among them
  std::optional<GoldenMismatch> first_mismatch;  ///< set when values_differing > 0
  /// A difference that is not a value: a size or intrinsics mismatch, a missing disparity tap,
  /// outputs for frames without input; empty when none.
  std::string problem;
  /// Why the case could not be run (an input that is missing, an unknown filter, an option the
  /// file lacks); empty when it ran. The other fields then say what was compared before.
  std::string error;

  /// Bit-exact: it ran, every output compared, and nothing differed.
  bool match() const { return error.empty() && problem.empty() && values_differing == 0; }
};

/// Every case of one golden set, in cases.json's order.
struct GoldenReport {
  std::vector<GoldenCaseResult> cases;

  /// The cases that match bit for bit.
  size_t bit_exact() const;
};

/// The golden set's file itself is unusable: it cannot be opened, is not JSON or has no
/// "cases" array (the message names the file). A broken case is not this: it is reported in
/// its GoldenCaseResult and the other cases still run.
class GoldenFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Runs every case of `cases_json` through hrcsense's filter chain and compares each of its
/// outputs with the SDK's golden file. The cases' inputs are paths relative to `shared_dir`
/// (the folder holding data/); the golden outputs are relative to cases_json's folder. Throws
/// GoldenFileError when cases_json itself is unusable.
GoldenReport verify_filter_goldens(const std::string& cases_json, const std::string& shared_dir);

}  // namespace hrcsense::eval
