// SPDX-License-Identifier: Apache-2.0
// hrcsense — 16-bit grayscale depth PNG in and out, 8-bit RGB PNG out, with libpng.

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "hrcsense/io/io.hpp"
#include "io_fail.hpp"

namespace hrcsense {
namespace {

// libpng reports errors by longjmp. C++ forbids jumping over frames that hold objects with
// non-trivial destructors, so every setjmp below sits in a small function whose locals are
// all trivial, and the C++ objects (file handle, png structs, output vector) live in the
// caller, which the jump never leaves. The message travels in a plain char buffer.

/// Largest image side we accept: far above any depth camera, small enough that a corrupt or
/// hostile header cannot make us allocate gigabytes.
constexpr png_uint_32 kMaxPngSidePx = 16384;

struct PngErrorState {
  char message[256] = {};
  char last_warning[256] = {};  ///< libpng often gives the detail as a warning before the error
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof(state->message), "%s", message);
  png_longjmp(png, 1);
}

/// The library never prints; a warning alone (e.g. an unknown ancillary chunk) does not change
/// the pixels, so it is only kept to explain a following error.
void on_png_warning(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  std::snprintf(state->last_warning, sizeof(state->last_warning), "%s", message);
}

std::string describe(const PngErrorState& state) {
  std::string text = state.message;
  if (state.last_warning[0] != '\0') {
    text += std::string(" (") + state.last_warning + ")";
  }
  return text;
}

struct PngFileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using FilePtr = std::unique_ptr<std::FILE, PngFileCloser>;

struct PngReadStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngReadStructs() { png_destroy_read_struct(&png, &info, nullptr); }
};

struct PngWriteStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngWriteStructs() { png_destroy_write_struct(&png, &info); }
};

struct PngHeader {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int bit_depth = 0;
  int color_type = 0;
};

constexpr bool kLittleEndianHost = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

using io_detail::fail;

const char* color_type_name(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY:
      return "grayscale";
    case PNG_COLOR_TYPE_GRAY_ALPHA:
      return "grayscale+alpha";
    case PNG_COLOR_TYPE_RGB:
      return "RGB";
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return "RGBA";
    case PNG_COLOR_TYPE_PALETTE:
      return "palette";
    default:
      return "unknown colour type";
  }
}

bool read_png_header(png_structp png, png_infop info, std::FILE* file, PngHeader* header) {
  if (setjmp(png_jmpbuf(png))) {
    return false;
  }
  png_init_io(png, file);
  png_set_sig_bytes(png, 8);
  png_set_user_limits(png, kMaxPngSidePx, kMaxPngSidePx);
  png_read_info(png, info);
  int interlace = 0;
  png_get_IHDR(png, info, &header->width, &header->height, &header->bit_depth, &header->color_type,
               &interlace, nullptr, nullptr);
  return true;
}

/// Reads the rows straight into the caller's buffer (no row-pointer array), so reading a
/// sequence of frames into one DepthImage only allocates inside libpng.
bool read_png_rows16(png_structp png, png_infop info, uint16_t* pixels, png_uint_32 width,
                     png_uint_32 height) {
  if (setjmp(png_jmpbuf(png))) {
    return false;
  }
  if (kLittleEndianHost) {
    png_set_swap(png);  // PNG stores 16-bit samples big-endian
  }
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != static_cast<size_t>(width) * sizeof(uint16_t)) {
    png_error(png, "unexpected row size after transforms");  // guards the buffer we write into
  }
  for (int pass = 0; pass < passes; ++pass) {
    for (png_uint_32 y = 0; y < height; ++y) {
      png_read_row(png, reinterpret_cast<png_bytep>(pixels + static_cast<size_t>(y) * width), nullptr);
    }
  }
  png_read_end(png, nullptr);
  return true;
}

struct WriteRequest {
  const uint8_t* data = nullptr;
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int bit_depth = 0;
  int color_type = 0;
  size_t row_bytes = 0;
};

bool write_png_rows(png_structp png, png_infop info, std::FILE* file, const WriteRequest* request) {
  if (setjmp(png_jmpbuf(png))) {
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, request->width, request->height, request->bit_depth, request->color_type,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (request->bit_depth == 16 && kLittleEndianHost) {
    png_set_swap(png);
  }
  for (png_uint_32 y = 0; y < request->height; ++y) {
    png_write_row(png, request->data + static_cast<size_t>(y) * request->row_bytes);
  }
  png_write_end(png, nullptr);
  return true;
}

void check_write_size(const std::string& path, int width, int height, size_t samples, size_t samples_per_px) {
  if (width <= 0 || height <= 0 || static_cast<png_uint_32>(width) > kMaxPngSidePx ||
      static_cast<png_uint_32>(height) > kMaxPngSidePx) {
    fail(path, "cannot write an image of size " + std::to_string(width) + "x" + std::to_string(height));
  }
  const size_t expected = static_cast<size_t>(width) * static_cast<size_t>(height) * samples_per_px;
  if (samples != expected) {
    fail(path, "image claims " + std::to_string(width) + "x" + std::to_string(height) + " but holds " +
                   std::to_string(samples) + " samples instead of " + std::to_string(expected));
  }
}

void write_png(const std::string& path, const WriteRequest& request) {
  FilePtr file(std::fopen(path.c_str(), "wb"));
  if (!file) {
    fail(path, std::string("cannot open for writing: ") + std::strerror(errno));
  }
  PngErrorState error;
  PngWriteStructs structs;
  structs.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, on_png_error, on_png_warning);
  structs.info = structs.png ? png_create_info_struct(structs.png) : nullptr;
  if (!structs.info) {
    fail(path, "libpng could not allocate its write structures");
  }
  const bool written = write_png_rows(structs.png, structs.info, file.get(), &request);
  const bool closed = std::fclose(file.release()) == 0;  // a full disk shows up here
  if (!written || !closed) {
    std::remove(path.c_str());  // never leave a half-written image behind
    fail(path, written ? "write failed (disk full?)" : "PNG write failed: " + describe(error));
  }
}

/// Any 8-bit or 16-bit PNG as 8-bit RGB: palettes expanded, grey replicated, alpha dropped.
bool read_png_rows_rgb8(png_structp png, png_infop info, uint8_t* rgb, png_uint_32 width, png_uint_32 height) {
  if (setjmp(png_jmpbuf(png))) {
    return false;
  }
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_strip_alpha(png);
  png_set_gray_to_rgb(png);
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != static_cast<size_t>(width) * 3) {
    png_error(png, "unexpected row size after transforms");  // guards the buffer we write into
  }
  for (int pass = 0; pass < passes; ++pass) {
    for (png_uint_32 y = 0; y < height; ++y) {
      png_read_row(png, rgb + static_cast<size_t>(y) * width * 3, nullptr);
    }
  }
  png_read_end(png, nullptr);
  return true;
}

/// An open PNG file whose header has been read; throws IoError naming the file otherwise.
struct PngReader {
  FilePtr file;
  PngErrorState error;
  PngReadStructs structs;
  PngHeader header;

  explicit PngReader(const std::string& path) : file(std::fopen(path.c_str(), "rb")) {
    if (!file) {
      fail(path, std::string("cannot open: ") + std::strerror(errno));
    }
    png_byte signature[8] = {};
    if (std::fread(signature, 1, sizeof(signature), file.get()) != sizeof(signature) ||
        png_sig_cmp(signature, 0, sizeof(signature)) != 0) {
      fail(path, "not a PNG file (bad signature)");
    }
    structs.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, on_png_error, on_png_warning);
    structs.info = structs.png ? png_create_info_struct(structs.png) : nullptr;
    if (!structs.info) {
      fail(path, "libpng could not allocate its read structures");
    }
    if (!read_png_header(structs.png, structs.info, file.get(), &header)) {
      fail(path, "unreadable PNG header: " + describe(error));
    }
  }
};

}  // namespace

void read_depth_png(const std::string& path, DepthImage& out) { read_depth_png(path, out, 0, 0); }

void read_depth_png(const std::string& path, DepthImage& out, int expected_width, int expected_height) {
  PngReader reader(path);
  const PngHeader& header = reader.header;
  if (header.bit_depth != 16 || header.color_type != PNG_COLOR_TYPE_GRAY) {
    fail(path, "expected a 16-bit grayscale depth PNG, found " + std::to_string(header.bit_depth) + "-bit " +
                   color_type_name(header.color_type));
  }
  if (header.width == 0 || header.height == 0) {
    fail(path, "empty image");  // libpng rejects this already; kept as the invariant we rely on
  }
  if (expected_width > 0 && (header.width != static_cast<png_uint_32>(expected_width) ||
                             header.height != static_cast<png_uint_32>(expected_height))) {
    fail(path, "image is " + std::to_string(header.width) + "x" + std::to_string(header.height) + ", expected " +
                   std::to_string(expected_width) + "x" + std::to_string(expected_height) + " (wrong size)");
  }
  // Sizes are bounded by kMaxPngSidePx through png_set_user_limits, so this cannot overflow.
  out.resize(static_cast<int>(header.width), static_cast<int>(header.height));
  if (!read_png_rows16(reader.structs.png, reader.structs.info, out.pixels.data(), header.width, header.height)) {
    fail(path, "damaged or truncated PNG data: " + describe(reader.error));
  }
}

void read_color_png(const std::string& path, ColorImage& out) {
  PngReader reader(path);
  const PngHeader& header = reader.header;
  if (header.width == 0 || header.height == 0 ||
      static_cast<long long>(header.width) * header.height > kMaxColorPixels) {
    fail(path, "colour image of " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                   " pixels is empty or too large");
  }
  out.width = static_cast<int>(header.width);
  out.height = static_cast<int>(header.height);
  out.rgb.resize(static_cast<size_t>(header.width) * header.height * 3);
  if (!read_png_rows_rgb8(reader.structs.png, reader.structs.info, out.rgb.data(), header.width, header.height)) {
    fail(path, "damaged or truncated PNG data: " + describe(reader.error));
  }
}

void write_depth_png(const std::string& path, const DepthImage& depth) {
  check_write_size(path, depth.width, depth.height, depth.pixels.size(), 1);
  WriteRequest request;
  request.data = reinterpret_cast<const uint8_t*>(depth.pixels.data());
  request.width = static_cast<png_uint_32>(depth.width);
  request.height = static_cast<png_uint_32>(depth.height);
  request.bit_depth = 16;
  request.color_type = PNG_COLOR_TYPE_GRAY;
  request.row_bytes = static_cast<size_t>(depth.width) * sizeof(uint16_t);
  write_png(path, request);
}

void write_color_png(const std::string& path, const ColorImage& color) {
  check_write_size(path, color.width, color.height, color.rgb.size(), 3);
  WriteRequest request;
  request.data = color.rgb.data();
  request.width = static_cast<png_uint_32>(color.width);
  request.height = static_cast<png_uint_32>(color.height);
  request.bit_depth = 8;
  request.color_type = PNG_COLOR_TYPE_RGB;
  request.row_bytes = static_cast<size_t>(color.width) * 3;
  write_png(path, request);
}

}  // namespace hrcsense
