// SPDX-License-Identifier: Apache-2.0
// `hrcsense-view --fused` end to end, headless under `xvfb-run -a` with Mesa's llvmpipe: fake
// cameras of config/cell-ur5-3cam.yaml (their measurement, cloud and depth preview) and a fake
// fuser's verdict published from this process on loopback; the viewer, a child process, writes
// one fused PNG: the border in the verdict's colour (run: green), each camera's colour present
// (clouds, frusta, previews' frames), the pair's foreground marker. Skips without xvfb-run.
#if HRCSENSE_HAVE_DDS

#include "viewer/fused_view.hpp"

#include "dds/camera_previews.hpp"
#include "dds/dds_entity.hpp"
#include "dds/measurement_messages.hpp"
#include "dds/ros2_output_messages.hpp"
#include "tests/dds/dds_test_util.hpp"

#include "hrcsense/clock.hpp"
#include "hrcsense/io/io.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::fused_snapshot_test {
namespace {

namespace fs = std::filesystem;

view::Rgb png_pixel(const ColorImage& image, int x, int y) {
  const size_t i = 3 * (static_cast<size_t>(y) * image.width + x);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

int png_count(const ColorImage& image, const view::Rgb& color) {
  int n = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) n += png_pixel(image, x, y) == color ? 1 : 0;
  }
  return n;
}

// One fake camera process of the cell and the fake fuser's verdict, all on one participant.
class FakeCell {
 public:
  FakeCell(uint32_t domain, const std::vector<std::string>& names) : scope_(domain) {
    const ros2::QosHandle qos(ros2::EndpointQos{true, false, 1});
    for (const std::string& name : names) {
      const std::string topic = ros2::dds_topic_name(ros2::measurement_topic("/hrcsense", name));
      const dds_entity_t t = scope_.own(dds_create_topic(scope_.participant(), &hrcsense_msgs_msg_dds__Measurement__desc,
                                                         topic.c_str(), nullptr, nullptr),
                                        "topic");
      measurement_writers_.push_back(scope_.own(dds_create_writer(scope_.participant(), t, qos.get(), nullptr), "writer"));
      ros2::CameraPreviewParams params;
      params.domain_id = domain;
      params.camera_name = name;
      previews_.push_back(std::make_unique<ros2::CameraPreviewWriter>(params));
      names_.push_back(name);
    }
    const dds_entity_t t = scope_.own(dds_create_topic(scope_.participant(), &hrcsense_msgs_msg_dds__Verdict__desc,
                                                       "rt/hrcsense/verdict", nullptr, nullptr),
                                      "topic");
    verdict_writer_ = scope_.own(dds_create_writer(scope_.participant(), t, qos.get(), nullptr), "writer");
  }

  // Every camera sees one person 0.3 m above (index + 1) × 0.5 m over the floor at x 1 m; the
  // second camera's contact (0.25 m) is the fused pair.
  void publish_all() {
    const int64_t now_ns = shared_clock_ns();
    for (size_t i = 0; i < names_.size(); ++i) {
      CameraMeasurement m;
      m.camera_name = names_[i];
      m.session = 11;
      m.sequence = ++sequence_;
      m.nominal_fps = 30.0;
      m.capture_ns = now_ns - static_cast<int64_t>(i) * 20'000'000;
      m.valid = true;
      m.reason_code = ReasonCode::clear;
      m.T_base_camera = Pose::Identity();
      m.T_base_camera.translation() = Eigen::Vector3d(2.0 * std::cos(2.1 * i), 2.0 * std::sin(2.1 * i), 1.6);
      LinkContact link;
      link.link = 2;
      link.contact.valid = true;
      link.contact.distance_m = i == 1 ? 0.25F : 0.6F;
      link.contact.closest_robot_base = Eigen::Vector3f(0.3F, 0.0F, 0.8F);
      link.contact.closest_base = Eigen::Vector3f(0.3F + link.contact.distance_m, 0.0F, 0.8F);
      link.contact.robot_link = 2;
      m.links = {link};
      m.contact = link.contact;
      const hrcsense_msgs_msg_dds__Measurement_ msg = ros2::measurement_message(m, "base", buffers_);
      dds_write(measurement_writers_[i], &msg);
      PointCloud cloud;
      for (int k = 0; k < 400; ++k) {
        cloud.x.push_back(1.0F + 0.005F * static_cast<float>(k % 20));
        cloud.y.push_back(-0.5F + static_cast<float>(i) * 0.5F);
        cloud.z.push_back(0.5F + 0.01F * static_cast<float>(k / 20));
      }
      previews_[i]->write_cloud(cloud, m.capture_ns);
      ros2::DepthPreview preview;
      preview.width = 212;
      preview.height = 120;
      preview.depth_mm.assign(212 * 120, static_cast<uint16_t>(1000 + 500 * i));
      preview.timestamp_ns = m.capture_ns;
      previews_[i]->write_depth_preview(preview);
    }
    hrcsense_msgs_msg_dds__Verdict_ verdict{};
    verdict.header.stamp = ros2::stamp_from_ns(now_ns);
    verdict.header.frame_id = const_cast<char*>("base");
    verdict.verdict = 0;  // run
    verdict.distance_m = 0.25F;
    verdict.governing_link = 2;
    dds_write(verdict_writer_, &verdict);
  }

 private:
  ros2::ParticipantScope scope_;
  std::vector<std::string> names_;
  std::vector<dds_entity_t> measurement_writers_;
  std::vector<std::unique_ptr<ros2::CameraPreviewWriter>> previews_;
  dds_entity_t verdict_writer_ = 0;
  ros2::MeasurementBuffers buffers_;
  uint64_t sequence_ = 0;
};

TEST(FusedSnapshot, OnePictureOfThreeFakeCamerasAndTheFusersVerdict) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) GTEST_SKIP() << "xvfb-run is not installed";
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint32_t domain = test::test_domain();
  const fs::path dir = fs::temp_directory_path() / ("hrcsense_fused_snapshot_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  FakeCell cell(domain, {"front", "left", "overhead_back"});
  std::atomic<bool> done{false};
  // The cameras write every 50 ms while the viewer runs (bounded: 30 s at most).
  std::thread cameras([&] {
    for (int turn = 0; turn < 600 && !done.load(); ++turn) {
      cell.publish_all();
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  const std::string command = "xvfb-run -a -s '-screen 0 1280x1024x24' " + std::string(HRCSENSE_VIEW) +
                              " --config " + HRCSENSE_SOURCE_DIR + "/config/cell-ur5-3cam.yaml --set ros2.domain_id=" +
                              std::to_string(domain) + " --fused --snapshot " + dir.string() +
                              " --snapshot-wait-s 20 2> " + (dir.string() + ".log");
  const int status = std::system(command.c_str());
  done.store(true);
  cameras.join();
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0) << "see " << dir.string() << ".log";
  ColorImage png;
  read_color_png((dir / "fused.png").string(), png);
  ASSERT_EQ(png.width, 1280);
  ASSERT_EQ(png.height, 720);
  // The fuser's run: the border green, the viewer's own never.
  EXPECT_EQ(png_pixel(png, 3, 3), view::kRunColor);
  EXPECT_EQ(png_pixel(png, 1276, 716), view::kRunColor);
  for (size_t i = 0; i < 3; ++i) EXPECT_GT(png_count(png, view::fused_camera_color(i)), 100) << "camera " << i;
  EXPECT_GT(png_count(png, view::kContactMarker), 10);
  fs::remove_all(dir);
  fs::remove(dir.string() + ".log");
}

}  // namespace
}  // namespace hrcsense::fused_snapshot_test

#endif  // HRCSENSE_HAVE_DDS
