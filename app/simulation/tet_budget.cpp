#include "app/simulation/tet_budget.hpp"

#include <cmath>
#include <sstream>

#include "engine/geometry.hpp"

namespace vdmsim {

namespace {
// The volume of a regular tetrahedron of unit edge: 1 / (6 sqrt 2).
const double kUnitTetVolume = 1.0 / (6.0 * std::sqrt(2.0));
}  // namespace

double tets_needed(double volume, double edge) { return volume / (kUnitTetVolume * edge * edge * edge); }

bool check_tet_budget(const vdm::SurfaceMesh& surface, double edge, std::string& error) {
  if (!(edge > 0) || surface.node_count() == 0) return true;
  const vdm::NodeMat& x = surface.positions;
  const double volume = std::abs(vdm::enclosed_volume(x, surface.triangles, x.colwise().mean().transpose()));
  const double tets = tets_needed(volume, edge);
  if (tets <= kMaxTets) return true;
  std::ostringstream m;
  m.precision(3);
  m << "tet_size " << edge << " m would give at least " << tets << " tetrahedra in the organ's " << volume * 1e6
    << " cm^3, more than the limit of " << kMaxTets << ": use a tet_size of at least "
    << std::cbrt(volume / (kUnitTetVolume * kMaxTets)) << " m";
  error = m.str();
  return false;
}

}  // namespace vdmsim
