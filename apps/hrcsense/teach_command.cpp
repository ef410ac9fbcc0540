// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense teach --config FILE --out PATH`: learns the background of the
// configured cell as a run learns it and writes it as a reference (the `background.path`
// format) for `background.reference` (docs/SAFETY.md, "Commissioning a cell").
#include "commands.hpp"

#include "common/app_errors.hpp"
#include "common/background_start.hpp"

#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/pipeline.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace hrcsense::app {

int teach_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets);
  // A reference is taught, never checked against itself, and a stored background.path would
  // skip learning altogether: neither is read.
  if (!config.background_reference.empty() || !config.background_path.empty()) {
    spdlog::info("teach: background.path and background.reference are not read; the background is learnt from "
                 "the source");
  }
  const TeachResult taught = teach_background(config, args.frames);
  if (!taught.learnt) {
    const std::string why = taught.message.empty() ? "" : "; last restart: " + taught.message;
    const std::string ended = args.frames >= 0 && taught.frames >= args.frames
                                  ? "stopped at --frames " + std::to_string(args.frames)
                                  : "ended after " + std::to_string(taught.frames) + " frame(s)";
    return report_error("teach: the source (" + taught.source + ") " + ended +
                            " before the background was learnt (background.frames " +
                            std::to_string(config.pipeline.background.frames) + why + "); nothing written to " +
                            args.out,
                        kExitRuntime);
  }
  const std::filesystem::path parent = std::filesystem::path(args.out).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  save_background(args.out, taught.background);
  const BackgroundModel& model = taught.background;
  std::printf("reference background written to %s (%dx%d, learnt by frame %lld); use it with background.reference: %s\n",
              args.out.c_str(), model.width, model.height, static_cast<long long>(taught.last_frame), args.out.c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace hrcsense::app
