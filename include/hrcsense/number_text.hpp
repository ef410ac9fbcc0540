// SPDX-License-Identifier: Apache-2.0
// hrcsense — a number as text that reads back as the same float (%.9g), for everything that
// writes settings or measurements to be read again: --set overrides, intrinsics.json, the
// evaluation tables.
#pragma once

#include <cstdio>
#include <string>

namespace hrcsense {

/// `value` with nine significant digits (%.9g): enough for any float to read back as the same
/// float, so a file or override written from float settings reloads exactly. Not the shortest
/// such text (0.1F prints as 0.100000001); a double may lose its last digits.
inline std::string float_digits_text(double value) {
  char text[32];  // "-1.23456789e-308" and the terminator fit
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

/// `value` with `digits` digits after the point (%.*f): figures for people, and poses written
/// to a set precision (`hrcsense calibrate`).
inline std::string fixed_digits_text(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

}  // namespace hrcsense
