#pragma once
// Running a scene: the simulator's main loop. Builds the organ from the scene, applies the
// scripted loads and motions each frame, steps the engine, writes metrics.csv and run.json.
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "app/scene.hpp"
#include "engine/organ_solver.hpp"
#include "engine/tissue_model.hpp"

namespace vdmsim {

// Nodes of the rest mesh selected by `region` (sorted). Errors (a node index out of range, a
// region that selects nothing) are appended to `problems`, naming the region's position.
std::vector<int> select_nodes(const Region& region, const vdm::NodeMat& rest, const std::string& field,
                              std::vector<SceneProblem>& problems);

// An instrument's skin meshes, loaded and placed in the instrument frame (empty: parametric).
struct InstrumentSkin {
  std::shared_ptr<render::SkinMesh> body, jaws[2];
};

struct PreparedScene {
  SceneDef scene;
  vdm::TissueModel model;
  std::vector<std::vector<int>> load_nodes;        // per organ.loads entry
  std::vector<std::vector<int>> prescribed_nodes;  // per organ.prescribed entry
  std::vector<vdm::Vec3> prescribed_about;         // rotation centre per entry (m)
  std::vector<InstrumentSkin> skins;               // per instrument
  std::unique_ptr<vdm::OrganSolver> organ;         // organ.model fem or mass_spring; null: vdm::step
};

// The organ's solver for organ.model fem (tet mesh by gmsh) or mass_spring, on `model`'s
// surface with its fixed entries; null for vdm. False with a message on failure.
bool make_organ_solver(const SceneDef& scene, const vdm::TissueModel& model, std::unique_ptr<vdm::OrganSolver>& out,
                       std::string& error);

// Loads and validates the scene and its mesh and builds the model. On failure returns false
// with every problem in `problems` (warnings are there too on success).
bool prepare_scene(const std::string& path, PreparedScene& out, std::vector<SceneProblem>& problems);
// The same from an already loaded (and possibly edited) scene.
bool prepare_scene_def(const SceneDef& scene, PreparedScene& out, std::vector<SceneProblem>& problems);

struct RunOptions {
  std::string out_dir;      // empty: out/<scene name>
  int frames = -1;          // override the scene's frame count when > 0
  bool render = true;       // render the scene's views (when it has a render: section)
  bool video = false;       // also encode DIR/video.mp4 with ffmpeg
  bool resume = false;      // continue an interrupted run in out_dir from its checkpoint
  int checkpoint_every = 30;  // frames between checkpoints (each waits for the PNG writer)
  // When set: for each frame, the wall time (ms since the run's loop started) at which it was
  // done (simulated and, when rendering, handed to the render thread). `vdmsim bench` takes
  // the pipeline's frame interval from it.
  std::vector<double>* frame_done_ms = nullptr;
  // Testing: the renderer fails to draw this frame, as if OpenGL had refused it.
  int fail_render_at_frame = -1;
};

// Runs a prepared scene; returns the exit code (0, or 1 on a runtime failure). `progress`
// gets a bar when it is a terminal, plain lines otherwise.
int run_scene(PreparedScene& prepared, const RunOptions& options, std::ostream& out, std::ostream& err,
              bool progress_is_terminal);

}  // namespace vdmsim
