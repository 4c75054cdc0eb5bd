#pragma once
// The CLI's commands as functions (so tests can call them). Each returns the exit code.
#include <ostream>
#include <string>
#include <vector>

#include "app/run/scene_run.hpp"
#include "app/studies/paper_beam.hpp"

namespace vdmsim {

int cmd_mesh_info(const std::string& path, double scale, std::ostream& out, std::ostream& err);
int cmd_paper(const std::string& experiment, const std::string& out_dir, std::ostream& out,
              std::ostream& err);

// The beam experiments of `paper` with a given configuration (tests use a small beam).
int paper_beams(const std::vector<BeamCase>& beams, const BeamConfig& config, const std::string& out_dir,
                std::ostream& out, std::ostream& err);

// vdmsim calibrate: fits VDM's bulk and connectivity moduli to the FEM reference (E, nu) on
// the organ `mesh` (tets by gmsh), pressed and pulled at its top with its base held; writes
// the material block to `out_path` (YAML).
int cmd_calibrate(const std::string& mesh, double scale, double young, double poisson, int steps, double tet_size,
                  const std::string& out_path, std::ostream& out, std::ostream& err);

// Meshes the project's liver at icosphere `level` and writes it as OBJ to `out_path`; with
// `scan_like`, damaged as a CT segmentation gives it (app/scene/scan_like_organ.hpp: millimetres,
// scanner coordinates, bumpy, cropped open, self-intersecting), for prepare-mesh.
int cmd_make_organ(const std::string& organ, int level, const std::string& out_path, std::ostream& out,
                   std::ostream& err, bool scan_like = false);

// vdmsim check SCENE: validates the scene and its mesh without simulating.
int cmd_check(const std::string& scene_path, std::ostream& out, std::ostream& err);
// vdmsim run SCENE: validates, then simulates every frame.
int cmd_run(const std::string& scene_path, const RunOptions& options, std::ostream& out, std::ostream& err, bool terminal);
// The same with the options one by one (as the tests call it).
int cmd_run(const std::string& scene_path, const std::string& out_dir, int frames, bool render, bool video, bool resume, int checkpoint_every, std::ostream& out,
            std::ostream& err, bool terminal);

}  // namespace vdmsim
