// SPDX-License-Identifier: Apache-2.0
// hrcsense — JPEG colour images in and out with libturbojpeg (optional: without it, every call
// is an IoError naming the file, and folders with JPEG colour still play their depth).
#include "hrcsense/io/io.hpp"
#include "io_fail.hpp"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#if HRCSENSE_HAVE_TURBOJPEG
#include <turbojpeg.h>
#endif

namespace hrcsense {

#if HRCSENSE_HAVE_TURBOJPEG

namespace {

/// Largest JPEG file read (a 33 Mpx colour image is far smaller), so that reading a wrong file
/// cannot allocate without bound.
constexpr long kMaxJpegBytes = 256L << 20;

struct TjCloser {
  void operator()(void* handle) const { tjDestroy(handle); }
};
using TjHandle = std::unique_ptr<void, TjCloser>;

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

using io_detail::fail;

std::vector<unsigned char> read_file(const std::string& path) {
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(path, "cannot open");
  if (std::fseek(file.get(), 0, SEEK_END) != 0) fail(path, "cannot seek");
  const long size = std::ftell(file.get());
  if (size < 0 || size > kMaxJpegBytes) fail(path, "cannot tell its size, or larger than 256 MiB");
  std::vector<unsigned char> bytes(static_cast<size_t>(size));
  if (std::fseek(file.get(), 0, SEEK_SET) != 0 || std::fread(bytes.data(), 1, bytes.size(), file.get()) != bytes.size()) {
    fail(path, "cannot read");
  }
  return bytes;
}

}  // namespace

bool jpeg_supported() { return true; }

void read_color_jpeg(const std::string& path, ColorImage& out) {
  const std::vector<unsigned char> bytes = read_file(path);
  TjHandle tj(tjInitDecompress());
  if (!tj) fail(path, "cannot create a JPEG decoder");
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(tj.get(), bytes.data(), static_cast<unsigned long>(bytes.size()), &width, &height,
                          &subsampling, &colorspace) != 0) {
    fail(path, std::string("not a readable JPEG: ") + tjGetErrorStr2(tj.get()));
  }
  // The header's size is checked before the pixel buffer (and the decoder's own) is allocated.
  if (width <= 0 || height <= 0 || static_cast<long long>(width) * height > kMaxColorPixels) {
    fail(path, "JPEG of " + std::to_string(width) + "x" + std::to_string(height) + " pixels is empty or too large");
  }
  out.width = width;
  out.height = height;
  out.rgb.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
  // TJFLAG_STOPONWARNING: a truncated or corrupt stream is an error, not a half-grey image.
  if (tjDecompress2(tj.get(), bytes.data(), static_cast<unsigned long>(bytes.size()), out.rgb.data(), width, 0, height,
                    TJPF_RGB, TJFLAG_STOPONWARNING) != 0) {
    fail(path, std::string("damaged JPEG data: ") + tjGetErrorStr2(tj.get()));
  }
}

void write_color_jpeg(const std::string& path, const ColorImage& color, int quality) {
  if (color.width <= 0 || color.height <= 0 ||
      color.rgb.size() != static_cast<size_t>(color.width) * static_cast<size_t>(color.height) * 3) {
    fail(path, "cannot write a colour image of " + std::to_string(color.width) + "x" + std::to_string(color.height) +
                   " holding " + std::to_string(color.rgb.size()) + " bytes");
  }
  TjHandle tj(tjInitCompress());
  if (!tj) fail(path, "cannot create a JPEG encoder");
  unsigned char* jpeg = nullptr;
  unsigned long jpeg_bytes = 0;
  const int rc = tjCompress2(tj.get(), color.rgb.data(), color.width, 0, color.height, TJPF_RGB, &jpeg, &jpeg_bytes,
                             TJSAMP_420, quality, 0);
  const std::unique_ptr<unsigned char, void (*)(unsigned char*)> owned(jpeg, tjFree);
  if (rc != 0) fail(path, std::string("JPEG encoding failed: ") + tjGetErrorStr2(tj.get()));
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
  if (!file || std::fwrite(jpeg, 1, jpeg_bytes, file.get()) != jpeg_bytes || std::fclose(file.release()) != 0) {
    std::remove(path.c_str());
    fail(path, "cannot write");
  }
}

#else

bool jpeg_supported() { return false; }

void read_color_jpeg(const std::string& path, ColorImage& /*out*/) {
  throw IoError(path + ": JPEG colour images need libturbojpeg (Debian libturbojpeg0-dev); this build has none");
}

void write_color_jpeg(const std::string& path, const ColorImage& /*color*/, int /*quality*/) {
  throw IoError(path + ": JPEG colour images need libturbojpeg (Debian libturbojpeg0-dev); this build has none");
}

#endif

}  // namespace hrcsense
