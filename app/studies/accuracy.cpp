#include "app/studies/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "app/studies/accuracy_report.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "app/studies/quantile.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/scene_run.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "app/studies/surface_samples.hpp"

namespace vdmsim {
namespace fs = std::filesystem;

namespace {

constexpr int kSampleLevel = 3;          // the common surface points: the level-3 liver's nodes
constexpr double kRefYoung = 5000;       // E (Pa) the fem and mass_spring runs start from
constexpr double kPoisson = 0.45;
constexpr double kVolumeToYoung = 4;     // mass_spring: volume spring modulus / E

// One simulated trajectory, frame by frame.
struct Trajectory {
  std::vector<vdm::NodeMat> u;           // samples x 3 (m)
  std::vector<vdm::Vec3> force;          // force of the organ on the instruments (N)
  std::vector<double> step_ms, volume_rel;
  int nodes = 0;
  int unconverged = 0;                   // steps whose solve (or contact active set) did not converge
  bool failed = false;
  std::string failure;
};

std::string level_mesh(int level) { return "liver_L" + std::to_string(level) + ".obj"; }

std::string config_name(const AccuracyConfig& c) {
  std::ostringstream s;
  s << c.scenario << "_" << c.varied << "_" << vdm::to_string(c.model) << "_L" << c.level;
  if (c.model == vdm::ModelKind::vdm)
    s << "_" << vdm::to_string(c.method) << "_tol" << std::setprecision(0) << std::scientific << c.tolerance << "_r"
      << c.refresh_every << "_n" << c.nonlinear_iterations;
  if (c.model == vdm::ModelKind::vdm && c.capsule != vdm::CapsuleForm::membrane) s << "_" << vdm::to_string(c.capsule);
  return s.str();
}

// The scene of a configuration, as a file a user can run again (`vdmsim run`).
std::string scene_yaml(const AccuracyConfig& c, int frames) {
  std::ostringstream y;
  y << std::setprecision(12);
  y << "# Written by `vdmsim accuracy` (" << c.varied << " row): run it with `vdmsim run`.\n"
    << "name: " << config_name(c) << "\n"
    << "organ:\n"
    << "  mesh: ../meshes/" << level_mesh(c.level) << "\n"
    << "  model: " << vdm::to_string(c.model) << "\n";
  if (c.model == vdm::ModelKind::vdm)
    y << "  material: {bulk_modulus: 20000, connectivity_modulus: 2000, density: 1060, capsule: "
      << vdm::to_string(c.capsule) << "}\n";
  else if (c.model == vdm::ModelKind::fem)
    y << "  material: {young_modulus: " << kRefYoung << ", poisson_ratio: " << kPoisson << ", density: 1060}\n";
  else
    y << "  material: {young_modulus: " << kRefYoung << ", volume_modulus: " << kVolumeToYoung * kRefYoung
      << ", density: 1060}\n";
  y << "  fixed:\n"
    << "    - {box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}    # the underside rests on the table\n"
    << "simulation:\n"
    << "  frames: " << frames << "\n"
    << "  dt: 0.0333333\n";
  if (c.scenario == "probe_poke") {
    y << "  effects: [contact]\n";
  } else {
    y << "  effects: [grasp]\n";
  }
  y << "  solver: {method: " << vdm::to_string(c.method) << ", tolerance: " << c.tolerance
    << ", refresh_every: " << c.refresh_every << ", nonlinear_iterations: " << c.nonlinear_iterations << "}\n"
    << "instruments:\n";
  if (c.scenario == "probe_poke") {
    y << "  - type: probe\n"
      << "    radius: 0.004\n"
      << "    length: 0.25\n"
      << "    script:\n"
      << "      - {t: 0.0, tip: [0.035, 0.0, 0.075], axis: [0, 0, -1]}\n"
      << "      - {t: 0.5, tip: [0.035, 0.0, 0.0603]}\n"
      << "      - {t: 1.5, tip: [0.035, 0.0, 0.0453]}\n"
      << "      - {t: 2.0, tip: [0.035, 0.0, 0.0453]}\n"
      << "      - {t: 3.0, tip: [0.035, 0.0, 0.075]}\n";
  } else {
    y << "  - type: grasper\n"
      << "    radius: 0.005\n"
      << "    jaw_length: 0.015\n"
      << "    grasp_width: 0.006\n"
      << "    script:\n"
      << "      - {t: 0.0, tip: [0.035, 0.0, 0.075], axis: [0, 0, -1], jaw: open}\n"
      << "      - {t: 0.5, tip: [0.035, 0.0, 0.0603]}\n"
      << "      - {t: 0.6, jaw: closed}\n"
      << "      - {t: 1.6, tip: [0.035, 0.0, 0.0803]}\n"
      << "      - {t: 2.2, jaw: open}\n"
      << "      - {t: 3.0, tip: [0.035, 0.0, 0.1]}\n";
  }
  return y.str();
}

bool write_text(const fs::path& path, const std::string& text, std::string& error) {
  std::ofstream f(path);
  f << text;
  f.close();
  if (!f) {
    error = path.string() + ": write failed";
    return false;
  }
  return true;
}

// Simulates the scene at `path`; samples the surface displacement at `points` every frame.
Trajectory simulate(const std::string& path, const vdm::NodeMat& points) {
  Trajectory tr;
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  if (!prepare_scene(path, ps, problems)) {
    tr.failed = true;
    tr.failure = problems.empty() ? "the scene did not load" : problems.front().where + ": " + problems.front().message;
    return tr;
  }
  tr.nodes = ps.model.n;
  const SurfaceSamples samples(ps.model.rest, points);
  SceneSimulation sim(ps);
  const vdm::FlagMat& fixed = ps.model.held;  // fixed (or infinitely stiff): not the instruments' doing
  vdm::NodeMat at;
  for (int f = 0; f < ps.scene.frames; ++f) {
    sim.advance(f);
    const vdm::SimState& s = sim.state();
    if (s.failed || !s.u.allFinite()) {
      tr.failed = true;
      tr.failure = s.failed ? s.failure : "non-finite displacement";
      return tr;
    }
    samples.interpolate(s.u, at);
    tr.u.push_back(at);
    // The instruments' force: the constraint reactions on every node the scene does not fix.
    vdm::Vec3 force = vdm::Vec3::Zero();
    for (int i = 0; i < ps.model.n; ++i) {
      const bool held = fixed.rows() == ps.model.n && fixed.row(i).any();
      if (!held && s.reaction.rows() == ps.model.n) force -= s.reaction.row(i).transpose();
    }
    tr.force.push_back(force);
    tr.step_ms.push_back(sim.frame_step_ms());
    if (!s.stats.converged || (sim.contact_simulated() && !sim.contact_report().converged)) ++tr.unconverged;
    tr.volume_rel.push_back(s.volume_rel_error);
  }
  return tr;
}

// Compares a trajectory with the reference over the loaded frames.
void compare(const Trajectory& ref, const std::vector<int>& loaded, const Trajectory& tr, double force_scale,
             AccuracyRow& row) {
  double sum2 = 0, max = 0, f2 = 0, fpeak = 0, vmax = 0;
  long count = 0;
  std::vector<double> ms;
  for (int f : loaded) {
    const auto k = static_cast<size_t>(f);
    const vdm::NodeMat d = tr.u[k] - ref.u[k];
    for (int s = 0; s < d.rows(); ++s) {
      const double e2 = d.row(s).squaredNorm();
      sum2 += e2;
      max = std::max(max, std::sqrt(e2));
      ++count;
    }
    f2 += (force_scale * tr.force[k] - ref.force[k]).squaredNorm();
    fpeak = std::max(fpeak, ref.force[k].norm());
    ms.push_back(tr.step_ms[k]);
  }
  for (double v : tr.volume_rel) vmax = std::max(vmax, std::abs(v));
  row.rms_mm = count > 0 ? 1e3 * std::sqrt(sum2 / static_cast<double>(count)) : 0;
  row.max_mm = 1e3 * max;
  row.force_rms_n = loaded.empty() ? 0 : std::sqrt(f2 / static_cast<double>(loaded.size()));
  row.force_rel = fpeak > 0 ? row.force_rms_n / fpeak : 0;
  row.volume_rel_error = vmax;
  row.median_ms = quantile(ms, 0.5);
  row.p95_ms = quantile(ms, 0.95);
  row.nodes = tr.nodes;
}

// RMS difference (mm) of two trajectories' surface displacements over the loaded frames.
double rms_difference_mm(const Trajectory& a, const Trajectory& b, const std::vector<int>& loaded) {
  double sum2 = 0;
  long count = 0;
  for (int f : loaded) {
    const auto k = static_cast<size_t>(f);
    sum2 += (a.u[k] - b.u[k]).rowwise().squaredNorm().sum();
    count += a.u[k].rows();
  }
  return count > 0 ? 1e3 * std::sqrt(sum2 / static_cast<double>(count)) : 0;
}

// Least-squares factor s with s F ~ F_ref over the loaded frames. For fem and mass_spring
// with prescribed motions (kinematic contact, grasping) every force scales with E while the
// displacements do not depend on it, so the run at kRefYoung gives the run at s kRefYoung.
double matching_scale(const Trajectory& ref, const std::vector<int>& loaded, const Trajectory& tr) {
  double num = 0, den = 0;
  for (int f : loaded) {
    const auto k = static_cast<size_t>(f);
    num += tr.force[k].dot(ref.force[k]);
    den += tr.force[k].squaredNorm();
  }
  return den > 0 ? num / den : 1.0;
}

}  // namespace

std::vector<AccuracyConfig> accuracy_configs(bool quick) {
  std::vector<AccuracyConfig> out;
  for (const char* scenario : {"probe_poke", "grasp_lift"}) {
    AccuracyConfig ref;
    ref.scenario = scenario;
    ref.varied = "reference";
    ref.level = quick ? 5 : 6;
    ref.tolerance = 1e-10;
    ref.nonlinear_iterations = 3;
    out.push_back(ref);
    AccuracyConfig base;
    base.scenario = scenario;
    base.varied = "baseline";
    base.level = quick ? 4 : 5;
    out.push_back(base);
    auto vary = [&](const char* what, auto&& edit) {
      AccuracyConfig c = base;
      c.varied = what;
      edit(c);
      out.push_back(c);
    };
    for (vdm::SolverMethod m : {vdm::SolverMethod::reference, vdm::SolverMethod::direct})
      vary("solver", [&](AccuracyConfig& c) { c.method = m; });
    const std::vector<double> tols = quick ? std::vector<double>{1e-3, 1e-5} : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-6, 1e-10};
    for (double t : tols) vary("tolerance", [&](AccuracyConfig& c) { c.tolerance = t; });
    const std::vector<int> refresh = quick ? std::vector<int>{5} : std::vector<int>{2, 5, 10};
    for (int r : refresh) vary("refresh", [&](AccuracyConfig& c) { c.refresh_every = r; });
    const std::vector<int> nonlinear = quick ? std::vector<int>{3} : std::vector<int>{2, 4};
    for (int k : nonlinear) vary("nonlinear", [&](AccuracyConfig& c) { c.nonlinear_iterations = k; });
    const std::vector<int> levels = quick ? std::vector<int>{3} : std::vector<int>{3, 4, 6};
    for (int l : levels) vary("mesh", [&](AccuracyConfig& c) { c.level = l; });
    // The capsule's other forms on the baseline's mesh: what the membrane's consistency costs
    // and what the paper's form gives up.
    for (vdm::CapsuleForm f : {vdm::CapsuleForm::paper, vdm::CapsuleForm::corotational})
      vary("capsule", [&](AccuracyConfig& c) { c.capsule = f; });
    // The reference models on the coarse liver: their Newton solves cost seconds per step on
    // finer ones (mass_spring converges slowly where its membrane is pushed along its normal).
    vary("model", [&](AccuracyConfig& c) {
      c.model = vdm::ModelKind::mass_spring;
      c.level = 3;
    });
    vary("model", [&](AccuracyConfig& c) {
      c.model = vdm::ModelKind::fem;
      c.level = 3;
    });
  }
  return out;
}

void mark_pareto(std::vector<AccuracyRow>& rows) {
  for (AccuracyRow& a : rows) {
    a.pareto = false;
    if (a.failed || a.config.varied == "reference") continue;
    bool dominated = false;
    for (const AccuracyRow& b : rows) {
      if (&a == &b || b.failed || b.config.varied == "reference" || b.config.scenario != a.config.scenario) continue;
      if (b.median_ms <= a.median_ms && b.rms_mm <= a.rms_mm && (b.median_ms < a.median_ms || b.rms_mm < a.rms_mm))
        dominated = true;
    }
    a.pareto = !dominated;
  }
}

int run_accuracy(const AccuracyOptions& options, std::ostream& out, std::ostream& err) {
  std::string error;
  if (!prepare_output_dir(options.out_dir, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  const fs::path dir(options.out_dir);
  std::error_code ec;
  fs::create_directories(dir / "meshes", ec);
  fs::create_directories(dir / "scenes", ec);
  if (ec) {
    err << "vdmsim: error: " << dir.string() << ": cannot create meshes/ and scenes/: " << ec.message() << "\n";
    return 2;
  }
  const std::vector<AccuracyConfig> configs = accuracy_configs(options.quick);
  const int frames = options.quick ? 48 : 90;  // quick: to the deepest press / the top of the lift

  // The project's own liver at every level the study uses, and the common surface points.
  std::vector<int> levels{kSampleLevel};
  for (const AccuracyConfig& c : configs) levels.push_back(c.level);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  vdm::NodeMat points;
  for (int level : levels) {
    const vdm::SurfaceMesh mesh = make_liver_mesh(level);
    if (level == kSampleLevel) points = mesh.positions;
    if (!save_obj(mesh, (dir / "meshes" / level_mesh(level)).string(),
                  "vdmsim liver level " + std::to_string(level) + " (app/organ_generator.cpp), for `vdmsim accuracy`",
                  error)) {
      err << "vdmsim: error: " << error << "\n";
      return 2;
    }
  }
  out << "accuracy: " << configs.size() << " configurations, " << frames << " frames each, errors on "
      << points.rows() << " surface points" << (options.quick ? " (quick)" : "") << "\n";

  std::vector<AccuracyRow> rows;
  Trajectory ref, base;  // this scenario's reference and baseline
  int base_level = 0;
  std::vector<int> loaded;
  for (size_t k = 0; k < configs.size(); ++k) {
    const AccuracyConfig& c = configs[k];
    AccuracyRow row;
    row.config = c;
    const fs::path scene = dir / "scenes" / (config_name(c) + ".yaml");
    row.scene_file = fs::relative(scene, dir).string();
    if (!write_text(scene, scene_yaml(c, frames), error)) {
      err << "vdmsim: error: " << error << "\n";
      return 2;
    }
    Trajectory tr;
    try {
      tr = simulate(scene.string(), points);
    } catch (const std::exception& e) {  // e.g. a reference model that cannot be built: this row fails
      tr.failed = true;
      tr.failure = e.what();
    }
    if (c.varied == "reference") {
      base = Trajectory{};  // a new scenario: the previous one's baseline does not apply
      if (tr.failed) {
        err << "vdmsim: error: the reference of " << c.scenario << " failed: " << tr.failure << "\n";
        return 1;
      }
      ref = tr;
      // Loaded frames: the instrument pushes or pulls with at least 1 % of its peak force.
      double peak = 0;
      for (const vdm::Vec3& f : ref.force) peak = std::max(peak, f.norm());
      loaded.clear();
      for (size_t f = 0; f < ref.force.size(); ++f)
        if (ref.force[f].norm() >= 0.01 * peak) loaded.push_back(static_cast<int>(f));
    }
    if (tr.failed) {
      row.failed = true;
      row.note = tr.failure;
    } else {
      double scale = 1;
      if (c.model != vdm::ModelKind::vdm) {
        scale = matching_scale(ref, loaded, tr);
        row.young_modulus = scale * kRefYoung;
      }
      compare(ref, loaded, tr, scale, row);
      if (c.varied == "baseline") {
        base = tr;
        base_level = c.level;
      }
      // The solver's own error: against the baseline on the same mesh (mesh error left out).
      if (c.model == vdm::ModelKind::vdm && !base.u.empty() && c.level == base_level)
        row.rms_vs_baseline_mm = rms_difference_mm(tr, base, loaded);
      if (tr.unconverged > 0) row.note = std::to_string(tr.unconverged) + " steps did not converge";
    }
    out << "[" << (k + 1) << "/" << configs.size() << "] " << config_name(c) << ": ";
    if (row.failed)
      out << "failed (" << row.note << ")\n";
    else
      out << std::setprecision(3) << row.median_ms << " ms/step, displacement error RMS " << row.rms_mm << " mm, max "
          << row.max_mm << " mm, force " << 100 * row.force_rel << " %\n";
    out.flush();
    rows.push_back(row);
  }
  mark_pareto(rows);
  if (!write_accuracy_csv((dir / "accuracy.csv").string(), rows, error) ||
      !write_accuracy_plot((dir / "accuracy.png").string(), rows, error) ||
      !write_recommendations((dir / "recommendations.md").string(), rows, options.quick, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  out << "accuracy: wrote " << (dir / "accuracy.csv").string() << ", accuracy.png, recommendations.md\n";
  return 0;
}

}  // namespace vdmsim
