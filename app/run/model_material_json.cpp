// Each organ model's lines of run.json (organ_model_table.hpp's write_run_json): the material
// it used.
#include <cmath>
#include <ostream>
#include <string>

#include "app/scene/organ_model_table.hpp"
#include "app/simulation/prepared_scene.hpp"

namespace vdmsim {

// The moduli the VDM model used (an infinite bulk modulus as the string "inf").
void VdmRow::write_run_json(const PreparedScene& ps, std::ostream& js) {
  const SceneDef& s = ps.scene;
  const vdm::TissueModel& m = ps.model;
  auto modulus = [](double b) { return std::isfinite(b) ? std::to_string(b) : std::string("\"inf\""); };
  js << "  \"material\": {\"bulk_modulus_pa\": [" << modulus(s.bulk_modulus[0]) << ", " << modulus(s.bulk_modulus[1])
     << ", " << modulus(s.bulk_modulus[2]) << "], \"connectivity_modulus_pa\": " << s.connectivity_modulus
     << ", \"capsule\": \"" << vdm::to_string(m.capsule) << '"';
  if (m.membrane_capsule()) js << ", \"capsule_tension_n_per_m\": " << m.capsule_tension;
  if (m.bending_modulus > 0) js << ", \"bending_modulus_n_m\": " << m.bending_modulus;
  if (s.moduli_from_elastic)
    js << ", \"from\": {\"young_modulus_pa\": " << s.young_modulus << ", \"poisson_ratio\": " << s.poisson_ratio
       << ", \"rule\": \"docs/model.md: B = beta E, B_ij = gamma(nu) E\"}";
  js << "},\n";
}

// The elastic core's material and lattice.
void VdmCoreRow::write_run_json(const PreparedScene& ps, std::ostream& js) {
  const vdm::core::CoreModel& c = ps.reference.core;
  js << "  \"material\": {\"young_modulus_pa\": " << c.young_modulus << ", \"core\": {\"cell_size_m\": " << c.h
     << ", \"lattice_nodes\": " << c.ng << ", \"cubes\": " << c.cubes.rows() << ", \"tie_pa_per_m\": " << c.kappa
     << "}},\n";
}

// The reference models report no material of their own.
void FemRow::write_run_json(const PreparedScene&, std::ostream&) {}
void MassSpringRow::write_run_json(const PreparedScene&, std::ostream&) {}

}  // namespace vdmsim
