// SPDX-License-Identifier: Apache-2.0
// hrcsense — how two calibrated cameras of a cell agree on the arm (calibration.hpp,
// docs/CALIBRATION.md, "Cells with several cameras"): the two cameras' keyframes are paired by the
// nearest arm pose, each camera's points of a link are fitted to the link's shapes at its own
// keyframe's joints by a translation, and the two translations are compared.
#include "hrcsense/calibration.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>

namespace hrcsense {
namespace {

// One camera's points of one link in one view, with that link's shapes there.
struct LinkSlice {
  std::vector<Capsule> shapes_base;
  std::vector<Eigen::Vector3f> points_base;
};

// The slices of a view by link: each gated point goes to the link of its nearest shape.
std::map<int, LinkSlice> slices_by_link(const ArmView& view, float gate_m) {
  std::map<int, LinkSlice> out;
  for (const Capsule& c : view.shapes_base) out[c.link].shapes_base.push_back(c);
  for (const Eigen::Vector3f& p : view.points_base) {
    int link = -1;
    float best = std::numeric_limits<float>::infinity();
    for (const Capsule& c : view.shapes_base) {
      const Eigen::Vector3f e = c.b - c.a;
      const float ee = e.squaredNorm();
      const float t = ee > 0.0F ? std::clamp((p - c.a).dot(e) / ee, 0.0F, 1.0F) : 0.0F;
      const float d = (p - (c.a + t * e)).norm() - c.radius_m;
      if (d < best) {
        best = d;
        link = c.link;
      }
    }
    if (link >= 0 && std::abs(best) <= gate_m) out[link].points_base.push_back(p);
  }
  return out;
}

// How far the arm's shapes lie apart between two views: the largest distance between the same
// end of the same capsule. A rigid move displaces the points of a segment affinely, so no point
// of a shape's axis lies farther apart than its farther end. Infinite for two different shape
// lists (another arm or tool): such views are not compared.
double shapes_travel_m(const std::vector<Capsule>& a, const std::vector<Capsule>& b, double limit_m) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double travel_m = 0.0;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].link != b[k].link) return std::numeric_limits<double>::infinity();
    const double first_end_m = (a[k].a - b[k].a).norm();
    const double second_end_m = (a[k].b - b[k].b).norm();
    // A shape with a NaN (invalid joints) pairs with nothing.
    if (!std::isfinite(first_end_m) || !std::isfinite(second_end_m)) return std::numeric_limits<double>::infinity();
    travel_m = std::max({travel_m, first_end_m, second_end_m});
    if (travel_m > limit_m) break;  // enough to know the pair is out of reach
  }
  return travel_m;
}

struct ViewPair {
  size_t a = 0;
  size_t b = 0;
  double travel_m = 0.0;
};

// Each view in one pair at most, nearest poses first: every pair within `max_travel_m`, sorted by
// travel (ties by the views' order, so that the result is the same on every run), taken while both
// its views are free. A view of a camera at twice the other's rate thus finds the other's nearest
// view once, and the rest of its views stay out instead of counting a view of the other twice.
std::vector<ViewPair> nearest_view_pairs(const std::vector<ArmView>& a, const std::vector<ArmView>& b,
                                         double max_travel_m) {
  std::vector<ViewPair> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) {
      const double travel_m = shapes_travel_m(a[i].shapes_base, b[j].shapes_base, max_travel_m);
      if (travel_m <= max_travel_m) candidates.push_back({i, j, travel_m});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const ViewPair& x, const ViewPair& y) {
    if (x.travel_m != y.travel_m) return x.travel_m < y.travel_m;
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
  std::vector<bool> used_a(a.size(), false);
  std::vector<bool> used_b(b.size(), false);
  std::vector<ViewPair> pairs;
  for (const ViewPair& c : candidates) {
    if (used_a[c.a] || used_b[c.b]) continue;
    used_a[c.a] = true;
    used_b[c.b] = true;
    pairs.push_back(c);
  }
  // In the order of a's views, as the keyframes were taken.
  std::sort(pairs.begin(), pairs.end(), [](const ViewPair& x, const ViewPair& y) { return x.a < y.a; });
  return pairs;
}

double largest_joint_difference_rad(const JointAngles& a, const JointAngles& b) {
  double out = 0.0;
  for (size_t j = 0; j < a.size(); ++j) out = std::max(out, std::abs(a[j] - b[j]));
  return out;
}

// The translation o (base frame) that moves the shapes onto the slices' points best:
// least squares of the signed distances of p − o to the shapes, Gauss–Newton from 0. Directions
// the points' normals hardly constrain stay 0 (their count is left out of `constrained_axes`).
struct SurfaceOffset {
  Eigen::Vector3d offset_base_m = Eigen::Vector3d::Zero();
  size_t points = 0;
  int constrained_axes = 0;
};

SurfaceOffset surface_offset(const std::vector<const LinkSlice*>& slices, double min_axis_share) {
  SurfaceOffset out;
  for (const LinkSlice* s : slices) out.points += s->points_base.size();
  if (out.points == 0) return out;
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  for (int iteration = 0; iteration < 8; ++iteration) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    const Eigen::Vector3f o_f = o.cast<float>();
    for (const LinkSlice* s : slices) {
      for (const Eigen::Vector3f& p : s->points_base) {
        Eigen::Vector3f n;
        const float r = distance_to_shapes(s->shapes_base, p - o_f, n);
        const Eigen::Vector3d nd = n.cast<double>();
        // d r / d o = −n: the step solves H Δ = Σ r n.
        H += nd * nd.transpose();
        g += static_cast<double>(r) * nd;
      }
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H);
    const Eigen::Vector3d values = eig.eigenvalues();
    const double largest = values.maxCoeff();
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    int axes = 0;
    for (int k = 0; k < 3; ++k) {
      if (!(values[k] > min_axis_share * largest) || largest <= 0.0) continue;
      const Eigen::Vector3d v = eig.eigenvectors().col(k);
      step += v * (v.dot(g) / values[k]);
      ++axes;
    }
    out.constrained_axes = axes;
    o += step;
    if (step.norm() < 1e-7) break;
  }
  out.offset_base_m = o;
  return out;
}

LinkAgreement agreement_of(int link, int views, const std::vector<const LinkSlice*>& a,
                           const std::vector<const LinkSlice*>& b, double min_axis_share) {
  const SurfaceOffset oa = surface_offset(a, min_axis_share);
  const SurfaceOffset ob = surface_offset(b, min_axis_share);
  LinkAgreement out;
  out.link = link;
  out.views = views;
  out.points_a = oa.points;
  out.points_b = ob.points;
  out.offset_a_base_m = oa.offset_base_m;
  out.offset_b_base_m = ob.offset_base_m;
  out.disagreement_m = (oa.offset_base_m - ob.offset_base_m).norm();
  out.constrained_axes = std::min(oa.constrained_axes, ob.constrained_axes);
  return out;
}

}  // namespace

std::vector<ArmView> arm_views(const ArmSamples& samples, const Pose& T_base_camera) {
  std::vector<ArmView> views;
  RobotModel shapes;
  const Eigen::Matrix3f R = T_base_camera.rotation().cast<float>();
  const Eigen::Vector3f t = T_base_camera.translation().cast<float>();
  for (const ArmKeyframe& keyframe : samples.keyframes()) {
    ArmView view;
    view.q_rad = keyframe.q_rad;
    for (const Eigen::Vector3f& p : arm_candidates(samples, keyframe)) view.points_base.push_back(R * p + t);
    if (view.points_base.empty()) continue;
    robot_render_capsules(samples.arm(), keyframe.q_rad, samples.base_frame(), shapes);
    view.shapes_base = shapes.capsules;
    views.push_back(std::move(view));
  }
  return views;
}

CameraAgreement camera_agreement(const std::vector<ArmView>& a, const std::vector<ArmView>& b,
                                 const AgreementParams& params) {
  CameraAgreement out;
  const auto min_points = static_cast<size_t>(std::max(1, params.min_points));
  out.views_a = static_cast<int>(a.size());
  out.views_b = static_cast<int>(b.size());
  // Per view pair, per link: the slices of each camera, each cut by its own view's shapes; kept
  // alive here for the fits.
  std::vector<std::map<int, LinkSlice>> kept_a;
  std::vector<std::map<int, LinkSlice>> kept_b;
  std::vector<double> travels_m;
  for (const ViewPair& pair : nearest_view_pairs(a, b, params.pair_travel_m)) {
    ++out.paired_views;
    travels_m.push_back(pair.travel_m);
    out.pair_travel_max_m = std::max(out.pair_travel_max_m, pair.travel_m);
    out.pair_joint_max_rad =
        std::max(out.pair_joint_max_rad, largest_joint_difference_rad(a[pair.a].q_rad, b[pair.b].q_rad));
    kept_a.push_back(slices_by_link(a[pair.a], params.gate_m));
    kept_b.push_back(slices_by_link(b[pair.b], params.gate_m));
  }
  if (!travels_m.empty()) {
    const auto middle = travels_m.begin() + static_cast<std::ptrdiff_t>(travels_m.size() / 2);
    std::nth_element(travels_m.begin(), middle, travels_m.end());
    out.pair_travel_median_m = *middle;
  }
  std::map<int, std::vector<const LinkSlice*>> link_a;
  std::map<int, std::vector<const LinkSlice*>> link_b;
  std::map<int, int> link_views;
  for (size_t v = 0; v < kept_a.size(); ++v) {
    for (const auto& [link, slice_a] : kept_a[v]) {
      const auto found = kept_b[v].find(link);
      if (found == kept_b[v].end()) continue;
      if (slice_a.points_base.size() < min_points || found->second.points_base.size() < min_points) continue;
      link_a[link].push_back(&slice_a);
      link_b[link].push_back(&found->second);
      ++link_views[link];
    }
  }
  std::vector<const LinkSlice*> all_a;
  std::vector<const LinkSlice*> all_b;
  int all_views = 0;
  const auto min_link_points = static_cast<size_t>(std::max(1, params.min_link_points));
  const auto count = [](const std::vector<const LinkSlice*>& slices) {
    size_t n = 0;
    for (const LinkSlice* s : slices) n += s->points_base.size();
    return n;
  };
  for (const auto& [link, slices] : link_a) {
    if (count(slices) < min_link_points || count(link_b[link]) < min_link_points) continue;
    out.links.push_back(agreement_of(link, link_views[link], slices, link_b[link], params.min_axis_share));
    all_a.insert(all_a.end(), slices.begin(), slices.end());
    all_b.insert(all_b.end(), link_b[link].begin(), link_b[link].end());
    all_views += link_views[link];
  }
  out.all = agreement_of(-1, all_views, all_a, all_b, params.min_axis_share);
  return out;
}

}  // namespace hrcsense
