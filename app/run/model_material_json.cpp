// Each organ model's part of an organ's entry in run.json (organ_model_table.hpp's
// write_run_json): the material it used.
#include <cmath>
#include <ostream>
#include <string>

#include "app/scene/organ_model_table.hpp"
#include "app/simulation/prepared_scene.hpp"

namespace vdmsim {

// The moduli the VDM model used (an infinite bulk modulus as the string "inf").
void VdmRow::write_run_json(const OrganDef& o, const PreparedOrgan& organ, std::ostream& js) {
  const vdm::TissueModel& m = organ.model;
  auto modulus = [](double b) { return std::isfinite(b) ? std::to_string(b) : std::string("\"inf\""); };
  js << "\"material\": {\"bulk_modulus_pa\": [" << modulus(o.bulk_modulus[0]) << ", " << modulus(o.bulk_modulus[1])
     << ", " << modulus(o.bulk_modulus[2]) << "], \"connectivity_modulus_pa\": " << o.connectivity_modulus
     << ", \"capsule\": \"" << vdm::to_string(m.capsule) << '"';
  if (m.membrane_capsule()) js << ", \"capsule_tension_n_per_m\": " << m.capsule_tension;
  if (m.bending_modulus > 0) js << ", \"bending_modulus_n_m\": " << m.bending_modulus;
  if (o.moduli_from_elastic)
    js << ", \"from\": {\"young_modulus_pa\": " << o.young_modulus << ", \"poisson_ratio\": " << o.poisson_ratio
       << ", \"rule\": \"docs/model.md: B = beta E, B_ij = gamma(nu) E\"}";
  js << "}";
}

// The elastic core's material and lattice.
void VdmCoreRow::write_run_json(const OrganDef&, const PreparedOrgan& organ, std::ostream& js) {
  const vdm::core::CoreModel& c = organ.reference.core;
  js << "\"material\": {\"young_modulus_pa\": " << c.young_modulus << ", \"core\": {\"cell_size_m\": " << c.h
     << ", \"lattice_nodes\": " << c.ng << ", \"cubes\": " << c.cubes.rows() << ", \"tie_pa_per_m\": " << c.kappa
     << "}}";
}

// The reference models report no material of their own.
void FemRow::write_run_json(const OrganDef&, const PreparedOrgan&, std::ostream&) {}
void MassSpringRow::write_run_json(const OrganDef&, const PreparedOrgan&, std::ostream&) {}

}  // namespace vdmsim
