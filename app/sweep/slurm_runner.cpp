#include "app/sweep/slurm_runner.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <sstream>
#include <thread>

#include "app/run/output_dir.hpp"
#include "app/run/stop_signals.hpp"
#include "app/sweep/child_process.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

// The array's tasks still queued or running, by state (squeue); empty when it has left the
// queue. False when squeue does not answer.
bool queued_tasks(const std::string& job, std::map<std::string, int>& states, std::string& said) {
  states.clear();
  const int code = run_program({"squeue", "--noheader", "--array", "--jobs", job, "--format", "%T"}, said);
  if (code != 0) {
    // A job that has left the controller's memory is an "invalid job id" to squeue.
    return said.find("Invalid job id") != std::string::npos;
  }
  std::istringstream lines(said);
  std::string line;
  while (std::getline(lines, line))
    if (!trim(line).empty()) ++states[trim(line)];
  return true;
}

}  // namespace

std::string array_indices(const std::vector<int>& indices) {
  std::string out;
  for (size_t i = 0; i < indices.size();) {
    size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(indices[i]) + (j > i ? "-" + std::to_string(indices[j]) : "");
    i = j + 1;
  }
  return out;
}

std::string batch_script(const std::vector<RunJob>& jobs, const SweepOptions& o, const fs::path& dir,
                         const std::string& program) {
  std::vector<int> indices;
  for (const RunJob& j : jobs) indices.push_back(j.index);
  const int limit = o.max_parallel > 0 ? o.max_parallel : int(jobs.size());
  std::ostringstream s;
  s << "#!/bin/sh\n"
    << "# vdmsim sweep " << o.sweep_file << ": one array task per run (written by vdmsim sweep --slurm)\n"
    << "#SBATCH --job-name=vdmsim-sweep\n"
    << "#SBATCH --array=" << array_indices(indices) << "%" << limit << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --output=" << (dir / "slurm" / "task_%a.out").string() << "\n";
  if (!o.partition.empty()) s << "#SBATCH --partition=" << o.partition << "\n";
  s << "exec " << shell_quote(program) << " sweep " << shell_quote(fs::absolute(o.sweep_file).string()) << " --out "
    << shell_quote(dir.string()) << " --task \"$SLURM_ARRAY_TASK_ID\"";
  if (o.frames > 0) s << " --frames " << o.frames;
  if (!o.render) s << " --no-render";
  if (o.video) s << " --video";
  s << "\n";
  return s.str();
}

int run_on_slurm(const std::vector<RunJob>& jobs, const SweepOptions& o, const fs::path& dir, std::ostream& err) {
  const fs::path slurm = dir / "slurm";
  std::string error;
  if (!prepare_output_dir(slurm.string(), error) ||
      !write_file_atomically(slurm / "sweep.sbatch", batch_script(jobs, o, dir, own_program()), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  const StopSignals signals;
  std::string said;
  const int code = run_program({"sbatch", "--parsable", (slurm / "sweep.sbatch").string()}, said);
  const std::string job = trim(said.substr(0, said.find(';')));
  if (code != 0 || job.empty() || !std::all_of(job.begin(), job.end(), ::isdigit)) {
    err << "vdmsim: error: sbatch " << (slurm / "sweep.sbatch").string() << " failed"
        << (code < 0 ? "" : " (exit " + std::to_string(code) + ")") << ": " << trim(said)
        << (code < 0 ? " (is Slurm installed here? --slurm submits from a cluster's login node)" : "") << "\n";
    return 1;
  }
  err << "sweep: submitted " << jobs.size() << " runs as Slurm job array " << job << " (" << slurm.string()
      << "/task_<run>.out has each task's output)\n";
  bool cancelled = false;
  std::string last;
  double wait_s = 0.5;
  int silent = 0;
  for (;;) {
    if (!cancelled && signals.received()) {
      cancelled = true;
      run_program({"scancel", job}, said);
      err << "sweep: stopping: cancelled job " << job << "; its runs stop after their current frame\n";
    }
    std::map<std::string, int> states;
    if (!queued_tasks(job, states, said)) {
      // squeue did not answer: the controller may be busy; give up after a few minutes.
      if (++silent > 60) {
        err << "vdmsim: error: squeue does not answer about job " << job << ": " << trim(said) << "\n";
        return 1;
      }
    } else {
      silent = 0;
      if (states.empty()) break;
      std::string now;
      for (const auto& [state, count] : states) now += (now.empty() ? "" : ", ") + std::to_string(count) + " " + state;
      if (now != last) err << "sweep: job " << job << ": " << now << "\n";
      last = now;
    }
    // Polls often at first, then every 10 s at most (squeue is a query of the controller).
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(int(wait_s * 1000));
    while (std::chrono::steady_clock::now() < until && (cancelled || !signals.received()))
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    wait_s = std::min(10.0, wait_s * 1.3);
  }
  err << "sweep: job " << job << " " << (cancelled ? "cancelled" : "done") << "\n";
  return cancelled ? 130 : 0;
}

}  // namespace vdmsim
