// SPDX-License-Identifier: Apache-2.0
// hrcsense — "is this a file we can read?", asked before open(): opening a FIFO with no writer
// blocks forever, a character device may never end, and a directory opens but fails on read.
#include "hrcsense/io/io.hpp"

#include <filesystem>
#include <system_error>

namespace hrcsense {

std::string not_regular_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);  // follows symbolic links
  switch (status.type()) {
    case fs::file_type::regular: return {};
    case fs::file_type::not_found: return "does not exist";
    case fs::file_type::directory: return "is a directory, not a file";
    case fs::file_type::fifo: return "is a FIFO (named pipe), not a regular file";
    case fs::file_type::character: return "is a character device, not a regular file";
    case fs::file_type::block: return "is a block device, not a regular file";
    case fs::file_type::socket: return "is a socket, not a regular file";
    default: break;
  }
  return error ? "cannot be read: " + error.message() : std::string("is not a regular file");
}

void require_regular_file(const std::string& path, const std::string& what) {
  const std::string problem = not_regular_file(path);
  if (!problem.empty()) throw IoError(path + ": " + (what.empty() ? "" : what + " ") + problem);
}

}  // namespace hrcsense
