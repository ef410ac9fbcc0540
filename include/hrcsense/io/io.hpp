// SPDX-License-Identifier: Apache-2.0
// hrcsense — file formats: 16-bit depth PNG, intrinsics as JSON, the background model file.
// Every function throws IoError whose message names the file and what is wrong with it.
#pragma once

#include "hrcsense/segmentation.hpp"
#include "hrcsense/types.hpp"

#include <optional>
#include <stdexcept>
#include <string>

namespace hrcsense {

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Why `path` cannot be opened as a file, or "" when it is a regular file (or a link to one):
/// "does not exist", "is a directory, not a file", "is a FIFO (named pipe), not a regular file",
/// ... Every reader asks before open(): a FIFO with no writer would block it forever and a
/// device might never end. (A path swapped between the check and the open is not guarded.)
std::string not_regular_file(const std::string& path);
/// Throws IoError "<path>: <what> <not_regular_file(path)>" unless `path` is a regular file.
void require_regular_file(const std::string& path, const std::string& what);

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
/// Reads intrinsics_to_json's form. Throws IoError naming `what` and the field for a missing or
/// ill-typed field, a duplicate key, or values that fail intrinsics_problem().
Intrinsics intrinsics_from_json(const std::string& json_text, const std::string& what);

/// Names of the intrinsics' fields in a file, for messages ("fx", or "depth_K[0][0]").
struct IntrinsicsFieldNames {
  const char* fx = "fx";
  const char* fy = "fy";
  const char* ppx = "ppx";
  const char* ppy = "ppy";
  const char* coeffs = "coeffs";
};
/// The first problem of intrinsics read from a file, naming the field, or "" when they are
/// plausible: width and height in [1, 16384] px; fx and fy normal floats in (1, 1e5) px (a D435
/// has 200-1400 px, a 16K-wide 8-degree telephoto under 1e5); ppx in [-width, 2·width] and ppy in
/// [-height, 2·height] (the principal point near the image, off-centre lenses included); every
/// distortion coefficient finite. Anything else would put points at infinity or nowhere.
std::string intrinsics_problem(const Intrinsics& intrinsics, const IntrinsicsFieldNames& names = {});

/// A folder's `intrinsics.json` (docs/RECORDINGS.md): hrcsense's own form, or the datasets'
/// {"width", "height", "depth_K", "depth_units_m", "pixel_convention", "rgb_K",
/// "depth_to_rgb_R", "depth_to_rgb_T_m"}.
struct FolderCalibration {
  Intrinsics depth;                     ///< 0-based pixel centres
  float depth_units_m = 0.0F;           ///< 0 when the file does not say
  Intrinsics color;                     ///< fx 0 when the file has no rgb_K; width, height 0
  std::optional<Extrinsics> depth_to_color;
};
/// Parses either form; a 1-based pixel convention is shifted to 0-based. Throws IoError naming
/// `what` and the field (depth_K[0][0], ...) for anything missing, ill-typed, duplicated,
/// non-finite or implausible (intrinsics_problem; depth_units_m in [1e-6, 1] m).
FolderCalibration folder_calibration_from_json(const std::string& json_text, const std::string& what);

/// Throws IoError "<what>: duplicate key '<path>'" when an object of the JSON text has a key
/// twice (a JSON parser keeps one of them silently). Text that is not JSON is left to the parser.
void check_unique_json_keys(const std::string& json_text, const std::string& what);

/// Saves the background model: a versioned binary file with a checksum.
void save_background(const std::string& path, const BackgroundModel& model);
/// Loads a background model; a damaged, truncated or foreign file is an IoError.
BackgroundModel load_background(const std::string& path);

}  // namespace hrcsense
