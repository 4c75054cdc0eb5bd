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

std::string batch_script(const std::vector<RunJob>& jobs, const SlurmArray& array, const fs::path& dir) {
  std::vector<int> indices;
  for (const RunJob& j : jobs) indices.push_back(j.index);
  const int limit = array.max_parallel > 0 ? array.max_parallel : int(jobs.size());
  std::ostringstream s;
  s << "#!/bin/sh\n"
    << "# " << array.what << ": one array task per run (written by vdmsim " << array.name << " --slurm)\n"
    << "#SBATCH --job-name=vdmsim-" << array.name << "\n"
    << "#SBATCH --array=" << array_indices(indices) << "%" << limit << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --output=" << (dir / "slurm" / "task_%a.out").string() << "\n";
  if (!array.partition.empty()) s << "#SBATCH --partition=" << array.partition << "\n";
  s << "exec";
  for (const std::string& word : array.task_command) s << " " << shell_quote(word);
  s << " --task \"$SLURM_ARRAY_TASK_ID\"\n";
  return s.str();
}

SlurmArray sweep_array(const SweepOptions& o, const fs::path& dir) {
  SlurmArray a;
  a.name = "sweep";
  a.what = "vdmsim sweep " + o.sweep_file;
  a.task_command = {own_program(), "sweep", fs::absolute(o.sweep_file).string(), "--out", dir.string()};
  if (o.frames > 0) a.task_command.insert(a.task_command.end(), {"--frames", std::to_string(o.frames)});
  if (!o.render) a.task_command.push_back("--no-render");
  if (o.video) a.task_command.push_back("--video");
  a.partition = o.partition;
  a.max_parallel = o.max_parallel;
  return a;
}

int run_on_slurm(const std::vector<RunJob>& jobs, const SlurmArray& array, const fs::path& dir, std::ostream& err) {
  const fs::path slurm = dir / "slurm";
  const fs::path script = slurm / (array.name + ".sbatch");
  const std::string label = array.name;
  std::string error;
  if (!prepare_output_dir(slurm.string(), error) || !write_file_atomically(script, batch_script(jobs, array, dir), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  const StopSignals signals;
  std::string said;
  const int code = run_program({"sbatch", "--parsable", script.string()}, said);
  const std::string job = trim(said.substr(0, said.find(';')));
  if (code != 0 || job.empty() || !std::all_of(job.begin(), job.end(), ::isdigit)) {
    err << "vdmsim: error: sbatch " << script.string() << " failed"
        << (code < 0 ? "" : " (exit " + std::to_string(code) + ")") << ": " << trim(said)
        << (code < 0 ? " (is Slurm installed here? --slurm submits from a cluster's login node)" : "") << "\n";
    return 1;
  }
  err << label << ": submitted " << jobs.size() << " runs as Slurm job array " << job << " (" << slurm.string()
      << "/task_<run>.out has each task's output)\n";
  bool cancelled = false;
  std::string last;
  double wait_s = 0.5;
  int silent = 0;
  for (;;) {
    if (!cancelled && signals.received()) {
      cancelled = true;
      run_program({"scancel", job}, said);
      err << label << ": stopping: cancelled job " << job << "; its runs stop\n";
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
      if (now != last) err << label << ": job " << job << ": " << now << "\n";
      last = now;
    }
    // Polls often at first, then every 10 s at most (squeue is a query of the controller).
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(int(wait_s * 1000));
    while (std::chrono::steady_clock::now() < until && (cancelled || !signals.received()))
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    wait_s = std::min(10.0, wait_s * 1.3);
  }
  err << label << ": job " << job << " " << (cancelled ? "cancelled" : "done") << "\n";
  return cancelled ? 130 : 0;
}

}  // namespace vdmsim
