// SPDX-License-Identifier: Apache-2.0
// The tests, benchmarks and fuzz seed corpus write bags with the production writer
// (hrcsense/recordings/bag_writer.hpp); its params make the deliberately odd ones (no index, no trailing
// depth units, uncompressed chunks, only the reader's topics with sdk_metadata = false).
#pragma once

#include "hrcsense/recordings/bag_writer.hpp"

namespace hrcsense::test {

using hrcsense::BagCompression;
using hrcsense::BagWriter;
using hrcsense::BagWriterParams;

}  // namespace hrcsense::test
