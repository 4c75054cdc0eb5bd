#include "app/check/instrument_reach.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/simulation/tool_depth.hpp"
#include "engine/tool_shape.hpp"

namespace vdmsim {

namespace {

// The smallest signed distance from the rows of x to one shape. Exact distances only for the
// nodes that could be nearer than the best found: a node at distance r from the shape frame's
// origin is at least r - bound() from the shape.
double smallest_to_shape(const vdm::ToolShape& shape, const vdm::NodeMat& x) {
  if (x.rows() == 0) return std::numeric_limits<double>::infinity();
  const Eigen::VectorXd lower =
      (x.rowwise() - shape.pose.translation().transpose()).rowwise().norm().array() - shape.bound();
  Eigen::Index first = 0;
  lower.minCoeff(&first);
  vdm::Vec3 point, normal;
  double best = vdm::tool_distance(shape, x.row(first).transpose(), point, normal);
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    if (lower[i] < best) best = std::min(best, vdm::tool_distance(shape, x.row(i).transpose(), point, normal));
  return best;
}

}  // namespace

std::vector<double> reach_times(const InstrumentDef& def, int frames, double dt) {
  std::vector<double> times{0.0};
  const int stride = frames > kMaxSampledFrames ? (frames + kMaxSampledFrames - 1) / kMaxSampledFrames : 1;
  // Frame f is the scene at f dt: frames 0 .. frames - 1.
  for (int f = stride; f < frames - 1; f += stride) times.push_back(f * dt);
  if (frames > 1) times.push_back((frames - 1) * dt);
  const double end = (frames - 1 + 0.01) * dt;  // a keyframe within round-off of the last frame
  for (const Keyframe& k : def.script)
    if (k.t > 0 && k.t <= end) times.push_back(k.t);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  return times;
}

double smallest_distance(const InstrumentDef& def, double t, const vdm::NodeMat& x) {
  const tools::InstrumentPose pose = tools::pose_at(def, t);
  if (def.type == InstrumentDef::Type::probe) return smallest_to_shape(tools::probe_shape(def, pose, pose), x);
  double best = smallest_to_shape(tools::shaft_shape(def, pose, pose), x);
  for (int side : {+1, -1}) best = std::min(best, smallest_to_shape(tools::jaw_shape(def, pose, pose, side), x));
  return best;
}

InstrumentReach instrument_reach(const InstrumentDef& def, const vdm::SurfaceMesh& rest, const std::vector<double>& times) {
  InstrumentReach r;
  r.closest = std::numeric_limits<double>::infinity();
  for (double t : times) {
    const double d = smallest_distance(def, t, rest.positions);
    if (t == 0) r.start_distance = d;
    if (d < r.closest) {
      r.closest = d;
      r.closest_at = t;
    }
    if (d > 0) continue;
    const double tip = depth_inside(rest.positions, rest.triangles, tools::pose_at(def, t).tip);
    const double depth = std::max(-d, tip);
    if (t == 0) r.start_depth = depth;
    if (!r.touches) {
      r.touches = true;
      r.first_touch = r.deepest_at = t;
    }
    if (depth > r.deepest) {
      r.deepest = depth;
      r.deepest_at = t;
    }
  }
  return r;
}

}  // namespace vdmsim
