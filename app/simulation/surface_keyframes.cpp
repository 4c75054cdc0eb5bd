#include "app/simulation/surface_keyframes.hpp"

#include <sstream>

#include "app/mesh_prep/ray_locate.hpp"

namespace vdmsim {

namespace {

std::string triple(const vdm::Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

}  // namespace

std::string placement_field(const SurfacePlacement& p) {
  return "instruments[" + std::to_string(p.instrument) + "].script[" + std::to_string(p.keyframe) + "]";
}

bool resolve_surface_keyframes(SceneDef& scene, const vdm::SurfaceMesh& surface, std::vector<SurfaceHit>& hits,
                               std::vector<SceneProblem>& problems) {
  hits.clear();
  bool ok = true;
  for (const SurfacePlacement& p : scene.surface_keyframes) {
    const std::string field = placement_field(p) + ".on_surface";
    const RayHit h = first_hit(surface, p.from, p.toward);
    if (!h.hit) {
      const vdm::Vec3 lo = surface.positions.colwise().minCoeff(), hi = surface.positions.colwise().maxCoeff();
      problems.push_back({p.where, field,
                          "the ray from " + triple(p.from) + " toward " + triple(p.toward) +
                              " misses the organ, which spans " + triple(lo) + " to " + triple(hi) +
                              " m after scale, rotate_deg and translate",
                          false});
      ok = false;
      hits.emplace_back();
      continue;
    }
    if (h.normal.dot(p.toward) > 0) {
      problems.push_back({p.where, field,
                          "the ray from " + triple(p.from) + " starts inside the organ (it leaves the surface at " +
                              triple(h.point) + "): start it outside",
                          false});
      ok = false;
      hits.emplace_back();
      continue;
    }
    SurfaceHit out;
    out.point = h.point;
    out.normal = h.normal;
    out.tip = h.point - p.depth * h.normal;
    hits.push_back(out);
    if (p.instrument >= scene.instruments.size() || p.keyframe >= scene.instruments[p.instrument].script.size()) continue;
    Keyframe& key = scene.instruments[p.instrument].script[p.keyframe];
    key.tip = out.tip;
    if (p.align) key.axis = -h.normal;
  }
  return ok;
}

}  // namespace vdmsim
