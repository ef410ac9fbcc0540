// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — how a run gets its background: compared with a taught reference
// (`background.reference`), loaded from or saved to `background.path`, or learnt alone; and
// `hrcsense teach`, which learns one as a run does and writes it (docs/SAFETY.md,
// "Commissioning a cell").
#pragma once

#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/source.hpp"

#include <cstdint>
#include <string>

namespace hrcsense {

/// Where a run's background comes from.
enum class BackgroundStart {
  reference,  ///< learnt afresh and checked against background.reference
  loaded,     ///< loaded from background.path
  learnt,     ///< learnt from the first frames (and saved to background.path when it is set)
};

/// Prepares `pipeline`'s background as the configuration says and logs what it chose:
/// with background.reference, loads it (a warning when background.path is set too: it is
/// ignored); else loads background.path when that file exists; else learns. Warns at start
/// whenever there is no reference: a person standing still while the background is learnt
/// becomes background. Throws ConfigError naming the key and the file when background.reference
/// does not exist, IoError naming the file when it is damaged or not of the filtered resolution
/// (as load_background_file).
BackgroundStart start_background(const Config& config, const SourceInfo& info, Pipeline& pipeline);

/// What `hrcsense teach` did.
struct TeachResult {
  bool learnt = false;      ///< the background was learnt before the source ended (or --frames)
  int64_t frames = 0;       ///< source frames read
  int64_t last_frame = -1;  ///< index of the frame that completed it
  std::string message;      ///< why learning last restarted, if it did
  std::string source;       ///< the source's description (SourceInfo::description)
  BackgroundModel background;  ///< the learnt background (empty unless `learnt`)
};

/// Learns the background from the configured source exactly as a run's pipeline learns it (the
/// same filters, learner, self-filter and robot states looked up at the source time as an
/// unpaced run does), reading at most `max_frames` frames (-1: until the source ends).
/// background.path and background.reference are not read; a follow_link arm plays its
/// trajectory as programmed.
TeachResult teach_background(const Config& config, int64_t max_frames);

}  // namespace hrcsense
