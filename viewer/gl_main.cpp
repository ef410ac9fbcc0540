// SPDX-License-Identifier: Apache-2.0
// hrcsense-view — `hrcsense run` with a window: the same flags, sinks and links, and the
// viewer as one more consumer of the results (docs/VIEWER.md). The run goes on a thread of its
// own; GLFW and OpenGL stay on the main thread, which reads the newest frame from the view
// tap's latest-value mailbox (the processing thread's picture of each frame, published with
// the verdict the run decided for it by a sink on the output thread); the panels' requests go
// back through a ControlInbox and a recording's pause, step and seek through a PlaybackControl. Headless: --snapshot DIR
// --snapshot-at LIST writes PNGs from an offscreen framebuffer and exits after the last.
#include "viewer/cloud_view.hpp"
#include "viewer/fused_view.hpp"
#include "viewer/gl_panels.hpp"
#include "viewer/gl_renderer.hpp"
#include "viewer/playback.hpp"
#include "viewer/view_control.hpp"
#include "viewer/view_model.hpp"
#include "viewer/view_tap.hpp"

#include "common/app_errors.hpp"
#include "common/run_session.hpp"

#include "hrcsense/clock.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"

#if HRCSENSE_HAVE_DDS
#include "dds/fused_view_reader.hpp"
#endif

#include <CLI/CLI.hpp>
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace {

using namespace hrcsense;
using namespace hrcsense::view;

constexpr int kSnapshotWidth = 1280;   // issue E: snapshots are 1280×720
constexpr int kSnapshotHeight = 720;
constexpr float kDepthAlpha = 0.5F;    // depth over colour, half and half
constexpr int kMarkerRadiusPx = 6;
constexpr double kLingerAfterEndS = 2.0;  // the last verdict stays this long after the run ends
constexpr int kExitNoDisplay = 3;

struct ViewArgs {
  std::string config_path;
  std::vector<std::string> sets;
  int64_t frames = -1;
  std::string out;
  std::string record;
  bool overwrite = false;  ///< --overwrite: the recording may replace an existing file
  std::string snapshot_dir;
  std::string snapshot_at;
  std::string pane = "2d";
  int slow_render_ms = 0;  ///< hidden: a deliberately slow renderer (tests of the mailbox)
  bool fused = false;      ///< --fused: a cell's cameras read off DDS, no pipeline of its own
  double snapshot_wait_s = 10.0;  ///< --fused --snapshot: how long to wait for every camera
};

// Set by GLFW's callbacks (main thread), read by the loop. Keys typed into an ImGui field
// are ImGui's, not shortcuts.
std::atomic<bool> g_quit{false};
std::atomic<bool> g_screenshot{false};
bool g_toggle_pause = false, g_step = false, g_relearn = false, g_next_pane = false;
double g_cursor_x = 0.0, g_cursor_y = 0.0;
float g_drag_x = 0.0F, g_drag_y = 0.0F, g_wheel = 0.0F;  ///< orbit input since the last frame

bool imgui_has(bool keyboard) {
  if (ImGui::GetCurrentContext() == nullptr) return false;
  return keyboard ? ImGui::GetIO().WantCaptureKeyboard : ImGui::GetIO().WantCaptureMouse;
}

void on_key(GLFWwindow* /*window*/, int key, int /*scancode*/, int action, int /*mods*/) {
  if (action != GLFW_PRESS || imgui_has(true)) return;
  if (key == GLFW_KEY_Q || key == GLFW_KEY_ESCAPE) g_quit.store(true);
  if (key == GLFW_KEY_S) g_screenshot.store(true);
  if (key == GLFW_KEY_SPACE) g_toggle_pause = true;
  if (key == GLFW_KEY_PERIOD) g_step = true;
  if (key == GLFW_KEY_R) g_relearn = true;
  if (key == GLFW_KEY_V) g_next_pane = true;
}

void on_cursor(GLFWwindow* window, double x, double y) {
  if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && !imgui_has(false)) {
    g_drag_x += static_cast<float>(x - g_cursor_x);
    g_drag_y += static_cast<float>(y - g_cursor_y);
  }
  g_cursor_x = x;
  g_cursor_y = y;
}

void on_scroll(GLFWwindow* /*window*/, double /*dx*/, double dy) {
  if (!imgui_has(false)) g_wheel += static_cast<float>(dy);
}

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Nearest rank: the smallest value at or below which the share q of the values lies.
double nearest_rank(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return values[std::min(n - 1, static_cast<size_t>(std::max(1.0, std::ceil(q * static_cast<double>(n)))) - 1)];
}

std::string glfw_error_text() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description != nullptr ? description : "unknown GLFW error";
}

// The keys and the mouse since the last frame: pause and step a recording, ask for a relearn,
// cycle the panes, orbit the 3D view. True when the orbit camera moved.
bool handle_input(PlaybackControl* playback, Panels& panels, PaneMode& mode, OrbitCamera* orbit) {
  if (std::exchange(g_toggle_pause, false) && playback != nullptr) playback->set_paused(!playback->paused());
  if (std::exchange(g_step, false) && playback != nullptr) playback->step();
  if (std::exchange(g_relearn, false)) panels.ask_relearn();
  if (std::exchange(g_next_pane, false)) {
    mode = mode == PaneMode::view_2d ? PaneMode::view_3d : mode == PaneMode::view_3d ? PaneMode::split : PaneMode::view_2d;
  }
  const float dx = std::exchange(g_drag_x, 0.0F);
  const float dy = std::exchange(g_drag_y, 0.0F);
  const float wheel = std::exchange(g_wheel, 0.0F);
  if (orbit == nullptr || mode == PaneMode::view_2d || (dx == 0.0F && dy == 0.0F && wheel == 0.0F)) return false;
  orbit_drag(*orbit, dx, dy);
  orbit_zoom(*orbit, wheel);
  return true;
}

std::string paused_notice(const PlaybackControl& playback) {
  char text[128];
  std::snprintf(text, sizeof text, "PAUSED at %lld of %lld (space: play, .: step)",
                static_cast<long long>(playback.position()), static_cast<long long>(playback.frame_count()));
  return text;
}

// Draws the view offscreen at the snapshot size and writes DIR/frame_%06d.png. False when the
// offscreen framebuffer cannot be made.
bool write_snapshot(Renderer& renderer, const ViewFrame& frame, const PaneImages& panes, ShownState state,
                    const ViewStats& stats, const std::string& dir, ColorImage& scratch) {
  if (!renderer.snapshot(frame, panes, state, stats, kSnapshotWidth, kSnapshotHeight, scratch)) {
    spdlog::error("snapshot: the offscreen framebuffer could not be made");
    return false;
  }
  char name[64];
  std::snprintf(name, sizeof(name), "frame_%06lld.png", static_cast<long long>(frame.frame));
  const std::string path = (std::filesystem::path(dir) / name).string();
  write_color_png(path, scratch);
  spdlog::info("snapshot: {} ({}, distance {})", path, state_word(state),
               frame.contact.valid ? std::to_string(frame.contact.distance_m) + " m" : std::string("none"));
  return true;
}

// Opens the window (hidden for snapshots) with an OpenGL 3.3 core context and the input
// callbacks; without a display or such a context, says so in one line and returns nullptr.
GLFWwindow* open_window(bool hidden) {
  // No display: one line and a non-zero exit, never a crash (GLFW would only say "X11: ...").
  const char* x_display = std::getenv("DISPLAY");
  const char* wayland_display = std::getenv("WAYLAND_DISPLAY");
  if ((x_display == nullptr || *x_display == '\0') && (wayland_display == nullptr || *wayland_display == '\0')) {
    std::fprintf(stderr,
                 "hrcsense-view: no display (DISPLAY is not set); run it under `xvfb-run -a` for snapshots, or use "
                 "`hrcsense run`\n");
    return nullptr;
  }
  glfwSetErrorCallback(nullptr);
  if (glfwInit() != GLFW_TRUE) {
    std::fprintf(stderr, "hrcsense-view: no display (%s); run it under `xvfb-run -a`, or use `hrcsense run`\n",
                 glfw_error_text().c_str());
    return nullptr;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, hidden ? GLFW_FALSE : GLFW_TRUE);
  GLFWwindow* window = glfwCreateWindow(kSnapshotWidth, kSnapshotHeight, "hrcsense-view", nullptr, nullptr);
  if (window == nullptr) {
    const std::string why = glfw_error_text();
    glfwTerminate();
    std::fprintf(stderr, "hrcsense-view: no OpenGL 3.3 core context (%s)\n", why.c_str());
    return nullptr;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(hidden ? 0 : 1);
  // Before ImGui's init, which chains them.
  glfwSetKeyCallback(window, on_key);
  glfwSetCursorPosCallback(window, on_cursor);
  glfwSetScrollCallback(window, on_scroll);
  return window;
}

// What the draw loop keeps between turns: the newest frame, the panes' images and which frame
// (the tap's take() count, `serial`) each one shows, the orbit camera and the figures.
struct LoopState {
  ViewFrame frame;
  ColorImage image;     // the 2D pane
  ColorImage cloud;     // the 3D pane
  ColorImage snapshot;  // the offscreen picture
  ComposeScratch scratch;
  Cloud3dScratch cloud_scratch;
  OrbitCamera orbit;
  bool orbit_ready = false;
  bool reset_orbit = false;
  PaneMode mode = PaneMode::view_2d;
  int64_t serial = 0, serial_2d = -1, serial_3d = -1;
  ViewStats stats;
  std::vector<double> frame_times_ms;    // compose + draw + swap of each new frame
  std::vector<double> compose_times_ms;  // compose_2d alone (CPU)
  int64_t drawn = 0;
};

// Composes again the panes the window shows whose frame, size or orbit changed.
void compose_panes(LoopState& s, const PaneRects& rects, bool orbit_moved) {
  if (rects.image_2d.width > 0 && s.serial_2d != s.serial) {
    const auto c0 = std::chrono::steady_clock::now();
    compose_2d(s.frame, kDepthAlpha, kMarkerRadiusPx, s.scratch, s.image);
    s.compose_times_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - c0).count());
    s.serial_2d = s.serial;
  }
  if (s.frame.frame >= 0 && (!s.orbit_ready || s.reset_orbit)) {
    s.orbit = default_orbit(s.frame);
    s.orbit_ready = true;
    s.reset_orbit = false;
    s.serial_3d = -1;
  }
  if (rects.cloud_3d.width > 0 && (s.serial_3d != s.serial || orbit_moved || s.cloud.width != rects.cloud_3d.width ||
                                   s.cloud.height != rects.cloud_3d.height)) {
    compose_3d(s.frame, s.orbit, rects.cloud_3d.width, rects.cloud_3d.height, s.cloud_scratch, s.cloud);
    s.serial_3d = s.serial;
  }
}

// The status strip's figures for this turn.
void update_stats(LoopState& s, ViewTap& tap, const PlaybackControl* playback, int64_t start_ns, bool ended) {
  s.stats.viewer_dropped = tap.dropped();
  s.stats.pipeline_dropped = tap.index_gaps() - (playback != nullptr ? playback->skipped() : 0);
  tap.timeline(s.stats.timeline);
  s.stats.session_ended = ended;
  s.stats.notice = playback != nullptr && playback->paused() ? paused_notice(*playback) : std::string();
  const double elapsed_s = static_cast<double>(steady_ns() - start_ns) * 1e-9;
  s.stats.display_fps = elapsed_s > 0.0 ? static_cast<double>(s.drawn) / elapsed_s : 0.0;
}

// The run's options: hrcsense run's, plus the view tap after each processed frame and its sink
// for each decided result, the panels' requests before each frame and, for a replay, the
// playback control around the recording.
app::SessionOptions session_options(const ViewArgs& args, bool snapshots, ViewTap& tap, ViewSink& sink,
                                    ControlInbox& inbox, PlaybackControl* playback) {
  app::SessionOptions options;
  options.frames = args.frames;
  options.out = args.out;
  options.record = args.record;
  options.overwrite = args.overwrite;
  options.unpaced = snapshots;  // snapshots wait for the renderer: a paced clock would drop
  options.on_processed = [&tap](const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
    tap.offer(frame, pipeline, result);
  };
  options.viewer_sink = &sink;
  options.viewer_frames_dropped = [&tap] { return tap.dropped(); };
  options.with_color = true;
  options.before_process = [&inbox](Pipeline& pipeline, const FrameResult& previous) { inbox.apply(pipeline, previous); };
  if (playback != nullptr) {
    options.wrap_recording = [playback](std::unique_ptr<Source> opened, std::function<std::unique_ptr<Source>()> open) {
      return std::make_unique<PlaybackSource>(std::move(opened), std::move(open), *playback);
    };
  }
  return options;
}

// What both draw loops share: the window and its renderer, the run's tap and controls.
struct ViewerParts {
  const ViewArgs& args;
  GLFWwindow* window;
  Renderer& renderer;
  ViewTap& tap;
  Panels& panels;
  PlaybackControl* playback;  ///< a recording's pause, step and seek; null for other sources
  double max_frame_age_s;
  int64_t start_ns;
};

// One picture's inputs: the panes composed again where needed, the strip's figures and the
// state shown (a result older than max_frame_age_s is NO DATA: a frozen pipeline).
struct Picture {
  PaneImages panes;
  ShownState state;
};

Picture compose_picture(LoopState& s, const ViewerParts& v, int width, int height, bool fresh, bool orbit_moved,
                        bool ended) {
  const PaneRects rects = window_panes(s.mode, width, height);
  if (fresh && v.args.slow_render_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(v.args.slow_render_ms));
  compose_panes(s, rects, orbit_moved);
  update_stats(s, v.tap, v.playback, v.start_ns, ended);
  const PaneImages panes{s.mode, rects.image_2d.width > 0 ? &s.image : nullptr,
                         rects.cloud_3d.width > 0 ? &s.cloud : nullptr};
  return {panes, shown_state(s.frame, steady_ns(), v.max_frame_age_s)};
}

void count_drawn(LoopState& s, std::chrono::steady_clock::time_point t0) {
  ++s.drawn;
  s.frame_times_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
}

// Headless: draws only the --snapshot-at frames, offscreen, until the last one is written or
// the run ends. Returns 1 when a picture could not be written.
int snapshot_loop(LoopState& s, const ViewerParts& v, const std::set<int64_t>& snapshot_frames,
                  const std::atomic<bool>& session_done) {
  int exit_code = 0;
  while (v.tap.snapshots_pending() > 0) {
    glfwPollEvents();
    const bool fresh = v.tap.take(s.frame, 1.0 / 60.0);
    if (!fresh && session_done.load()) break;
    if (!fresh) continue;
    ++s.serial;
    if (snapshot_frames.count(s.frame.frame) == 0) continue;
    const auto t0 = std::chrono::steady_clock::now();
    const Picture picture = compose_picture(s, v, kSnapshotWidth, kSnapshotHeight, true, false, session_done.load());
    if (!write_snapshot(v.renderer, s.frame, picture.panes, picture.state, s.stats, v.args.snapshot_dir, s.snapshot)) {
      exit_code = 1;
    }
    v.tap.rendered(s.frame.frame);
    count_drawn(s, t0);
  }
  return exit_code;
}

// The window: every turn polls the input, takes the newest frame and draws it with the
// panels, until the user quits or kLingerAfterEndS after the run ended. Key s writes a PNG
// into the working folder. Returns 1 when such a picture could not be written.
int interactive_loop(LoopState& s, const ViewerParts& v, const std::atomic<bool>& session_done) {
  int64_t ended_ns = 0;
  int exit_code = 0;
  bool quit_requested = false;
  while (true) {
    glfwPollEvents();
    if (g_quit.load() || glfwWindowShouldClose(v.window)) quit_requested = true;
    // Asked again every turn: a request made before the run installed its handlers is reset.
    if (quit_requested && !session_done.load()) app::request_session_stop();
    const bool orbit_moved = handle_input(v.playback, v.panels, s.mode, s.orbit_ready ? &s.orbit : nullptr);
    const bool fresh = v.tap.take(s.frame, 1.0 / 60.0);
    if (fresh) ++s.serial;
    if (session_done.load() && ended_ns == 0) ended_ns = steady_ns();
    if (ended_ns != 0 && (quit_requested || steady_ns() - ended_ns > kLingerAfterEndS * 1e9)) break;
    const auto t0 = std::chrono::steady_clock::now();
    int width = kSnapshotWidth, height = kSnapshotHeight;
    glfwGetFramebufferSize(v.window, &width, &height);
    const Picture picture = compose_picture(s, v, width, height, fresh, orbit_moved, ended_ns != 0);
    if (g_screenshot.exchange(false) &&
        !write_snapshot(v.renderer, s.frame, picture.panes, picture.state, s.stats, ".", s.snapshot)) {
      exit_code = 1;
    }
    v.panels.take_events();
    v.renderer.draw(s.frame, picture.panes, picture.state, s.stats, width, height,
                    [&] { v.panels.draw(s.mode, s.reset_orbit); });
    glfwSwapBuffers(v.window);
    if (fresh) count_drawn(s, t0);
  }
  return exit_code;
}

// One picture (NO DATA) before the run starts: llvmpipe compiles its shaders at the first draw
// on every core, which would otherwise starve the run's first frames (a paced run then drops
// one that no slowness of the pipeline caused).
void draw_first_picture(LoopState& s, const ViewerParts& v) {
  int width = kSnapshotWidth, height = kSnapshotHeight;
  glfwGetFramebufferSize(v.window, &width, &height);
  const PaneRects rects = window_panes(s.mode, width, height);
  compose_panes(s, rects, false);
  const PaneImages panes{s.mode, rects.image_2d.width > 0 ? &s.image : nullptr,
                         rects.cloud_3d.width > 0 ? &s.cloud : nullptr};
  v.panels.take_events();
  v.renderer.draw(s.frame, panes, shown_state(s.frame, steady_ns(), v.max_frame_age_s), s.stats, width, height,
                  [&] { v.panels.draw(s.mode, s.reset_orbit); });
  glfwSwapBuffers(v.window);
}

// The window with an OpenGL 3.3 context and the renderer on it; null (after saying why) when
// there is no display or no such context.
GLFWwindow* open_renderer(bool hidden, Renderer& renderer) {
  GLFWwindow* window = open_window(hidden);
  if (window == nullptr) return nullptr;
  std::string gl_error;
  if (renderer.init(window, gl_error)) return window;
  renderer.shutdown();
  glfwDestroyWindow(window);
  glfwTerminate();
  std::fprintf(stderr, "hrcsense-view: %s\n", gl_error.c_str());
  return nullptr;
}

void log_frame_times(const LoopState& s, const ViewTap& tap) {
  if (s.frame_times_ms.empty()) return;
  spdlog::info("viewer: {} frames drawn, {} dropped; frame time p50 {:.2f} ms, p99 {:.2f} ms (compose p50 {:.2f} ms)",
               s.drawn, tap.dropped(), nearest_rank(s.frame_times_ms, 0.5), nearest_rank(s.frame_times_ms, 0.99),
               nearest_rank(s.compose_times_ms, 0.5));
}


#if HRCSENSE_HAVE_DDS
// --fused: what the status strip reads of the fused verdict and pair, as a ViewFrame: the
// verdict is the fuser's (never the viewer's own); none yet, or one older than
// max_frame_age_s, is NO DATA (shown_state).
void fused_status_frame(const ros2::FusedView& view, const FusedPair& pair, int64_t verdicts, ViewFrame& frame) {
  frame.frame = view.verdict.received ? verdicts : -1;
  frame.made_ns = view.verdict.received_steady_ns;
  frame.timestamp_ns = view.verdict.stamp_ns;
  frame.valid = view.verdict.received;
  frame.verdict.state = view.verdict.verdict;
  frame.verdict.code = static_cast<ReasonCode>(view.verdict.reason_code);
  frame.contact = Contact{};
  frame.contact.valid = pair.valid;
  frame.contact.distance_m = pair.distance_m;
  frame.contact.closest_base = pair.closest_base;
  frame.contact.closest_robot_base = pair.closest_robot_base;
  frame.contact.robot_link = pair.link;
  frame.foreground_points = 0;
  for (const ros2::FusedCameraView& camera : view.cameras) frame.foreground_points += camera.cloud_base.size();
}

ros2::FusedViewParams fused_view_params(const Config& config) {
  ros2::FusedViewParams params;
  params.domain_id = static_cast<uint32_t>(config.ros2.domain_id);
  params.node_namespace = config.ros2.node_namespace;
  for (const CameraEntry& entry : config.cameras) {
    params.cameras.push_back({entry.name, entry.T_base_camera, entry.intrinsics.value_or(Intrinsics{})});
  }
  return params;
}

// Every camera has sent a measurement, a cloud and a preview.
bool fused_view_complete(const ros2::FusedView& view, std::string& missing) {
  missing.clear();
  for (const ros2::FusedCameraView& camera : view.cameras) {
    if (!camera.measurement || camera.cloud_stamp_ns == 0 || camera.preview.width == 0) {
      missing += (missing.empty() ? "" : ", ") + camera.name;
    }
  }
  return missing.empty();
}

// The fused view: no pipeline, one 3D pane of every camera's outputs, the camera list, the
// fused verdict in the border. Headless (--snapshot DIR): one DIR/fused.png once every camera
// and the fuser's verdict have been heard (or --snapshot-wait-s passed: exit code 1 when a camera
// is missing, naming it; a missing verdict is a warning, the picture then says NO DATA).
int run_fused_viewer(const ViewArgs& args, const Config& config) {
  if (config.cameras.empty()) {
    const std::string where = args.config_path.empty() ? std::string("configuration") : args.config_path;
    throw ConfigError(where + ": --fused needs a cell configuration with `cameras:` (docs/MULTICAMERA.md)");
  }
  const bool snapshot = !args.snapshot_dir.empty();
  if (snapshot) std::filesystem::create_directories(args.snapshot_dir);
  ros2::FusedViewReader reader(fused_view_params(config));
  spdlog::info("fused view: {} cameras under {} on domain {}", config.cameras.size(), config.ros2.node_namespace,
               config.ros2.domain_id);
  Renderer renderer;
  GLFWwindow* window = open_renderer(snapshot, renderer);
  if (window == nullptr) return kExitNoDisplay;
  ViewFrame frame;
  frame.slow_distance_m = config.pipeline.safety.slow_distance_m;
  frame.stop_distance_m = config.pipeline.safety.stop_distance_m;
  ColorImage pane, picture;
  FusedScratch scratch;
  ViewStats stats;
  OrbitCamera orbit = fused_default_orbit(reader.view());
  const int64_t start_ns = steady_ns();
  int64_t verdicts = 0, drawn = 0, last_verdict_stamp_ns = -1;
  Timeline timeline(kTimelineSeconds);
  int exit_code = 0;
  bool reset_orbit = false;
  PaneMode mode = PaneMode::view_3d;
  while (true) {
    glfwPollEvents();
    if (g_quit.load() || glfwWindowShouldClose(window)) break;
    const ros2::FusedView& view = reader.poll(seconds_to_ns(1.0 / 60.0), steady_ns());
    const FusedPair pair = fused_closest_pair(view);
    const std::vector<FusedCameraRow> rows = fused_camera_rows(view, shared_clock_ns());
    // Each new fused verdict on the strip's timeline: its distance and verdict, as the fuser sent.
    if (view.verdict.received && view.verdict.stamp_ns != last_verdict_stamp_ns) {
      last_verdict_stamp_ns = view.verdict.stamp_ns;
      ++verdicts;
      const bool contact = std::isfinite(view.verdict.distance_m);
      timeline.add(TimelinePoint{view.verdict.stamp_ns, view.verdict.received_steady_ns,
                                 contact ? view.verdict.distance_m : -1.0F, view.verdict.verdict, 0.0});
      stats.timeline = timeline.points();
    }
    fused_status_frame(view, pair, verdicts, frame);
    if (std::exchange(reset_orbit, false)) orbit = fused_default_orbit(view);
    orbit_drag(orbit, std::exchange(g_drag_x, 0.0F), std::exchange(g_drag_y, 0.0F));
    orbit_zoom(orbit, std::exchange(g_wheel, 0.0F));
    int width = kSnapshotWidth, height = kSnapshotHeight;
    if (!snapshot) glfwGetFramebufferSize(window, &width, &height);
    const PaneRects rects = window_panes(mode, width, height);
    compose_fused_3d(view, fused_robot_capsules(view, config.pipeline.robot), pair, orbit, rects.cloud_3d.width,
                     rects.cloud_3d.height, scratch, pane);
    const PaneImages panes{mode, nullptr, &pane};
    const ShownState state = shown_state(frame, steady_ns(), config.pipeline.safety.max_frame_age_s);
    ++drawn;
    stats.display_fps = static_cast<double>(drawn) / std::max(1e-9, static_cast<double>(steady_ns() - start_ns) * 1e-9);
    const auto list = [&] { draw_fused_camera_list(rows, pair); };
    if (snapshot) {
      std::string missing;
      const bool complete = fused_view_complete(view, missing);
      const bool timed_out = static_cast<double>(steady_ns() - start_ns) * 1e-9 > args.snapshot_wait_s;
      // The fuser's verdict too, when it publishes one: a picture without it says NO DATA.
      if (!(complete && view.verdict.received) && !timed_out) continue;
      if (!complete) {
        spdlog::error("fused view: nothing (measurement, cloud and preview) from {} within {:g} s", missing,
                      args.snapshot_wait_s);
        exit_code = 1;
      }
      if (!view.verdict.received) spdlog::warn("fused view: no fused verdict within {:g} s (NO DATA)", args.snapshot_wait_s);
      // Twice: ImGui sizes an auto-resized window on its first frame and shows it on the next.
      renderer.snapshot(frame, panes, state, stats, width, height, picture, list);
      if (!renderer.snapshot(frame, panes, state, stats, width, height, picture, list)) {
        spdlog::error("snapshot: the offscreen framebuffer could not be made");
        exit_code = 1;
        break;
      }
      const std::string path = (std::filesystem::path(args.snapshot_dir) / "fused.png").string();
      write_color_png(path, picture);
      spdlog::info("snapshot: {} ({}, closest {})", path, state_word(state),
                   pair.valid ? std::to_string(pair.distance_m) + " m by " + pair.camera : std::string("none"));
      break;
    }
    if (g_screenshot.exchange(false)) {
      renderer.snapshot(frame, panes, state, stats, kSnapshotWidth, kSnapshotHeight, picture, list);
      write_color_png("fused.png", picture);
    }
    renderer.draw(frame, panes, state, stats, width, height, list);
    glfwSwapBuffers(window);
  }
  renderer.shutdown();
  glfwDestroyWindow(window);
  glfwTerminate();
  return exit_code;
}
#endif

int run_viewer(const ViewArgs& args) {
  const Config config = load_config(args.config_path, args.sets);
  if (args.fused) {
#if HRCSENSE_HAVE_DDS
    return run_fused_viewer(args, config);
#else
    throw ConfigError("--fused: this hrcsense-view was built without Cyclone DDS; install cyclonedds-dev and "
                      "cyclonedds-tools (scripts/setup does) and rebuild");
#endif
  }
  const bool snapshots = !args.snapshot_dir.empty();
  std::set<int64_t> snapshot_frames;
  if (snapshots) {
    snapshot_frames = parse_frame_list(args.snapshot_at);
    std::filesystem::create_directories(args.snapshot_dir);
  } else if (!args.snapshot_at.empty()) {
    throw ConfigError("--snapshot-at needs --snapshot DIR");
  }
  const std::optional<PaneMode> pane_mode = parse_pane_mode(args.pane);
  if (!pane_mode) throw ConfigError("--pane: '" + args.pane + "' is not 2d, 3d or split");
  Renderer renderer;
  GLFWwindow* window = open_renderer(snapshots, renderer);
  if (window == nullptr) return kExitNoDisplay;

  ViewTap tap(snapshot_frames);
  ViewSink view_sink(tap);
  ControlInbox inbox(config.pipeline);  // tunings are judged against the run's start
  PlaybackControl playback;
  // run_session wraps only recordings (.bag, folder); a headless run plays straight through.
  const bool replay = !snapshots && is_recording(config.source.type);
  const app::SessionOptions options = session_options(args, snapshots, tap, view_sink, inbox, replay ? &playback : nullptr);
  Panels panels(PanelContext{args.config_path, args.sets, &inbox, replay ? &playback : nullptr}, config);
  const ViewerParts parts{args,   window, renderer, tap, panels, replay ? &playback : nullptr,
                          config.pipeline.safety.max_frame_age_s, steady_ns()};
  LoopState s;
  s.mode = *pane_mode;
  if (!snapshots) draw_first_picture(s, parts);
  std::atomic<bool> session_done{false};
  int session_code = 0;
  std::thread session([&] {
    try {
      session_code = app::run_session(config, options);
    } catch (const std::exception& e) {
      session_code = app::report_error(e);
    }
    session_done.store(true);
  });
  int exit_code = snapshots ? snapshot_loop(s, parts, snapshot_frames, session_done) : interactive_loop(s, parts, session_done);
  if (!session_done.load()) app::request_session_stop();
  tap.close();  // a session waiting at a snapshot frame goes on
  session.join();
  if (snapshots && tap.snapshots_pending() > 0) {
    spdlog::error("snapshot: {} of the --snapshot-at frames never came (the run ended before them)",
                  tap.snapshots_pending());
    exit_code = 1;
  }
  log_frame_times(s, tap);
  renderer.shutdown();
  glfwDestroyWindow(window);
  glfwTerminate();
  return session_code != 0 ? session_code : exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_default_logger(spdlog::stderr_color_mt("hrcsense-view"));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  CLI::App app{"hrcsense-view: hrcsense run with a window (docs/VIEWER.md); hrcsense is not a safety-rated device"};
  ViewArgs args;
  app.add_option("--config", args.config_path, "YAML configuration file (docs/CONFIG.md)");
  app.add_option("--set", args.sets, "override a key, KEY=VALUE with VALUE in YAML (repeatable)")->allow_extra_args(false);
  app.add_option("--frames", args.frames, "stop after N source frames, 1 to 10^10 (default: the source's length)")
      ->check(CLI::Range(int64_t{1}, int64_t{10'000'000'000}));
  app.add_option("--out", args.out, "JSON Lines output file (default: stdout)");
  app.add_option("--record", args.record, "also record the source's frames to this RealSense .bag");
  app.add_flag("--overwrite", args.overwrite, "with --record: replace an existing recording (never the source itself)");
  app.add_option("--snapshot", args.snapshot_dir, "headless: write DIR/frame_%06d.png (1280x720) at --snapshot-at");
  app.add_option("--snapshot-at", args.snapshot_at, "comma-separated source frame indices for --snapshot");
  app.add_option("--pane", args.pane, "what the window shows: 2d (default), 3d or split (key v cycles)");
  app.add_flag("--fused", args.fused,
               "a cell with several cameras: show every camera's cloud, preview and age and the fused verdict, read "
               "over DDS (no pipeline of its own; docs/VIEWER.md)");
  app.add_option("--snapshot-wait-s", args.snapshot_wait_s,
                 "with --fused --snapshot: wait at most this long for every camera (default 10)")
      ->check(CLI::Range(0.1, 600.0));
  app.add_option("--slow-render-ms", args.slow_render_ms, "testing: sleep this long per frame drawn")
      ->group("")
      ->check(CLI::Range(0, 10'000));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    return hrcsense::app::report_error(e.what(), hrcsense::app::kExitUsage);
  }
  try {
    return run_viewer(args);
  } catch (const std::exception& e) {
    return hrcsense::app::report_error(e);
  }
}
