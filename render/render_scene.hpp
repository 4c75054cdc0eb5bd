#pragma once
// RenderScene: what one frame shows, built from the simulation state and the instrument
// poses (MuJoCo's mjvScene). The renderer draws it and nothing else; it never reads SimState.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "engine/sim_state.hpp"
#include "engine/tissue_model.hpp"
#include "tools_scripted/instrument.hpp"

namespace render {

// What the stress view colours the organ by.
enum class Quantity { stress_magnitude, stress_x, stress_y, stress_z, contact_pressure, displacement, volumetric_strain };
bool parse_quantity(const std::string& text, Quantity& out);
const char* to_string(Quantity q);
std::vector<std::string> quantity_names();
const char* quantity_label(Quantity q);  // "Stress magnitude", ...
const char* quantity_unit(Quantity q);   // SI unit: "Pa", "m", "" (dimensionless)
bool quantity_is_signed(Quantity q);     // components and volumetric strain
// Stress components, magnitude and volumetric strain: computed only by the model's stress pass
// (organ.model vdm with the stress effect); elsewhere SimState's stress and strain are not set.
bool quantity_needs_stress(Quantity q);
std::vector<Quantity> all_quantities();  // in the order of quantity_names()

// `q` at every node of `state` (size N).
void scalar_field(Quantity q, const vdm::SimState& state, std::vector<float>& out);

// A triangle mesh in some local frame (metres), with per-vertex normals.
struct SkinMesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;
  std::vector<unsigned> indices;  // 3 per triangle
};

// An instrument in its frame: origin at the tip, +z along the axis (handle toward tip).
struct InstrumentView {
  tools::InstrumentDef::Type type = tools::InstrumentDef::Type::probe;
  tools::ProbeShape shape;                   // probe: what collides, drawn as it is
  double radius = 0.004, length = 0.3, jaw_length = 0.02;
  double jaw_opening = 1;                    // grasper: 0 closed, 1 fully open
  tools::InstrumentDef::JawLook jaw_look = tools::InstrumentDef::JawLook::box;  // grasper: the jaws drawn
  tools::InstrumentDef::ProbeLook probe_look = tools::InstrumentDef::ProbeLook::plain;  // capsule probe: as drawn
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  const SkinMesh* skin = nullptr;            // replaces the parametric body (probe, or grasper shaft)
  const SkinMesh* jaw_skins[2] = {nullptr, nullptr};  // grasper jaws, in the frame, closed
};

InstrumentView instrument_view(const tools::InstrumentDef& def, const tools::InstrumentPose& pose);

// Numbers shown by the HUD.
struct HudInfo {
  std::string scene_name;
  int frame = 0, frames = 0;  // frame number (from 0, as in the file names) of `frames`
  double time_s = 0;
  bool has_contact = false;
  double contact_force_n = 0;
  double pressure_pa = 0;       // the fluid's (the model's internal) pressure
  double volume_rel_error = 0;
  // The order of the pressures and forces the scene can have (its moduli, and those times the
  // organ's size squared): values below 1e-12 of these are round-off, shown as 0.
  double pressure_scale_pa = 0, force_scale_n = 0;
  double step_ms = 0;
  bool show_step_time = false;  // wall-clock time differs run to run: opt-in (bit-identical pictures without)
};

struct RenderScene {
  const vdm::NodeMat* positions = nullptr;  // N x 3 current organ positions (m)
  std::vector<float> scalar;                // N values of the stress view's quantity
  std::vector<InstrumentView> instruments;
  HudInfo hud;
  // The endoscope's pose this frame (world from camera, OpenCV axes: x right, y down, z
  // forward; at its tip), and the distance its light's exposure is set for when no organ is in
  // view (the renderer sets it for the organ it sees). Read only when the renderer's camera is
  // an endoscope.
  Eigen::Isometry3d camera_pose = Eigen::Isometry3d::Identity();
  double light_distance = 0.1;  // m
};

}  // namespace render
