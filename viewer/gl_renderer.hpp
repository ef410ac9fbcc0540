// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — drawing with OpenGL 3.3 core and Dear ImGui: the composed 2D image as a
// texture (nearest sampling, so its exact marker colours reach the screen), the state border,
// the verdict word, the distance labels and the status line. Needs a current GL context made
// by GLFW (gl_main.cpp).
#pragma once

#include "viewer/view_model.hpp"

#include <cstdint>
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
  bool session_ended = false;   ///< the run is over (the last frame stays on screen)
  std::vector<TimelinePoint> timeline;  ///< every processed frame of the last seconds (ViewTap)
};

/// Window layout, in pixels of the framebuffer drawn to.
inline constexpr int kBorderPx = 12;   ///< the state border, ≥ 8 px (issue E)
inline constexpr int kStatusPx = 150;  ///< the status strip under the image, inside the border
inline constexpr float kTimelineWidthPx = 420.0F;  ///< the distance plot at the strip's right
inline constexpr double kTimelineSeconds = 10.0;   ///< of source time across the plot

class Renderer {
 public:
  /// Creates the GL objects and ImGui's context and fonts for `window` (its context current).
  /// False with `error` set when the context cannot do what the viewer needs.
  bool init(GLFWwindow* window, std::string& error);
  void shutdown();
  /// Draws the view into the framebuffer bound now, of width × height pixels: `image` (the
  /// composed 2D pane of `frame`) fitted into pane_area(), the border in state_color(state).
  void draw(const ViewFrame& frame, const ColorImage& image, ShownState state, const ViewStats& stats, int width,
            int height);
  /// Draws the same into an offscreen framebuffer of width × height and reads it back into
  /// `out` (rgb8, top row first). False when the framebuffer cannot be made.
  bool snapshot(const ViewFrame& frame, const ColorImage& image, ShownState state, const ViewStats& stats, int width,
                int height, ColorImage& out);

 private:
  void upload(const ColorImage& image);
  void draw_overlay(const ViewFrame& frame, const ColorImage& image, ShownState state, const ViewStats& stats,
                    const Rect& image_rect, int width, int height);
  void draw_timeline(ImDrawList* draw, const ViewFrame& frame, const ViewStats& stats, const ImVec2& at,
                     const ImVec2& size);

  GLFWwindow* window_ = nullptr;
  unsigned program_ = 0, vao_ = 0, vbo_ = 0, texture_ = 0;
  int texture_width_ = 0, texture_height_ = 0;
  unsigned fbo_ = 0, fbo_texture_ = 0;
  int fbo_width_ = 0, fbo_height_ = 0;
  ImFont* font_small_ = nullptr;
  ImFont* font_large_ = nullptr;
  bool imgui_ready_ = false;
};

}  // namespace hrcsense::view
