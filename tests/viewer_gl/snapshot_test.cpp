// SPDX-License-Identifier: Apache-2.0
// hrcsense-view end to end, headless under `xvfb-run -a` with Mesa's llvmpipe: snapshots of
// the simulated cells checked pixel by pixel against what the test works out itself from the
// run's JSON Lines and the simulator's cameras (its own pinhole projection and the layout
// rule written out here), the NO DATA state of a frozen pipeline, a deliberately slow viewer
// that must not cost the output a single frame, and the one-line refusal without a display.
// Skips when xvfb-run is not installed (scripts/setup installs it).
#include "viewer/view_model.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace hrcsense::view {
namespace {

namespace fs = std::filesystem;

const std::string kSource = HRCSENSE_SOURCE_DIR;
const std::string kView = HRCSENSE_VIEW;
// Xvfb's default screen is 8 bits deep, which has no GLX visual for llvmpipe: 24 bits.
const std::string kXvfb = "xvfb-run -a -s '-screen 0 1280x1024x24' ";

bool have_xvfb() { return std::system("command -v xvfb-run > /dev/null 2>&1") == 0; }

int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hrcsense_viewer_gl_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

struct Jsonl {
  std::map<int64_t, nlohmann::json> frames;  ///< first line of each source frame index
  nlohmann::json summary;
};

Jsonl read_jsonl(const fs::path& path) {
  Jsonl out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j["type"] == "frame") out.frames.emplace(j["frame"].get<int64_t>(), j);
    if (j["type"] == "summary") out.summary = j;
  }
  return out;
}

Rgb at(const ColorImage& image, int x, int y) {
  const size_t i = 3 * (static_cast<size_t>(y) * image.width + x);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

Rgb verdict_color(const std::string& verdict) {
  if (verdict == "run") return kRunColor;
  if (verdict == "slow") return kSlowColor;
  return kStopColor;
}

// The layout as docs/VIEWER.md states it, worked out here: a 12 px border, a 150 px status strip
// inside it at the bottom, the image fitted into the rest keeping its aspect ratio, centred.
struct ScreenMap {
  double x0, y0, scale_x, scale_y;
  Eigen::Vector2d operator()(const Eigen::Vector2d& image_px) const {
    // Image pixel centres sit at integer coordinates; the texel u covers [u, u + 1) of the fit.
    return {x0 + (image_px.x() + 0.5) * scale_x, y0 + (image_px.y() + 0.5) * scale_y};
  }
};

ScreenMap screen_map(int image_width, int image_height) {
  const int area_w = 1280 - 2 * 12;
  const int area_h = 720 - 2 * 12 - 150;
  int w = area_w;
  int h = area_w * image_height / image_width;
  if (h > area_h) {
    h = area_h;
    w = area_h * image_width / image_height;
  }
  return {12.0 + (area_w - w) / 2, 12.0 + (area_h - h) / 2, static_cast<double>(w) / image_width,
          static_cast<double>(h) / image_height};
}

// The simulator's colour camera, independently of the viewer: intrinsics and extrinsics from
// its first frame.
struct ColorCamera {
  Intrinsics intrinsics;
  Extrinsics depth_to_color;
  Eigen::Vector2d project(const Eigen::Vector3d& p_depth) const {
    Eigen::Vector3d p;
    for (int i = 0; i < 3; ++i) {
      p[i] = depth_to_color.translation_m[i];
      for (int j = 0; j < 3; ++j) p[i] += depth_to_color.rotation[3 * j + i] * p_depth[j];
    }
    return {intrinsics.fx * p.x() / p.z() + intrinsics.ppx, intrinsics.fy * p.y() / p.z() + intrinsics.ppy};
  }
};

ColorCamera color_camera(const Config& config) {
  std::unique_ptr<Source> sim = make_source(config);
  Frame frame;
  EXPECT_EQ(sim->next(frame), Source::Status::frame);
  EXPECT_TRUE(frame.color.has_value());
  EXPECT_TRUE(frame.depth_to_color.has_value());
  for (float c : frame.color_intrinsics.coeffs) EXPECT_EQ(c, 0.0F);  // the pinhole formula is then exact
  return {frame.color_intrinsics, frame.depth_to_color.value_or(Extrinsics{})};
}

Eigen::Vector3d vec3(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

// Centroid of the pixels of exactly `color` within `radius` px of `around`; count 0 if none.
struct Blob {
  int count = 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
};
Blob find_color(const ColorImage& image, const Rgb& color, const Eigen::Vector2d& around, int radius) {
  Blob blob;
  for (int y = static_cast<int>(around.y()) - radius; y <= static_cast<int>(around.y()) + radius; ++y) {
    for (int x = static_cast<int>(around.x()) - radius; x <= static_cast<int>(around.x()) + radius; ++x) {
      if (x < 0 || y < 0 || x >= image.width || y >= image.height || at(image, x, y) != color) continue;
      ++blob.count;
      blob.centroid += Eigen::Vector2d(x + 0.5, y + 0.5);  // pixel x covers [x, x + 1)
    }
  }
  if (blob.count > 0) blob.centroid /= blob.count;
  return blob;
}

void expect_border(const ColorImage& png, const Rgb& expected, const std::string& what) {
  int checked = 0;
  for (int d : {0, 5, 11}) {
    for (int x = 0; x < png.width; x += 37) {
      EXPECT_EQ(at(png, x, d), expected) << what << " top border at " << x << "," << d;
      EXPECT_EQ(at(png, x, png.height - 1 - d), expected) << what << " bottom border at " << x;
      checked += 2;
    }
    for (int y = 0; y < png.height; y += 29) {
      EXPECT_EQ(at(png, d, y), expected) << what << " left border at " << d << "," << y;
      EXPECT_EQ(at(png, png.width - 1 - d, y), expected) << what << " right border at " << y;
      checked += 2;
    }
  }
  EXPECT_GT(checked, 100);
}

class ViewerGl : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (scripts/setup installs xvfb, xauth, libgl1-mesa-dri)";
  }
};

TEST_F(ViewerGl, WalkSnapshotsShowTheVerdictAndTheClosestPoint) {
  const fs::path dir = fresh_dir("walk");
  // An empty cell, far (the person just in, 2.2 m), slow (0.74 m) and stop (0.29 m).
  const std::set<int64_t> picks{108, 120, 162, 198};
  const std::string command = kXvfb + kView + " --config " + kSource + "/config/walk.yaml --snapshot " +
                              dir.string() + " --snapshot-at 108,120,162,198 --out " + (dir / "run.jsonl").string() +
                              " 2> " + (dir / "stderr.txt").string();
  ASSERT_EQ(shell(command), 0) << "see " << (dir / "stderr.txt");
  const Jsonl run = read_jsonl(dir / "run.jsonl");
  const Config config = load_config(kSource + "/config/walk.yaml", {});
  const ColorCamera camera = color_camera(config);
  const ScreenMap map = screen_map(camera.intrinsics.width, camera.intrinsics.height);
  std::set<std::string> verdicts;
  int markers_checked = 0;
  for (int64_t f : picks) {
    SCOPED_TRACE("frame " + std::to_string(f));
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%06lld.png", static_cast<long long>(f));
    ColorImage png;
    read_color_png((dir / name).string(), png);
    ASSERT_EQ(png.width, 1280);
    ASSERT_EQ(png.height, 720);
    ASSERT_TRUE(run.frames.count(f));
    const nlohmann::json& line = run.frames.at(f);
    const std::string verdict = line["verdict"].get<std::string>();
    verdicts.insert(verdict);
    expect_border(png, verdict_color(verdict), verdict);
    // Not blank: the pane holds many colours.
    std::set<uint32_t> colors;
    for (int y = 100; y < 600; y += 7) {
      for (int x = 150; x < 1100; x += 7) {
        const Rgb c = at(png, x, y);
        colors.insert((uint32_t{c[0]} << 16) | (uint32_t{c[1]} << 8) | c[2]);
      }
    }
    EXPECT_GT(colors.size(), 30U);
    if (line["distance_m"].is_null()) continue;
    // The closest point: its camera-frame position from the output, projected by this test.
    const Eigen::Vector2d image_px = camera.project(vec3(line["closest_camera"]));
    // The depth camera sees a little more than the colour camera at the image's right edge:
    // a point outside the colour image has no marker (frame 120).
    if (image_px.x() < 8 || image_px.y() < 8 || image_px.x() > camera.intrinsics.width - 8 ||
        image_px.y() > camera.intrinsics.height - 8) {
      continue;
    }
    const Eigen::Vector2d expected = map(image_px);
    ++markers_checked;
    const Blob marker = find_color(png, kContactMarker, expected, 20);
    ASSERT_GT(marker.count, 20) << "no closest-point marker near " << expected.transpose();
    EXPECT_LE((marker.centroid - expected).norm(), 3.0) << "marker at " << marker.centroid.transpose()
                                                         << ", the point projects to " << expected.transpose();
    // The robot point (walk.yaml's fixed robot point; base frame = camera frame).
    const Eigen::Vector2d robot_expected = map(camera.project(vec3(line["closest_robot_base"])));
    const Blob robot = find_color(png, kRobotMarker, robot_expected, 20);
    ASSERT_GT(robot.count, 10);
    EXPECT_LE((robot.centroid - robot_expected).norm(), 3.0);
  }
  EXPECT_GE(markers_checked, 2);
  // The picks cover every verdict.
  EXPECT_TRUE(verdicts.count("run") && verdicts.count("slow") && verdicts.count("stop"))
      << "walk.yaml's frames 108, 120, 162, 198 no longer give run, slow and stop";
}

TEST_F(ViewerGl, MovingArmIsDrawnWhereItsCapsulesProject) {
  const fs::path dir = fresh_dir("arm");
  const int64_t pick = 140;
  const std::string config_path = kSource + "/config/cell-ur5-moving.yaml";
  const std::string command = kXvfb + kView + " --config " + config_path + " --snapshot " + dir.string() +
                              " --snapshot-at " + std::to_string(pick) + " --out " + (dir / "run.jsonl").string() +
                              " 2> " + (dir / "stderr.txt").string();
  ASSERT_EQ(shell(command), 0) << "see " << (dir / "stderr.txt");
  const Jsonl run = read_jsonl(dir / "run.jsonl");
  ASSERT_TRUE(run.frames.count(pick));
  const nlohmann::json& line = run.frames.at(pick);
  ASSERT_TRUE(line["valid"].get<bool>());
  ColorImage png;
  read_color_png((dir / "frame_000140.png").string(), png);
  const Config config = load_config(config_path, {});
  const ColorCamera camera = color_camera(config);
  const ScreenMap map = screen_map(camera.intrinsics.width, camera.intrinsics.height);
  // The capsules from the output's joint angles through the arm's kinematics.
  JointAngles q{};
  for (int j = 0; j < kJointCount; ++j) q[static_cast<size_t>(j)] = line["joints_rad"][j].get<double>();
  const RobotModel arm = robot_model_at(config.pipeline.robot, q);
  const Pose T_camera_base = config.pipeline.T_base_camera.inverse();
  int interiors = 0, outlined = 0, samples = 0;
  for (const Capsule& capsule : arm.capsules) {
    for (double s : {0.25, 0.5, 0.75}) {
      const Eigen::Vector3d p_base = (capsule.a + static_cast<float>(s) * (capsule.b - capsule.a)).cast<double>();
      const Eigen::Vector3d p_camera = T_camera_base * p_base;
      if (p_camera.z() < 0.2) continue;
      const Eigen::Vector2d image_px = camera.project(p_camera);
      if (image_px.x() < 0 || image_px.y() < 0 || image_px.x() > camera.intrinsics.width - 1 ||
          image_px.y() > camera.intrinsics.height - 1) {
        continue;
      }
      const double radius_px = camera.intrinsics.fx * capsule.radius_m / p_camera.z() * map.scale_x;
      if (radius_px < 5.0) continue;
      const Eigen::Vector2d screen = map(image_px);
      ++samples;
      // The axis is inside the drawn silhouette: brightened halfway to white (every channel at
      // least 127), no outline there.
      const Rgb c = at(png, static_cast<int>(screen.x()), static_cast<int>(screen.y()));
      if (c != kRobotOutline && c[0] >= 127 && c[1] >= 127 && c[2] >= 127) ++interiors;
      // The outline lies about one projected radius away from the axis in some direction.
      bool found = false;
      for (int k = 0; k < 16 && !found; ++k) {
        const double angle = k * M_PI / 8.0;
        for (double r = 0.6 * radius_px; r <= radius_px + 3.0 && !found; r += 0.5) {
          const int x = static_cast<int>(screen.x() + r * std::cos(angle));
          const int y = static_cast<int>(screen.y() + r * std::sin(angle));
          if (x >= 0 && y >= 0 && x < png.width && y < png.height && at(png, x, y) == kRobotOutline) found = true;
        }
      }
      outlined += found ? 1 : 0;
    }
  }
  ASSERT_GE(samples, 6) << "too few capsule samples in view at frame " << pick;
  EXPECT_EQ(interiors, samples);
  EXPECT_GE(outlined * 10, samples * 7);  // overlapping capsules hide some outlines
  expect_border(png, verdict_color(line["verdict"].get<std::string>()), "arm");
}

TEST_F(ViewerGl, FrozenPipelineShowsNoDataNeverGreen) {
  // A renderer that draws frame 108 0.8 s after the pipeline made it, the pipeline waiting for
  // the snapshot meanwhile: the newest result is older than safety.max_frame_age_s (0.5 s).
  const fs::path dir = fresh_dir("nodata");
  const std::string command = kXvfb + kView + " --config " + kSource + "/config/walk.yaml --snapshot " +
                              dir.string() + " --snapshot-at 108 --slow-render-ms 800 --out " +
                              (dir / "run.jsonl").string() + " 2> " + (dir / "stderr.txt").string();
  ASSERT_EQ(shell(command), 0) << "see " << (dir / "stderr.txt");
  const Jsonl run = read_jsonl(dir / "run.jsonl");
  ASSERT_EQ(run.frames.at(108)["verdict"], "run");  // the pipeline said run for it
  ColorImage png;
  read_color_png((dir / "frame_000108.png").string(), png);
  expect_border(png, kNoDataColor, "no data");
  for (int x = 0; x < png.width; x += 13) EXPECT_NE(at(png, x, 3), kRunColor);
}

TEST_F(ViewerGl, SlowViewerCostsTheOutputNoFrame) {
  // A paced cell at 5 frames/s and a viewer three times slower than the camera: the viewer
  // drops pictures, the pipeline none. 5 frames/s rather than 30 leaves the pipeline 200 ms
  // per frame, so a loaded 2-core machine running llvmpipe beside it does not drop a frame
  // for reasons that have nothing to do with the viewer (the family also runs alone).
  const fs::path dir = fresh_dir("slow");
  const std::string command = kXvfb + kView + " --config " + kSource +
                              "/config/walk.yaml --set source.pace=true --set sim.fps=5 --frames 45 "
                              "--slow-render-ms 600 --out " +
                              (dir / "run.jsonl").string() + " 2> " + (dir / "stderr.txt").string();
  ASSERT_EQ(shell(command), 0) << "see " << (dir / "stderr.txt");
  const Jsonl run = read_jsonl(dir / "run.jsonl");
  for (int64_t f = 0; f < 45; ++f) EXPECT_TRUE(run.frames.count(f)) << "frame " << f << " missing";
  EXPECT_EQ(run.summary["frames_processed"], 45);
  EXPECT_EQ(run.summary["frames_dropped"], 0);
  ASSERT_TRUE(run.summary["viewer_frames_dropped"].is_number_integer());
  EXPECT_GT(run.summary["viewer_frames_dropped"].get<int64_t>(), 0);
}

TEST_F(ViewerGl, CloudPaneShowsTheArmAndTheClosestPair) {
  // The moving arm at frame 300: the hand 0.23 m from the arm, stop. The 3D pane alone.
  const fs::path dir = fresh_dir("cloud");
  const std::string command = kXvfb + kView + " --config " + kSource + "/config/cell-ur5-moving.yaml --pane 3d --snapshot " +
                              dir.string() + " --snapshot-at 300 --out " + (dir / "run.jsonl").string() + " 2> " +
                              (dir / "stderr.txt").string();
  ASSERT_EQ(shell(command), 0) << "see " << (dir / "stderr.txt");
  const Jsonl run = read_jsonl(dir / "run.jsonl");
  const nlohmann::json& line = run.frames.at(300);
  ASSERT_EQ(line["verdict"], "stop");
  ColorImage png;
  read_color_png((dir / "frame_000300.png").string(), png);
  expect_border(png, kStopColor, "cloud");
  // The pane: the window inside the border, above the 150 px strip (whose text is white too).
  ColorImage pane;
  pane.width = 1280 - 24;
  pane.height = 720 - 24 - 150;
  pane.rgb.resize(static_cast<size_t>(pane.width) * pane.height * 3);
  for (int y = 0; y < pane.height; ++y) {
    std::copy_n(&png.rgb[3 * (static_cast<size_t>(y + 12) * png.width + 12)], 3 * pane.width,
                &pane.rgb[3 * static_cast<size_t>(y) * pane.width]);
  }
  const Eigen::Vector2d centre(pane.width / 2.0, pane.height / 2.0);
  const int half = pane.width / 2;
  const Blob contact = find_color(pane, kContactMarker, centre, half);
  const Blob robot = find_color(pane, kRobotMarker, centre, half);
  const Blob outline = find_color(pane, kRobotOutline, centre, half);
  const Blob joining = find_color(pane, kContactLine, centre, half);
  EXPECT_GE(contact.count, 20);   // a disc of radius 4 px: 49 pixels, less what the other covers
  EXPECT_GE(robot.count, 20);
  EXPECT_GE(outline.count, 100);  // the arm's edge
  // 0.23 m apart a few metres from the orbit camera: tens of pixels, never across the pane.
  EXPECT_LT((contact.centroid - robot.centroid).norm(), 120.0);
  EXPECT_GE(joining.count + contact.count, 20);
}

bool have_xdotool() { return std::system("command -v xdotool > /dev/null 2>&1") == 0; }

// The window as a person uses it, keys sent by xdotool: space pauses a replay, `s` writes a
// screenshot, `.` steps one frame, `q` quits. While paused no frame reaches the pipeline, so
// its watchdog writes stops (no_frame) and the view says NO DATA: a paused replay never says run.
TEST_F(ViewerGl, PausedReplayStopsTheCellAndStepsOneFrame) {
  if (!have_xdotool()) GTEST_SKIP() << "xdotool not installed (scripts/setup installs it)";
  const fs::path dir = fresh_dir("replay");
  const std::string config = kSource + "/config/walk.yaml";
  ASSERT_EQ(shell(std::string(HRCSENSE_CLI) + " record --config " + config + " --out " + (dir / "walk.bag").string() +
                  " 2> " + (dir / "record.txt").string()),
            0)
      << "see " << (dir / "record.txt");
  // The watchdog at max_frame_age_s (0.5 s, 15 periods) rather than 2 frame periods: this test
  // is about pausing, and a paced replay that falls behind its 30 frames/s on a loaded machine
  // (the viewer renders with llvmpipe beside it) would get watchdog stops of its own.
  const std::string view = kView + " --config " + config + " --set source.type=bag --set source.path=walk.bag" +
                           " --set source.pace=true --set safety.max_frame_gap_periods=15 --out run.jsonl 2> stderr.txt";
  // Every wait is bounded: xdotool's search by `timeout`, the viewer by the replay's length.
  const std::string script = "cd " + dir.string() + " && " + view +
                             " & pid=$!; w=$(timeout 30 xdotool search --sync --name hrcsense-view | head -1); "
                             "xdotool windowfocus --sync \"$w\"; sleep 1; xdotool key space; sleep 1.5; xdotool key s; "
                             "sleep 0.5; xdotool key period; sleep 1; xdotool key s; sleep 0.5; xdotool key q; wait $pid";
  ASSERT_EQ(shell(kXvfb + "sh -c '" + script + "' > " + (dir / "xdotool.txt").string() + " 2>&1"), 0)
      << "see " << (dir / "stderr.txt");
  std::vector<int64_t> shots;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("frame_", 0) == 0) shots.push_back(std::stoll(name.substr(6, 6)));
  }
  std::sort(shots.begin(), shots.end());
  ASSERT_EQ(shots.size(), 2U) << "see " << (dir / "stderr.txt");
  EXPECT_EQ(shots[1], shots[0] + 1);  // `.` let exactly one frame through
  ColorImage paused;
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06lld.png", static_cast<long long>(shots[0]));
  read_color_png((dir / name).string(), paused);
  expect_border(paused, kNoDataColor, "paused");

  // The output: the watchdog's stops while paused, between the two frames; the run ended by q.
  std::ifstream in(dir / "run.jsonl");
  std::string text;
  int watchdog_stops = 0;
  int64_t last_frame = -1;
  nlohmann::json summary;
  while (std::getline(in, text)) {
    const nlohmann::json j = nlohmann::json::parse(text);
    if (j["type"] == "summary") summary = j;
    if (j["type"] == "verdict" && j["reason_code"] == "no_frame") {  // a stop that stands for no frame
      EXPECT_EQ(j["verdict"], "stop");
      EXPECT_EQ(j["frame"].get<int64_t>(), last_frame);  // repeats the last frame's index
      // Paused at the first screenshot's frame, then (after the step) at the second's.
      EXPECT_TRUE(last_frame == shots[0] || last_frame == shots[1]) << last_frame;
      watchdog_stops += last_frame == shots[0] ? 1 : 0;
    }
    if (j["type"] == "frame") last_frame = j["frame"].get<int64_t>();
  }
  EXPECT_GE(watchdog_stops, 2);  // 1.5 s paused at frame shots[0], safety.max_frame_age_s 0.5 s
  EXPECT_EQ(summary["end_reason_code"], "stop_requested") << summary.dump();
  EXPECT_LT(summary["frames_in"].get<int64_t>(), 201);
}

TEST(ViewerNoDisplay, OneLineAndANonZeroExit) {
  const fs::path dir = fresh_dir("nodisplay");
  const std::string command = "env -u DISPLAY -u WAYLAND_DISPLAY " + kView + " --config " + kSource +
                              "/config/walk.yaml --frames 5 > " + (dir / "out.txt").string() + " 2> " +
                              (dir / "err.txt").string();
  const int code = shell(command);
  EXPECT_NE(code, 0);
  EXPECT_LT(code, 128);  // an exit, not a signal
  std::ifstream err(dir / "err.txt");
  std::string first, rest;
  std::getline(err, first);
  EXPECT_NE(first.find("no display"), std::string::npos) << first;
  EXPECT_FALSE(std::getline(err, rest)) << "more than one line: " << rest;
}

}  // namespace
}  // namespace hrcsense::view
