// SPDX-License-Identifier: Apache-2.0
// The fuzz targets' per-input code (see fuzz_entries.hpp). Besides "no crash, no leak, no
// sanitizer report, no allocation over -malloc_limit_mb", it checks the sources' contract and
// aborts when it is broken: an error is never empty and names the file, and a failed source
// stays failed (fail safe: no frames after damage).
#include "fuzz_entries.hpp"

#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"
#include "hrcsense/robot_state_history.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <vector>

namespace hrcsense::fuzz {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void contract_broken(const std::string& what, const std::string& detail) {
  std::fprintf(stderr, "fuzz: source contract broken: %s: %s\n", what.c_str(), detail.c_str());
  std::abort();
}

/// Plays `source` to its end or first error and checks the error contract; with `states` (a
/// bag's recorded joint states), looks each frame's state up as the pipeline would.
Outcome play(Source& source, const std::string& path, RobotStateSource* states = nullptr) {
  Outcome out;
  (void)source.info();
  Frame frame;
  Source::Status status = Source::Status::frame;
  while ((status = source.next(frame)) == Source::Status::frame) {
    ++out.frames;
    RobotState state;
    if (states != nullptr && states->state_at(frame.timestamp_ns, state) &&
        !(state.valid && all_finite(state.q_rad) && all_finite(state.qd_rad_s))) {
      contract_broken("a recorded joint state is invalid or not finite", path);
    }
  }
  if (status == Source::Status::error) {
    out.error = source.error();
    // Folder errors name the frame and the file that failed, which a list may place anywhere.
    if (out.error.find(path) == std::string::npos && out.error.rfind("frame ", 0) != 0) {
      contract_broken("error names neither the file nor the frame", out.error);
    }
    if (source.next(frame) != Source::Status::error) contract_broken("a failed source recovered", out.error);
  }
  return out;
}

/// summarize_recording (`hrcsense info`) on the same input: it may throw IoError, nothing else.
void summarize(const std::string& path) {
  try {
    const RecordingSummary summary = summarize_recording(path);
    if (summary.streams.empty()) contract_broken("summary without a depth stream", path);
  } catch (const IoError& e) {
    if (std::string(e.what()).find(path) == std::string::npos) contract_broken("error does not name the file", e.what());
  }
}

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!file) contract_broken("cannot write the fuzz input", path.string());
}

std::string read_file(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

/// Where run_bag puts its input: an in-memory file (memfd) when the kernel has them, so the
/// fuzzer does not wear a disk; else a file in the temp folder.
struct BagFile {
  std::string path;
  int fd = -1;
  BagFile() {
    fd = memfd_create("hrcsense_fuzz_bag", MFD_CLOEXEC);
    path = fd >= 0 ? "/proc/self/fd/" + std::to_string(fd)
                   : (fs::temp_directory_path() / ("hrcsense_fuzz_" + std::to_string(getpid()) + ".bag")).string();
  }
  ~BagFile() {
    if (fd >= 0) {
      close(fd);
    } else {
      std::remove(path.c_str());
    }
  }
  void write(const uint8_t* data, size_t size) const {
    if (fd < 0) return write_file(path, std::string(reinterpret_cast<const char*>(data), size));
    if (ftruncate(fd, 0) != 0) contract_broken("cannot reset the memfd", path);
    size_t done = 0;
    while (done < size) {
      const ssize_t n = pwrite(fd, data + done, size - done, static_cast<off_t>(done));
      if (n <= 0) contract_broken("cannot write the memfd", path);
      done += static_cast<size_t>(n);
    }
  }
};

DepthImage ramp_depth(int first) {
  DepthImage depth;
  depth.resize(8, 6);
  for (size_t i = 0; i < depth.pixels.size(); ++i) depth.pixels[i] = static_cast<uint16_t>(first + 10 * static_cast<int>(i));
  return depth;
}

ColorImage gradient_color(int shift) {
  ColorImage color{8, 6, std::vector<uint8_t>(8 * 6 * 3)};
  for (size_t i = 0; i < color.rgb.size(); ++i) color.rgb[i] = static_cast<uint8_t>(shift + 5 * static_cast<int>(i));
  return color;
}

/// Two tiny valid folders (ist and TUM layout) in a per-process temp folder; run_folder
/// replaces one file, plays, and puts the valid file back.
struct FolderBase {
  fs::path root;
  std::map<FolderTarget, fs::path> files;
  std::map<FolderTarget, std::string> valid;

  FolderBase() : root(fs::temp_directory_path() / ("hrcsense_fuzz_folders_" + std::to_string(getpid()))) {
    fs::remove_all(root);
    const fs::path ist = root / "ist", tum = root / "tum";
    for (const fs::path& dir : {ist / "depth", ist / "rgb", tum / "depth", tum / "rgb"}) fs::create_directories(dir);
    write_depth_png((ist / "depth/000000.png").string(), ramp_depth(500));
    write_depth_png((ist / "depth/000001.png").string(), ramp_depth(900));
    write_color_png((ist / "rgb/000000.png").string(), gradient_color(0));
    if (jpeg_supported()) write_color_jpeg((ist / "rgb/000001.jpg").string(), gradient_color(40), 80);
    write_file(ist / "intrinsics.json",
               R"({"pixel_convention": "1-based", "depth_units_m": 0.001, "width": 8, "height": 6,)"
               R"( "depth_K": [[6.5, 0, 4.5], [0, 6.25, 3.5], [0, 0, 1]],)"
               R"( "rgb_K": [[7, 0, 4], [0, 7, 3], [0, 0, 1]],)"
               R"( "depth_to_rgb_R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "depth_to_rgb_T_m": [-0.025, 0, 0]})");
    write_file(ist / "frames.txt", "# index depth rgb\n0 depth/000000.png rgb/000000.png\n1 depth/000001.png rgb/000001.jpg\n");
    write_depth_png((tum / "depth/1.png").string(), ramp_depth(5000));
    write_depth_png((tum / "depth/2.png").string(), ramp_depth(6000));
    write_color_png((tum / "rgb/1.png").string(), gradient_color(7));
    write_color_png((tum / "rgb/2.png").string(), gradient_color(9));
    write_file(tum / "depth.txt", "# timestamp filename\n1305031102.160407 depth/1.png\n1305031102.194330 depth/2.png\n");
    write_file(tum / "rgb.txt", "# timestamp filename\n1305031102.175304 rgb/1.png\n1305031102.211214 rgb/2.png\n");
    write_file(tum / "intrinsics.json",
               R"({"width": 8, "height": 6, "fx": 6.5, "fy": 6.25, "ppx": 3.5, "ppy": 2.5, "model": "Brown Conrady",)"
               R"( "coeffs": [0, 0, 0, 0, 0]})");
    files = {{FolderTarget::depth_png, ist / "depth/000000.png"}, {FolderTarget::dataset_json, ist / "intrinsics.json"},
             {FolderTarget::frames_txt, ist / "frames.txt"},      {FolderTarget::color_png, ist / "rgb/000000.png"},
             {FolderTarget::color_jpeg, ist / "rgb/000001.jpg"},  {FolderTarget::depth_txt, tum / "depth.txt"},
             {FolderTarget::rgb_txt, tum / "rgb.txt"},            {FolderTarget::hrcsense_json, tum / "intrinsics.json"}};
    for (const auto& [target, path] : files) valid[target] = read_file(path);
  }
  ~FolderBase() {
    std::error_code ignored;
    fs::remove_all(root, ignored);
  }
};

FolderBase& folder_base() {
  static FolderBase base;
  return base;
}

}  // namespace

Outcome run_bag(const uint8_t* data, size_t size) {
  static const BagFile file;
  file.write(data, size);
  Outcome out;
  try {
    RecordingParams params{file.path};
    params.with_color = true;
    params.with_joint_states = true;  // the JointState parser of /hrcsense/joint_states too
    BagSource source(params);
    const std::unique_ptr<RobotStateSource> states = source.recorded_robot_state();
    out = play(source, file.path, states.get());
  } catch (const IoError& e) {
    out.error = e.what();
    if (out.error.find(file.path) == std::string::npos) contract_broken("error does not name the file", out.error);
  }
  summarize(file.path);
  return out;
}

Outcome run_folder(const uint8_t* data, size_t size) {
  if (size == 0) return {};
  FolderBase& base = folder_base();
  const auto target = static_cast<FolderTarget>(data[0] % kFolderTargets);
  const fs::path& file = base.files.at(target);
  write_file(file, std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  const std::string folder = file.parent_path().filename() == "ist" || file.parent_path().filename() == "tum"
                                 ? file.parent_path().string()
                                 : file.parent_path().parent_path().string();
  Outcome out;
  try {
    RecordingParams params{folder};
    params.with_color = true;
    FolderSource source(params);
    out = play(source, folder);
  } catch (const IoError& e) {
    out.error = e.what();
    if (out.error.find(folder) == std::string::npos) contract_broken("error does not name the file", out.error);
  }
  summarize(folder);
  write_file(file, base.valid.at(target));
  return out;
}

std::string folder_seed(FolderTarget target) {
  return std::string(1, static_cast<char>(target)) + folder_base().valid.at(target);
}

namespace {

// What the stages would compute with: a non-finite value here would reach the pipeline.
bool stage_parameters_finite(const Config& c) {
  const PipelineParams& p = c.pipeline;
  bool ok = p.T_base_camera.matrix().allFinite() && std::isfinite(p.safety.slow_distance_m) &&
            std::isfinite(p.safety.stop_distance_m) && std::isfinite(p.safety.max_frame_age_s) &&
            std::isfinite(p.safety.min_valid_share) && std::isfinite(p.foreground.k_sigma) &&
            std::isfinite(p.foreground.min_margin_m) && std::isfinite(p.foreground.min_object_mm) &&
            std::isfinite(p.filters.threshold.min_m) && std::isfinite(p.filters.threshold.max_m);
  for (const Capsule& capsule : fixed_robot_model(c).capsules) {
    ok = ok && capsule.a.allFinite() && capsule.b.allFinite() && std::isfinite(capsule.radius_m);
  }
  // The stopping data give a finite stop at any speed up to the arm's fastest.
  const SsmParams& ssm = p.safety.ssm;
  for (const double v : {0.0, 0.5, static_cast<double>(ssm.robot_max_speed_mps)}) {
    const StopProfile stop = robot_stop(ssm, v);
    ok = ok && std::isfinite(stop.distance_m) && std::isfinite(stop.time_s) && stop.distance_m >= 0.0;
  }
  ok = ok && std::isfinite(ssm.source_latency_s) && std::isfinite(ssm.receiver_timeout_s);
  return ok;
}

}  // namespace

// `hrcsense calibrate --write-back`'s edit of the same text (with_camera_pose_text): a ConfigError
// naming the file, or a text that load_config reads with the new pose for that entry.
void check_pose_write_back(const std::string& text, const std::string& camera, const fs::path& path) {
  static const fs::path edited_path =
      fs::temp_directory_path() / ("hrcsense_fuzz_write_back_" + std::to_string(::getpid()) + ".yaml");
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(0.25, -0.5, 1.75);
  std::string edited;
  try {
    edited = with_camera_pose_text(text, camera, T, path.string());
  } catch (const ConfigError& e) {
    if (std::string(e.what()).find(path.string()) == std::string::npos) contract_broken("write-back error names no file", e.what());
    return;
  }
  {
    std::ofstream file(edited_path, std::ios::binary | std::ios::trunc);
    file << edited;
  }
  const Config config = load_config(edited_path.string(), {});  // a ConfigError here escapes: a crash
  for (const CameraEntry& entry : config.cameras) {
    if (entry.name == camera && (entry.T_base_camera.translation() - T.translation()).norm() > 1e-5) {
      contract_broken("write-back", "the edited entry does not read back the written pose");
    }
  }
}

Outcome run_config(const uint8_t* data, size_t size) {
  static const fs::path path = fs::temp_directory_path() / ("hrcsense_fuzz_config_" + std::to_string(::getpid()) + ".yaml");
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  Outcome out;
  try {
    const Config config = load_config(path.string(), {});
    if (!stage_parameters_finite(config)) contract_broken("config", "loaded with a non-finite stage parameter");
    out.frames = 1;
    const std::string text(reinterpret_cast<const char*>(data), size);
    for (const CameraEntry& entry : config.cameras) check_pose_write_back(text, entry.name, path);
  } catch (const ConfigError& e) {
    out.error = e.what();
    if (out.error.find(path.string()) == std::string::npos) contract_broken("config error names no file", out.error);
  }
  // Any other exception escapes: libFuzzer reports it as a crash (the contract says ConfigError).
  return out;
}

}  // namespace hrcsense::fuzz
