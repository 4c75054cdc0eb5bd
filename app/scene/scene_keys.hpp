#pragma once
// Every key a scene file may have, in one table: the scene reader (scene.cpp) takes from it
// the keys it accepts in each mapping and the range and unit of each number, and
// `vdmsim scene-reference` prints it as docs/scene-reference.md (scene_reference.cpp), so the
// reference cannot drift from the reader. A test compares the committed page with the
// printed one; another loads every key's example.
//
// Paths are dotted; `[]` marks a list's items (`instruments[].radius`); `region.` is a region
// (organ.fixed[], organ.loads[], organ.prescribed[] are regions with keys of their own).
// Within one mapping the keys are in the order the reader's messages list them.
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "app/scene/scene.hpp"
#include "engine/tissue_model.hpp"

namespace vdmsim {

enum class KeyType {
  section,      // a mapping of further keys
  list,         // a list of mappings (their keys under path[])
  region_list,  // a list of regions (their own keys under path[])
  region,       // the region's keys (documentation only: not a key of its own)
  number,
  integer,
  vector3,      // [x, y, z]
  boolean,
  text,
  file,         // a path relative to the scene file
  choice,       // one of `values()`
  choice_list,  // a list of `values()`
};

// Default values, written as a scene would write them.
std::string yaml_number(double v);  // 1e-08 -> 1e-8, infinity -> inf
std::string yaml_vector(const vdm::Vec3& v);
std::string yaml_bool(bool b);

struct SceneKey {
  const char* path = "";
  KeyType type = KeyType::section;
  const char* description = "";
  const char* type_text = nullptr;  // the type in words, when the type's own name is not enough
  const char* unit = "";            // named in the reader's messages (numbers, vectors); integers: reference only
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;             // lo itself not allowed
  bool allow_inf = false;           // "inf" allowed
  bool required = false;
  const char* allowed_text = nullptr;  // what is allowed, when the range alone does not say it
  const char* shapes = nullptr;        // instruments[].shape keys: the shape types that take them (nullptr: all)
  std::vector<std::string> (*values)() = nullptr;  // choice, choice_list
  std::string (*default_value)() = nullptr;        // nullptr: no default
  const char* default_text = nullptr;              // a default that is not a value (e.g. "automatic framing")
  const char* example = "";                        // YAML of the key's mapping, the key in it

  constexpr SceneKey in(const char* u) const { SceneKey k = *this; k.unit = u; return k; }
  constexpr SceneKey range(double l, double h) const { SceneKey k = *this; k.lo = l; k.hi = h; return k; }
  constexpr SceneKey above(double l, double h = std::numeric_limits<double>::infinity()) const {
    SceneKey k = *this; k.lo = l; k.hi = h; k.lo_open = true; return k;
  }
  constexpr SceneKey or_inf() const { SceneKey k = *this; k.allow_inf = true; return k; }
  constexpr SceneKey needed() const { SceneKey k = *this; k.required = true; return k; }
  constexpr SceneKey typed(const char* t) const { SceneKey k = *this; k.type_text = t; return k; }
  constexpr SceneKey allowing(const char* t) const { SceneKey k = *this; k.allowed_text = t; return k; }
  constexpr SceneKey for_shapes(const char* s) const { SceneKey k = *this; k.shapes = s; return k; }
  constexpr SceneKey one_of(std::vector<std::string> (*f)()) const { SceneKey k = *this; k.values = f; return k; }
  constexpr SceneKey by_default(std::string (*f)()) const { SceneKey k = *this; k.default_value = f; return k; }
  constexpr SceneKey by_default(const char* t) const { SceneKey k = *this; k.default_text = t; return k; }
  constexpr SceneKey eg(const char* yaml) const { SceneKey k = *this; k.example = yaml; return k; }
};

constexpr SceneKey key(const char* path, KeyType type, const char* description) {
  SceneKey k;
  k.path = path;
  k.type = type;
  k.description = description;
  return k;
}

using Words = std::vector<std::string>;
using KT = KeyType;

// clang-format off
inline constexpr SceneKey kSceneKeys[] = {
  // The top of the file.
  key("name", KT::text, "The scene's name: the HUD shows it and `run` writes to `out/<name>` by default.")
      .by_default("the scene file's name without its extension").eg("name: probe_poke"),
  key("organ", KT::section, "The organ: its surface mesh, material, and what holds, loads or moves it. A scene has "
      "`organ` or, for several organs, `organs`.").typed("mapping; this or `organs` is required")
      .eg("organ: {mesh: ../meshes/liver_L4.obj, fixed: [{all: true, axes: [z]}]}"),
  key("organs", KT::list, "Several organs in one scene, instead of `organ`: a list of organ mappings, each with a "
      "`name` and the keys of `organ` (below). Each organ has its own model, material and holds and keeps its own "
      "volume; the instruments touch and grasp whichever organ they meet.")
      .eg("organs: [{name: liver, mesh: ../meshes/liver_L4.obj}, {name: gallbladder, mesh: ../meshes/gallbladder.obj, "
          "translate: [0.3, 0, 0]}]"),
  key("attachments", KT::list, "Ties between organs (with `organs`): each node of the first organ within `within` of "
      "the second's surface at rest is held to the point of that surface nearest it, by a spring in every direction; "
      "a tie lets go when its force passes `tear_force`. Simulated when every organ is on `vdm_core` with the "
      "`contact` effect (the contact between organs is then simulated too).")
      .eg("attachments: [{between: [gallbladder, liver], within: 0.004}]"),
  // A region (documented after the organ; its keys are below).
  key("region", KT::region, "A set of the organ's nodes, chosen on the rest mesh (after `organ.scale`): exactly one of "
      "`box`, `sphere`, `nodes` or `all`."),
  key("simulation", KT::section, "Frames, time step, the effects simulated, the solver and contact.")
      .eg("simulation: {frames: 45, dt: 0.0333333, effects: [stress]}"),
  key("instruments", KT::list, "Probes and graspers moved along scripted timelines.")
      .eg("instruments: [{type: probe, radius: 0.004, script: [{t: 0, tip: [0.035, 0, 0.075]}, {t: 1, tip: [0.035, 0, 0.05]}]}]"),
  key("render", KT::section, "Pictures: with this section every frame is drawn (PNG images, a contact sheet; video with `run --video`).")
      .eg("render: {width: 640, height: 480, views: [shaded, stress]}"),

  // organ
  key("organ.mesh", KT::file, "The organ's closed surface mesh: OBJ, PLY, STL, glTF or any format assimp reads.").needed()
      .eg("mesh: ../meshes/liver_L5.obj"),
  key("organ.look", KT::choice, "How the organ's tissue looks in the shaded views: `liver` (red-brown) or "
      "`gallbladder` (olive green).").one_of([] { return Words{"liver", "gallbladder"}; })
      .by_default([] { return std::string("liver"); }).eg("look: gallbladder"),
  key("organ.scale", KT::number, "Multiplies the mesh's coordinates to give metres.").in("mesh units to metres").above(0)
      .by_default([] { return yaml_number(OrganDef().scale); }).eg("scale: 0.001"),
  key("organ.rotate_deg", KT::vector3, "Turns the organ, after `scale`, about the centre of its bounding box (as scaled): "
      "about the fixed x axis, then y, then z (extrinsic). Regions, instruments and the camera are in the frame after "
      "`scale`, `rotate_deg` and `translate`.").in("degrees")
      .by_default([] { return yaml_vector(OrganDef().rotate_deg); }).eg("rotate_deg: [0, 0, 90]"),
  key("organ.translate", KT::vector3, "Moves the organ, after `scale` and `rotate_deg`.").in("m")
      .by_default([] { return yaml_vector(OrganDef().translate); }).eg("translate: [0.09, -0.16, 1.23]"),
  key("organ.material", KT::section, "The tissue's material: `young_modulus` and `poisson_ratio` (and `density`). "
      "Without `model`, VDM's own moduli `bulk_modulus` and `connectivity_modulus` select `model: vdm` (with a note); "
      "for `model: vdm` give either those or `young_modulus` and `poisson_ratio` (mapped to them by the rule of "
      "[the model page](model.md)).")
      .eg("material: {young_modulus: 3000, poisson_ratio: 0.45, density: 1060}"),
  key("organ.fixed", KT::region_list, "Regions of nodes held in place, on all axes or on those listed in `axes`.")
      .eg("fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]"),
  key("organ.model", KT::choice, "The tissue model: `vdm_core` (VDM's surface and pressure on an elastic core: the "
      "model closest to the FEM; [the model page](model.md)), `vdm` (the paper's Volume Distribution Method, the default "
      "when the material is given by `bulk_modulus` or `connectivity_modulus`), or the reference models `fem` "
      "(corotational linear tetrahedra, meshed by gmsh) and `mass_spring` (springs on the surface edges).")
      .one_of(organ_model_names).by_default([] { return std::string(vdm::to_string(OrganDef().model)); }).eg("model: fem"),
  key("organ.loads", KT::region_list, "Forces: a total force spread equally over a region's nodes, ramped over a time interval.")
      .eg("loads: [{sphere: {center: [0, 0, 0.06], radius: 0.02}, force: [0, 0, -2], t: [0, 1]}]"),
  key("organ.prescribed", KT::region_list, "Prescribed motion: a region's nodes moved rigidly from rest, ramped over a time interval.")
      .eg("prescribed: [{nodes: [5, 6], translate: [0, 0, -0.015], t: [0, 1]}]"),
  key("organ.cell_size", KT::number, "The core's cell (a cube's edge); 0 takes the organ's "
      "volume over its area V/A, no wider than the smallest instrument (a probe's narrowest part, a grasper's jaw face "
      "across), and no finer than gives "
      "about 10000 cubes inside the organ (run.json reports the cell used). Smaller cells follow smaller loads (a dent narrower than a few cells is spread over "
      "them) and cost more. Refused when a cell does not fit in the organ's box (larger than its smallest side) and when "
      "the box would hold more than 2e7 cells; warned when more than twice as wide as the smallest instrument.")
      .in("m").range(0, std::numeric_limits<double>::infinity())
      .by_default([] { return yaml_number(OrganDef().cell_size); }).eg("cell_size: 0.005"),
  key("organ.tet_size", KT::number, "The largest tetrahedron edge; 0 grades the tetrahedra from the surface. Refused when the organ would need more than 5 million tetrahedra of that edge (its volume over a regular tetrahedron's).")
      .in("m").range(0, std::numeric_limits<double>::infinity())
      .by_default([] { return yaml_number(OrganDef().tet_size); }).eg("tet_size: 0.01"),

  // organs[]: an organ's keys, and its name
  key("organs[].name", KT::text, "The organ's name: letters, digits, `_` and `-`, unique in the scene. It names the "
      "organ's columns in metrics.csv, its entry in run.json and its folder of exported meshes.").needed()
      .eg("name: gallbladder"),

  // attachments[]
  key("attachments[].between", KT::text, "The two organs tied: the first's nodes near the second's surface are held "
      "to it.").typed("[organ name, organ name]").needed().eg("between: [gallbladder, liver]"),
  key("attachments[].within", KT::number, "How near the second organ's surface (at rest) a node of the first is tied.")
      .in("m").above(0, 1).needed().eg("within: 0.004"),
  key("attachments[].stiffness", KT::number, "The ties' stiffness per area of the tied surface: a tie holds its node's "
      "share of the first organ's surface area times this. By default a layer of connective tissue as thick as "
      "`within` and as stiff as the softer organ: E / within.").in("Pa/m").above(0)
      .by_default("the softer organ's young_modulus / within").eg("stiffness: 1000000"),
  key("attachments[].tear_force", KT::number, "The force at which a tie lets go (`inf`: never); metrics.csv counts "
      "the torn ties.").in("N").above(0).or_inf().by_default([] { return std::string("inf"); }).eg("tear_force: 0.05"),

  // organ.material
  key("organ.material.bulk_modulus", KT::number, "The fluid's bulk term B (per axis when three values are given; "
      "`inf` holds that axis as a constraint).").typed("number or [bx, by, bz]").in("Pa").above(0).or_inf()
      .by_default([] { return yaml_number(OrganDef().bulk_modulus.x()); }).eg("bulk_modulus: [20000, inf, 20000]"),
  key("organ.material.connectivity_modulus", KT::number, "The capsule's (skin's) modulus B_ij. It must be above 0 "
      "and at least the largest finite `bulk_modulus` / 1e9 (beyond that the system cannot be solved "
      "reliably).").in("Pa").range(0, 1e12)
      .by_default([] { return yaml_number(OrganDef().connectivity_modulus); }).eg("connectivity_modulus: 2000"),
  key("organ.material.capsule", KT::choice, "The capsule's form: `membrane` (mesh-consistent), `corotational` "
      "(the membrane in each node's rotated frame) or `paper` (the paper's edge weights).")
      .one_of([] { return Words{"membrane", "corotational", "paper"}; })
      .by_default([] { return std::string(vdm::to_string(OrganDef().capsule)); }).eg("capsule: corotational"),
  key("organ.material.bending_modulus", KT::number, "The capsule's thin-shell bending modulus D (`membrane` or "
      "`corotational` capsule): energy ½ D ∫ |Δu|² dA over the surface, so the skin resists bending as "
      "well as stretch (docs/model.md, \"Bending\"). 0: no bending term.").in("N m").range(0, 1e6)
      .by_default([] { return yaml_number(OrganDef().bending_modulus); }).eg("bending_modulus: 0.0005"),
  key("organ.material.density", KT::number, "Mass density: the weight with the `gravity` effect, the mass with `inertia`.")
      .in("kg/m^3").above(0, 1e5).by_default([] { return yaml_number(OrganDef().density); }).eg("density: 1060"),
  key("organ.material.damping", KT::number, "Mass-proportional damping, with the `inertia` effect.").in("1/s").range(0, 1e6)
      .by_default([] { return yaml_number(OrganDef().damping); }).eg("damping: 5"),
  key("organ.material.young_modulus", KT::number, "Young's modulus E: the stiffness of `vdm_core`, `fem` and "
      "`mass_spring`; for `vdm`, with `poisson_ratio`, instead of `bulk_modulus` and `connectivity_modulus`.").in("Pa").above(0, 1e12)
      .by_default([] { return yaml_number(OrganDef().young_modulus); }).eg("young_modulus: 3000"),
  key("organ.material.poisson_ratio", KT::number, "Poisson's ratio ν (for `vdm`, with `young_modulus`). "
      "0.5 is exactly incompressible: use up to 0.49. `vdm_core` keeps the organ's volume whatever ν is (warned below "
      "0.4).").range(0, 0.5).allowing(">= 0 and < 0.5")
      .by_default([] { return yaml_number(OrganDef().poisson_ratio); }).eg("young_modulus: 3000, poisson_ratio: 0.45"),
  key("organ.material.thickness", KT::number, "The skin thickness that sets the springs' stiffness.")
      .in("m").above(0, 10).by_default([] { return yaml_number(OrganDef().thickness); }).eg("thickness: 0.005"),
  key("organ.material.volume_modulus", KT::number, "The volume spring's modulus; 0 for none.")
      .in("Pa").range(0, 1e12).by_default([] { return yaml_number(OrganDef().volume_modulus); }).eg("volume_modulus: 20000"),

  // The regions of organ.fixed, organ.loads and organ.prescribed.
  key("region.box", KT::section, "The nodes inside an axis-aligned box.").eg("box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}"),
  key("region.sphere", KT::section, "The nodes inside a sphere.").eg("sphere: {center: [0.035, 0, 0.06], radius: 0.015}"),
  key("region.nodes", KT::integer, "The nodes with these indices (0-based, in the mesh file's vertex order).")
      .typed("list of whole numbers").range(0, 1 << 30).eg("nodes: [0, 17, 42]"),
  key("region.all", KT::boolean, "Every node (`all: true`; `false` is an error).").eg("all: true"),
  key("region.box.min", KT::vector3, "The box's lower corner.").in("m").needed().eg("min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]"),
  key("region.box.max", KT::vector3, "The box's upper corner (each coordinate >= min's).").in("m").needed()
      .eg("min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]"),
  key("region.sphere.center", KT::vector3, "The sphere's centre.").in("m").needed().eg("center: [0.035, 0, 0.06], radius: 0.015"),
  key("region.sphere.radius", KT::number, "The sphere's radius.").in("m").above(0).needed().eg("center: [0.035, 0, 0.06], radius: 0.015"),

  // organ.fixed[], organ.loads[], organ.prescribed[]: their own keys beside the region's.
  key("organ.fixed[].axes", KT::choice_list, "The axes held; leave out to hold all three.")
      .one_of([] { return Words{"x", "y", "z"}; }).by_default([] {
        const FixedDef d;
        std::string s;
        for (int a = 0; a < 3; ++a) if (d.axes[a]) s += std::string(s.empty() ? "" : ", ") + "xyz"[a];
        return "[" + s + "]";
      }).eg("axes: [z]"),
  key("organ.loads[].force", KT::vector3, "The total force, spread equally over the region's nodes.").in("N").needed()
      .eg("force: [0, 0, -2]"),
  key("organ.loads[].t", KT::number, "The ramp: the force grows linearly from 0 at t_start to full at t_end, then holds ([0, 0]: in full from the start).")
      .typed("[t_start, t_end]").in("s").range(0, std::numeric_limits<double>::infinity())
      .by_default([] { const LoadDef d; return "[" + yaml_number(d.t0) + ", " + yaml_number(d.t1) + "]"; }).eg("t: [0, 1]"),
  key("organ.prescribed[].translate", KT::vector3, "The translation at the end of the ramp (after the rotation).").in("m")
      .by_default([] { return yaml_vector(PrescribedDef().translate); }).eg("translate: [0, 0, -0.015]"),
  key("organ.prescribed[].rotate_deg", KT::vector3, "The rotation at the end of the ramp: about x, then y, then z.")
      .in("degrees").by_default([] { return yaml_vector(PrescribedDef().rotate_deg); }).eg("rotate_deg: [0, 0, 10]"),
  key("organ.prescribed[].about", KT::vector3, "The rotation's centre.").in("m").by_default("the region's centroid")
      .eg("rotate_deg: [0, 0, 10], about: [0, 0, 0]"),
  key("organ.prescribed[].t", KT::number, "The ramp: the motion goes linearly from rest at t_start to full at t_end, then holds ([0, 0]: in full from the start).")
      .typed("[t_start, t_end]").in("s").range(0, std::numeric_limits<double>::infinity())
      .by_default([] { const PrescribedDef d; return "[" + yaml_number(d.t0) + ", " + yaml_number(d.t1) + "]"; })
      .eg("t: [0.5, 1.5]"),

  // simulation
  key("simulation.frames", KT::integer, "How many frames to simulate and write: frame f is the scene at t = f dt, "
      "frame 0 at t = 0 (before the script moves anything) and the last at (frames - 1) dt; one step per frame "
      "after the first.").range(1, kMaxFrames)
      .by_default([] { return std::to_string(SceneDef().frames); }).eg("frames: 91"),
  key("simulation.dt", KT::number, "Simulated time from one frame to the next.").in("s").above(0, 10)
      .by_default([] { return yaml_number(SceneDef().dt); }).eg("dt: 0.0333333"),
  key("simulation.effects", KT::choice_list, "The effects simulated: only these run (an unlisted effect costs nothing, "
      "and its metrics.csv columns stay empty). `contact`: instruments push the tissue; `grasp`: graspers hold it; "
      "`gravity`: the organ's weight; `inertia`: mass and damping; `stress`: strain and stress after each step.")
      .one_of([] { return Words{"contact", "grasp", "gravity", "inertia", "stress"}; })  // the order of vdmsim::Effect
      .by_default([] {
        std::string s;
        for (Effect e : SceneDef().effects) s += std::string(s.empty() ? "" : ", ") + to_string(e);
        return "[" + s + "]";
      })
      .eg("effects: [contact, stress]"),
  key("simulation.solver", KT::section, "The linear solver and how often the nonlinear terms are refreshed.")
      .eg("solver: {method: structured, tolerance: 1.0e-8, refresh_every: 1}"),
  key("simulation.gravity", KT::vector3, "Gravity's acceleration, with the `gravity` effect.").in("m/s^2")
      .by_default([] { return yaml_vector(SceneDef().gravity); }).eg("gravity: [0, -9.81, 0]"),
  key("simulation.volume_constraint", KT::boolean, "Keep the organ's volume (VDM's fluid). `false` leaves the pressure out.")
      .by_default([] { return yaml_bool(SceneDef().volume_constraint); }).eg("volume_constraint: false"),
  key("simulation.contact", KT::section, "How instruments and tissue meet (with the `contact` effect).")
      .eg("contact: {method: penalty, stiffness: 1.0e8, max_iterations: 40}"),

  // simulation.solver
  key("simulation.solver.method", KT::choice, "`structured` (block PCG over the three axes), `direct` (sparse LDLᵀ per "
      "axis) or `reference` (the paper's BiCGSTAB on the whole system); all three agree to 1e-7 of the motion.")
      .one_of([] { return Words{"reference", "structured", "direct"}; })
      .by_default([] { return std::string(vdm::to_string(SceneDef().solver.method)); }).eg("method: direct"),
  key("simulation.solver.tolerance", KT::number, "Each linear solve's relative residual.").in("relative residual").above(0, 0.1)
      .by_default([] { return yaml_number(SceneDef().solver.tolerance); }).eg("tolerance: 1.0e-6"),
  key("simulation.solver.max_iterations", KT::integer, "Iterations per Krylov solve before it falls back to the direct solver.")
      .range(1, 1000000).by_default([] { return std::to_string(SceneDef().solver.max_iterations); }).eg("max_iterations: 500"),
  key("simulation.solver.refresh_every", KT::integer, "Recompute the geometry and the matrices every this many steps.")
      .range(1, 1000000).by_default([] { return std::to_string(SceneDef().solver.refresh_every); }).eg("refresh_every: 5"),
  key("simulation.solver.nonlinear_iterations", KT::integer, "Solves per step, the geometry refreshed between them "
      "(1: the paper's one update per step).").range(1, 1000)
      .by_default([] { return std::to_string(SceneDef().solver.nonlinear_iterations); }).eg("nonlinear_iterations: 3"),
  key("simulation.solver.volume_corrections", KT::integer, "Newton corrections of the pressure after each solve, bringing "
      "the volume back (0: the paper's single linearised volume row).").range(0, 100)
      .by_default([] { return std::to_string(SceneDef().solver.volume_corrections); }).eg("volume_corrections: 0"),
  key("simulation.solver.volume_tolerance", KT::number, "The relative volume error left without a correction.")
      .in("relative volume error").above(0, 1e-2)
      .by_default([] { return yaml_number(SceneDef().solver.volume_tolerance); }).eg("volume_tolerance: 1.0e-6"),
  key("simulation.solver.warm_start", KT::boolean, "Start each iterative solve from the last step's solution.")
      .by_default([] { return yaml_bool(SceneDef().solver.warm_start); }).eg("warm_start: false"),

  // simulation.contact
  key("simulation.contact.method", KT::choice, "`constraint`: non-penetration constraints along the tool's normal at "
      "surface points (nodes, and points inside triangles a thin tool meets), with Coulomb friction `friction` (slides "
      "or sticks; the default for `vdm_core` and `vdm`; the reference models take `kinematic` unless a method is named, "
      "and converge with it without friction only); `kinematic`: nodes that enter a tool are put on its "
      "surface and held there for the step (the tissue sticks); `penalty`: frictionless and compliant, pushed out by "
      "stiffness × depth (slides; `organ.model: vdm` only).")
      .one_of([] { return Words{"constraint", "kinematic", "penalty"}; })
      .by_default([] {
        switch (SceneDef().contact.method) {
          case vdm::ContactSettings::Method::constraint: return std::string("constraint");
          case vdm::ContactSettings::Method::kinematic: return std::string("kinematic");
          default: return std::string("penalty");
        }
      })
      .eg("method: kinematic"),
  key("simulation.contact.friction", KT::number, "`constraint` only: the Coulomb friction coefficient μ between tools and "
      "tissue (0: frictionless sliding; a point sticks while its tangential force is below μ times its normal force).")
      .in("friction coefficient (dimensionless)").range(0, 10)
      .by_default([] { return yaml_number(SceneDef().contact.friction); }).eg("method: constraint, friction: 0.3"),
  key("simulation.contact.stiffness", KT::number, "`penalty` only: the contact pressure per metre of penetration.")
      .in("Pa/m (contact pressure per metre of penetration)").above(0, 1e15)
      .by_default([] { return yaml_number(SceneDef().contact.penalty_stiffness); }).eg("method: penalty, stiffness: 1.0e8"),
  key("simulation.contact.max_iterations", KT::integer, "`constraint` and `penalty`: solves of the organ per step at most "
      "(the default: 30 for `constraint`, 40 for `penalty`).").range(1, 1000)
      .by_default([] { return std::to_string(SceneDef().contact.max_penalty_iterations); }).eg("method: constraint, max_iterations: 60"),

  // instruments[]
  key("instruments[].type", KT::choice, "A `probe` (a rigid tool, shaped by `shape`) or a `grasper` (a shaft and two jaws "
      "that hold tissue when closed, with the `grasp` effect).").one_of([] { return Words{"probe", "grasper"}; }).needed()
      .eg("type: grasper"),
  key("instruments[].radius", KT::number, "The probe's or the grasper shaft's radius; the jaws' half-width.").in("m").above(0, 1)
      .by_default([] { return yaml_number(tools::InstrumentDef().radius); }).eg("radius: 0.004"),
  key("instruments[].length", KT::number, "From the tip to the handle's end.").in("m").above(0, 10)
      .by_default([] { return yaml_number(tools::InstrumentDef().length); }).eg("length: 0.25"),
  key("instruments[].jaw_length", KT::number, "Grasper: the jaws from the pivot to the tip.").in("m").above(0, 1)
      .by_default([] { return yaml_number(tools::InstrumentDef().jaw_length); }).eg("jaw_length: 0.015"),
  key("instruments[].jaws", KT::choice, "Grasper: how its jaws look in the pictures: `box` (their collision boxes), "
      "`fenestrated` (an atraumatic grasper's jaws, a window in each) or `maryland` (a dissector's jaws, tapering and "
      "curving to the side). Contact and grasping use the boxes whatever the look.")
      .one_of([] { return Words{"box", "fenestrated", "maryland"}; }).by_default("box").eg("type: grasper, jaws: fenestrated"),
  key("instruments[].look", KT::choice, "Capsule probe: how it looks in the pictures: `plain` (the capsule) or `hook` "
      "(an L-hook electrode: an insulated shaft and a bare wire that turns over at the tip and comes back on the "
      "+x side of the instrument's frame; `roll_deg` turns it). Contact uses the capsule whatever the look.")
      .one_of([] { return Words{"plain", "hook"}; }).by_default("plain").eg("type: probe, look: hook"),
  key("instruments[].grasp_width", KT::number, "Grasper: surface nodes this close to the closed jaws are held.").in("m").above(0, 1)
      .by_default([] { return yaml_number(tools::InstrumentDef().grasp_width); }).eg("grasp_width: 0.006"),
  key("instruments[].port", KT::vector3, "A port in the abdominal wall: the shaft always passes through it. The "
      "keyframes then place the tip (`tip`, `on_surface`, or the port coordinates `pan_deg`, `tilt_deg`, `depth`) "
      "and give no `axis`: it runs from the port through the tip. A tip at or behind the port (on its side away "
      "from the organ), or farther from it than the instrument is long, is an error.").in("m")
      .by_default("none: the keyframes give the axis").eg("port: [0.09, -0.08, 0.14]"),
  key("instruments[].script", KT::list, "The timeline: keyframes in increasing time; a field a keyframe leaves out keeps "
      "its previous value. Before the first keyframe the instrument waits at it, after the last it stays.").needed()
      .eg("script: [{t: 0, tip: [0.035, 0, 0.075], axis: [0, 0, -1]}, {t: 1.5, tip: [0.035, 0, 0.0453]}]"),
  key("instruments[].skin", KT::section, "Meshes drawn in place of the instrument's parametric shape (the picture only: "
      "collision and grasping keep the shape), placed in the instrument frame: origin at the tip, +z from the handle "
      "toward the tip.")
      .eg("skin: {body: ../meshes/probe.obj, scale: 0.001, origin: [0, 0, -0.028]}"),
  key("instruments[].path", KT::choice, "How tip positions move between keyframes: `linear`, or `spline` (monotone "
      "cubic, continuous velocity, no overshoot; a hold stays a hold). Axes turn by slerp either way.")
      .one_of([] { return Words{"linear", "spline"}; }).by_default([] { return std::string(tools::InstrumentDef().path == tools::InstrumentDef::Path::linear ? "linear" : "spline"); })
      .eg("path: spline"),
  key("instruments[].shape", KT::section, "A probe's collision shape, which is also what is drawn (a capsule may look "
      "like a hook: `look`): a name "
      "(`capsule`, `cylinder`) or a mapping with `type` and the shape's own keys.").typed("name or mapping")
      .eg("shape: {type: cylinder, rounding: 0.001}"),

  // instruments[].shape
  key("instruments[].shape.type", KT::choice, "`capsule` (rounded end at the tip), `cylinder` (flat tip, edges rounded by "
      "`rounding`), `box` (`size`, its +z face at the tip) or `convex` (the convex hull of `mesh`).")
      .one_of([] { return Words{"capsule", "cylinder", "box", "convex"}; }).by_default([] { return Words{"capsule", "cylinder", "box", "convex"}[static_cast<int>(tools::ProbeShape().kind)]; })
      .eg("type: cylinder"),
  key("instruments[].shape.size", KT::number, "Its full sizes along x, y and z (z along the axis).").typed("[x, y, z]")
      .in("m").above(0, 10).for_shapes("box").needed().eg("type: box, size: [0.03, 0.006, 0.08]"),
  key("instruments[].shape.rounding", KT::number, "The edges' rounding radius.").in("m")
      .range(0, std::numeric_limits<double>::infinity())
      .allowing(">= 0, and <= the radius (cylinder) or half the smallest size (box)").for_shapes("cylinder box")
      .by_default([] { return yaml_number(tools::ProbeShape().rounding); }).eg("type: box, size: [0.03, 0.006, 0.08], rounding: 0.0005"),
  key("instruments[].shape.mesh", KT::file, "The mesh whose convex hull is the shape: at most 10,000 vertices (after coincident ones are merged).").for_shapes("convex").needed()
      .eg("type: convex, mesh: ../meshes/tool.obj"),
  key("instruments[].shape.scale", KT::number, "Multiplies the mesh's coordinates to give metres.").in("mesh units -> m")
      .above(0).for_shapes("convex").by_default([] { return yaml_number(ConvexDef().scale); })
      .eg("type: convex, mesh: ../meshes/tool.obj, scale: 0.001"),
  key("instruments[].shape.origin", KT::vector3, "Where the mesh's origin goes in the instrument frame.").in("m")
      .for_shapes("convex").by_default([] { return yaml_vector(ConvexDef().origin); })
      .eg("type: convex, mesh: ../meshes/tool.obj, origin: [0, 0, -0.01]"),
  key("instruments[].shape.rotate_deg", KT::vector3, "The mesh's rotation, about x, then y, then z.").in("degrees")
      .for_shapes("convex").by_default([] { return yaml_vector(ConvexDef().rotate_deg); })
      .eg("type: convex, mesh: ../meshes/tool.obj, rotate_deg: [90, 0, 0]"),

  // instruments[].skin
  key("instruments[].skin.body", KT::file, "Drawn as the probe, or as the grasper's shaft.").eg("body: ../meshes/probe.obj"),
  key("instruments[].skin.jaws", KT::file, "A grasper's upper and lower jaw, drawn closed in the files and turned about the "
      "pivot (the x axis through (0, 0, -jaw_length)) as the jaws open.").typed("[file, file]")
      .eg("jaws: [../meshes/jaw_upper.obj, ../meshes/jaw_lower.obj]"),
  key("instruments[].skin.scale", KT::number, "Multiplies the meshes' coordinates to give metres.").in("mesh units -> m").above(0)
      .by_default([] { return yaml_number(SkinDef().scale); }).eg("body: ../meshes/probe.obj, scale: 0.001"),
  key("instruments[].skin.origin", KT::vector3, "Where the meshes' origin goes in the instrument frame.").in("m")
      .by_default([] { return yaml_vector(SkinDef().origin); }).eg("body: ../meshes/probe.obj, origin: [0, 0, -0.028]"),
  key("instruments[].skin.rotate_deg", KT::vector3, "The meshes' rotation, about x, then y, then z.").in("degrees")
      .by_default([] { return yaml_vector(SkinDef().rotate_deg); }).eg("body: ../meshes/probe.obj, rotate_deg: [0, 90, 0]"),

  // instruments[].script[]
  key("instruments[].script[].t", KT::number, "The keyframe's time; each keyframe's comes after the one before.").in("s")
      .range(0, std::numeric_limits<double>::infinity()).needed().eg("t: 0.5"),
  key("instruments[].script[].tip", KT::vector3, "Where the working end is. The first keyframe must give it "
      "(or `on_surface`).").in("m")
      .by_default("the previous keyframe's").eg("tip: [0.035, 0, 0.0453]"),
  key("instruments[].script[].axis", KT::vector3, "The direction from the handle toward the tip (normalised; not zero).")
      .in("unit vector").by_default("the previous keyframe's; [0, 0, -1] at the first").eg("axis: [0, 0.2, -1]"),
  key("instruments[].script[].on_surface", KT::section, "The tip placed on the organ instead of at `tip`: where the ray "
      "from `from` along `toward` first meets the organ's surface (as placed by `organ.scale`, `rotate_deg` and "
      "`translate`), then moved `depth` along the surface's inward normal there. Found when the scene is loaded; "
      "`vdmsim check` prints where. A ray that misses the organ, or starts inside it, is an error.")
      .eg("on_surface: {from: [0.035, 0, 0.3], toward: [0, 0, -1]}"),
  key("instruments[].script[].depth", KT::number, "With `on_surface`: how far the tip goes past the surface point, "
      "along the inward normal (negative: it stays outside, that far from the surface). With a `port` and port "
      "coordinates (`pan_deg`, `tilt_deg`): how far the tip is past the port, along the shaft (above 0).")
      .in("m").range(-1, 1)
      .by_default([] { return yaml_number(0.0); }).eg("on_surface: {from: [0.035, 0, 0.3], toward: [0, 0, -1]}, depth: 0.005"),
  key("instruments[].script[].align", KT::boolean, "With `on_surface`: the axis set along the inward normal at the "
      "surface point, so that the instrument pushes straight in (give `axis` or `align`, not both).")
      .by_default([] { return yaml_bool(false); }).eg("on_surface: {from: [0.035, 0, 0.3], toward: [0, 0, -1]}, align: true"),
  key("instruments[].script[].pan_deg", KT::number, "With a `port`: the shaft's heading, turned about the world's z "
      "axis from +x toward +y (0: the tip lies toward +x of the port). With `tilt_deg` and `depth` the tip's place "
      "in port coordinates; each left out keeps the previous keyframe's (its tip's, if it gave a tip).")
      .in("degrees").range(-360, 360).by_default("the previous keyframe's").eg("pan_deg: 90, tilt_deg: 50, depth: 0.12"),
  key("instruments[].script[].tilt_deg", KT::number, "With a `port`: how far the shaft points below the horizontal, "
      "from the port toward the tip (90: straight down).").in("degrees").range(-90, 90)
      .by_default("the previous keyframe's").eg("pan_deg: 90, tilt_deg: 50, depth: 0.12"),
  key("instruments[].script[].roll_deg", KT::number, "The instrument turned about its shaft (right-handed, handle "
      "toward tip): where a grasper's jaws open. Moves linearly between keyframes.").in("degrees").range(-720, 720)
      .by_default("the previous keyframe's; 0 at the first").eg("roll_deg: 90"),
  key("instruments[].script[].jaw", KT::choice, "Grasper: the jaws' state, reached at this keyframe (they swing "
      "linearly from the previous keyframe).").one_of([] { return Words{"open", "closed"}; })
      .by_default("the previous keyframe's; open at the first").eg("jaw: closed"),

  // instruments[].script[].on_surface
  key("instruments[].script[].on_surface.from", KT::vector3, "Where the ray starts, outside the organ.").in("m").needed()
      .eg("from: [0.035, 0, 0.3], toward: [0, 0, -1]"),
  key("instruments[].script[].on_surface.toward", KT::vector3, "The ray's direction (any length, not zero).")
      .in("direction").needed().eg("from: [0.035, 0, 0.3], toward: [0, 0, -1]"),

  // render
  key("render.width", KT::integer, "The image width.").in("pixels").range(16, 8192)
      .by_default([] { return std::to_string(RenderDef().settings.width); }).eg("width: 1920"),
  key("render.height", KT::integer, "The image height.").in("pixels").range(16, 8192)
      .by_default([] { return std::to_string(RenderDef().settings.height); }).eg("height: 1080"),
  key("render.antialias", KT::choice, "`edge`: one sample per pixel, the edges' staircases smoothed; `msaa`: "
      "multisampling (about twice the rendering time); `none`.").one_of([] { return Words{"edge", "msaa", "none"}; })
      .by_default([] { return std::string(render::to_string(RenderDef().settings.antialias)); }).eg("antialias: msaa"),
  key("render.samples", KT::integer, "`antialias: msaa` only: samples per pixel (the software renderer uses 4 "
      "whatever is asked). A scene without `antialias` that gives `samples` gets msaa for 2 to 16, none for 1.")
      .range(1, 16).allowing("1, 2, 4, 8 or 16").by_default([] { return std::to_string(RenderDef().settings.samples); })
      .eg("antialias: msaa, samples: 4"),
  key("render.camera", KT::section, "The camera: a framing camera outside the body (`eye` and `target`; leave them out "
      "for automatic framing of the organ, or of the instruments' working area with `focus`), or a laparoscope "
      "(`type: endoscope`, through a `port`).")
      .eg("camera: {eye: [0.16, -0.24, 0.19], target: [0.025, 0, 0.025], up: [0, 0, 1], fov_deg: 35}"),
  key("render.views", KT::choice_list, "The images drawn each frame: `shaded` (what a camera sees) into "
      "`frames/frame_NNNNN.png`, `stress` (the organ coloured by `stress.quantity`) into `stress/stress_NNNNN.png`; "
      "the ground truth, with `camera.json` and `poses.csv`: `depth` (the distance along the optical axis, m, float32) "
      "into `depth/depth_NNNNN.npy`, `segmentation` (8-bit ids: 0 the background, 1 the organ, 2 + i `instruments[i]`) "
      "into `segmentation/segmentation_NNNNN.png`, `normals` (camera-space normals as RGB) into "
      "`normals/normals_NNNNN.png`.")
      .one_of(render::view_names).by_default([] {
        std::string text;
        for (render::View v : RenderDef().views) text += (text.empty() ? "" : ", ") + std::string(render::view_row(v).name);
        return "[" + text + "]";
      })
      .eg("views: [shaded, depth, segmentation]"),
  key("render.stress", KT::section, "What the stress view shows and its colours.")
      .eg("stress: {quantity: magnitude, colormap: viridis, range: auto}"),
  key("render.hud", KT::boolean, "The overlay: scene name, frame, time, contact force, fluid pressure, volume error.")
      .by_default([] { return yaml_bool(RenderDef().hud); }).eg("hud: false"),
  key("render.hud_step_time", KT::boolean, "Add each step's wall-clock time to the HUD (then the pictures differ from run "
      "to run).").by_default([] { return yaml_bool(RenderDef().hud_step_time); }).eg("hud_step_time: true"),
  key("render.gizmo", KT::boolean, "Small x, y and z axes (red, green, blue) in the bottom-left corner, turned as the "
      "camera sees them.").by_default([] { return yaml_bool(RenderDef().settings.gizmo); }).eg("gizmo: true"),
  key("render.floor", KT::boolean, "A floor under the organ, with the organ's and the instruments' soft shadow.")
      .by_default([] { return yaml_bool(RenderDef().settings.floor); }).eg("floor: false"),
  key("render.shadows", KT::boolean, "Instruments cast soft shadows on the organ and the floor.")
      .by_default([] { return yaml_bool(RenderDef().settings.shadows); }).eg("shadows: false"),
  key("render.png_compression", KT::integer, "The PNG files' zlib level (1 is fast and about as small as 6 for these "
      "images).").range(0, 9).by_default([] { return std::to_string(RenderDef().png_compression); }).eg("png_compression: 6"),
  key("render.fps", KT::number, "The video's frame rate (`run --video`).").in("frames per second").range(1, 240)
      .by_default([] { return yaml_number(RenderDef().fps); }).eg("fps: 60"),

  // render.camera
  key("render.camera.eye", KT::vector3, "Where the camera is; give `target` with it.").in("m").by_default("automatic framing")
      .eg("eye: [0.16, -0.24, 0.19], target: [0.025, 0, 0.025]"),
  key("render.camera.target", KT::vector3, "The point the camera looks at; give `eye` with it.").in("m")
      .by_default("automatic framing").eg("eye: [0.16, -0.24, 0.19], target: [0.025, 0, 0.025]"),
  key("render.camera.focus", KT::choice, "What the automatic camera frames (without `eye` and `target`): the `organ`, "
      "or the `instruments`' working area: where their tips go while in or near contact over the script, with room "
      "around it for the dent.").one_of([] { return Words{"organ", "instruments"}; })
      .by_default([] { return std::string(render::to_string(RenderDef().settings.focus)); }).eg("focus: instruments"),
  key("render.camera.up", KT::vector3, "Which way is up in the picture (not zero).").in("unit vector")
      .by_default([] { return yaml_vector(RenderDef().settings.camera.up); }).eg("up: [0, 1, 0]"),
  key("render.camera.fov_deg", KT::number, "The field of view: vertical for the framing camera, horizontal for the "
      "endoscope.").in("degrees").range(1, 170)
      .by_default([] {
        return yaml_number(RenderDef().settings.camera.fov_deg) + " (framing), " +
               yaml_number(tools::EndoscopeDef().fov_deg) + " (endoscope)";
      })
      .eg("fov_deg: 35"),
  key("render.camera.type", KT::choice, "`framing`: a camera outside the organ (`eye`, `target`, or automatic); "
      "`endoscope`: a laparoscope through a port in the abdominal wall, its light at its tip, the abdomen's wall "
      "behind the organ instead of the floor.").one_of([] { return Words{"framing", "endoscope"}; })
      .by_default("framing").eg("type: endoscope, port: [0, -0.12, 0.12], look_at: [0, 0, 0.02], depth: 0.05"),
  key("render.camera.port", KT::vector3, "Endoscope: where its shaft passes the abdominal wall.").in("m").needed()
      .eg("port: [0, -0.12, 0.12]"),
  key("render.camera.look_at", KT::vector3, "Endoscope: the point its shaft is aimed at (not the port).").in("m")
      .needed().eg("look_at: [0, 0, 0.02]"),
  key("render.camera.depth", KT::number, "Endoscope: how far its tip (the lens and the light) is past the port, along "
      "the shaft.").in("m").above(0, 1).by_default([] { return yaml_number(tools::EndoscopeDef().depth); })
      .eg("depth: 0.06"),
  key("render.camera.angle_deg", KT::number, "Endoscope: how far its optics look off the shaft (0, 30 and 45 degree "
      "scopes): above the shaft at roll 0, below it at roll 180.").in("degrees").range(0, 60)
      .by_default([] { return yaml_number(tools::EndoscopeDef().angle_deg); }).eg("angle_deg: 30"),
  key("render.camera.roll_deg", KT::number, "Endoscope: the scope turned about its shaft (right-handed, handle toward "
      "tip), and with it where its angled optics look. The picture stays level (the camera head held level): the "
      "world's up (+z) toward its top.").in("degrees").range(-360, 360)
      .by_default([] { return yaml_number(tools::EndoscopeDef().roll_deg); }).eg("roll_deg: 15"),
  key("render.camera.script", KT::list, "Endoscope: a timeline moving `look_at`, `depth` and `roll_deg` from the "
      "values above (at t = 0), linearly from keyframe to keyframe; a field a keyframe leaves out keeps its value; "
      "after the last keyframe the scope stays.")
      .eg("script: [{t: 1, look_at: [0.02, 0, 0.02]}, {t: 2, depth: 0.08, roll_deg: 20}]"),

  // render.camera.script[]
  key("render.camera.script[].t", KT::number, "The keyframe's time, after 0 and after the keyframe before.").in("s")
      .above(0, std::numeric_limits<double>::infinity()).needed().eg("t: 1.5"),
  key("render.camera.script[].look_at", KT::vector3, "Where the shaft is aimed from then (not the port).").in("m")
      .by_default("the previous value").eg("look_at: [0.02, 0, 0.02]"),
  key("render.camera.script[].depth", KT::number, "The tip past the port from then.").in("m").above(0, 1)
      .by_default("the previous value").eg("depth: 0.08"),
  key("render.camera.script[].roll_deg", KT::number, "The scope's roll from then.").in("degrees").range(-360, 360)
      .by_default("the previous value").eg("roll_deg: 20"),

  // render.stress
  key("render.stress.quantity", KT::choice, "The quantity coloured: `magnitude` (the norm of the per-axis stress), "
      "`stress_x`, `stress_y`, `stress_z` (signed), `contact_pressure`, `displacement` (norm) or `volumetric_strain`. "
      "The stress components, magnitude and strain need the `stress` effect and `organ.model: vdm` or `vdm_core`.")
      .one_of(render::quantity_names)
      .by_default([] { return std::string(render::to_string(RenderDef().stress_view.quantity)); })
      .eg("quantity: contact_pressure"),
  key("render.stress.range", KT::number, "The colour range, the same for every frame; `auto` takes it from a first pass "
      "over the sequence (the 0.5 % and 99.5 % quantiles). In the quantity's SI unit.").typed("auto or [low, high]").in("")
      .by_default([] { const RenderDef d; return d.range_auto ? std::string("auto") : "[" + yaml_number(d.stress_view.lo) + ", " + yaml_number(d.stress_view.hi) + "]"; }).eg("range: [0, 5000]"),
  key("render.stress.colormap", KT::choice, "The colour map: perceptually uniform; `coolwarm` is diverging, and the default for the signed quantities.")
      .one_of(render::colormap_names)
      .by_default([] {
        return std::string(render::to_string(RenderDef().stress_view.colormap));
      }).eg("colormap: magma"),
};
// clang-format on

constexpr bool same_text(const char* a, const char* b) {
  while (*a && *a == *b) ++a, ++b;
  return *a == *b;
}

// The index of `path` in kSceneKeys. In a constant expression (VDMSIM_SCENE_KEY) an unknown
// path does not compile.
constexpr std::size_t scene_key_index(const char* path) {
  for (std::size_t i = 0; i < sizeof(kSceneKeys) / sizeof(kSceneKeys[0]); ++i)
    if (same_text(kSceneKeys[i].path, path)) return i;
  throw "not a key of kSceneKeys";
}

// The keys of the mapping at `parent` ("" for the top), in order; for instruments[].shape,
// those of `shape` (capsule, cylinder, box, convex) only.
std::vector<std::string> scene_key_names(const std::string& parent, const char* shape = nullptr);

// The closest of `known` to `word` within a few edits (the "did you mean" of the messages);
// "" when none is that close.
std::string closest_name(const std::string& word, const std::vector<std::string>& known);

// The key's parent mapping: "organ.material" for "organ.material.density", "" at the top.
std::string scene_key_parent(const std::string& path);

}  // namespace vdmsim

// The entry of a key path, checked at compile time.
#define VDMSIM_SCENE_KEY(path) \
  (::vdmsim::kSceneKeys[std::integral_constant<std::size_t, ::vdmsim::scene_key_index(path)>::value])
