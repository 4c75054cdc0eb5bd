#include "app/studies/accuracy_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <iomanip>

#include "app/run/output_dir.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "app/studies/accuracy_errors.hpp"
#include "app/studies/accuracy_report.hpp"
#include "app/studies/accuracy_task.hpp"
#include "app/studies/ladder_command.hpp"
#include "app/studies/quantile.hpp"
#include "app/sweep/child_process.hpp"
#include "app/sweep/local_runner.hpp"
#include "app/sweep/run_folder.hpp"
#include "app/sweep/slurm_runner.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

std::string run_folder_name(int index, const AccuracyConfig& c) { return numbered_folder(index, config_name(c)); }

bool write_study_files(const fs::path& dir, const std::vector<AccuracyConfig>& configs, bool quick, bool missing_only,
                       std::string& error) {
  std::vector<int> levels;
  for (const AccuracyConfig& c : configs) levels.push_back(c.level);
  return write_study_meshes(dir, levels, quick, missing_only, error);
}

}  // namespace

std::string numbered_folder(int index, const std::string& name) {
  std::string number = std::to_string(index);
  number.insert(0, size_t(std::max(0, 3 - int(number.size()))), '0');
  return number + "_" + name;
}

bool write_study_meshes(const fs::path& dir, std::vector<int> levels, bool quick, bool missing_only,
                        std::string& error) {
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  if (!prepare_output_dir((dir / "meshes").string(), error)) return false;
  std::error_code ec;
  for (int level : levels) {
    const fs::path mesh = dir / "meshes" / level_mesh(level);
    if (missing_only && fs::exists(mesh, ec)) continue;
    const fs::path part = mesh.string() + ".part" + std::to_string(::getpid());
    if (!save_obj(make_liver_mesh(level), part.string(),
                  "vdmsim liver level " + std::to_string(level) + " (app/organ_generator.cpp), for `vdmsim accuracy`",
                  error))
      return false;
    fs::rename(part, mesh, ec);
    if (ec) {
      error = mesh.string() + ": cannot write: " + ec.message();
      return false;
    }
  }
  const fs::path yardstick = dir / "yardstick.yaml";
  if (missing_only && fs::exists(yardstick, ec)) return true;
  return write_file_atomically(yardstick,
                               "# The timing yardstick of `vdmsim accuracy`: every configuration's task runs it too.\n" +
                                   accuracy_scene_yaml(yardstick_config(quick), accuracy_frames(quick), "meshes"),
                               error);
}

namespace {

// A task's command line, without `--task I`: the same program and the same configurations.
std::vector<std::string> task_command(const AccuracyOptions& o, const fs::path& dir) {
  std::vector<std::string> argv = {own_program(), "accuracy", "--out", dir.string()};
  if (o.quick) argv.push_back("--quick");
  return argv;
}

// The study's rows from what the tasks left; false when the reference of a scenario failed.
bool measure(const std::vector<AccuracyConfig>& all, const std::vector<int>& which, const fs::path& dir,
             bool slurm, std::vector<AccuracyRow>& rows, std::ostream& out, std::ostream& err) {
  Trajectory ref, base;  // this scenario's reference and baseline
  int base_level = 0;
  std::vector<int> loaded;
  for (size_t k = 0; k < which.size(); ++k) {
    const AccuracyConfig& c = all[size_t(which[k])];
    const std::string folder = run_folder_name(which[k], c);
    AccuracyRow row;
    row.config = c;
    row.scene_file = "runs/" + folder + "/scene.yaml";
    ConfigResult result = read_config_result(dir / "runs" / folder);
    if (result.status == "not run") {
      result.reason = "did not finish (see " + (slurm ? "slurm/task_" + std::to_string(which[k]) + ".out" :
                                                        "runs/" + folder + "/run.log") + ")";
    }
    const Trajectory& tr = result.trajectory;
    const bool failed = result.status != "completed";
    if (c.varied == "reference") {
      base = Trajectory{};  // a new scenario: the previous one's baseline does not apply
      if (failed) {
        err << "vdmsim: error: the reference of " << c.scenario << " failed: " << result.reason << "\n";
        return false;
      }
      ref = tr;
      loaded = loaded_frames(ref);
    }
    if (failed || tr.u.size() != ref.u.size()) {
      row.failed = true;
      row.note = failed ? result.reason : "its frames are not the reference's";
    } else {
      double scale = 1;
      if (c.model != vdm::ModelKind::vdm) {
        scale = matching_scale(ref, loaded, tr);
        row.young_modulus = scale * kAccuracyStartYoung;
      }
      compare_with_reference(ref, loaded, tr, scale, row);
      row.yardstick_ms = result.yardstick_ms;
      if (c.varied == "baseline") {
        base = tr;
        base_level = c.level;
      }
      // The solver's own error: against the baseline on the same mesh (mesh error left out).
      if (c.model == vdm::ModelKind::vdm && !base.u.empty() && c.level == base_level)
        row.rms_vs_baseline_mm = rms_difference_mm(tr, base, loaded);
      if (tr.unconverged > 0) row.note = std::to_string(tr.unconverged) + " steps did not converge";
    }
    rows.push_back(row);
  }
  // Times on the study's typical node: each configuration's ratio to the yardstick measured in
  // its own task, times the yardstick's median over all tasks.
  std::vector<double> yardsticks;
  for (const AccuracyRow& r : rows)
    if (!r.failed && r.yardstick_ms > 0) yardsticks.push_back(r.yardstick_ms);
  const double typical = quantile(yardsticks, 0.5);
  for (AccuracyRow& r : rows) {
    if (r.failed || r.yardstick_ms <= 0) continue;
    r.p95_ms *= typical / r.yardstick_ms;
    r.median_ms = r.measured_median_ms * typical / r.yardstick_ms;
  }
  for (size_t k = 0; k < rows.size(); ++k) {
    const AccuracyRow& row = rows[k];
    out << "[" << (k + 1) << "/" << rows.size() << "] " << config_name(row.config) << ": ";
    if (row.failed)
      out << "failed (" << row.note << ")\n";
    else
      out << std::setprecision(3) << row.median_ms << " ms/step, displacement error RMS " << row.rms_mm << " mm, max "
          << row.max_mm << " mm, force " << 100 * row.force_rel << " %\n";
  }
  return true;
}

}  // namespace

int run_accuracy(const AccuracyOptions& o, std::ostream& out, std::ostream& err, bool terminal) {
  if (o.ladder) return run_ladder(o, out, err, terminal);
  const std::vector<AccuracyConfig> all = accuracy_configs(o.quick);
  std::vector<int> which;
  std::string error;
  if (!select_accuracy_configs(o, which, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  if (o.task >= int(all.size())) {
    err << "vdmsim: error: --task " << o.task << ": the study has " << all.size() << " configurations (0 to "
        << all.size() - 1 << ")\n";
    return 2;
  }
  if (o.task >= 0) which = {o.task};
  // The study's folder is one study's at a time (a task works in its own run folder only).
  fs::path dir;
  OutputLock lock;
  if (!open_sweep_dir(o.out_dir, o.task >= 0, dir, lock, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  const int frames = accuracy_frames(o.quick);
  const fs::path yardstick = dir / "yardstick.yaml";
  // The study writes them for its tasks; a task started by hand in a new folder, for itself.
  std::vector<AccuracyConfig> used{yardstick_config(o.quick)};
  for (int i : which) used.push_back(all[size_t(i)]);
  if (!write_study_files(dir, used, o.quick, o.task >= 0, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  std::vector<RunJob> jobs;
  for (int i : which) {
    const fs::path run_dir = dir / "runs" / run_folder_name(i, all[size_t(i)]);
    if (!write_run_scene(run_dir, accuracy_scene_yaml(all[size_t(i)], frames, "../../meshes"), error)) {
      err << "vdmsim: error: " << error << "\n";
      return 1;
    }
    if (!config_finished(run_dir)) jobs.push_back({i, run_dir, RunFolderState::fresh});
  }
  if (o.task >= 0) {
    // One task: its configuration, in this process.
    if (jobs.empty()) {
      out << run_folder_name(o.task, all[size_t(o.task)]) << ": finished already\n";
      return 0;
    }
    return run_config_task(jobs[0].dir, yardstick, out);
  }

  const fs::path shown = fs::path(o.out_dir);  // the folder as given, in messages
  err << "accuracy: " << which.size() << " configurations in " << (shown / "runs").string() << ", " << frames
      << " frames each" << (o.quick ? " (quick)" : "") << ": " << which.size() - jobs.size() << " finished already, "
      << jobs.size() << " to run\n";
  if (!jobs.empty() && o.slurm) {
    SlurmArray array;
    array.name = "accuracy";
    array.what = "vdmsim accuracy --out " + dir.string() + (o.quick ? " --quick" : "");
    array.task_command = task_command(o, dir);
    array.partition = o.partition;
    array.max_parallel = o.max_parallel;
    const int code = run_on_slurm(jobs, array, dir, err);
    if (code != 0) return code;
  } else if (!jobs.empty()) {
    LocalRunSettings s;
    s.label = "accuracy";
    s.on_stop = "configurations stop (to run again from their start)";
    s.parallel = o.jobs > 0 ? o.jobs : default_parallel();
    s.terminal = terminal;
    const std::vector<std::string> command = task_command(o, dir);
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
      err << "accuracy: stopped; `vdmsim accuracy` with the same options continues\n";
      return 130;
    }
  }

  std::vector<AccuracyRow> rows;
  if (!measure(all, which, dir, o.slurm, rows, out, err)) return 1;
  mark_pareto(rows);
  if (!write_accuracy_csv((dir / "accuracy.csv").string(), rows, error) ||
      !write_accuracy_plot((dir / "accuracy.png").string(), rows, error) ||
      !write_recommendations((dir / "recommendations.md").string(), rows, o.quick, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  out << "accuracy: wrote " << (shown / "accuracy.csv").string() << ", accuracy.png, recommendations.md\n";
  return 0;
}

}  // namespace vdmsim
