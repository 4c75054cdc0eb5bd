#include "render/render_scene.hpp"

#include <cmath>

#include "tools_scripted/grasp.hpp"

namespace render {
namespace {

struct QuantityInfo {
  Quantity q;
  const char* name;
  const char* label;
  const char* unit;
  bool is_signed;
  bool needs_stress;  // from the model's stress pass (organ.model vdm with the stress effect)
};

const QuantityInfo kQuantities[] = {
    {Quantity::stress_magnitude, "magnitude", "Stress magnitude", "Pa", false, true},
    {Quantity::stress_x, "stress_x", "Stress x", "Pa", true, true},
    {Quantity::stress_y, "stress_y", "Stress y", "Pa", true, true},
    {Quantity::stress_z, "stress_z", "Stress z", "Pa", true, true},
    {Quantity::contact_pressure, "contact_pressure", "Contact pressure", "Pa", false, false},
    {Quantity::displacement, "displacement", "Displacement", "m", false, false},
    {Quantity::volumetric_strain, "volumetric_strain", "Volumetric strain", "", true, true},
};

const QuantityInfo& info(Quantity q) { return kQuantities[static_cast<int>(q)]; }

}  // namespace

bool parse_quantity(const std::string& text, Quantity& out) {
  for (const QuantityInfo& i : kQuantities)
    if (text == i.name) {
      out = i.q;
      return true;
    }
  return false;
}

const char* to_string(Quantity q) { return info(q).name; }
const char* quantity_label(Quantity q) { return info(q).label; }
const char* quantity_unit(Quantity q) { return info(q).unit; }
bool quantity_is_signed(Quantity q) { return info(q).is_signed; }
bool quantity_needs_stress(Quantity q) { return info(q).needs_stress; }

std::vector<Quantity> all_quantities() {
  std::vector<Quantity> out;
  for (const QuantityInfo& i : kQuantities) out.push_back(i.q);
  return out;
}

std::vector<std::string> quantity_names() {
  std::vector<std::string> out;
  for (const QuantityInfo& i : kQuantities) out.push_back(i.name);
  return out;
}

void scalar_field(Quantity q, const vdm::SimState& s, std::vector<float>& out) {
  const Eigen::Index n = s.u.rows();
  out.resize(static_cast<size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    double v = 0;
    switch (q) {
      case Quantity::stress_magnitude: v = s.stress.row(i).norm(); break;
      case Quantity::stress_x: v = s.stress(i, 0); break;
      case Quantity::stress_y: v = s.stress(i, 1); break;
      case Quantity::stress_z: v = s.stress(i, 2); break;
      case Quantity::contact_pressure: v = s.reaction_pressure.size() == n ? s.reaction_pressure(i) : 0.0; break;
      case Quantity::displacement: v = s.u.row(i).norm(); break;
      case Quantity::volumetric_strain: v = s.strain.row(i).sum(); break;
    }
    out[static_cast<size_t>(i)] = std::isfinite(v) ? static_cast<float>(v) : 0.0f;
  }
}

InstrumentView instrument_view(const tools::InstrumentDef& def, const tools::InstrumentPose& pose) {
  InstrumentView v;
  v.type = def.type;
  v.shape = def.shape;
  v.radius = def.radius;
  v.length = def.length;
  v.jaw_length = def.jaw_length;
  v.jaw_opening = pose.jaw_opening;
  v.jaw_look = def.jaw_look;
  v.probe_look = def.probe_look;
  v.frame = tools::jaw_frame(pose);
  return v;
}

}  // namespace render
