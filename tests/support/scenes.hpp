// SPDX-License-Identifier: Apache-2.0
// Test support: the shipped scenes (config/*.yaml) by file name, for every test that runs or
// loads one.
#pragma once

#include <string>

namespace hrcsense::test {

/// The shipped configuration `name` ("walk.yaml", "cell-ur5-moving.yaml", ...) in the source
/// tree's config/ folder.
inline std::string scene_path(const std::string& name) { return std::string(HRCSENSE_SOURCE_DIR) + "/config/" + name; }

}  // namespace hrcsense::test
