// SPDX-License-Identifier: Apache-2.0
// The io library's one way to report a bad file: an IoError naming the file (or field) first.
#pragma once

#include "hrcsense/io/io.hpp"

#include <string>

namespace hrcsense::io_detail {

[[noreturn]] inline void fail(const std::string& what, const std::string& problem) {
  throw IoError(what + ": " + problem);
}

}  // namespace hrcsense::io_detail
