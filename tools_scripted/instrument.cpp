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
  pose.tip = (1 - w) * a.tip + w * b.tip;
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
