#include "tools_scripted/instrument.hpp"

#include <algorithm>
#include <Eigen/Geometry>

namespace tools {
namespace {

// Keyframes with every field filled in from the ones before.
struct Filled {
  double t;
  vdm::Vec3 tip, axis;
  bool jaw_closed;
};

Filled filled(const InstrumentDef& def, size_t k) {
  Filled f{def.script[k].t, vdm::Vec3::Zero(), -vdm::Vec3::UnitZ(), false};
  for (size_t j = 0; j <= k; ++j) {
    const Keyframe& key = def.script[j];
    if (key.tip) f.tip = *key.tip;
    if (key.axis) f.axis = key.axis->normalized();
    if (key.jaw_closed) f.jaw_closed = *key.jaw_closed;
  }
  return f;
}

// Fritsch-Butland tangent of coordinate d at interior keyframe k: zero where the coordinate
// turns or holds, else a weighted harmonic mean of the neighbouring slopes (monotone).
double spline_tangent(const InstrumentDef& def, size_t k, int d) {
  if (k == 0 || k + 1 >= def.script.size()) return 0.0;  // at rest at both ends
  const Filled a = filled(def, k - 1), b = filled(def, k), c = filled(def, k + 1);
  const double h0 = b.t - a.t, h1 = c.t - b.t;
  const double s0 = (b.tip[d] - a.tip[d]) / h0, s1 = (c.tip[d] - b.tip[d]) / h1;
  if (s0 * s1 <= 0) return 0.0;
  return 3 * (h0 + h1) / ((2 * h1 + h0) / s0 + (h1 + 2 * h0) / s1);
}

}  // namespace

InstrumentPose pose_at(const InstrumentDef& def, double t) {
  InstrumentPose pose;
  if (def.script.empty()) return pose;
  size_t k = 0;
  while (k + 1 < def.script.size() && def.script[k + 1].t <= t) ++k;
  const Filled a = filled(def, k);
  if (k + 1 == def.script.size() || t <= a.t) {
    pose.tip = a.tip;
    pose.axis = a.axis;
    pose.jaw_closed = a.jaw_closed;
    pose.jaw_opening = a.jaw_closed ? 0.0 : 1.0;
    return pose;
  }
  const Filled b = filled(def, k + 1);
  const double w = std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0);
  if (def.path == InstrumentDef::Path::spline) {
    const double h = b.t - a.t, w2 = w * w, w3 = w2 * w;
    const double h00 = 2 * w3 - 3 * w2 + 1, h10 = w3 - 2 * w2 + w, h01 = -2 * w3 + 3 * w2, h11 = w3 - w2;
    for (int d = 0; d < 3; ++d)
      pose.tip[d] = h00 * a.tip[d] + h10 * h * spline_tangent(def, k, d) + h01 * b.tip[d] +
                    h11 * h * spline_tangent(def, k + 1, d);
  } else {
    pose.tip = (1 - w) * a.tip + w * b.tip;
  }
  pose.axis = Eigen::Quaterniond::Identity().slerp(w, Eigen::Quaterniond::FromTwoVectors(a.axis, b.axis)) * a.axis;
  pose.jaw_closed = w < 1.0 ? a.jaw_closed : b.jaw_closed;
  pose.jaw_opening = (1 - w) * (a.jaw_closed ? 0.0 : 1.0) + w * (b.jaw_closed ? 0.0 : 1.0);
  return pose;
}

vdm::Capsule probe_capsule(const InstrumentDef& def, const InstrumentPose& pose) {
  vdm::Capsule c;
  c.radius = def.radius;
  c.p0 = pose.tip - def.radius * pose.axis;                                  // centre of the rounded tip
  c.p1 = pose.tip - std::max(def.length - def.radius, def.radius) * pose.axis;  // toward the handle
  return c;
}

}  // namespace tools
