// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the Dear ImGui panels (gl_panels.hpp).
#include "viewer/gl_panels.hpp"

#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <string>
#include <utility>

namespace hrcsense::view {
namespace {

constexpr size_t kLogLines = 6;
constexpr const char* kRelearnPopup = "Relearn the background?";

// A slider that reports a change once it is let go (dragging would parse the configuration
// every frame); the ranges are the configuration's (docs/CONFIG.md), so what the slider gives
// passes the parser unless two values disagree (threshold min above max).
bool slider(const char* label, float& value, float min, float max, const char* format = "%.3f") {
  ImGui::SliderFloat(label, &value, min, max, format);
  return ImGui::IsItemDeactivatedAfterEdit();
}

bool slider(const char* label, int& value, int min, int max) {
  ImGui::SliderInt(label, &value, min, max);
  return ImGui::IsItemDeactivatedAfterEdit();
}

}  // namespace

Panels::Panels(PanelContext context, const Config& config)
    : context_(std::move(context)), edit_(tuning_of(config.pipeline)), tuned_(config) {
  std::snprintf(save_path_.data(), save_path_.size(), "%s", "hrcsense-tuned.yaml");
}

void Panels::note(std::string text, bool error) {
  if (error) {
    spdlog::warn("viewer: {}", text);
  } else {
    spdlog::info("viewer: {}", text);
  }
  log_.push_front((error ? "! " : "") + std::move(text));
  while (log_.size() > kLogLines) log_.pop_back();
}

void Panels::take_events() {
  if (context_.inbox == nullptr) return;
  for (const ControlEvent& event : context_.inbox->take_events()) {
    log_.push_front((event.refused ? "! " : "") + event.text + " (after frame " + std::to_string(event.after_frame) + ")");
    while (log_.size() > kLogLines) log_.pop_back();
  }
}

void Panels::apply_edit() {
  try {
    Config tuned = tuned_config(context_.config_path, context_.sets, edit_);
    // Refused here too, not only by the inbox, so that the sliders go back and "save" never
    // writes a value the pipeline did not take.
    const std::string refusal =
        context_.inbox != nullptr ? live_tuning_refusal(context_.inbox->configured(), tuning_of(tuned.pipeline)) : "";
    if (!refusal.empty()) {
      note(refusal, true);
      edit_ = tuning_of(tuned_.pipeline);  // back to the last accepted values
      return;
    }
    tuned_ = std::move(tuned);
    edit_ = tuning_of(tuned_.pipeline);  // as the parser read it
    if (context_.inbox != nullptr) context_.inbox->post_tuning(edit_);
  } catch (const std::exception& e) {
    note(e.what(), true);
    edit_ = tuning_of(tuned_.pipeline);  // back to the last accepted values
  }
}

void Panels::draw(PaneMode& mode, bool& reset_orbit) {
  ImGui::SetNextWindowPos(ImVec2(20.0F, 20.0F), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(380.0F, 0.0F), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver);  // the view first; the panel on a click
  ImGui::SetNextWindowBgAlpha(0.85F);
  if (ImGui::Begin("hrcsense controls")) {
    int m = static_cast<int>(mode);
    ImGui::RadioButton("2D", &m, static_cast<int>(PaneMode::view_2d));
    ImGui::SameLine();
    ImGui::RadioButton("3D", &m, static_cast<int>(PaneMode::view_3d));
    ImGui::SameLine();
    ImGui::RadioButton("both", &m, static_cast<int>(PaneMode::split));
    mode = static_cast<PaneMode>(m);
    ImGui::SameLine();
    if (ImGui::Button("reset 3D view")) reset_orbit = true;
    if (context_.playback != nullptr) draw_playback();
    edited_ = false;
    draw_filters();
    draw_foreground();
    if (edited_) apply_edit();
    draw_background_and_save();
    ImGui::Separator();
    for (const std::string& line : log_) {
      if (line.rfind("! ", 0) == 0) {
        ImGui::TextColored(ImVec4(1.0F, 0.45F, 0.35F, 1.0F), "%s", line.c_str() + 2);
      } else {
        ImGui::TextUnformatted(line.c_str());
      }
    }
  }
  ImGui::End();
  if (confirm_relearn_) {
    ImGui::OpenPopup(kRelearnPopup);
    confirm_relearn_ = false;
  }
  if (ImGui::BeginPopupModal(kRelearnPopup, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::TextUnformatted("The cell stops (learning_background) until the new background is learnt.");
    ImGui::TextUnformatted("Refused while the robot moves or anything is within the slow distance.");
    ImGui::TextUnformatted("Whatever stands still in the cell now becomes background.");
    if (ImGui::Button("Relearn")) {
      if (context_.inbox != nullptr) context_.inbox->post_relearn();
      note("relearn requested", false);
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
}

void Panels::draw_playback() {
  if (!ImGui::CollapsingHeader("Recording", ImGuiTreeNodeFlags_DefaultOpen)) return;
  PlaybackControl& playback = *context_.playback;
  const bool paused = playback.paused();
  if (ImGui::Button(paused ? "play (space)" : "pause (space)")) playback.set_paused(!paused);
  ImGui::SameLine();
  if (ImGui::Button("step (.)")) playback.step();
  int position = static_cast<int>(std::max<int64_t>(0, playback.position()));
  const int64_t count = playback.frame_count();
  const int last = count > 0 ? static_cast<int>(count - 1) : std::max(position, 1);
  ImGui::SliderInt("seek", &position, 0, last);
  if (ImGui::IsItemDeactivatedAfterEdit()) playback.seek(position);
}

void Panels::draw_filters() {
  if (!ImGui::CollapsingHeader("Depth filters")) return;
  FilterChainParams& f = edit_.filters;
  if (f.order.empty()) ImGui::TextUnformatted("no filters (filters.preset none)");
  if (has_block(edit_.filters.order, FilterBlock::threshold)) {
    edited_ |= slider("threshold min (m)", f.threshold.min_m, 0.0F, 16.0F);
    edited_ |= slider("threshold max (m)", f.threshold.max_m, 0.0F, 16.0F);
  }
  if (has_block(edit_.filters.order, FilterBlock::decimation)) {
    ImGui::Text("decimation magnitude %d (sets the background's size: not live)", f.decimation.magnitude);
  }
  if (has_block(edit_.filters.order, FilterBlock::spatial)) {
    edited_ |= slider("spatial alpha", f.spatial.alpha, 0.25F, 1.0F);
    edited_ |= slider("spatial delta", f.spatial.delta, 1, 50);
    edited_ |= slider("spatial magnitude", f.spatial.magnitude, 1, 5);
    edited_ |= slider("spatial holes_fill", f.spatial.holes_fill, 0, 5);
  }
  if (has_block(edit_.filters.order, FilterBlock::temporal)) {
    edited_ |= slider("temporal alpha", f.temporal.alpha, 0.0F, 1.0F);
    edited_ |= slider("temporal delta", f.temporal.delta, 1, 100);
    edited_ |= slider("temporal persistence", f.temporal.persistence, 0, 8);
  }
  if (has_block(edit_.filters.order, FilterBlock::hole_filling)) edited_ |= slider("hole_filling mode", f.hole_filling.mode, 0, 2);
}

void Panels::draw_foreground() {
  if (!ImGui::CollapsingHeader("Foreground and search")) return;
  ForegroundParams& fg = edit_.foreground;
  edited_ |= slider("k_sigma", fg.k_sigma, 0.5F, 12.0F, "%.2f");
  edited_ |= slider("min_margin_m", fg.min_margin_m, 0.0F, 0.2F);
  edited_ |= slider("min_object_mm", fg.min_object_mm, 0.0F, 300.0F, "%.0f");
  constexpr int kBackendCount = static_cast<int>(std::size(kProximityBackends));
  const char* names[kBackendCount];
  int backend = 0;
  for (int i = 0; i < kBackendCount; ++i) {
    names[i] = proximity_backend_name(kProximityBackends[i]);
    if (edit_.backend == kProximityBackends[i]) backend = i;
  }
  if (ImGui::Combo("backend", &backend, names, kBackendCount) && edit_.backend != kProximityBackends[backend]) {
    edit_.backend = kProximityBackends[backend];
    edited_ = true;
  }
}

void Panels::draw_background_and_save() {
  if (!ImGui::CollapsingHeader("Background and saving", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (ImGui::Button("relearn background (r)")) ask_relearn();
  ImGui::InputText("file", save_path_.data(), save_path_.size());
  if (ImGui::Button("save tuned parameters")) {
    const std::string path(save_path_.data());
    try {
      save_tuned_config(tuned_, path);
      note("saved " + path + " (hrcsense run --config " + path + ")", false);
    } catch (const std::exception& e) {
      note(e.what(), true);
    }
  }
}

void draw_fused_camera_list(const std::vector<FusedCameraRow>& rows, const FusedPair& pair) {
  ImGui::SetNextWindowPos(ImVec2(20.0F, 20.0F), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.8F);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings;
  if (!ImGui::Begin("cameras", nullptr, flags)) {
    ImGui::End();
    return;
  }
  for (const FusedCameraRow& row : rows) {
    const ImVec4 color(row.color[0] / 255.0F, row.color[1] / 255.0F, row.color[2] / 255.0F, 1.0F);
    ImGui::TextColored(color, "%-10s", row.name.c_str());
    ImGui::SameLine();
    if (row.age_ms) {
      ImGui::Text("%7.0f ms", *row.age_ms);
    } else {
      ImGui::Text("%7s ms", "-");
    }
    ImGui::SameLine();
    if (row.valid) {
      ImGui::Text("valid    %6zu points", row.cloud_points);
    } else {
      ImGui::TextColored(ImVec4(1.0F, 0.35F, 0.35F, 1.0F), "invalid (%d) %s", row.reason_code, row.reason.c_str());
    }
    if (row.rejected > 0) {
      ImGui::SameLine();
      ImGui::Text("[%lld unreadable]", static_cast<long long>(row.rejected));
    }
  }
  ImGui::Separator();
  if (pair.valid) {
    ImGui::Text("closest: %.3f m, link %d, seen by %s", static_cast<double>(pair.distance_m), pair.link,
                pair.camera.c_str());
  } else {
    ImGui::Text("closest: none (no valid camera sees anything)");
  }
  ImGui::End();
}

}  // namespace hrcsense::view
