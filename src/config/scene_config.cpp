// SPDX-License-Identifier: Apache-2.0
// hrcsense config — `scene.objects`: simulated objects made of planes, boxes, spheres, capsules.
#include "yaml_tree.hpp"

#include "hrcsense/sim/sim.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::config_detail {
namespace {

// Errors inside the scene name the item by its position, e.g. scene.objects[2].shapes[0].
struct SceneReader : YamlTree {
  float radius(const YAML::Node& map, const std::string& key) const {
    const double r = number(required(map, key, "radius_m"), key + ".radius_m");
    if (r <= 0.0) fail(key + ".radius_m", "expected a number > 0");
    return static_cast<float>(r);
  }

  Shape shape(const YAML::Node& node, const std::string& key) const {
    if (!node.IsMap() || node.size() != 1) {
      fail(key, "expected one of {plane: ...}, {box: ...}, {sphere: ...}, {capsule: ...}");
    }
    const std::string type = node.begin()->first.Scalar();
    const YAML::Node body = node.begin()->second;
    const std::string sub = key + "." + type;
    Shape out;
    if (type == "plane") {
      only_keys(body, sub, {"point", "normal"});
      out.type = Shape::Type::plane;
      out.point = vec3f(required(body, sub, "point"), sub + ".point");
      const Eigen::Vector3f normal = vec3f(required(body, sub, "normal"), sub + ".normal");
      if (normal.norm() < 1e-6F) fail(sub + ".normal", "expected a non-zero vector");
      out.normal = normal.normalized();
    } else if (type == "box") {
      only_keys(body, sub, {"min", "max"});
      out.type = Shape::Type::box;
      out.min = vec3f(required(body, sub, "min"), sub + ".min");
      out.max = vec3f(required(body, sub, "max"), sub + ".max");
      if ((out.min.array() > out.max.array()).any()) fail(sub, "expected min <= max on every axis");
    } else if (type == "sphere") {
      only_keys(body, sub, {"center", "radius_m"});
      out.type = Shape::Type::sphere;
      out.point = vec3f(required(body, sub, "center"), sub + ".center");
      out.radius_m = radius(body, sub);
    } else if (type == "capsule") {
      only_keys(body, sub, {"a", "b", "radius_m"});
      out.type = Shape::Type::capsule;
      out.a = vec3f(required(body, sub, "a"), sub + ".a");
      out.b = vec3f(required(body, sub, "b"), sub + ".b");
      out.radius_m = radius(body, sub);
    } else {
      fail(key, "unknown shape '" + type + "'; expected plane, box, sphere or capsule");
    }
    return out;
  }

  int64_t frame_number(const YAML::Node& map, const std::string& key, const char* name,
                       int64_t fallback, int64_t min) const {
    const YAML::Node& const_map = map;
    const YAML::Node node = const_map[name];
    if (!node.IsDefined() || node.IsNull()) return fallback;
    int64_t value = 0;
    if (node.IsScalar() && !leading_zero_problem(node.Scalar()).empty()) fail(key + "." + name, leading_zero_problem(node.Scalar()));
    if (!node.IsScalar() || !YAML::convert<int64_t>::decode(node, value) || value < min) {
      fail(key + "." + name, "expected an integer >= " + std::to_string(min));
    }
    return value;
  }

  std::vector<Waypoint> path(const YAML::Node& node, const std::string& key) const {
    if (!node.IsSequence()) fail(key, "expected a list of {t_s, offset_m}");
    const auto read_offset = [this](const YAML::Node& value, const std::string& value_key, Waypoint& point) {
      point.offset_m = vec3f(value, value_key);
    };
    return waypoints<Waypoint>(node, key, "offset_m", read_offset);
  }

  /// `material: [dark, shiny, low_texture]` (any of them; a single flag may stand alone).
  Material material(const YAML::Node& node, const std::string& key) const {
    Material out;
    const auto set_flag = [&](const YAML::Node& item) {
      const std::string flag = item.IsScalar() ? item.Scalar() : std::string();
      if (flag == "dark") {
        out.dark = true;
      } else if (flag == "shiny") {
        out.shiny = true;
      } else if (flag == "low_texture") {
        out.low_texture = true;
      } else {
        fail(key, "unknown material '" + flag + "'; expected dark, shiny or low_texture");
      }
    };
    if (node.IsScalar()) {
      set_flag(node);
    } else if (node.IsSequence()) {
      for (size_t i = 0; i < node.size(); ++i) set_flag(node[i]);
    } else {
      fail(key, "expected a list of dark, shiny, low_texture");
    }
    return out;
  }

  /// `color: [r, g, b]`, integers 0..255.
  std::array<uint8_t, 3> color(const YAML::Node& node, const std::string& key) const {
    if (!node.IsSequence() || node.size() != 3) fail(key, "expected [r, g, b] with integers 0..255");
    std::array<uint8_t, 3> out{};
    for (size_t i = 0; i < 3; ++i) {
      int value = -1;
      if (node[i].IsScalar() && !leading_zero_problem(node[i].Scalar()).empty()) fail(key, leading_zero_problem(node[i].Scalar()));
      if (!node[i].IsScalar() || !YAML::convert<int>::decode(node[i], value) || value < 0 || value > 255) {
        fail(key, "expected [r, g, b] with integers 0..255");
      }
      out[i] = static_cast<uint8_t>(value);
    }
    return out;
  }

  SceneObject object(const YAML::Node& node, const std::string& key, size_t index) const {
    only_keys(node, key, {"name", "static", "first_frame", "last_frame", "path", "material", "color", "shapes"});
    SceneObject out;
    const YAML::Node& map = node;
    out.name = "object" + std::to_string(index);
    if (map["name"].IsDefined() && !map["name"].IsNull()) {
      if (!map["name"].IsScalar()) fail(key + ".name", "expected a string");
      out.name = map["name"].Scalar();
    }
    if (map["static"].IsDefined() && !map["static"].IsNull() &&
        (!map["static"].IsScalar() || !YAML::convert<bool>::decode(map["static"], out.is_static))) {
      fail(key + ".static", "expected true or false");
    }
    out.first_frame = frame_number(map, key, "first_frame", 0, 0);
    out.last_frame = frame_number(map, key, "last_frame", -1, -1);
    if (out.last_frame >= 0 && out.last_frame < out.first_frame) {
      fail(key + ".last_frame", "expected -1 or a frame >= first_frame");
    }
    if (map["path"].IsDefined() && !map["path"].IsNull()) out.path = path(map["path"], key + ".path");
    if (map["material"].IsDefined() && !map["material"].IsNull()) {
      out.material = material(map["material"], key + ".material");
    }
    if (map["color"].IsDefined() && !map["color"].IsNull()) out.color_rgb = color(map["color"], key + ".color");
    const YAML::Node shapes = required(map, key, "shapes");
    if (!shapes.IsSequence() || shapes.size() == 0) fail(key + ".shapes", "expected a non-empty list of shapes");
    for (size_t i = 0; i < shapes.size(); ++i) {
      out.shapes.push_back(shape(shapes[i], key + ".shapes[" + std::to_string(i) + "]"));
    }
    return out;
  }
};

YAML::Node vec3_node(const Eigen::Vector3f& v) {
  YAML::Node out(YAML::NodeType::Sequence);
  out.SetStyle(YAML::EmitterStyle::Flow);
  for (int i = 0; i < 3; ++i) out.push_back(float_text(v[i]));
  return out;
}

YAML::Node shape_node(const Shape& shape) {
  YAML::Node body(YAML::NodeType::Map);
  body.SetStyle(YAML::EmitterStyle::Flow);
  YAML::Node out(YAML::NodeType::Map);
  switch (shape.type) {
    case Shape::Type::plane:
      body["point"] = vec3_node(shape.point);
      body["normal"] = vec3_node(shape.normal);
      out["plane"] = body;
      break;
    case Shape::Type::box:
      body["min"] = vec3_node(shape.min);
      body["max"] = vec3_node(shape.max);
      out["box"] = body;
      break;
    case Shape::Type::sphere:
      body["center"] = vec3_node(shape.point);
      body["radius_m"] = float_text(shape.radius_m);
      out["sphere"] = body;
      break;
    case Shape::Type::capsule:
      body["a"] = vec3_node(shape.a);
      body["b"] = vec3_node(shape.b);
      body["radius_m"] = float_text(shape.radius_m);
      out["capsule"] = body;
      break;
  }
  return out;
}

}  // namespace

YAML::Node scene_objects_node(const Scene& scene) {
  YAML::Node objects(YAML::NodeType::Sequence);
  if (scene.objects.empty()) objects.SetStyle(YAML::EmitterStyle::Flow);  // "objects: []"
  for (const SceneObject& object : scene.objects) {
    YAML::Node node(YAML::NodeType::Map);
    node["name"] = object.name;
    node["static"] = object.is_static;
    node["first_frame"] = object.first_frame;
    node["last_frame"] = object.last_frame;
    YAML::Node path(YAML::NodeType::Sequence);
    for (const Waypoint& point : object.path) {
      YAML::Node waypoint(YAML::NodeType::Map);
      waypoint.SetStyle(YAML::EmitterStyle::Flow);
      waypoint["t_s"] = double_text(point.t_s);
      waypoint["offset_m"] = vec3_node(point.offset_m);
      path.push_back(waypoint);
    }
    if (object.path.empty()) path.SetStyle(YAML::EmitterStyle::Flow);
    node["path"] = path;
    YAML::Node material(YAML::NodeType::Sequence);
    material.SetStyle(YAML::EmitterStyle::Flow);
    if (object.material.dark) material.push_back("dark");
    if (object.material.shiny) material.push_back("shiny");
    if (object.material.low_texture) material.push_back("low_texture");
    node["material"] = material;
    if (object.color_rgb) {
      YAML::Node color(YAML::NodeType::Sequence);
      color.SetStyle(YAML::EmitterStyle::Flow);
      for (const uint8_t c : *object.color_rgb) color.push_back(static_cast<int>(c));
      node["color"] = color;
    }
    YAML::Node shapes(YAML::NodeType::Sequence);
    for (const Shape& shape : object.shapes) shapes.push_back(shape_node(shape));
    node["shapes"] = shapes;
    objects.push_back(node);
  }
  return objects;
}

void read_sim_effects(KeyReader& r, SimParams& sim) {
  // `sim` holds the sensor's preset (apply_sim_sensor): a key given replaces its value.
  const auto share = [&r](const std::string& key, float& value) {
    r.number(key, value, Bound::non_negative);
    if (value > 1.0F) r.fail(key, "expected a share between 0 and 1, got " + float_text(value));
  };
  // 0 (off) or at least 1/64 px: a finer step overflows the quantiser's 32-bit step count.
  r.number("sim.disparity_step_px", sim.disparity_step_px, Bound::non_negative, 1.0F);
  if (sim.disparity_step_px > 0.0F && sim.disparity_step_px < 1.0F / 64.0F) {
    r.fail("sim.disparity_step_px", "expected 0 (off) or a step in [0.015625, 1] px, got " + float_text(sim.disparity_step_px));
  }
  r.flag("sim.left_band", sim.left_band);
  r.flag("sim.occlusion_shadows", sim.occlusion_shadows);
  r.number("sim.max_disparity_px", sim.max_disparity_px, Bound::non_negative);
  r.number("sim.min_range_m", sim.min_range_m, Bound::non_negative);
  r.number("sim.max_range_m", sim.max_range_m, Bound::non_negative);
  if (sim.max_range_m > 0.0F && sim.max_range_m <= sim.min_range_m) {
    r.fail_pair("sim.min_range_m", "sim.max_range_m", "expected the maximum range (" + float_text(sim.max_range_m) +
                                                         " m) beyond the minimum (" + float_text(sim.min_range_m) + " m)");
  }
  share("sim.range_dropout", sim.range_dropout);
  r.number("sim.range_dropout_start_m", sim.range_dropout_start_m, Bound::non_negative);
  if (sim.range_dropout > 0.0F && !(sim.range_dropout_start_m < sim.max_range_m)) {
    r.fail_pair("sim.range_dropout", "sim.max_range_m", "range dropouts grow from sim.range_dropout_start_m (" +
                                                           float_text(sim.range_dropout_start_m) +
                                                           " m) to the maximum range, which must lie beyond it");
  }
  r.number("sim.edge_jump_px", sim.edge_jump_px, Bound::positive);
  share("sim.edge_dropout", sim.edge_dropout);
  share("sim.flying_pixels", sim.flying_pixels);
  share("sim.edge_flicker", sim.edge_flicker);
  share("sim.dark_dropout", sim.dark_dropout);
  share("sim.shiny_dropout", sim.shiny_dropout);
  share("sim.low_texture_dropout", sim.low_texture_dropout);
  r.integer("sim.material_cell_px", sim.material_cell_px, 1, 256);
  share("sim.speckle", sim.speckle);
  r.number("sim.correlated_noise_px", sim.correlated_noise_px, Bound::non_negative, 10.0F);
  r.integer("sim.correlated_cell_px", sim.correlated_cell_px, 2, 4096);
  r.flag("sim.color", sim.color);
  r.integer("sim.color_width", sim.color_width, 0, 65535);
  r.integer("sim.color_height", sim.color_height, 0, 65535);
  const int width = sim.color_width > 0 ? sim.color_width : sim.width;
  const int height = sim.color_height > 0 ? sim.color_height : sim.height;
  if (sim.color && !d435_color_intrinsics(width, height)) {
    r.fail_pair("sim.color_width", "sim.color_height", std::to_string(width) + "x" + std::to_string(height) +
                                  " is not a D435 colour resolution; expected 1920x1080, 1280x720, 960x540, "
                                  "848x480, 640x480, 640x360, 480x270, 424x240 or 320x240 (0x0: the depth's)");
  }
  r.vec3("sim.color_translation_m", sim.color_translation_m);
}

Scene read_scene_objects(const YAML::Node& objects, const std::string& where, const std::string& key) {
  Scene scene;
  if (!objects.IsDefined() || objects.IsNull()) return scene;
  const std::string no_prefix;
  const SceneReader reader{{where, no_prefix}};
  if (!objects.IsSequence()) reader.fail(key, "expected a list of objects");
  for (size_t i = 0; i < objects.size(); ++i) {
    scene.objects.push_back(reader.object(objects[i], key + "[" + std::to_string(i) + "]", i));
  }
  return scene;
}

}  // namespace hrcsense::config_detail
