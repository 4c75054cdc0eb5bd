#include "app/studies/ladder_command.hpp"

#include <iomanip>

#include "app/run/checkpoint.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/program_version.hpp"
#include "app/studies/accuracy_command.hpp"
#include "app/studies/accuracy_task.hpp"
#include "app/studies/ladder_cases.hpp"
#include "app/studies/ladder_report.hpp"
#include "app/studies/quantile.hpp"
#include "app/sweep/child_process.hpp"
#include "app/sweep/local_runner.hpp"
#include "app/sweep/run_folder.hpp"
#include "app/sweep/slurm_runner.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

bool is_scene(const LadderConfig& c) { return c.scenario == "liver_probe"; }

fs::path rung_dir(const fs::path& dir, int index, const LadderConfig& c) {
  return dir / "ladder" / numbered_folder(index, ladder_config_name(c));
}

// What a load-case rung's result depends on: its rung.txt and the program.
std::string rung_inputs_hash(const fs::path& run_dir) {
  const std::string rung = file_hash((run_dir / "rung.txt").string());
  if (rung.empty()) return "";
  RunInputs in;
  in.items.emplace_back("the rung", rung);
  in.items.emplace_back("the vdmsim program", program_version());
  return in.hash();
}

std::string inputs_hash(const fs::path& run_dir, const LadderConfig& c) {
  return is_scene(c) ? config_inputs_hash(run_dir / "scene.yaml") : rung_inputs_hash(run_dir);
}

// The rung's folder with what it runs (scene.yaml or rung.txt) as it is now.
bool write_rung(const fs::path& run_dir, const LadderConfig& c, std::string& error) {
  if (is_scene(c)) return write_run_scene(run_dir, ladder_scene_yaml(c, "../../meshes"), error);
  if (!prepare_output_dir(run_dir.string(), error)) return false;
  return write_file_atomically(run_dir / "rung.txt", ladder_config_text(c), error);
}

int run_rung_task(const fs::path& run_dir, const LadderConfig& c, const fs::path& yardstick, std::ostream& out) {
  const TaskSimulation simulate = [&]() -> Trajectory {
    if (is_scene(c)) return simulate_trajectory((run_dir / "scene.yaml").string(), accuracy_sample_points());
    return run_ladder_case(c);
  };
  return run_task(run_dir, inputs_hash(run_dir, c), simulate, yardstick, out);
}

// The rows from what the tasks left: each case's reference first, then its rungs against it.
std::vector<LadderRow> measure_rungs(const std::vector<LadderConfig>& all, const std::vector<int>& which,
                                     const fs::path& dir, bool slurm, std::ostream& out, std::ostream& err) {
  std::vector<LadderRow> rows;
  Trajectory ref;
  bool have_ref = false;
  for (int i : which) {
    const LadderConfig& c = all[size_t(i)];
    const fs::path run_dir = rung_dir(dir, i, c);
    LadderRow row;
    row.config = c;
    row.folder = "ladder/" + run_dir.filename().string();
    ConfigResult result = read_config_result(run_dir);
    if (result.status == "not run")
      result.reason = "did not finish (see " + (slurm ? "slurm/task_" + std::to_string(i) + ".out" : row.folder + "/run.log") + ")";
    if (c.reference) {
      have_ref = result.status == "completed";
      ref = result.trajectory;
      if (!have_ref) err << "vdmsim: error: the reference FEM of " << c.test_case << " failed: " << result.reason << "\n";
    }
    if (result.status != "completed") {
      row.failed = true;
      row.note = result.reason;
    } else if (!have_ref) {
      row.failed = true;
      row.note = "its case's reference FEM failed";
    } else if (result.trajectory.u.size() != ref.u.size()) {
      row.failed = true;
      row.note = "its frames are not the reference's";
    } else {
      measure_ladder_row(ref, result.trajectory, row);
      row.yardstick_ms = result.yardstick_ms;
      if (result.trajectory.unconverged > 0)
        row.note = std::to_string(result.trajectory.unconverged) + " steps did not converge";
    }
    rows.push_back(row);
  }
  // Times on the study's typical node, as the accuracy study's (accuracy.md, "Times from
  // different nodes").
  std::vector<double> yardsticks;
  for (const LadderRow& r : rows)
    if (!r.failed && r.yardstick_ms > 0) yardsticks.push_back(r.yardstick_ms);
  const double typical = quantile(yardsticks, 0.5);
  for (LadderRow& r : rows)
    if (!r.failed && r.yardstick_ms > 0) r.median_ms = r.measured_median_ms * typical / r.yardstick_ms;
  for (size_t k = 0; k < rows.size(); ++k) {
    const LadderRow& r = rows[k];
    out << "[" << (k + 1) << "/" << rows.size() << "] " << ladder_config_name(r.config) << ": ";
    if (r.failed)
      out << "failed (" << r.note << ")\n";
    else
      out << std::setprecision(3) << r.median_ms << " ms/step, error " << 100 * r.error << " % (" << r.detail << ")\n";
  }
  return rows;
}

}  // namespace

int run_ladder(const AccuracyOptions& o, std::ostream& out, std::ostream& err, bool terminal) {
  const std::vector<LadderConfig> all = ladder_configs(o.quick);
  std::vector<int> which;
  std::string error;
  if (!o.only.empty()) {
    err << "vdmsim: error: --only: the model ladder has no knobs (--scenario picks its cases)\n";
    return 2;
  }
  if (!select_ladder_configs(o.quick, o.scenario, which, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  if (o.task >= int(all.size())) {
    err << "vdmsim: error: --task " << o.task << ": the model ladder has " << all.size() << " rungs (0 to "
        << all.size() - 1 << ")\n";
    return 2;
  }
  if (o.task >= 0) which = {o.task};
  fs::path dir;
  OutputLock lock;
  if (!open_sweep_dir(o.out_dir, o.task >= 0, dir, lock, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  std::vector<int> levels{yardstick_config(o.quick).level};
  for (int i : which)
    if (is_scene(all[size_t(i)])) levels.push_back(all[size_t(i)].mesh);
  if (!write_study_meshes(dir, levels, o.quick, o.task >= 0, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  std::vector<RunJob> jobs;
  for (int i : which) {
    const fs::path run_dir = rung_dir(dir, i, all[size_t(i)]);
    if (!write_rung(run_dir, all[size_t(i)], error)) {
      err << "vdmsim: error: " << error << "\n";
      return 1;
    }
    if (!task_finished(run_dir, inputs_hash(run_dir, all[size_t(i)]))) jobs.push_back({i, run_dir, RunFolderState::fresh});
  }
  const fs::path yardstick = dir / "yardstick.yaml";
  if (o.task >= 0) {
    if (jobs.empty()) {
      out << rung_dir(dir, o.task, all[size_t(o.task)]).filename().string() << ": finished already\n";
      return 0;
    }
    return run_rung_task(jobs[0].dir, all[size_t(o.task)], yardstick, out);
  }

  const fs::path shown = fs::path(o.out_dir);
  err << "accuracy --ladder: " << which.size() << " rungs in " << (shown / "ladder").string()
      << (o.quick ? " (quick)" : "") << ": " << which.size() - jobs.size() << " finished already, " << jobs.size()
      << " to run\n";
  std::vector<std::string> command = {own_program(), "accuracy", "--ladder", "--out", dir.string()};
  if (o.quick) command.push_back("--quick");
  if (!jobs.empty() && o.slurm) {
    SlurmArray array;
    array.name = "ladder";
    array.what = "vdmsim accuracy --ladder --out " + dir.string() + (o.quick ? " --quick" : "");
    array.task_command = command;
    array.partition = o.partition;
    array.max_parallel = o.max_parallel;
    const int code = run_on_slurm(jobs, array, dir, err);
    if (code != 0) return code;
  } else if (!jobs.empty()) {
    LocalRunSettings s;
    s.label = "accuracy --ladder";
    s.on_stop = "rungs stop (to run again from their start)";
    s.parallel = o.jobs > 0 ? o.jobs : default_parallel();
    s.terminal = terminal;
    std::vector<int> codes;
    const bool all_ran = run_locally(
        jobs,
        [&command](const RunJob& job, bool) {
          std::vector<std::string> argv = command;
          argv.insert(argv.end(), {"--task", std::to_string(job.index)});
          return argv;
        },
        s, codes, err);
    if (!all_ran) {
      err << "accuracy --ladder: stopped; `vdmsim accuracy --ladder` with the same options continues\n";
      return 130;
    }
  }

  const std::vector<LadderRow> rows = measure_rungs(all, which, dir, o.slurm, out, err);
  if (!write_ladder_csv((dir / "ladder.csv").string(), rows, error) ||
      !write_ladder_plot((dir / "ladder.png").string(), rows, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  for (const LadderRow& r : rows)
    if (r.config.reference && r.failed) return 1;
  out << "accuracy --ladder: wrote " << (shown / "ladder.csv").string() << ", ladder.png\n";
  return 0;
}

}  // namespace vdmsim
