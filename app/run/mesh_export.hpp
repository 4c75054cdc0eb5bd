#pragma once
// `vdmsim run --export-mesh`: the organ's surface at every frame, for the users' own analysis
// (ParaView, meshio, their datasets). DIR/mesh/frame_NNNNN.vtu holds frame N's deformed
// triangles with point data `displacement` (m, 3 components) and each quantity the stress
// view can show, named as in render.stress.quantity and computed by the renderer's own
// function (render::scalar_field); DIR/mesh.pvd lists the frames with their times. Both are
// written on the simulation thread from the SimState (no rendering needed), the .pvd again
// after every frame so that it always lists exactly the frames on disk. With several organs each
// has its own: DIR/mesh/<name>/frame_NNNNN.vtu and DIR/<name>.pvd.
#include <filesystem>
#include <string>
#include <vector>

#include "app/simulation/prepared_scene.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "render/render_scene.hpp"

namespace vdmsim {

// The stress view's quantities written as scalar point data: every one when the model
// computes stress, else those that need none. Not `displacement`: that name is the vector
// array, whose magnitude is the stress view's displacement.
std::vector<render::Quantity> exported_scalars(bool stress_computed);

// The scene's organ names, which name the export's files when there are several.
std::vector<std::string> organ_names(const PreparedScene& ps);

// A fresh run: removes what an earlier run's export of organs `organs` (their names; empty or
// one: the one-organ layout) wrote in `dir` (the .pvd files and the frame_*.vtu files, with
// their .tmp), and nothing else.
void remove_mesh_export(const std::filesystem::path& dir, const std::vector<std::string>& organs = {});

// The frames before `frames` of which some organ's .vtu is missing (a resume's export extends
// them), ascending.
std::vector<int> missing_export_frames(const std::filesystem::path& dir, int frames,
                                       const std::vector<std::string>& organs = {});

class MeshExport {
 public:
  // Starts exporting `prepared`'s organ into `dir` (creates DIR/mesh). A resume at frame
  // `start` keeps the earlier run's files of the frames before it. False with `error`.
  bool open(const PreparedScene& prepared, const std::filesystem::path& dir, int start, std::string& error);
  bool active() const { return ps_ != nullptr; }
  // Frame f of `sim`: its .vtu, then mesh.pvd. True without writing when not active; false
  // with `error` when a file could not be written.
  bool write(int f, const SceneSimulation& sim, std::string& error);
  // After a render failure cut the run back: removes the files of frames `frames` and later
  // and lists only those before. False with `error` when mesh.pvd could not be rewritten.
  bool keep_frames(int frames, std::string& error);

  int frames() const { return static_cast<int>(listed_.size()); }  // frames mesh.pvd lists
  std::vector<std::string> point_data() const;  // the arrays' names, as in each file
  // Why the stress quantities are left out (no stress computed), or empty.
  const std::string& omitted_reason() const { return omitted_reason_; }
  double write_ms() const { return write_ms_; }

 private:
  std::filesystem::path frame_path(int f, size_t organ) const;
  bool write_pvd(std::string& error) const;

  const PreparedScene* ps_ = nullptr;
  std::filesystem::path dir_;
  std::vector<std::string> organs_;  // the organs' names
  std::vector<render::Quantity> scalars_;
  std::vector<int> listed_;  // frames on disk, ascending
  std::vector<std::vector<float>> values_;  // scratch: each scalar at every node
  std::string omitted_reason_;
  double write_ms_ = 0;
};

}  // namespace vdmsim
