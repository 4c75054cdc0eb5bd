#pragma once
// Running a prepared scene: the simulator's main loop. Applies the scripted loads and motions
// each frame, steps the engine, writes metrics.csv, the pictures and run.json.
#include <ostream>
#include <string>
#include <vector>

#include "app/simulation/prepared_scene.hpp"

namespace vdmsim {

struct RunOptions {
  std::string out_dir;      // empty: out/<scene name>
  int frames = -1;          // override the scene's frame count when > 0
  bool render = true;       // render the scene's views (when it has a render: section)
  bool video = false;       // also encode DIR/video.mp4 with ffmpeg
  bool resume = false;      // continue an interrupted run in out_dir from its checkpoint
  bool export_mesh = false;  // write DIR/mesh/frame_NNNNN.vtu and DIR/mesh.pvd (mesh_export.hpp)
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
