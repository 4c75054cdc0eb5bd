#include "app/run/instrument_focus.hpp"

#include <algorithm>
#include <limits>

#include "app/check/instrument_reach.hpp"
#include "app/simulation/tool_depth.hpp"

namespace vdmsim {

double working_distance(const InstrumentDef& def) { return std::max(0.005, 3 * def.radius); }

bool instruments_working_area(const PreparedScene& ps, vdm::Vec3& lo, vdm::Vec3& hi) {
  const SceneDef& s = ps.scene;
  const vdm::SurfaceMesh& rest = ps.surface;
  if (s.instruments.empty()) return false;
  const double inf = std::numeric_limits<double>::infinity();
  vdm::Vec3 near_lo = vdm::Vec3::Constant(inf), near_hi = vdm::Vec3::Constant(-inf);
  vdm::Vec3 all_lo = near_lo, all_hi = near_hi;
  bool any_near = false;
  double radius = 0, deepest = 0;
  for (const InstrumentDef& def : s.instruments) {
    radius = std::max(radius, def.radius);
    for (double t : reach_times(def, s.frames, s.dt)) {
      const vdm::Vec3 tip = tools::pose_at(def, t).tip;
      all_lo = all_lo.cwiseMin(tip);
      all_hi = all_hi.cwiseMax(tip);
      if (smallest_distance(def, t, rest.positions) > working_distance(def)) continue;
      any_near = true;
      near_lo = near_lo.cwiseMin(tip);
      near_hi = near_hi.cwiseMax(tip);
      deepest = std::max(deepest, depth_inside(rest.positions, rest.triangles, tip));
    }
  }
  const double pad = std::max({0.06 * ps.organ().model.size, 5 * radius, 2 * deepest});
  lo = (any_near ? near_lo : all_lo) - vdm::Vec3::Constant(pad);
  hi = (any_near ? near_hi : all_hi) + vdm::Vec3::Constant(pad);
  return true;
}

render::RenderSettings framed_settings(const PreparedScene& ps) {
  render::RenderSettings settings = ps.scene.render.settings;
  for (const tools::InstrumentDef& in : ps.scene.instruments)
    if (in.port) settings.ports.push_back(*in.port);
  vdm::Vec3 lo, hi;
  if (settings.auto_camera && settings.focus == render::CameraFocus::instruments && instruments_working_area(ps, lo, hi)) {
    settings.has_focus_box = true;
    settings.focus_lo = lo;
    settings.focus_hi = hi;
  }
  // Each organ's triangles in its own look and segmentation id (several organs, or one with a
  // look other than the liver's).
  const bool looks = std::any_of(ps.scene.organs.begin(), ps.scene.organs.end(),
                                 [](const OrganDef& o) { return o.gallbladder_look; });
  if (looks || ps.organs.size() > 1)
    for (size_t i = 0; i < ps.organs.size() && i < ps.scene.organs.size(); ++i)
      settings.organ_parts.push_back({static_cast<long>(ps.organs[i].model.rest.triangles.rows()),
                                      ps.scene.organs[i].gallbladder_look ? render::TissueLook::gallbladder
                                                                          : render::TissueLook::liver});
  return settings;
}

}  // namespace vdmsim
