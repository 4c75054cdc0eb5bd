#include "app/check/scene_sanity.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "app/scene/scene_keys.hpp"
#include "app/simulation/organ_overlap.hpp"
#include "app/simulation/organ_ties.hpp"
#include "app/simulation/scene_simulation.hpp"

namespace vdmsim {

namespace {

std::string num(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

std::string share(int part, int whole) { return num(whole > 0 ? 100.0 * part / whole : 0.0, 3) + " %"; }

std::string instrument_name(size_t k) {
  return "instruments[" + std::to_string(k) + "]";
}

// How far across a region is (m; 0 for node lists and `all`).
double region_extent(const Region& r) {
  if (r.kind == Region::Kind::box) return (r.max - r.min).norm();
  if (r.kind == Region::Kind::sphere) return 2 * r.radius;
  return 0;
}

void check_fixed(const SceneDef& s, const OrganDef& o, const FixedCount& c, double organ_size,
                 std::vector<SceneProblem>& out) {
  if (c.nodes == 0 || c.fixed < c.nodes) return;
  std::string message = "all " + std::to_string(c.nodes) + " nodes are fixed on every axis: nothing can move";
  size_t widest = 0;
  for (size_t k = 0; k < o.fixed.size(); ++k)
    if (region_extent(o.fixed[k].region) > region_extent(o.fixed[widest].region)) widest = k;
  const double extent = o.fixed.empty() ? 0 : region_extent(o.fixed[widest].region);
  if (extent > 10 * organ_size)
    message += " (" + o.field + ".fixed[" + std::to_string(widest) + "] is " + num(extent) + " m across, the organ " + num(organ_size) +
               " m: a region in millimetres? regions are in metres, after organ.scale)";
  else
    message += "; fix only the part of the organ that rests on something";
  out.push_back({o.fixed.empty() ? s.file : o.fixed[widest].region.where, o.field + ".fixed", message, false});
}

// Organs that overlap at rest: deeper than a run allows (it would stop at its first frame) an
// error, a touch within it a warning.
void check_overlaps(const PreparedScene& ps, std::vector<SceneProblem>& out) {
  const SceneDef& s = ps.scene;
  for (size_t i = 0; i < ps.organs.size(); ++i)
    for (size_t j = i + 1; j < ps.organs.size(); ++j) {
      const vdm::SurfaceMesh &a = ps.organs[i].model.rest, &b = ps.organs[j].model.rest;
      const OrganOverlap o = find_overlap(a.positions, a.triangles, b.positions, b.triangles);
      if (!o.crossing) continue;
      const OrganDef& in = s.organs[o.in_b ? i : j];
      const OrganDef& into = s.organs[o.in_b ? j : i];
      const bool deep = o.depth > kOrganOverlap;
      out.push_back({s.file, s.organs[j].field,
                     s.organs[i].name + " and " + s.organs[j].name + " overlap at rest: node " + std::to_string(o.node) +
                         " of " + in.name + " is " + num(o.depth * 1000) + " mm inside " + into.name + " at [" +
                         num(o.where.x()) + ", " + num(o.where.y()) + ", " + num(o.where.z()) + "] m" +
                         (deep ? "; a run stops when organs are more than " + num(kOrganOverlap * 1000) +
                                     " mm inside each other (contact between organs cannot push apart organs placed "
                                     "inside each other); move them apart"
                               : " (their surfaces touch)"),
                     !deep});
    }
}

// Attachments that tie no node: no node of the first organ is within `within` of the second's
// surface at rest.
void check_attachments(const PreparedScene& ps, std::vector<SceneProblem>& out) {
  std::vector<int> ties;
  organ_ties(ps, &ties);
  for (size_t k = 0; k < ties.size() && k < ps.scene.attachments.size(); ++k) {
    if (ties[k] > 0) continue;
    const AttachmentDef& a = ps.scene.attachments[k];
    out.push_back({ps.scene.file, a.field,
                   "ties nothing: no node of " + ps.scene.organs[static_cast<size_t>(a.first)].name + " is within " +
                       num(a.within * 1000) + " mm of " + ps.scene.organs[static_cast<size_t>(a.second)].name +
                       "'s surface at rest; place the organs nearer or raise within",
                   true});
  }
}

void check_instruments(const SceneDef& s, const std::vector<InstrumentReach>& reach, double organ_size, double end,
                       std::vector<SceneProblem>& out) {
  for (size_t k = 0; k < reach.size(); ++k) {
    const InstrumentReach& r = reach[k];
    const InstrumentDef& def = s.instruments[k];
    const std::string where = k < s.instrument_where.size() ? s.instrument_where[k] : s.file;
    // A grasper holds the nodes within grasp_width of its closed jaws: it need not touch.
    const bool grasps = def.type == InstrumentDef::Type::grasper && s.has(Effect::grasp);
    const bool meant_to_touch = s.has(Effect::contact) || grasps;
    const double reach = grasps ? def.grasp_width : 0.0;
    if (meant_to_touch && !r.touches && r.closest > reach) {
      std::string message = "never touches the organ in the " + std::to_string(s.frames) + " frames (closest " +
                            num(r.closest) + " m, at t = " + num(r.closest_at) + " s" +
                            (grasps ? ": farther than its grasp_width, " + num(def.grasp_width) + " m" : "") + ")";
      if (r.closest > 10 * organ_size)
        message += ": the organ is " + num(organ_size) + " m across; keyframes in millimetres? tips are in metres";
      out.push_back({where, instrument_name(k), message, true});
    }
    if (r.start_distance < 0)
      out.push_back({where, instrument_name(k),
                     "starts inside the organ: " + num(r.start_depth * 1000) +
                         " mm into the rest surface at t = 0 (a reversed axis, or a tip on the wrong side?)",
                     true});
  }
  // The script that ends last, when it ends after the last frame.
  double last = 0;
  size_t which = 0;
  for (size_t k = 0; k < s.instruments.size(); ++k)
    for (const Keyframe& key : s.instruments[k].script)
      if (key.t > last) {
        last = key.t;
        which = k;
      }
  // A shortfall under 1 % of a frame is the round-off of a dt written with few digits.
  if (last > end + 0.01 * s.dt) {
    // Frame f is the scene at f dt: the script's last time needs frames 0 .. ceil(last / dt).
    const long needed = static_cast<long>(std::ceil(last / s.dt - 0.01)) + 1;
    out.push_back({s.file, "simulation.frames",
                   "the script of " + instrument_name(which) + " runs to t = " + num(last) + " s but " +
                       std::to_string(s.frames) + " frames of " + num(s.dt) + " s (the first at t = 0) end at t = " +
                       num(end) + " s: the rest is not simulated; " + std::to_string(needed) + " frames cover it",
                   true});
  }
}

void check_material(const SceneDef& s, std::vector<SceneProblem>& out) {
  if (s.organ().material_given) return;
  const SceneDef d;
  // The model's material keys with their defaults, as the scene reference gives them.
  std::string values;
  for (const std::string& path : organ_model(s.organ().model).material) {
    const SceneKey& k = kSceneKeys[scene_key_index(path.c_str())];
    values += (values.empty() ? "" : ", ") + path.substr(path.rfind('.') + 1) + " " + k.default_value() +
              (*k.unit ? std::string(" ") + k.unit : std::string());
  }
  out.push_back({s.file, "organ.material",
                 "not given: the default material is used (" + values + ", density " + num(d.organ().density, 6) +
                     " kg/m^3); give your tissue's",
                 true});
}

// Coordinates of the order of `scale`, those within round-off of zero (and -0) printed as 0.
std::string point(const vdm::Vec3& v, double scale) {
  std::string s;
  for (int d = 0; d < 3; ++d) s += (d ? " " : "") + num(std::abs(v[d]) < 1e-12 * scale ? 0.0 : v[d]);
  return s;
}

// Where instrument k's keyframes placed on the organ (on_surface) put its tip.
void print_placements(const PreparedScene& ps, size_t k, std::ostream& out) {
  const std::vector<SurfacePlacement>& list = ps.scene.surface_keyframes;
  const double size = std::max(ps.organ().model.size, 1e-300);
  for (size_t j = 0; j < list.size() && j < ps.surface_hits.size(); ++j) {
    const SurfacePlacement& p = list[j];
    if (p.instrument != k) continue;
    const SurfaceHit& h = ps.surface_hits[j];
    out << "            script[" << p.keyframe << "] (t = " << num(ps.scene.instruments[k].script[p.keyframe].t)
        << " s): tip " << point(h.tip, size) << " m, ";
    if (p.depth == 0) out << "on";
    else out << num(std::abs(p.depth) * 1000) << " mm " << (p.depth > 0 ? "inside" : "outside");
    out << " the surface point " << point(h.point, size) << " (outward normal " << point(h.normal, 1.0) << ")"
        << (p.align ? ", axis along the inward normal" : "") << "\n";
  }
}

}  // namespace

SanityReport scene_sanity(const PreparedScene& ps) {
  const SceneDef& s = ps.scene;
  SanityReport r;
  r.end_time = std::max(s.frames - 1, 0) * s.dt;  // frame f is the scene at f dt
  for (size_t o = 0; o < s.organs.size(); ++o) {
    r.fixed.push_back(count_fixed(s.organs[o], ps.organs[o].model.rest.positions));
    check_fixed(s, s.organs[o], r.fixed.back(), ps.organs[o].model.size, r.problems);
  }
  check_overlaps(ps, r.problems);
  check_attachments(ps, r.problems);
  for (const InstrumentDef& def : s.instruments)
    r.reach.push_back(instrument_reach(def, ps.surface, reach_times(def, s.frames, s.dt)));
  check_instruments(s, r.reach, ps.organ().model.size, r.end_time, r.problems);
  check_material(s, r.problems);
  return r;
}

void print_sanity(const PreparedScene& ps, const SanityReport& report, std::ostream& out) {
  const SceneDef& s = ps.scene;
  for (size_t o = 0; o < report.fixed.size(); ++o) {
    const FixedCount& c = report.fixed[o];
    const OrganDef& organ = s.organs[o];
    out << (report.fixed.size() > 1 ? "fixed (" + organ.name + "): " : std::string("fixed:      ")) << c.fixed << " of "
        << c.nodes << " nodes (" << share(c.fixed, c.nodes) << ") on every axis";
    if (c.partly) out << ", " << c.partly << " (" << share(c.partly, c.nodes) << ") on some axes";
    out << "\n";
    for (size_t k = 0; k < c.per_region.size(); ++k)
      out << "            " << organ.field << ".fixed[" << k << "]: " << c.per_region[k] << " nodes ("
          << share(c.per_region[k], c.nodes) << ")\n";
  }
  for (size_t k = 0; k < report.reach.size(); ++k) {
    const InstrumentReach& r = report.reach[k];
    out << instrument_name(k) << " ("
        << (s.instruments[k].type == InstrumentDef::Type::probe ? "probe" : "grasper") << "): ";
    if (r.touches)
      out << "first touches the organ at t = " << num(r.first_touch) << " s, deepest " << num(r.deepest * 1000)
          << " mm into the rest surface at t = " << num(r.deepest_at) << " s\n";
    else
      out << "does not touch the organ (closest " << num(r.closest * 1000) << " mm, at t = " << num(r.closest_at)
          << " s)\n";
    print_placements(ps, k, out);
  }
}

}  // namespace vdmsim
