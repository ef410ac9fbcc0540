// SPDX-License-Identifier: Apache-2.0
// hrcsense — file formats: 16-bit depth PNG, intrinsics as JSON, the background model file.
// Every function throws IoError whose message names the file and what is wrong with it.
#pragma once

#include "hrcsense/segmentation.hpp"
#include "hrcsense/types.hpp"

#include <stdexcept>
#include <string>

namespace hrcsense {

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a 16-bit grayscale PNG into `out` (depth_scale_m left unchanged).
/// Rejects other bit depths and colour types with a message naming the file.
void read_depth_png(const std::string& path, DepthImage& out);
/// Writes `depth` as a 16-bit grayscale PNG.
void write_depth_png(const std::string& path, const DepthImage& depth);
/// Writes an 8-bit RGB PNG.
void write_color_png(const std::string& path, const ColorImage& color);

/// Intrinsics as JSON: {"width","height","fx","fy","ppx","ppy","model","coeffs"}.
std::string intrinsics_to_json(const Intrinsics& intrinsics);
Intrinsics intrinsics_from_json(const std::string& json_text, const std::string& what);

/// Saves the background model: a versioned binary file with a checksum.
void save_background(const std::string& path, const BackgroundModel& model);
/// Loads a background model; a damaged, truncated or foreign file is an IoError.
BackgroundModel load_background(const std::string& path);

}  // namespace hrcsense
