// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — OpenGL 3.3 core and Dear ImGui drawing (gl_renderer.hpp).
#define GL_GLEXT_PROTOTYPES 1
#include "viewer/gl_renderer.hpp"

#include <GL/gl.h>
#include <GL/glext.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include "hrcsense/safety.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <utility>

namespace hrcsense::view {
namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec2 position;
layout(location = 1) in vec2 texcoord;
out vec2 uv;
void main() { uv = texcoord; gl_Position = vec4(position, 0.0, 1.0); }
)";

constexpr const char* kFragmentShader = R"(#version 330 core
in vec2 uv;
out vec4 color;
uniform sampler2D image;
void main() { color = vec4(texture(image, uv).rgb, 1.0); }
)";

unsigned compile(GLenum kind, const char* source, std::string& error) {
  const GLuint shader = glCreateShader(kind);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::array<char, 1024> log{};
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    error = std::string("shader compilation failed: ") + log.data();
    glDeleteShader(shader);
    return 0;
  }
  return shader;
}

ImU32 im_color(const Rgb& c, int alpha = 255) { return IM_COL32(c[0], c[1], c[2], alpha); }

void clear_rect(int x, int y, int w, int h, int framebuffer_height, const Rgb& c) {
  // GL's origin is the bottom left; the layout's the top left.
  glScissor(x, framebuffer_height - y - h, w, h);
  glClearColor(c[0] / 255.0F, c[1] / 255.0F, c[2] / 255.0F, 1.0F);
  glClear(GL_COLOR_BUFFER_BIT);
}

std::string distance_text(const ViewFrame& frame) {
  if (frame.frame < 0) return "-";
  if (!frame.contact.valid) return frame.valid ? "clear" : "-";
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f m", static_cast<double>(frame.contact.distance_m));
  return text;
}

// The distance beside the line between the two closest points, placed by projecting both into
// the 2D pane's image (`image`, its pixels) and scaling to where that image is drawn
// (`image_rect`, window pixels); nothing when either point does not project.
void draw_contact_distance_label(ImDrawList* draw, ImFont* font, const ViewFrame& frame, const ColorImage& image,
                                 const Rect& image_rect) {
  const ViewCamera camera = view_camera(frame);
  const std::optional<Eigen::Vector2f> a = project_to_view(camera, frame.contact.closest_camera);
  const Eigen::Vector3f robot_camera = frame.T_camera_base.cast<float>() * frame.contact.closest_robot_base;
  const std::optional<Eigen::Vector2f> b = project_to_view(camera, robot_camera);
  if (!a || !b) return;
  const float scale = static_cast<float>(image_rect.width) / static_cast<float>(image.width);
  const Eigen::Vector2f mid = (*a + *b) * 0.5F;
  const ImVec2 at(image_rect.x + (mid.x() + 0.5F) * scale + 12.0F, image_rect.y + (mid.y() + 0.5F) * scale - 14.0F);
  const std::string text = distance_text(frame);
  const ImVec2 size = font->CalcTextSizeA(28.0F, 1e9F, 0.0F, text.c_str());
  draw->AddRectFilled(ImVec2(at.x - 4, at.y - 2), ImVec2(at.x + size.x + 4, at.y + size.y + 2), IM_COL32(0, 0, 0, 200));
  draw->AddText(font, 28.0F, at, IM_COL32(255, 255, 255, 255), text.c_str());
}

// The status strip's small lines under the large verdict (x and the strip's top strip_y in
// window pixels): the verdict's reason, the frame's figures, the rates and drops, then the
// disclaimer with any notice beside it.
void draw_status_lines(ImDrawList* draw, ImFont* font, const ViewFrame& frame, ShownState state, const ViewStats& stats,
                       float x, float strip_y) {
  const RateStats rates = rate_stats(stats.timeline);
  const std::string reason = state == ShownState::no_data
                                 ? std::string("no result newer than safety.max_frame_age_s")
                                 : std::string(reason_code_name(frame.verdict.code)) + ": " + frame.verdict.reason;
  char line2[160];
  char line3[200];
  std::snprintf(line2, sizeof(line2), "frame %lld  fg %zu pts  invalid %zu px  latency %.2f / %.2f ms%s",
                static_cast<long long>(frame.frame), frame.foreground_points, frame.invalid_pixels,
                rates.latency_p50_us / 1000.0, rates.latency_p99_us / 1000.0, stats.session_ended ? "  (ended)" : "");
  std::snprintf(line3, sizeof(line3), "capture %.1f  processing %.1f  view %.1f frames/s  dropped %lld, view %lld",
                rates.capture_fps, rates.processing_fps, stats.display_fps,
                static_cast<long long>(stats.pipeline_dropped), static_cast<long long>(stats.viewer_dropped));
  draw->AddText(font, 18.0F, ImVec2(x, strip_y + 68.0F), IM_COL32(230, 230, 230, 255), reason.c_str());
  draw->AddText(font, 18.0F, ImVec2(x, strip_y + 88.0F), IM_COL32(170, 170, 170, 255), line2);
  draw->AddText(font, 18.0F, ImVec2(x, strip_y + 108.0F), IM_COL32(170, 170, 170, 255), line3);
  const char* disclaimer = "hrcsense is not a safety-rated device";
  draw->AddText(font, 18.0F, ImVec2(x, strip_y + 128.0F), IM_COL32(140, 140, 140, 255), disclaimer);
  if (!stats.notice.empty()) {
    const float after = font->CalcTextSizeA(18.0F, 1e9F, 0.0F, disclaimer).x + 24.0F;
    draw->AddText(font, 18.0F, ImVec2(x + after, strip_y + 128.0F), IM_COL32(255, 210, 80, 255), stats.notice.c_str());
  }
}

}  // namespace

bool Renderer::init(GLFWwindow* window, std::string& error) {
  window_ = window;
  const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader, error);
  if (vs == 0) return false;
  const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader, error);
  if (fs == 0) return false;
  program_ = glCreateProgram();
  glAttachShader(program_, vs);
  glAttachShader(program_, fs);
  glLinkProgram(program_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint linked = 0;
  glGetProgramiv(program_, GL_LINK_STATUS, &linked);
  if (!linked) {
    error = "shader program did not link";
    return false;
  }
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, 16 * sizeof(float), nullptr, GL_DYNAMIC_DRAW);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), nullptr);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), reinterpret_cast<void*>(2 * sizeof(float)));
  glEnableVertexAttribArray(1);
  glBindVertexArray(0);
  for (PaneTexture* texture : {&texture_2d_, &texture_3d_}) {
    glGenTextures(1, &texture->id);
    glBindTexture(GL_TEXTURE_2D, texture->id);
    // Nearest: each screen pixel takes one image pixel's exact colour (markers, outline).
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini written into the user's folder
  ImFontConfig small;
  small.SizePixels = 18.0F;
  font_small_ = io.Fonts->AddFontDefault(&small);
  ImFontConfig large;
  large.SizePixels = 56.0F;  // the verdict and the distance, readable from a few metres
  font_large_ = io.Fonts->AddFontDefault(&large);
  // Chains the key callback gl_main installed before this call.
  if (!ImGui_ImplGlfw_InitForOpenGL(window, true) || !ImGui_ImplOpenGL3_Init("#version 330 core")) {
    error = "Dear ImGui's GLFW / OpenGL 3 backends did not start";
    return false;
  }
  imgui_ready_ = true;
  return true;
}

void Renderer::shutdown() {
  if (imgui_ready_) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    imgui_ready_ = false;
  }
  if (fbo_ != 0) glDeleteFramebuffers(1, &fbo_);
  if (fbo_texture_ != 0) glDeleteTextures(1, &fbo_texture_);
  for (PaneTexture* texture : {&texture_2d_, &texture_3d_}) {
    if (texture->id != 0) glDeleteTextures(1, &texture->id);
    *texture = PaneTexture{};
  }
  if (vbo_ != 0) glDeleteBuffers(1, &vbo_);
  if (vao_ != 0) glDeleteVertexArrays(1, &vao_);
  if (program_ != 0) glDeleteProgram(program_);
  fbo_ = fbo_texture_ = vbo_ = vao_ = program_ = 0;
}

PaneRects window_panes(PaneMode mode, int width, int height) {
  return pane_rects(mode, pane_area(width, height, kBorderPx, kStatusPx), kPaneGapPx);
}

void Renderer::draw_image(PaneTexture& texture, const ColorImage& image, const Rect& rect, int width, int height) {
  if (rect.width <= 0 || rect.height <= 0 || image.rgb.empty()) return;
  glBindTexture(GL_TEXTURE_2D, texture.id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (image.width != texture.width || image.height != texture.height) {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, image.width, image.height, 0, GL_RGB, GL_UNSIGNED_BYTE, image.rgb.data());
    texture.width = image.width;
    texture.height = image.height;
  } else {
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.width, image.height, GL_RGB, GL_UNSIGNED_BYTE, image.rgb.data());
  }
  const float x0 = 2.0F * rect.x / width - 1.0F;
  const float x1 = 2.0F * (rect.x + rect.width) / width - 1.0F;
  const float y0 = 1.0F - 2.0F * rect.y / height;
  const float y1 = 1.0F - 2.0F * (rect.y + rect.height) / height;
  // Triangle strip: top left, bottom left, top right, bottom right; the image's first row on top.
  const std::array<float, 16> quad{x0, y0, 0.0F, 0.0F, x0, y1, 0.0F, 1.0F, x1, y0, 1.0F, 0.0F, x1, y1, 1.0F, 1.0F};
  glScissor(rect.x, height - rect.y - rect.height, rect.width, rect.height);
  glUseProgram(program_);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture.id);
  glUniform1i(glGetUniformLocation(program_, "image"), 0);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferSubData(GL_ARRAY_BUFFER, 0, sizeof(quad), quad.data());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glBindVertexArray(0);
  glUseProgram(0);
}

void Renderer::draw(const ViewFrame& frame, const PaneImages& panes, ShownState state, const ViewStats& stats,
                    int width, int height, const std::function<void()>& panels) {
  glViewport(0, 0, width, height);
  glDisable(GL_FRAMEBUFFER_SRGB);
  glDisable(GL_BLEND);
  glEnable(GL_SCISSOR_TEST);
  // The border: the whole target in the state's colour, then the inside dark.
  clear_rect(0, 0, width, height, height, state_color(state));
  clear_rect(kBorderPx, kBorderPx, width - 2 * kBorderPx, height - 2 * kBorderPx, height, Rgb{24, 24, 24});
  const PaneRects rects = window_panes(panes.mode, width, height);
  Rect fit;
  if (panes.image_2d != nullptr && rects.image_2d.width > 0) {
    fit = fit_rect(panes.image_2d->width, panes.image_2d->height, rects.image_2d);
    draw_image(texture_2d_, *panes.image_2d, fit, width, height);
  }
  if (panes.cloud_3d != nullptr && rects.cloud_3d.width > 0) {
    // Composed at the rectangle's size; a stale size (the window just resized) is fitted.
    draw_image(texture_3d_, *panes.cloud_3d, fit_rect(panes.cloud_3d->width, panes.cloud_3d->height, rects.cloud_3d),
               width, height);
  }
  glDisable(GL_SCISSOR_TEST);

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGuiIO& io = ImGui::GetIO();
  io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
  io.DisplayFramebufferScale = ImVec2(1.0F, 1.0F);
  ImGui::NewFrame();
  draw_overlay(frame, panes.image_2d, state, stats, fit, width, height);
  if (panels) panels();
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void Renderer::draw_overlay(const ViewFrame& frame, const ColorImage* image, ShownState state, const ViewStats& stats,
                            const Rect& image_rect, int width, int height) {
  ImDrawList* draw = ImGui::GetForegroundDrawList();
  // Everything stays inside the border: clip to the inner rectangle.
  draw->PushClipRect(ImVec2(kBorderPx, kBorderPx), ImVec2(static_cast<float>(width - kBorderPx),
                                                           static_cast<float>(height - kBorderPx)));
  if (state != ShownState::no_data && frame.contact.valid && image != nullptr && image->width > 0 &&
      image_rect.width > 0) {
    draw_contact_distance_label(draw, font_small_, frame, *image, image_rect);
  }
  // The status strip: the word in the state's colour and the distance, large; the reason and
  // the figures under them; the timeline on the right.
  const float strip_y = static_cast<float>(height - kBorderPx - kStatusPx);
  const float x = kBorderPx + 16.0F;
  const char* word = state_word(state);
  const Rgb word_color = state == ShownState::no_data ? kStopColor : state_color(state);
  draw->AddText(font_large_, 56.0F, ImVec2(x, strip_y + 6.0F), im_color(word_color), word);
  const float word_width = font_large_->CalcTextSizeA(56.0F, 1e9F, 0.0F, "NO DATA").x;
  const std::string distance = state == ShownState::no_data ? "-" : distance_text(frame);
  draw->AddText(font_large_, 56.0F, ImVec2(x + word_width + 40.0F, strip_y + 6.0F), IM_COL32(255, 255, 255, 255),
                distance.c_str());
  draw_status_lines(draw, font_small_, frame, state, stats, x, strip_y);
  draw_timeline(draw, frame, stats, ImVec2(static_cast<float>(width - kBorderPx) - 16.0F - kTimelineWidthPx,
                                           strip_y + 8.0F),
                ImVec2(kTimelineWidthPx, static_cast<float>(kStatusPx) - 16.0F));
  draw->PopClipRect();
}

void Renderer::draw_timeline(ImDrawList* draw, const ViewFrame& frame, const ViewStats& stats, const ImVec2& at,
                             const ImVec2& size) {
  draw->AddRectFilled(at, ImVec2(at.x + size.x, at.y + size.y), IM_COL32(40, 40, 40, 255));
  const std::vector<TimelinePoint>& points = stats.timeline;
  // Distance 0 at the bottom to twice the slow distance at the top; the newest at the right
  // edge, kTimelineSeconds of source time across.
  const float top_m = std::max(2.0F * frame.slow_distance_m, 1.0F);
  auto y_of = [&](float d) { return at.y + size.y - std::clamp(d / top_m, 0.0F, 1.0F) * size.y; };
  for (const auto& [d, c] : {std::pair{frame.slow_distance_m, kSlowColor}, std::pair{frame.stop_distance_m, kStopColor}}) {
    if (d > 0.0F) draw->AddLine(ImVec2(at.x, y_of(d)), ImVec2(at.x + size.x, y_of(d)), im_color(c, 160), 1.0F);
  }
  draw->AddText(font_small_, 16.0F, ImVec2(at.x + 4.0F, at.y + 2.0F), IM_COL32(200, 200, 200, 255),
                "distance, last 10 s");
  if (points.empty()) return;
  const int64_t newest_ns = points.back().timestamp_ns;
  const double span_ns = kTimelineSeconds * 1e9;
  for (const TimelinePoint& p : points) {
    const double age_ns = static_cast<double>(newest_ns - p.timestamp_ns);
    if (age_ns < 0.0 || age_ns > span_ns) continue;
    const float px = at.x + size.x * static_cast<float>(1.0 - age_ns / span_ns);
    const Rgb c = p.state == VerdictState::run ? kRunColor : p.state == VerdictState::slow ? kSlowColor : kStopColor;
    // No contact: a mark along the top (the cell clear, or no valid frame).
    const float py = p.distance_m >= 0.0F ? y_of(p.distance_m) : at.y + 3.0F;
    draw->AddRectFilled(ImVec2(px - 1.0F, py - 1.5F), ImVec2(px + 1.0F, py + 1.5F), im_color(c));
  }
}

bool Renderer::snapshot(const ViewFrame& frame, const PaneImages& panes, ShownState state, const ViewStats& stats,
                        int width, int height, ColorImage& out, const std::function<void()>& panels) {
  if (fbo_ == 0 || fbo_width_ != width || fbo_height_ != height) {
    if (fbo_ != 0) glDeleteFramebuffers(1, &fbo_);
    if (fbo_texture_ != 0) glDeleteTextures(1, &fbo_texture_);
    glGenFramebuffers(1, &fbo_);
    glGenTextures(1, &fbo_texture_);
    glBindTexture(GL_TEXTURE_2D, fbo_texture_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, fbo_texture_, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      return false;
    }
    fbo_width_ = width;
    fbo_height_ = height;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  draw(frame, panes, state, stats, width, height, panels);
  glFinish();
  std::vector<uint8_t> rows(static_cast<size_t>(width) * height * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  out.width = width;
  out.height = height;
  out.rgb.resize(rows.size());
  const size_t stride = static_cast<size_t>(width) * 3;
  for (int y = 0; y < height; ++y) {
    std::copy_n(rows.data() + static_cast<size_t>(height - 1 - y) * stride, stride, out.rgb.data() + y * stride);
  }
  return true;
}

}  // namespace hrcsense::view
