#pragma once
// Where an instrument's script takes it relative to the organ, without simulating: a geometric
// pass over the script against the organ's rest (undeformed) surface, for `vdmsim check`.
#include <vector>

#include "app/scene/scene.hpp"

namespace vdmsim {

struct InstrumentReach {
  double start_distance = 0;   // the smallest signed distance at t = 0 (m; negative: inside)
  double start_depth = 0;      // how deep it is into the rest surface at t = 0 (m, >= 0)
  double closest = 0;          // the smallest signed distance over the pass (m), and when
  double closest_at = 0;
  bool touches = false;        // some sampled time has a distance <= 0
  double first_touch = 0;      // the first such time (s)
  double deepest = 0;          // how deep it goes into the rest surface (m, >= 0), and when
  double deepest_at = 0;
};

// The times the pass samples for `def`: every frame's time f dt (f = 0 .. frames - 1; every
// k-th frame when there are more than kMaxSampledFrames, and the last), and the script's
// keyframe times up to the last frame's, sorted.
constexpr int kMaxSampledFrames = 20000;
std::vector<double> reach_times(const InstrumentDef& def, int frames, double dt);

// The smallest signed distance from the rest nodes `x` to the instrument's collision shapes
// (a probe's shape; a grasper's two jaws and shaft) at time t.
double smallest_distance(const InstrumentDef& def, double t, const vdm::NodeMat& x);

// The pass over `times`. The depth at a time is the larger of how far the rest nodes are
// inside the instrument and how far its tip is inside the rest surface.
InstrumentReach instrument_reach(const InstrumentDef& def, const vdm::SurfaceMesh& rest, const std::vector<double>& times);

}  // namespace vdmsim
