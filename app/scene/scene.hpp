#pragma once
// Scene files (YAML, docs/scene-reference.md): parsed into plain, immutable data, validated before
// anything runs. Every problem is reported as "file:line:col: field: what was expected".
#include <array>
#include <cstdint>
#include <optional>
#include <limits>
#include <string>
#include <vector>

#include "app/scene/organ_model_table.hpp"
#include "engine/contact_settings.hpp"
#include "engine/organ_solver.hpp"
#include "engine/settings.hpp"
#include "engine/types.hpp"
#include "render/view_settings.hpp"
#include "render/views.hpp"
#include "tools_scripted/instrument.hpp"

namespace vdmsim {

// A set of organ nodes, chosen on the rest mesh (in scene units after `scale`, i.e. metres).
struct Region {
  enum class Kind { box, sphere, nodes, all } kind = Kind::all;
  vdm::Vec3 min = vdm::Vec3::Zero(), max = vdm::Vec3::Zero();  // box
  vdm::Vec3 center = vdm::Vec3::Zero();                        // sphere
  double radius = 0;                                           // sphere
  std::vector<int> nodes;                                      // explicit node indices
  std::string where;                                           // "file:line:col" for messages
};

struct FixedDef {
  Region region;
  std::array<bool, 3> axes = {true, true, true};
};

// A total force spread equally over the region's nodes, ramped linearly over t = [t0, t1]
// and held after t1.
struct LoadDef {
  Region region;
  vdm::Vec3 force = vdm::Vec3::Zero();  // N
  double t0 = 0, t1 = 0;
};

// A rigid motion of the region's nodes from rest, ramped over [t0, t1]: rotation by
// `rotate_deg` (x, then y, then z) about `about` (default: the region's centroid), then
// translation.
struct PrescribedDef {
  Region region;
  vdm::Vec3 translate = vdm::Vec3::Zero();  // m
  vdm::Vec3 rotate_deg = vdm::Vec3::Zero();
  std::optional<vdm::Vec3> about;
  double t0 = 0, t1 = 0;
};

// An instrument's optional mesh skin, for the picture only (collision and grasping keep the
// parametric shape). Mesh files (any format assimp reads, e.g. STL) are placed in the
// instrument frame (origin at the tip, +z from the handle toward the tip): scaled by `scale`,
// rotated by `rotate_deg` (x, then y, then z), and their origin moved to `origin`.
struct SkinDef {
  bool present = false;
  std::string body;                 // probe, or grasper shaft (resolved path; may be empty)
  std::array<std::string, 2> jaws;  // grasper jaws (upper, lower), closed pose, pivot at the origin
  double scale = 1.0;
  vdm::Vec3 origin = vdm::Vec3::Zero();      // m, in the instrument frame
  vdm::Vec3 rotate_deg = vdm::Vec3::Zero();
  std::string where;                // file:line:col
};

// A convex probe's mesh: its convex hull is the collision shape (and the picture). Placed in
// the instrument frame like a skin: scaled, rotated (x, then y, then z), origin at `origin`.
struct ConvexDef {
  bool present = false;
  std::string mesh;                 // resolved path
  double scale = 1.0;
  vdm::Vec3 origin = vdm::Vec3::Zero();      // m, in the instrument frame
  vdm::Vec3 rotate_deg = vdm::Vec3::Zero();
  std::string where;                // file:line:col of the mesh field
};

// A keyframe whose tip is placed on the organ (instruments[].script[].on_surface): where the
// ray from `from` along `toward` first meets the placed organ's surface, moved `depth` along the
// inward normal there; with `align`, the axis along the inward normal. prepare_scene_def
// resolves it into the keyframe's tip (and axis); until then the keyframe has neither.
struct SurfacePlacement {
  size_t instrument = 0, keyframe = 0;      // which keyframe: instruments[instrument].script[keyframe]
  vdm::Vec3 from = vdm::Vec3::Zero();       // m
  vdm::Vec3 toward = -vdm::Vec3::UnitZ();   // not zero
  double depth = 0;                         // m, inward (negative: outside)
  bool align = false;
  std::string where;                        // file:line:col of the on_surface key
};

using Keyframe = tools::Keyframe;
using InstrumentDef = tools::InstrumentDef;

// The scene's `render:` section.
struct RenderDef {
  render::RenderSettings settings;     // size, samples, camera (auto unless given), floor, shadows
  std::vector<render::View> views = {render::View::shaded};  // in the view table's order, each once
  render::StressView stress_view;      // quantity, colour map, range
  bool range_auto = true;              // range computed in a first pass over the sequence
  bool hud = true;
  bool hud_step_time = false;          // the HUD's step time (varies run to run: opt-in)
  int png_compression = 1;             // zlib level 0-9 (1: fast)
  double fps = 30;                     // video frame rate

  bool has(render::View v) const;
  bool has_ground_truth() const;        // a view of ViewPass::ground_truth (camera.json, poses.csv)
  bool has_picture() const;             // a view of ViewPass::picture (contact sheet, video)
  void remove(render::View v);
};

// The rotation of a `rotate_deg` field: about x, then y, then z (degrees).
Eigen::Matrix3d rotation_from_degrees(const vdm::Vec3& deg);

enum class Effect { contact, grasp, gravity, inertia, stress };
const char* to_string(Effect e);

// One organ (`organ:`, or an item of `organs:`): its surface mesh and where it is placed, its
// model and material, and what holds, loads or moves it.
struct OrganDef {
  std::string name = "organ";  // organs[].name; "organ" in the one-organ form
  std::string field = "organ"; // where its keys are, for messages: "organ" or "organs[i]"
  std::string mesh_path;       // resolved against the scene file's folder
  bool gallbladder_look = false;  // look: gallbladder (else liver)
  double scale = 1.0;
  vdm::Vec3 rotate_deg = vdm::Vec3::Zero();  // rotate_deg: about the scaled mesh's bounding-box centre, x then y then z
  vdm::Vec3 translate = vdm::Vec3::Zero();   // translate (m), after the rotation
  vdm::Vec3 bulk_modulus = vdm::Vec3::Constant(20000.0);  // Pa per axis; inf allowed
  double connectivity_modulus = 2000.0;
  vdm::CapsuleForm capsule = vdm::CapsuleForm::membrane;  // vdm: membrane | corotational | paper
  double bending_modulus = 0.0;  // vdm, membrane capsules: the skin's bending modulus D (N m); 0 = none
  double density = 1060.0;
  double damping = 0.0;        // 1/s, with the inertia effect
  vdm::ModelKind model = kDefaultOrganModel;  // model (organ_model_table.hpp)
  double young_modulus = 3000;  // fem, mass_spring; vdm: mapped to bulk and connectivity (Pa)
  bool moduli_from_elastic = false;  // vdm: bulk_modulus and connectivity_modulus from E and nu
  double poisson_ratio = 0.45;  // fem, in [0, 0.5)
  double thickness = 0.005;     // mass_spring: skin thickness giving the springs' stiffness (m)
  double volume_modulus = 0;    // mass_spring: volume spring K_v (Pa), 0 = none
  double tet_size = 0;          // fem: largest tet edge (m) for gmsh, 0 = graded from the surface
  double cell_size = 0;         // vdm_core: the core's cell (m), 0 = the organ's V/A
  std::string cell_size_where;  // file:line:col of cell_size ("" when not given)
  bool material_given = false;  // the organ has material (false: every modulus is a default)
  std::vector<FixedDef> fixed;
  std::vector<LoadDef> loads;
  std::vector<PrescribedDef> prescribed;
};

// An attachment (`attachments:`): organ `first`'s nodes within `within` of organ `second`'s
// surface at rest tied to it (organ indices into SceneDef::organs).
struct AttachmentDef {
  std::string field;        // "attachments[i]", for messages
  int first = 0, second = 0;
  double within = 0;        // m
  double stiffness = 0;     // per area (Pa/m); 0: the softer organ's E / within
  double tear_force = std::numeric_limits<double>::infinity();  // N
};

struct SceneDef {
  std::string file;            // the scene file as given
  std::string name;
  // The organs: one from `organ:`, or those of `organs:` in file order (names unique). A
  // SceneDef made in code has one default organ.
  std::vector<OrganDef> organs = std::vector<OrganDef>(1);
  std::vector<AttachmentDef> attachments;
  // simulation
  int frames = 120;
  double dt = 1.0 / 30.0;
  std::vector<Effect> effects;
  vdm::Vec3 gravity = vdm::Vec3(0, 0, -9.81);
  bool volume_constraint = true;
  vdm::SolverSettings solver;
  vdm::ContactSettings contact;  // simulation.contact: method (constraint | kinematic | penalty), friction, stiffness, max_iterations
  // instruments and rendering
  std::vector<InstrumentDef> instruments;
  std::vector<std::string> instrument_where;  // file:line:col of each instrument
  std::vector<std::vector<std::string>> keyframe_where;  // file:line:col of instruments[i].script[k]
  std::vector<SkinDef> instrument_skins;      // one per instrument
  std::vector<ConvexDef> instrument_convex;   // one per instrument (present: shape convex)
  std::vector<SurfacePlacement> surface_keyframes;  // keyframes placed on the organ, in file order
  bool has_render = false;     // the scene has a render: section
  RenderDef render;

  bool has(Effect e) const;
  // The first organ (the only one in the one-organ form).
  const OrganDef& organ() const { return organs.front(); }
  OrganDef& organ() { return organs.front(); }
};

struct SceneProblem {
  std::string where;    // file:line:col
  std::string field;    // dotted path, e.g. organ.material.bulk_modulus
  std::string message;  // what was expected / what is wrong
  bool warning = false; // unknown keys are warnings
  std::string text() const;
};

// Prints every problem to `err` ("vdmsim: error: ..." or "vdmsim: ..." for a warning);
// true when none is an error.
bool report_problems(const std::vector<SceneProblem>& problems, std::ostream& err);

struct SceneLoadResult {
  SceneDef scene;
  std::vector<SceneProblem> problems;  // errors and warnings, in file order
  bool ok() const;
};

// The most frames a run may have (simulation.frames, --frames): a run keeps a few numbers per
// frame (the step times).
constexpr int kMaxFrames = 10000000;

// Scene files larger than this are refused before they are parsed.
constexpr std::uintmax_t kMaxSceneFileBytes = 10u << 20;

SceneLoadResult load_scene(const std::string& path);

}  // namespace vdmsim
