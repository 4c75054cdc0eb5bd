#include "app/simulation/core_cell.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "engine/geometry.hpp"
#include "tools_scripted/instrument.hpp"

namespace vdmsim {

namespace {

// The width of the tissue an instrument loads: a probe's diameter (its shape's smallest size),
// a grasper's jaw face across (it holds the tissue between its faces, however thin the jaws).
double loaded_width(const tools::InstrumentDef& def) {
  if (def.type == tools::InstrumentDef::Type::grasper) return 2 * tools::jaw_half_size(def).x();
  return 2 * tools::instrument_size(def);
}

// The narrowest loaded width of the scene's instruments (0 with none) and its index.
double smallest_instrument(const SceneDef& s, size_t& which) {
  double width = 0;
  which = 0;
  for (size_t k = 0; k < s.instruments.size(); ++k) {
    const double w = loaded_width(s.instruments[k]);
    if (w > 0 && (width == 0 || w < width)) width = w, which = k;
  }
  return width;
}

}  // namespace

double core_cell_size(const SceneDef& s, const OrganDef& o, const vdm::SurfaceMesh& organ) {
  if (o.cell_size > 0) return o.cell_size;
  const vdm::NodeMat& x = organ.positions;
  const double area = vdm::surface_area(x, organ.triangles);
  const double volume = std::abs(vdm::enclosed_volume(x, organ.triangles, x.colwise().mean().transpose()));
  if (!(area > 0) || !(volume > 0)) return 0.0;  // the engine's own default (and its error)
  double h = volume / area;
  size_t which = 0;
  const double width = smallest_instrument(s, which);
  if (width > 0) h = std::min(h, width);
  return std::max(h, std::cbrt(volume / kDefaultCoreCubes));
}

void check_core_cell(const SceneDef& s, const OrganDef& o, const vdm::SurfaceMesh& organ,
                     std::vector<SceneProblem>& problems) {
  if (organ.node_count() == 0) return;
  const vdm::NodeMat& x = organ.positions;
  const vdm::Vec3 extent = (x.colwise().maxCoeff() - x.colwise().minCoeff()).transpose();
  const double area = vdm::surface_area(x, organ.triangles);
  const double volume = std::abs(vdm::enclosed_volume(x, organ.triangles, x.colwise().mean().transpose()));
  const bool given = o.cell_size > 0;
  const double h = core_cell_size(s, o, organ);
  const std::string where = o.cell_size_where.empty() ? s.file : o.cell_size_where;
  std::ostringstream m;
  m.precision(3);
  // A cube fits in the organ's box when its edge is at most the box's smallest side.
  if (given && h > extent.minCoeff()) {
    m << "a cell of " << h << " m does not fit in the organ's box (" << extent.x() << " x " << extent.y() << " x "
      << extent.z() << " m): the core would be a cell or two and its forces wrong by orders of magnitude; give at most "
      << extent.minCoeff() << " m, or 0 for the default (at most the organ's volume over its area, " << volume / area << " m)";
    problems.push_back({where, o.field + ".cell_size", m.str(), false});
    return;
  }
  double cells = 1;
  for (int k = 0; k < 3; ++k) cells *= std::ceil(extent[k] / h) + 1;
  if (cells > kMaxCoreCells) {
    m << "a cell of " << h << " m gives about " << cells << " cells over the organ's box (" << extent.x() << " x "
      << extent.y() << " x " << extent.z() << " m), more than the core's " << kMaxCoreCells << ": give at least "
      << 1.1 * std::cbrt(extent.prod() / kMaxCoreCells) << " m";
    problems.push_back({where, o.field + ".cell_size", m.str(), false});
    return;
  }
  size_t which = 0;
  const double width = smallest_instrument(s, which);
  // More than twice its width: the dent under it spans less than half a cell (1 cm cells under
  // an 8 mm probe are within).
  if (width > 0 && h > 2 * width) {
    m << (given ? "a cell of " : "the default cell (bounded by the core's size) of ") << h
      << " m is more than twice as wide as instruments[" << which << "] (" << width
      << " m across): a dent narrower than a few cells is resisted by the ties alone and its force comes out too "
         "small; a cell_size near the instrument's half width ("
      << width / 2 << " m) follows it";
    problems.push_back({where, o.field + ".cell_size", m.str(), true});
  }
}

}  // namespace vdmsim
