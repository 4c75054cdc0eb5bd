#include "app/sweep/sweep_command.hpp"

#include <unistd.h>

#include "app/run/output_dir.hpp"
#include "app/sweep/child_process.hpp"
#include "app/sweep/local_runner.hpp"
#include "app/sweep/run_folder.hpp"
#include "app/sweep/slurm_runner.hpp"
#include "app/sweep/summary.hpp"
#include "app/sweep/sweep_plan.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

// Every run's scene must load: a value out of range is the sweep file's error, named at the
// value (and the scene's own message).
bool check_run_scenes(const SweepPlan& plan, const fs::path& runs, const std::vector<int>& which, std::ostream& err) {
  bool ok = true;
  for (int i : which) {
    const PlannedRun& run = plan.runs[size_t(i)];
    const SceneLoadResult scene = load_scene((runs / run.folder / "scene.yaml").string());
    for (const SceneProblem& p : scene.problems) {
      if (p.warning) continue;
      ok = false;
      // The value the problem is about (its key a prefix of the problem's field), else the run's first.
      std::string at, key;
      for (size_t k = 0; k < plan.columns.size(); ++k) {
        if (run.values[k].empty()) continue;
        const std::string& c = plan.columns[k];
        const bool about = p.field.compare(0, c.size(), c) == 0 || c.compare(0, p.field.size(), p.field) == 0;
        if (at.empty() || about) {
          at = run.wheres[k];
          key = c;
        }
        if (about) break;
      }
      err << "vdmsim: error: " << (at.empty() ? plan.sweep_file.string() : at) << ": " << key << ": run "
          << run.folder << " gets an invalid scene: " << p.field << ": " << p.message << " ("
          << (runs / run.folder / "scene.yaml").string() << ")\n";
    }
  }
  return ok;
}

// Each run is `vdmsim run` of its folder's scene, with the sweep's options.
JobCommand sweep_run_command(const SweepOptions& o) {
  const std::string program = own_program();
  return [program, o](const RunJob& job, bool resume) { return run_command(program, job, o, resume); };
}

}  // namespace

int cmd_sweep(const SweepOptions& o, std::ostream& out, std::ostream& err, bool terminal) {
  SweepFile sweep;
  std::vector<SceneProblem> problems;
  const bool read = read_sweep_file(o.sweep_file, sweep, problems);
  if (!report_problems(problems, err) || !read) return 2;
  const SweepPlan plan = plan_sweep(sweep);
  const int n = int(plan.runs.size());
  if (o.task >= n) {
    err << "vdmsim: error: --task " << o.task << ": the sweep has " << n << " runs (0 to " << n - 1 << ")\n";
    return 2;
  }
  // The sweep's folder is one sweep's at a time (a task works in its own run's folder only).
  fs::path dir;
  OutputLock lock;
  std::string error;
  if (!open_sweep_dir(o.out_dir, o.task >= 0, dir, lock, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  const fs::path runs = dir / "runs";
  std::vector<int> which;
  for (int i = 0; i < n; ++i)
    if (o.task < 0 || i == o.task) which.push_back(i);
  for (int i : which)
    if (!write_run_scene(runs / plan.runs[size_t(i)].folder, plan.runs[size_t(i)].scene_text, error)) {
      err << "vdmsim: error: " << error << "\n";
      return 1;
    }
  if (!check_run_scenes(plan, runs, which, err)) return 2;

  // What each run folder holds decides what is done with it.
  const RunOptions run_opt = run_options(o);
  std::vector<RunJob> jobs;
  int finished = 0, resumable = 0;
  for (int i : which) {
    RunJob job{i, runs / plan.runs[size_t(i)].folder, RunFolderState::fresh};
    job.state = run_folder_state(job.dir, run_opt);
    if (job.state == RunFolderState::finished) ++finished;
    else jobs.push_back(job);
    if (job.state == RunFolderState::resumable) ++resumable;
  }
  if (o.task >= 0) {
    // One Slurm array task: its run, in this process's group (a cancelled job signals them all).
    if (jobs.empty()) {
      out << plan.runs[size_t(o.task)].folder << ": finished already\n";
      return 0;
    }
    std::vector<int> codes;
    LocalRunSettings s;
    s.forward_signals = false;
    s.quiet = true;
    const bool all = run_locally(jobs, sweep_run_command(o), s, codes, err);
    RunResult r = read_run_result(jobs[0].dir);
    note_exit_code(r, codes[0], jobs[0].dir);
    out << plan.runs[size_t(o.task)].folder << ": " << r.status << (r.reason.empty() ? "" : ": " + r.reason) << "\n";
    return !all ? 130 : codes[0] == 0 ? 0 : codes[0] == 130 ? 130 : 1;
  }

  const fs::path shown = fs::path(o.out_dir);  // the folder as given, in messages
  err << "sweep: " << n << " runs in " << (shown / "runs").string() << ": " << finished << " finished already, " << resumable
      << " to continue, " << jobs.size() - size_t(resumable) << " to run\n";
  int code = 0;
  std::vector<int> codes;  // per job, its process's exit code (-1: not started)
  if (!jobs.empty() && o.slurm) {
    code = run_on_slurm(jobs, sweep_array(o, dir), dir, err);
    if (code == 1) return 1;
  } else if (!jobs.empty()) {
    LocalRunSettings s;
    s.parallel = o.jobs > 0 ? o.jobs : default_parallel();
    s.terminal = terminal;
    if (!run_locally(jobs, sweep_run_command(o), s, codes, err)) code = 130;
  }

  std::vector<RunResult> results;
  for (const PlannedRun& run : plan.runs)
    results.push_back(read_run_result(runs / run.folder,
                                      o.slurm ? dir / "slurm" / ("task_" + std::to_string(run.index) + ".out") : fs::path()));
  // What a run's process said outranks what its folder holds (another process may have written it).
  for (size_t j = 0; j < codes.size() && j < jobs.size(); ++j)
    note_exit_code(results[size_t(jobs[j].index)], codes[j], jobs[j].dir);
  if (!write_file_atomically(dir / "summary.csv", summary_csv(plan, results), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  bool png = false;
  if (o.render && !write_summary_png(plan, results, dir, png, error)) err << "vdmsim: warning: summary.png: " << error << "\n";
  int completed = 0;
  for (size_t i = 0; i < results.size(); ++i) {
    if (results[i].status == "completed") {
      ++completed;
      continue;
    }
    out << plan.runs[i].folder << ": " << results[i].status << (results[i].reason.empty() ? "" : ": " + results[i].reason) << "\n";
  }
  out << "sweep: " << completed << " of " << n << " runs completed -> " << (shown / "summary.csv").string()
      << (png ? " and summary.png" : "") << "\n";
  if (code == 130) return 130;
  return completed == n ? 0 : 1;
}

}  // namespace vdmsim
