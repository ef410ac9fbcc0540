// SPDX-License-Identifier: Apache-2.0
// hrcsense — how two calibrated cameras of a cell agree on the arm (calibration.hpp,
// docs/CALIBRATION.md, "Cells with several cameras"): at the arm poses both saw, each camera's
// points of a link are fitted to the link's shapes by a translation, and the two translations
// are compared.
#include "hrcsense/calibration.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
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

// Whether two views show the arm in the same pose: every joint within `tolerance_rad`.
bool same_arm_pose(const JointAngles& a, const JointAngles& b, double tolerance_rad) {
  for (size_t j = 0; j < a.size(); ++j) {
    if (!(std::abs(a[j] - b[j]) <= tolerance_rad)) return false;
  }
  return true;
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
  // Per view both cameras saw, per link: the slices of each; kept alive here for the fits.
  std::vector<std::map<int, LinkSlice>> kept_a;
  std::vector<std::map<int, LinkSlice>> kept_b;
  for (const ArmView& va : a) {
    const auto match = std::find_if(b.begin(), b.end(), [&](const ArmView& vb) {
      return same_arm_pose(va.q_rad, vb.q_rad, params.same_pose_rad);
    });
    if (match == b.end()) continue;
    ++out.shared_views;
    kept_a.push_back(slices_by_link(va, params.gate_m));
    kept_b.push_back(slices_by_link(*match, params.gate_m));
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
