// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — what the panels ask of the running pipeline: new parameters and a new
// background. The renderer posts requests; the processing thread applies them between two
// frames (RunOptions::before_process), so the pipeline is never touched by two threads.
#pragma once

#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"

#include <cstdint>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense::view {

/// The joint speed above which the robot counts as moving for relearn_refusal, rad/s.
inline constexpr float kRobotMovingRadS = 1e-3F;

/// Why the background may not be relearnt after the frame `previous`, or empty when it may:
/// refused without a valid robot state to judge by, while any joint moves faster than
/// kRobotMovingRadS, and while anything is within the slow distance of the robot (a valid
/// measurement whose contact the zones rule, verdict_for_contact with `safety`, puts in_slow_zone,
/// in_stop_zone or inside_robot, whatever safety.mode): a background learnt then would hide a
/// person. Judged on the measurement itself: on the processing thread, where the relearn is
/// applied, `previous` is not decided yet (its verdict is not set). A scene that moves while it
/// is learnt restarts the learning by itself (BackgroundLearner).
std::string relearn_refusal(const Measurement& previous, const SafetyParams& safety);

/// What happened to a request, for the panel and the log.
struct ControlEvent {
  int64_t after_frame = 0;  ///< the last frame processed before it (0 before the first)
  bool refused = false;
  std::string text;
};

/// The latest-wins inbox between the panels (any thread) and the processing thread.
class ControlInbox {
 public:
  /// `configured`: the parameters the run started with (Config::pipeline, as the Pipeline was
  /// built), which every posted tuning is judged against (live_tuning_refusal), never the last
  /// tuning applied.
  explicit ControlInbox(PipelineParams configured) : configured_(std::move(configured)) {}
  /// The parameters the run started with (never changes, so any thread may read it).
  const PipelineParams& configured() const { return configured_; }
  /// New parameters, taken before the next frame; a newer post replaces one not yet taken.
  void post_tuning(const LiveTuning& tuning);
  /// Relearn the background before the next frame, unless relearn_refusal() says no then.
  void post_relearn();
  /// The processing thread's side, before each frame (RunOptions::before_process): applies
  /// what was posted (a tuning unless live_tuning_refusal with configured() or Pipeline::retune
  /// refuses it, the pipeline then keeping its tuning; a relearn judged by relearn_refusal with
  /// the pipeline's safety parameters), logs it and keeps the outcome, refusals with their
  /// reason, for take_events(). Never waits for the renderer (the lock only guards the posted
  /// values).
  void apply(Pipeline& pipeline, const FrameResult& previous);
  /// Outcomes since the last call, oldest first.
  std::vector<ControlEvent> take_events();

 private:
  const PipelineParams configured_;
  std::mutex mutex_;
  std::optional<LiveTuning> tuning_;
  bool relearn_ = false;
  std::vector<ControlEvent> events_;
};

/// The tuned configuration: the run's file and --set overrides, then tuning_overrides(tuning),
/// read by load_config, which checks them as it checks a file (throws ConfigError naming the key).
Config tuned_config(const std::string& config_path, const std::vector<std::string>& sets, const LiveTuning& tuning);

/// Writes `config.canonical_yaml` to `path` under a comment saying where it came from: a
/// configuration `hrcsense run --config path` accepts. Throws IoError when it cannot.
void save_tuned_config(const Config& config, const std::string& path);

/// `--snapshot-at`'s comma-separated source frame indices ("123,198"), sorted and without
/// repeats; empty items are skipped. Throws ConfigError naming an item that is not a
/// non-negative integer, or when no index is given.
std::set<int64_t> parse_frame_list(const std::string& text);

}  // namespace hrcsense::view
