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
/// The same, for a PNG that must be `expected_width` x `expected_height`: the size in the
/// header is checked before any pixel buffer is allocated, so a damaged size field cannot make
/// the reader allocate more than the caller expects.
void read_depth_png(const std::string& path, DepthImage& out, int expected_width, int expected_height);
/// Reads an 8-bit PNG (grey, RGB or palette, alpha dropped) into rgb8. Images over
/// kMaxColorPixels are rejected before decoding.
void read_color_png(const std::string& path, ColorImage& out);
/// Largest colour image accepted from a file (8K UHD fits), so that a size field cannot make a
/// reader allocate without bound.
inline constexpr long long kMaxColorPixels = 1LL << 25;
/// True when hrcsense was built with libturbojpeg (JPEG colour frames); the CMake summary says.
bool jpeg_supported();
/// Decodes a JPEG into rgb8 (src/io/jpeg.cpp). Throws IoError naming the file when it is
/// damaged, larger than kMaxColorPixels, or when hrcsense was built without libturbojpeg.
void read_color_jpeg(const std::string& path, ColorImage& out);
/// Encodes rgb8 as a JPEG (quality 1-100, 4:2:0); for tests and tools. Same errors.
void write_color_jpeg(const std::string& path, const ColorImage& color, int quality = 90);
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
