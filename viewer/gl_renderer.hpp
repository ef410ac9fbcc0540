// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — drawing with OpenGL 3.3 core and Dear ImGui: the composed 2D image as a
// texture (nearest sampling, so its exact marker colours reach the screen), the state border,
// the verdict word, the distance labels and the status line. Needs a current GL context made
// by GLFW (gl_main.cpp).
#pragma once

#include "viewer/view_model.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

struct GLFWwindow;
struct ImDrawList;
struct ImFont;
struct ImVec2;

namespace hrcsense::view {

/// Figures for the status line.
struct ViewStats {
  double display_fps = 0.0;     ///< frames drawn per second
  int64_t viewer_dropped = 0;   ///< frames the viewer never drew (ViewTap::dropped)
  int64_t pipeline_dropped = 0; ///< source frames the run never wrote (paced runs; ViewTap::index_gaps)
  bool session_ended = false;   ///< the run is over (the last frame stays on screen)
  std::vector<TimelinePoint> timeline;  ///< every decided frame of the last seconds (ViewTap)
  std::string notice;           ///< one more line for the strip (e.g. "paused"); empty: none
};

/// The composed images of the panes shown (null: that pane is not shown).
struct PaneImages {
  PaneMode mode = PaneMode::view_2d;
  const ColorImage* image_2d = nullptr;  ///< compose_2d's, fitted into its rectangle
  const ColorImage* cloud_3d = nullptr;  ///< compose_3d's, of its rectangle's size
};

/// Window layout, in pixels of the framebuffer drawn to.
inline constexpr int kBorderPx = 12;   ///< the state border, ≥ 8 px (issue E)
inline constexpr int kStatusPx = 150;  ///< the status strip under the image, inside the border
inline constexpr float kTimelineWidthPx = 420.0F;  ///< the distance plot at the strip's right
inline constexpr double kTimelineSeconds = 10.0;   ///< of source time across the plot
inline constexpr int kPaneGapPx = 8;                ///< between the 2D and 3D panes (split)

/// The panes' rectangles in a framebuffer of width × height (pane_area, then pane_rects).
PaneRects window_panes(PaneMode mode, int width, int height);

class Renderer {
 public:
  /// Creates the GL objects and ImGui's context and fonts for `window` (its context current).
  /// False with `error` set when the context cannot do what the viewer needs.
  bool init(GLFWwindow* window, std::string& error);
  void shutdown();
  /// Draws the view into the framebuffer bound now, of width × height pixels: the panes'
  /// images in window_panes() (the 2D one fitted, fit_rect), the border in state_color(state),
  /// the status strip; then `panels` (ImGui calls, may be empty) inside the same ImGui frame.
  void draw(const ViewFrame& frame, const PaneImages& panes, ShownState state, const ViewStats& stats, int width,
            int height, const std::function<void()>& panels = {});
  /// Draws the same (with `panels`, usually none) into an offscreen framebuffer of width × height and
  /// reads it back into `out` (rgb8, top row first). False when the framebuffer cannot be made.
  bool snapshot(const ViewFrame& frame, const PaneImages& panes, ShownState state, const ViewStats& stats, int width,
                int height, ColorImage& out, const std::function<void()>& panels = {});

 private:
  /// A GL texture of a pane's image, re-allocated when the image's size changes.
  struct PaneTexture {
    unsigned id = 0;
    int width = 0, height = 0;
  };
  void draw_image(PaneTexture& texture, const ColorImage& image, const Rect& rect, int width, int height);
  void draw_overlay(const ViewFrame& frame, const ColorImage* image, ShownState state, const ViewStats& stats,
                    const Rect& image_rect, int width, int height);
  void draw_timeline(ImDrawList* draw, const ViewFrame& frame, const ViewStats& stats, const ImVec2& at,
                     const ImVec2& size);

  GLFWwindow* window_ = nullptr;
  unsigned program_ = 0, vao_ = 0, vbo_ = 0;
  PaneTexture texture_2d_, texture_3d_;
  unsigned fbo_ = 0, fbo_texture_ = 0;
  int fbo_width_ = 0, fbo_height_ = 0;
  ImFont* font_small_ = nullptr;
  ImFont* font_large_ = nullptr;
  bool imgui_ready_ = false;
};

}  // namespace hrcsense::view
