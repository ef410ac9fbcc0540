// SPDX-License-Identifier: Apache-2.0
// hrcsense config — a cell with several cameras (H2): the `cameras:` list, `--camera NAME`'s
// overlay of one entry on the top-level keys, `cell.*` (the shared seen-free grid) and
// `sim.epoch` (the shared scene clock). docs/CONFIG.md, "cameras" and "cell".
#include "cameras_config.hpp"

#include "yaml_tree.hpp"

#include "hrcsense/fusion.hpp"
#include "hrcsense/number_text.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <string>
#include <utility>

namespace hrcsense::config_detail {
namespace {

/// Cubes of the seen-free grid: at most 8 million (one bit each per camera and frame, and the
/// fuser's union), so that a mistyped voxel or box cannot allocate gigabytes.
constexpr double kMaxGridCells = 8e6;
/// `cell.clock_offset_max_s`: a second is far beyond any synchronised clock (chrony on a LAN keeps
/// well under 1 ms); more is a unit mistake.
constexpr double kMaxClockOffsetS = 1.0;
/// `cell.voxel_m`: 1 cm (finer is below the cameras' noise at a cell's distances) to 0.5 m
/// (coarser hides a person's arm in a cube seen free around it).
constexpr float kMinVoxelM = 0.01F;
constexpr float kMaxVoxelM = 0.5F;
/// `sim.epoch`: up to 4e9 s (the year 2096), so that epoch + sim.frames / sim.fps (at most 1e18
/// ns) stays inside int64 nanoseconds.
constexpr double kMaxEpochS = 4e9;

std::string entry_key(size_t index) { return "cameras[" + std::to_string(index) + "]"; }

// Whether `key` is a section of known keys (some known key starts with `key`.).
bool holds_known_keys(const std::set<std::string>& known, const std::string& key) {
  const auto next = known.lower_bound(key + ".");
  return next != known.end() && next->compare(0, key.size() + 1, key + ".") == 0;
}

// Every key below `map` (a `source:` or `sim:` map of an entry) must be `section`.<path> that the
// reader knows, or a section of such keys whose value is a map, looked into in turn. `shown` is
// the map's key as the file has it (cameras[1].source).
void check_overlay_keys(const YAML::Node& map, const std::string& section, const std::string& shown,
                        const std::string& where, const std::set<std::string>& known) {
  for (const auto& item : map) {
    const std::string name = item.first.Scalar();
    const std::string key = section + "." + name;
    const std::string shown_key = shown + "." + name;
    if (known.count(key) != 0) continue;  // its value is checked by the typed read
    if (!holds_known_keys(known, key)) throw ConfigError(where + ": unknown key '" + shown_key + "'");
    if (item.second.IsMap()) {
      check_overlay_keys(item.second, key, shown_key, where, known);
    } else if (!item.second.IsNull()) {
      fail(where, shown_key, "expected a map of keys");
    }
  }
}

// The entry `index` of the `cameras:` list below `root` (const access: reading never inserts).
YAML::Node camera_entry(const YAML::Node& root, size_t index) {
  const YAML::Node list = find_path(root, "cameras");
  const YAML::Node& const_list = list;
  return const_list[index];
}

// The member `name` of an entry; undefined when absent or null.
YAML::Node entry_member(const YAML::Node& entry, const std::string& name) {
  const YAML::Node& const_entry = entry;
  YAML::Node member = const_entry[name];
  return member.IsDefined() && !member.IsNull() ? member : YAML::Node(YAML::NodeType::Undefined);
}

// Lays every leaf of `map` over `section`.<path> of `root`: a map laid over a section replaces
// only the keys it names (`source: {ros2: {namespace: ...}}` keeps source.ros2.domain_id).
void lay_map_over(YAML::Node& root, const YAML::Node& map, const std::string& section) {
  for (const auto& item : map) {
    const std::string key = section + "." + item.first.Scalar();
    if (item.second.IsMap()) {
      lay_map_over(root, item.second, key);
    } else {
      set_path(root, key, YAML::Clone(item.second));
    }
  }
}

// The entry's `source.type` when it names one, else the top-level one (default sim).
std::string entry_source_type(const YAML::Node& root, const YAML::Node& entry) {
  const YAML::Node source = entry_member(entry, "source");
  if (source.IsMap()) {
    const YAML::Node type = entry_member(source, "type");
    if (type.IsScalar()) return type.Scalar();
  }
  const YAML::Node top = find_path(root, "source.type");
  return top.IsDefined() && top.IsScalar() ? top.Scalar() : std::string("sim");
}

// The message of an error in a tree read with an entry laid over it, naming the entry; the file
// is named once.
std::string in_entry(const std::string& message, const std::string& where, const std::string& entry,
                     const std::string& name) {
  const std::string head = where + ": ";
  const std::string rest = message.compare(0, head.size(), head) == 0 ? message.substr(head.size()) : message;
  return head + entry + " (camera '" + name + "', laid over the top-level keys): " + rest;
}

}  // namespace

void check_camera_entries(const YAML::Node& root, const std::string& where, const std::set<std::string>& known) {
  const YAML::Node list = find_path(root, "cameras");
  if (!list.IsDefined() || list.IsNull()) return;
  const std::string prefix;
  const YamlTree tree{where, prefix};
  if (!list.IsSequence() || list.size() == 0) {
    tree.fail("cameras", "expected a non-empty list of cameras, each {name, T_base_camera, fps, source, sim}");
  }
  std::vector<std::string> names;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string key = entry_key(i);
    const YAML::Node entry = camera_entry(root, i);
    tree.only_keys(entry, key, {"name", "T_base_camera", "fps", "source", "sim"});
    const YAML::Node name_node = tree.required(entry, key, "name");
    const std::string name = name_node.IsScalar() ? name_node.Scalar() : std::string();
    if (!is_camera_name(name)) {
      tree.fail(key + ".name", "expected a ROS 2 name token (a letter, then letters, digits and '_'), got '" + name +
                                   "'");
    }
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      tree.fail(key + ".name", "the name '" + name + "' is given to two cameras; names must be unique");
    }
    names.push_back(name);
    // Both parts of the pose: a pose half taken from the top-level camera would be a guess.
    const std::string pose_key = key + ".T_base_camera";
    const YAML::Node pose = tree.required(entry, key, "T_base_camera");
    tree.only_keys(pose, pose_key, {"translation_m", "rotation_rpy_deg"});
    tree.vec3(tree.required(pose, pose_key, "translation_m"), pose_key + ".translation_m");
    tree.vec3(tree.required(pose, pose_key, "rotation_rpy_deg"), pose_key + ".rotation_rpy_deg");
    const YAML::Node fps = tree.child(entry, "fps");
    if (fps.IsDefined()) {
      const double value = tree.number(fps, key + ".fps");
      if (!(value >= 1.0 && value <= 1000.0)) tree.fail(key + ".fps", "expected a number in [1, 1000] frames/s");
    }
    for (const char* section : {"source", "sim"}) {
      const YAML::Node map = tree.child(entry, section);
      if (!map.IsDefined()) continue;
      if (!map.IsMap()) tree.fail(key + "." + section, std::string("expected a map of ") + section + ".* keys");
      check_overlay_keys(map, section, key + "." + section, where, known);
    }
  }
}

std::vector<std::string> camera_names(const YAML::Node& root) {
  std::vector<std::string> names;
  const YAML::Node list = find_path(root, "cameras");
  if (!list.IsSequence()) return names;
  for (size_t i = 0; i < list.size(); ++i) names.push_back(entry_member(camera_entry(root, i), "name").Scalar());
  return names;
}

void lay_camera_over(YAML::Node& tree, const YAML::Node& root, const std::string& camera, const std::string& where) {
  const std::vector<std::string> names = camera_names(root);
  if (names.empty()) {
    throw ConfigError(where + ": --camera '" + camera + "': the configuration has no cameras: list");
  }
  const auto found = std::find(names.begin(), names.end(), camera);
  if (found == names.end()) {
    std::string list;
    for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
    throw ConfigError(where + ": --camera '" + camera + "': no such camera; the cameras are " + list);
  }
  const YAML::Node entry = camera_entry(root, static_cast<size_t>(found - names.begin()));
  const std::string type = entry_source_type(root, entry);
  set_path(tree, "camera.T_base_camera", YAML::Clone(entry_member(entry, "T_base_camera")));
  const YAML::Node fps = entry_member(entry, "fps");
  if (fps.IsDefined()) {
    // The simulator's rate, or the live camera's; other sources (ros2, recordings) run at the
    // rate they deliver, and the entry's fps is only the fuser's nominal period for them.
    if (type == "sim") set_path(tree, "sim.fps", YAML::Clone(fps));
    if (type == "realsense") set_path(tree, "source.fps", YAML::Clone(fps));
  }
  for (const char* section : {"source", "sim"}) {
    const YAML::Node map = entry_member(entry, section);
    if (map.IsMap()) lay_map_over(tree, map, section);
  }
}

std::vector<CameraEntry> read_camera_entries(const YAML::Node& root, const std::string& where,
                                             const ReadTree& read_tree) {
  std::vector<CameraEntry> entries;
  const std::vector<std::string> names = camera_names(root);
  for (size_t i = 0; i < names.size(); ++i) {
    YAML::Node tree = YAML::Clone(root);
    lay_camera_over(tree, root, names[i], where);
    Config read;
    try {
      read = read_tree(tree);
    } catch (const ConfigError& e) {
      throw ConfigError(in_entry(e.what(), where, entry_key(i), names[i]));
    }
    CameraEntry entry;
    entry.name = names[i];
    entry.T_base_camera = read.pipeline.T_base_camera;
    entry.source_type = read.source.type;
    const YAML::Node fps = entry_member(camera_entry(root, i), "fps");
    if (entry.source_type == SourceType::sim) {
      entry.fps = read.sim.fps;
      Simulator camera;  // the intrinsics the simulated camera renders with, from its sensor settings
      camera.params = read.sim;
      entry.intrinsics = camera.intrinsics();
    } else if (fps.IsDefined()) {
      entry.fps = fps.as<double>();  // checked by check_camera_entries
    } else {
      entry.fps = static_cast<double>(read.source.fps);
    }
    entries.push_back(std::move(entry));
  }
  return entries;
}

void read_cell(KeyReader& r, Config& c) {
  const YAML::Node cameras = r.raw("cameras");
  const bool has_cameras = cameras.IsSequence() && cameras.size() > 0;
  if (has_cameras) r.set_effective("cameras", YAML::Clone(cameras));

  // The grid's box: the foreground's workspace when one is set (the space that matters), else a
  // 3 x 3 x 2 m box around the base. Emitted only for a cell or when given.
  const bool given = r.raw("cell.workspace_base.min").IsDefined() || r.raw("cell.workspace_base.max").IsDefined() ||
                     r.raw("cell.voxel_m").IsDefined();
  SeenFreeGridSpec& grid = c.cell.grid;
  grid = SeenFreeGridSpec{};
  const AlignedBox& workspace = c.pipeline.foreground.workspace_base;
  const AlignedBox everywhere;
  if (workspace.min != everywhere.min || workspace.max != everywhere.max) {
    grid.box_base = Eigen::AlignedBox3f(workspace.min, workspace.max);
  }
  if (has_cameras || given) {
    Eigen::Vector3f min = grid.box_base.min();
    Eigen::Vector3f max = grid.box_base.max();
    r.vec3("cell.workspace_base.min", min, kMaxCoordinateM);
    r.vec3("cell.workspace_base.max", max, kMaxCoordinateM);
    r.number("cell.voxel_m", grid.voxel_m, Bound::positive, kMaxVoxelM);
    if (grid.voxel_m < kMinVoxelM) r.fail("cell.voxel_m", "expected a number in [0.01, 0.5] m, got " + float_text(grid.voxel_m));
    if (!(min.array() < max.array()).all()) {
      r.fail_pair("cell.workspace_base.min", "cell.workspace_base.max", "expected min < max on every axis");
    }
    double cells = 1.0;
    for (int axis = 0; axis < 3; ++axis) {
      cells *= std::ceil(static_cast<double>(max[axis] - min[axis]) / static_cast<double>(grid.voxel_m));
    }
    if (cells > kMaxGridCells) {
      r.fail_pair("cell.workspace_base.max", "cell.voxel_m",
                  "the grid would have " + double_text(cells) + " cubes; at most 8e6 (a larger voxel or a smaller box)");
    }
    grid.box_base = Eigen::AlignedBox3f(min, max);
  }
  grid.enabled = has_cameras;
  if (has_cameras || r.raw("cell.clock_offset_max_s").IsDefined()) {
    r.number("cell.clock_offset_max_s", c.cell.clock_offset_max_s, Bound::non_negative, kMaxClockOffsetS);
  }
  if (has_cameras || r.raw("cell.fuser_priority").IsDefined()) {
    // SCHED_FIFO's range on Linux.
    r.integer("cell.fuser_priority", c.cell.fuser_priority, 0, 99);
  }

  if (r.raw("sim.epoch").IsDefined()) {
    double epoch_s = 0.0;
    r.number("sim.epoch", epoch_s, Bound::non_negative, kMaxEpochS);
    // Whole seconds and the fraction apart: epoch_s · 1e9 in double would be some 100 ns off
    // (1.7e18 needs 61 bits), and 1700000000.25 is to mean exactly ...250000000 ns.
    const double whole_s = std::floor(epoch_s);
    c.sim_epoch_ns = static_cast<int64_t>(whole_s) * 1'000'000'000 + std::llround((epoch_s - whole_s) * 1e9);
  }
}

}  // namespace hrcsense::config_detail

// ---- The pose of one entry written back into the file's text (hrcsense calibrate --write-back).

namespace hrcsense {
namespace {

// The byte range [begin, end) of the flow list `[ ... ]` at `node` in `text`, which must lie
// after `after` and before `before` (inside its entry: not an anchor elsewhere); else an error.
std::pair<size_t, size_t> flow_list_span(const std::string& text, const YAML::Node& node, size_t after, size_t before,
                                         const std::string& where, const std::string& key) {
  const auto fail_form = [&](const std::string& why) {
    throw ConfigError(where + ": key '" + key + "': cannot write the calibrated pose back: " + why +
                      "; write it as a flow list [x, y, z] in the entry, or use --out");
  };
  if (!node.IsSequence() || node.Style() != YAML::EmitterStyle::Flow) fail_form("it is not a flow list");
  const auto begin = static_cast<size_t>(node.Mark().pos);
  if (begin <= after || begin >= before || begin >= text.size() || text[begin] != '[') {
    fail_form("the list is not written inside the entry (an alias?)");
  }
  for (size_t i = begin + 1; i < text.size(); ++i) {
    const char c = text[i];
    if (c == ']') return {begin, i + 1};
    // Numbers, signs, spaces, commas and line breaks only: anything else (a comment, a nested
    // list, a quoted string) is a form this edit does not take apart.
    if (!(std::isdigit(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '-' || c == '+' || c == 'e' ||
          c == 'E' || c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r')) {
      fail_form(std::string("the list holds '") + c + "'");
    }
  }
  fail_form("the list is not closed");
  return {0, 0};
}

std::string pose_list_text(const Eigen::Vector3d& v, int digits) {
  return "[" + fixed_digits_text(v.x(), digits) + ", " + fixed_digits_text(v.y(), digits) + ", " +
         fixed_digits_text(v.z(), digits) + "]";
}

}  // namespace

Eigen::Vector3d rotation_rpy_deg(const Pose& pose) {
  const Eigen::Matrix3d R = pose.rotation();
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw) * (180.0 / 3.14159265358979323846);
}

std::string with_camera_pose_text(const std::string& yaml_text, const std::string& camera, const Pose& T_base_camera,
                                  const std::string& where) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(where + ": not YAML: " + e.what());
  }
  const YAML::Node& const_root = root;
  const YAML::Node list = const_root["cameras"];
  if (!list.IsDefined() || !list.IsSequence()) throw ConfigError(where + ": key 'cameras': the file has no cameras: list");
  for (size_t i = 0; i < list.size(); ++i) {
    const YAML::Node entry = list[i];
    const YAML::Node name = entry.IsMap() ? entry["name"] : YAML::Node();
    if (!name.IsDefined() || !name.IsScalar() || name.Scalar() != camera) continue;
    const std::string key = "cameras[" + std::to_string(i) + "].T_base_camera";
    const YAML::Node pose = entry["T_base_camera"];
    if (!pose.IsDefined() || !pose.IsMap()) throw ConfigError(where + ": key '" + key + "': expected a map");
    const auto after = static_cast<size_t>(entry.Mark().pos);
    const size_t before = i + 1 < list.size() ? static_cast<size_t>(list[i + 1].Mark().pos) : yaml_text.size();
    const auto t_span = flow_list_span(yaml_text, pose["translation_m"], after, before, where, key + ".translation_m");
    const auto r_span = flow_list_span(yaml_text, pose["rotation_rpy_deg"], after, before, where, key + ".rotation_rpy_deg");
    std::string out = yaml_text;
    const std::string t_text = pose_list_text(T_base_camera.translation(), 6);
    const std::string r_text = pose_list_text(rotation_rpy_deg(T_base_camera), 5);
    // The later span first, so that the earlier one's offsets still hold.
    if (t_span.first > r_span.first) {
      out.replace(t_span.first, t_span.second - t_span.first, t_text);
      out.replace(r_span.first, r_span.second - r_span.first, r_text);
    } else {
      out.replace(r_span.first, r_span.second - r_span.first, r_text);
      out.replace(t_span.first, t_span.second - t_span.first, t_text);
    }
    return out;
  }
  throw ConfigError(where + ": key 'cameras': no camera named '" + camera + "'");
}

}  // namespace hrcsense
