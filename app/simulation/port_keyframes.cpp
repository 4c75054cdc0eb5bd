#include "app/simulation/port_keyframes.hpp"

#include <string>

namespace vdmsim {

bool check_port_keyframes(const SceneDef& scene, const vdm::SurfaceMesh& placed, std::vector<SceneProblem>& problems) {
  const vdm::Vec3 centre = 0.5 * (placed.positions.colwise().minCoeff() + placed.positions.colwise().maxCoeff()).transpose();
  bool ok = true;
  for (size_t i = 0; i < scene.instruments.size(); ++i) {
    const InstrumentDef& in = scene.instruments[i];
    if (!in.port) continue;
    const vdm::Vec3 port = *in.port, inward = centre - port;
    for (size_t k = 0; k < in.script.size(); ++k) {
      if (!in.script[k].tip) continue;
      const std::string field = "instruments[" + std::to_string(i) + "].script[" + std::to_string(k) + "]";
      const std::string where = i < scene.keyframe_where.size() && k < scene.keyframe_where[i].size()
                                    ? scene.keyframe_where[i][k]
                                    : scene.file;
      const vdm::Vec3 d = *in.script[k].tip - port;
      if (d.dot(inward) <= 0) {
        problems.push_back({where, field,
                            "the tip is behind the port (on its side away from the organ): the shaft cannot pass "
                            "the port toward it",
                            false});
        ok = false;
      } else if (d.norm() > in.length) {
        problems.push_back({where, field,
                            "the tip is " + std::to_string(d.norm()) + " m from the port: farther than the instrument "
                            "is long (" + std::to_string(in.length) + " m)",
                            false});
        ok = false;
      }
    }
  }
  return ok;
}

}  // namespace vdmsim
