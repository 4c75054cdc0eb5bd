#pragma once
// `vdmsim bench`: the standard performance cases, each run in its own process (so that its
// peak memory is its own) with warm-up and repeated measurement; writes bench.csv
// (case,model,nodes,median_ms,p95_ms,iterations,volume_rel_error,peak_mb) and scaling.png.
#include <ostream>
#include <string>

#include "app/scene_run.hpp"

namespace vdmsim {

// The bench's probe scene (assets/scenes/probe_poke.yaml) on `mesh` (a file in assets/meshes)
// with an 8 mm probe, so that it meets nodes on every mesh; `frames` frames.
PreparedScene bench_probe_scene(const std::string& mesh, int frames, bool render);

// `only` (may be empty): run only the cases whose label contains it. Each case runs in a
// process of its own: this program again with `case_fd` >= 0 and `only` the case's label,
// which writes the case's CSV row to that descriptor.
int cmd_bench(const std::string& out_dir, bool quick, std::ostream& out, std::ostream& err,
              const std::string& only = "", int case_fd = -1);

}  // namespace vdmsim
