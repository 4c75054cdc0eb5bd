#include "app/sweep/sweep_options.hpp"

namespace vdmsim {

RunOptions run_options(const SweepOptions& o) {
  RunOptions r;
  r.frames = o.frames;
  r.render = o.render;
  r.video = o.video;
  return r;
}

std::vector<std::string> run_command(const std::string& program, const RunJob& job, const SweepOptions& o, bool resume) {
  std::vector<std::string> argv = {program, "run", (job.dir / "scene.yaml").string(), "--out", job.dir.string()};
  if (o.frames > 0) argv.insert(argv.end(), {"--frames", std::to_string(o.frames)});
  if (!o.render) argv.push_back("--no-render");
  if (o.video) argv.push_back("--video");
  if (resume) argv.push_back("--resume");
  return argv;
}

}  // namespace vdmsim
