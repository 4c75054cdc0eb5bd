#pragma once
// Scripted instruments: a definition (shape and keyframe timeline) and its pose at any time.
// Positions are interpolated linearly between keyframes, or by a spline (a monotone cubic
// Hermite per coordinate: through every keyframe, continuous velocity, no overshoot, at rest at
// the first and last keyframe and wherever a coordinate turns or holds); axes by slerp. A
// keyframe that omits a field keeps the previous one. Before the first keyframe the instrument waits at it; after
// the last it stays there.
#include <optional>
#include <vector>

#include "engine/contact.hpp"
#include "engine/types.hpp"

namespace tools {

struct Keyframe {
  double t = 0;                      // s
  std::optional<vdm::Vec3> tip;      // m: where the working end is
  std::optional<vdm::Vec3> axis;     // unit vector from the handle toward the tip
  std::optional<bool> jaw_closed;    // grasper only
};

struct InstrumentDef {
  enum class Type { probe, grasper } type = Type::probe;
  double radius = 0.004;             // m
  double length = 0.3;               // m, tip to handle end
  double jaw_length = 0.02;          // grasper: jaws from the pivot to the tip (m)
  double grasp_width = 0.005;        // grasper: nodes within this of the closed jaws are held (m)
  std::vector<Keyframe> script;      // strictly increasing t, first keyframe has a tip
  enum class Path { linear, spline } path = Path::linear;  // how tip positions are interpolated
};

struct InstrumentPose {
  vdm::Vec3 tip = vdm::Vec3::Zero();
  vdm::Vec3 axis = -vdm::Vec3::UnitZ();
  bool jaw_closed = false;
  double jaw_opening = 1;  // for drawing: 1 open, 0 closed, moving linearly between keyframes
};

InstrumentPose pose_at(const InstrumentDef& def, double t);

// The probe's collision shape: a capsule whose rounded end is exactly at the tip.
vdm::Capsule probe_capsule(const InstrumentDef& def, const InstrumentPose& pose);

}  // namespace tools
