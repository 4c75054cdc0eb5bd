#include "tools_scripted/instrument.hpp"

#include <algorithm>
#include <cmath>
#include <Eigen/Geometry>

#include "engine/rotation.hpp"

namespace tools {
namespace {

// Keyframes with every field filled in from the ones before.
struct Filled {
  double t;
  vdm::Vec3 tip, axis;
  bool jaw_closed;
  double roll_deg;
};

Filled filled(const InstrumentDef& def, size_t k) {
  Filled f{def.script[k].t, vdm::Vec3::Zero(), -vdm::Vec3::UnitZ(), false, 0.0};
  for (size_t j = 0; j <= k; ++j) {
    const Keyframe& key = def.script[j];
    if (key.tip) f.tip = *key.tip;
    if (key.axis) f.axis = key.axis->normalized();
    if (key.jaw_closed) f.jaw_closed = *key.jaw_closed;
    if (key.roll_deg) f.roll_deg = *key.roll_deg;
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
    pose.roll_deg = a.roll_deg;
    if (def.port) pose.axis = (pose.tip - *def.port).normalized();
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
  pose.axis = Eigen::Quaterniond::Identity().slerp(w, vdm::rotation_between(a.axis, b.axis)) * a.axis;
  pose.jaw_closed = w < 1.0 ? a.jaw_closed : b.jaw_closed;
  pose.jaw_opening = (1 - w) * (a.jaw_closed ? 0.0 : 1.0) + w * (b.jaw_closed ? 0.0 : 1.0);
  pose.roll_deg = (1 - w) * a.roll_deg + w * b.roll_deg;
  if (def.port) pose.axis = (pose.tip - *def.port).normalized();  // through the port, whatever the path
  return pose;
}

vdm::Capsule probe_capsule(const InstrumentDef& def, const InstrumentPose& pose) {
  vdm::Capsule c;
  c.radius = def.radius;
  c.p0 = pose.tip - def.radius * pose.axis;                                  // centre of the rounded tip
  c.p1 = pose.tip - std::max(def.length - def.radius, def.radius) * pose.axis;  // toward the handle
  return c;
}

Eigen::Isometry3d instrument_frame(const InstrumentPose& pose) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = vdm::rotation_between(vdm::Vec3::UnitZ(), pose.axis.normalized()).toRotationMatrix();
  if (pose.roll_deg != 0)
    f.linear() = f.linear() * Eigen::AngleAxisd(pose.roll_deg * 3.14159265358979323846 / 180.0, vdm::Vec3::UnitZ());
  f.translation() = pose.tip;
  return f;
}

vdm::Vec3 port_direction(double pan_deg, double tilt_deg) {
  const double k = 3.14159265358979323846 / 180.0, pan = pan_deg * k, tilt = tilt_deg * k;
  return vdm::Vec3(std::cos(tilt) * std::cos(pan), std::cos(tilt) * std::sin(pan), -std::sin(tilt));
}

namespace {

// The probe's shape frame in the instrument frame, and the shape's sizes.
void probe_local(const InstrumentDef& def, vdm::ToolShape& t, Eigen::Isometry3d& local) {
  local = Eigen::Isometry3d::Identity();
  const double len = std::max(def.length, 2 * def.radius);
  switch (def.shape.kind) {
    case ProbeShape::Kind::capsule: {
      // Segment from the tip's centre (z = -r) to z = -max(L - r, r).
      const double z0 = -def.radius, z1 = -std::max(def.length - def.radius, def.radius);
      t.kind = vdm::ToolShape::Kind::capsule;
      t.half_size = vdm::Vec3(def.radius, def.radius, 0.5 * (z0 - z1));
      t.rounding = def.radius;
      local.translation() = vdm::Vec3(0, 0, 0.5 * (z0 + z1));
      break;
    }
    case ProbeShape::Kind::cylinder:
      t.kind = vdm::ToolShape::Kind::cylinder;
      t.half_size = vdm::Vec3(def.radius, def.radius, 0.5 * len);
      t.rounding = def.shape.rounding;
      local.translation() = vdm::Vec3(0, 0, -0.5 * len);
      break;
    case ProbeShape::Kind::box:
      t.kind = vdm::ToolShape::Kind::box;
      t.half_size = 0.5 * def.shape.size;
      t.rounding = def.shape.rounding;
      local.translation() = vdm::Vec3(0, 0, -0.5 * def.shape.size.z());
      break;
    case ProbeShape::Kind::convex:
      t.kind = vdm::ToolShape::Kind::convex;
      t.hull = def.shape.hull;
      t.rounding = 0;
      break;
  }
}

}  // namespace

vdm::ToolShape probe_shape(const InstrumentDef& def, const InstrumentPose& pose, const InstrumentPose& previous) {
  vdm::ToolShape t;
  Eigen::Isometry3d local;
  probe_local(def, t, local);
  t.pose = instrument_frame(pose) * local;
  t.previous = instrument_frame(previous) * local;
  return t;
}

vdm::Vec3 jaw_half_size(const InstrumentDef& def) {
  return vdm::Vec3(0.8 * def.radius, 0.5 * 0.45 * def.radius, 0.5 * def.jaw_length);
}

Eigen::Isometry3d jaw_transform(double jaw_length, double opening, int side) {
  const double angle = side * kMaxJawAngleDeg * 3.14159265358979323846 / 180.0 * std::clamp(opening, 0.0, 1.0);
  const vdm::Vec3 pivot(0, 0, -jaw_length);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translate(pivot);
  t.rotate(Eigen::AngleAxisd(-angle, vdm::Vec3::UnitX()));
  t.translate(-pivot);
  return t;
}

vdm::ToolShape jaw_shape(const InstrumentDef& def, const InstrumentPose& pose, const InstrumentPose& previous, int side) {
  vdm::ToolShape t;
  t.kind = vdm::ToolShape::Kind::box;
  t.half_size = jaw_half_size(def);
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
  local.translation() = vdm::Vec3(0, side * t.half_size.y(), -t.half_size.z());  // the closed jaw's centre
  t.pose = instrument_frame(pose) * jaw_transform(def.jaw_length, pose.jaw_opening, side) * local;
  t.previous = instrument_frame(previous) * jaw_transform(def.jaw_length, previous.jaw_opening, side) * local;
  return t;
}

vdm::ToolShape shaft_shape(const InstrumentDef& def, const InstrumentPose& pose, const InstrumentPose& previous) {
  // The drawn shaft (render/instrument_geometry: grasper_shaft_mesh) is a cylinder from
  // z = -jaw_length - 0.6 r back to the handle end with a hemisphere at the front.
  const double z0 = -def.jaw_length - 0.6 * def.radius;
  const double z1 = -std::max(def.length, def.jaw_length + 2 * def.radius);
  vdm::ToolShape t;
  t.kind = vdm::ToolShape::Kind::capsule;
  t.half_size = vdm::Vec3(def.radius, def.radius, 0.5 * (z0 - z1));
  t.rounding = def.radius;
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
  local.translation() = vdm::Vec3(0, 0, 0.5 * (z0 + z1));
  t.pose = instrument_frame(pose) * local;
  t.previous = instrument_frame(previous) * local;
  return t;
}

double instrument_motion(const InstrumentDef& def, const InstrumentPose& a, const InstrumentPose& b, double reach_limit) {
  // The tip's motion plus the turn of the axis and the jaws times the reach of the shapes.
  // (A roll moves no point farther than the reach times its angle either.)
  const double turn = std::acos(std::clamp(a.axis.normalized().dot(b.axis.normalized()), -1.0, 1.0)) +
                      std::abs(b.roll_deg - a.roll_deg) * 3.14159265358979323846 / 180.0;
  double reach = 0;
  if (def.type == InstrumentDef::Type::probe) {
    vdm::ToolShape t;
    Eigen::Isometry3d local;
    probe_local(def, t, local);
    reach = local.translation().norm() + t.bound();
  } else {
    const double jaws_reach = def.jaw_length + 3 * def.radius;
    reach = std::max(std::min(def.length, reach_limit), jaws_reach);  // the shaft's far end, or as far as it can touch
  }
  double jaws = 0;
  if (def.type == InstrumentDef::Type::grasper)
    jaws = std::abs(a.jaw_opening - b.jaw_opening) * kMaxJawAngleDeg * 3.14159265358979323846 / 180.0 * def.jaw_length;
  return (a.tip - b.tip).norm() + turn * reach + jaws;
}

double instrument_size(const InstrumentDef& def) {
  if (def.type == InstrumentDef::Type::grasper) return jaw_half_size(def).minCoeff();
  vdm::ToolShape t;
  Eigen::Isometry3d local;
  probe_local(def, t, local);
  return t.size();
}

}  // namespace tools
