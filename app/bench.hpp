#pragma once
// `vdmsim bench`: the standard performance cases, each run in its own process (so that its
// peak memory is its own) with warm-up and repeated measurement; writes bench.csv
// (case,model,nodes,median_ms,p95_ms,iterations,volume_rel_error,peak_mb) and scaling.png.
#include <ostream>
#include <string>

namespace vdmsim {

int cmd_bench(const std::string& out_dir, bool quick, std::ostream& out, std::ostream& err);

}  // namespace vdmsim
