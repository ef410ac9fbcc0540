// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the Dear ImGui panels: live filter and foreground parameters, the search
// backend, relearning the background, saving the tuned parameters, replay controls and the
// panes shown. Every change goes through the configuration parser first (the same checks as
// a file), then in `ssm` mode live_tuning_refusal, and reaches the pipeline through the
// ControlInbox, between frames.
#pragma once

#include "viewer/fused_view.hpp"
#include "viewer/playback.hpp"
#include "viewer/view_control.hpp"
#include "viewer/view_model.hpp"

#include "hrcsense/config/config.hpp"

#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace hrcsense::view {

/// What the panels act on; outlives the Panels.
struct PanelContext {
  std::string config_path;          ///< --config ("" for the defaults)
  std::vector<std::string> sets;    ///< --set, in order
  ControlInbox* inbox = nullptr;
  PlaybackControl* playback = nullptr;  ///< null: the source is not a recording
};

class Panels {
 public:
  Panels(PanelContext context, const Config& config);
  /// The panels, inside an ImGui frame (Renderer::draw's `panels`). `mode` and `reset_orbit`
  /// are the view's, changed by the panel.
  void draw(PaneMode& mode, bool& reset_orbit);
  /// Key r: asks for confirmation in the panel before the relearn is posted.
  void ask_relearn() { confirm_relearn_ = true; }
  /// Outcomes of requests (ControlInbox) into the panel's log; call once per drawn frame.
  void take_events();

 private:
  void draw_playback();
  void draw_filters();
  void draw_foreground();
  void draw_background_and_save();
  void apply_edit();
  void note(std::string text, bool error);

  PanelContext context_;
  LiveTuning edit_;      ///< what the sliders show
  Config tuned_;         ///< the last configuration that passed the parser (saved as is)
  std::array<char, 256> save_path_{};  ///< the file "save" writes (ImGui edits it in place)
  std::deque<std::string> log_;  ///< newest first, a few lines
  bool confirm_relearn_ = false;
  bool edited_ = false;  ///< a slider was released after a change this frame
};

/// `--fused`: the list of the cell's cameras (a window at the top left, always open): per camera
/// its name in its colour, the age of its newest measurement in ms, valid or its reason code and
/// reason, the points of its newest cloud, and how many samples could not be read; then the
/// fused closest pair and whose it is. Inside an ImGui frame.
void draw_fused_camera_list(const std::vector<FusedCameraRow>& rows, const FusedPair& pair);

}  // namespace hrcsense::view
