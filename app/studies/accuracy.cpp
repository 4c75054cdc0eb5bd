#include "app/studies/accuracy.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace vdmsim {

namespace {

constexpr double kPoisson = 0.45;
constexpr double kVolumeToYoung = 4;     // mass_spring: volume spring modulus / E
constexpr double kConnectivity = 2000;   // vdm: B_ij (Pa) of every configuration

// The bending variant's modulus (N m): a bending length sqrt(D / T) of 4.9 mm on the liver
// (T = B_ij V/A = 41.7 N/m), about the probe's radius. Its price grows steeply with D
// (docs/model.md, "Bending"): at sqrt(D / T) = V/A (21 mm) a step takes seconds.
constexpr double kBending = 0.001;

}  // namespace

std::string capsule_label(const AccuracyConfig& c) {
  return std::string(vdm::to_string(c.capsule)) + (c.bending > 0 ? "+bending" : "");
}

std::string level_mesh(int level) { return "liver_L" + std::to_string(level) + ".obj"; }

std::string config_name(const AccuracyConfig& c) {
  std::ostringstream s;
  s << c.scenario << "_" << c.varied << "_" << vdm::to_string(c.model) << "_L" << c.level;
  if (c.model == vdm::ModelKind::vdm)
    s << "_" << vdm::to_string(c.method) << "_tol" << std::setprecision(0) << std::scientific << c.tolerance << "_r"
      << c.refresh_every << "_n" << c.nonlinear_iterations;
  if (c.model == vdm::ModelKind::vdm && c.capsule != vdm::CapsuleForm::membrane) s << "_" << vdm::to_string(c.capsule);
  if (c.model == vdm::ModelKind::vdm && c.bending > 0) s << "_bending";
  return s.str();
}

std::string accuracy_scene_yaml(const AccuracyConfig& c, int frames, const std::string& mesh_dir) {
  std::ostringstream y;
  y << std::setprecision(12);
  if (c.model == vdm::ModelKind::vdm) {
    y << "  material: {bulk_modulus: 20000, connectivity_modulus: " << kConnectivity << ", density: 1060, capsule: "
      << vdm::to_string(c.capsule);
    if (c.bending > 0) y << ", bending_modulus: " << c.bending;
    y << "}\n";
  } else if (c.model == vdm::ModelKind::fem)
    y << "  material: {young_modulus: " << kAccuracyStartYoung << ", poisson_ratio: " << kPoisson << ", density: 1060}\n";
  else
    y << "  material: {young_modulus: " << kAccuracyStartYoung << ", volume_modulus: " << kVolumeToYoung * kAccuracyStartYoung
      << ", density: 1060}\n";
  std::ostringstream solver;
  solver << std::setprecision(12) << "{method: " << vdm::to_string(c.method) << ", tolerance: " << c.tolerance
         << ", refresh_every: " << c.refresh_every << ", nonlinear_iterations: " << c.nonlinear_iterations << "}";
  // simulation.solver sets the paper's model's steps only.
  return scenario_scene_yaml(config_name(c), std::string("`vdmsim accuracy` (") + c.varied + " row)", c.scenario,
                             mesh_dir + "/" + level_mesh(c.level), vdm::to_string(c.model), y.str(),
                             c.model == vdm::ModelKind::vdm ? solver.str() : "", frames);
}

std::string scenario_scene_yaml(const std::string& name, const std::string& writer, const std::string& scenario,
                                const std::string& mesh, const std::string& model, const std::string& organ_lines,
                                const std::string& solver, int frames) {
  std::ostringstream y;
  y << "# Written by " << writer << ": run it with `vdmsim run`.\n"
    << "name: " << name << "\n"
    << "organ:\n"
    << "  mesh: " << mesh << "\n"
    << "  model: " << model << "\n"
    << organ_lines;
  y << "  fixed:\n"
    << "    - {box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}    # the underside rests on the table\n"
    << "simulation:\n"
    << "  frames: " << frames << "\n"
    << "  dt: 0.0333333\n";
  if (scenario == "probe_poke") {
    // The probe holds the tissue (kinematic contact): every configuration's error is then its
    // model's and solver's, not a frictional contact's path (which loose solves change).
    y << "  effects: [contact]\n"
      << "  contact: {method: kinematic}\n";
  } else {
    y << "  effects: [grasp]\n";
  }
  if (!solver.empty()) y << "  solver: " << solver << "\n";
  y << "instruments:\n";
  if (scenario == "probe_poke") {
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
    // The membrane with the bending term (vdm-model.md 3b): what resisting bending costs.
    vary("capsule", [&](AccuracyConfig& c) { c.bending = kBending; });
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

bool select_accuracy_configs(const AccuracyOptions& o, std::vector<int>& indices, std::string& error) {
  const std::vector<AccuracyConfig> all = accuracy_configs(o.quick);
  std::vector<std::string> scenarios, knobs;
  for (const AccuracyConfig& c : all) {
    if (std::find(scenarios.begin(), scenarios.end(), c.scenario) == scenarios.end()) scenarios.push_back(c.scenario);
    if (c.varied != "reference" && c.varied != "baseline" && std::find(knobs.begin(), knobs.end(), c.varied) == knobs.end())
      knobs.push_back(c.varied);
  }
  auto list = [](const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
  };
  if (!o.scenario.empty() && std::find(scenarios.begin(), scenarios.end(), o.scenario) == scenarios.end()) {
    error = "--scenario: unknown scenario '" + o.scenario + "'; known scenarios: " + list(scenarios);
    return false;
  }
  std::vector<std::string> only;
  std::stringstream words(o.only);
  for (std::string w; std::getline(words, w, ',');) {
    if (w.empty()) continue;
    if (std::find(knobs.begin(), knobs.end(), w) == knobs.end()) {
      error = "--only: unknown knob '" + w + "'; known knobs: " + list(knobs);
      return false;
    }
    only.push_back(w);
  }
  indices.clear();
  for (size_t i = 0; i < all.size(); ++i) {
    const AccuracyConfig& c = all[i];
    if (!o.scenario.empty() && c.scenario != o.scenario) continue;
    const bool always = c.varied == "reference" || c.varied == "baseline";
    if (!only.empty() && !always && std::find(only.begin(), only.end(), c.varied) == only.end()) continue;
    indices.push_back(int(i));
  }
  return true;
}

AccuracyConfig yardstick_config(bool quick) {
  for (const AccuracyConfig& c : accuracy_configs(quick))
    if (c.scenario == "probe_poke" && c.varied == "baseline") return c;
  return AccuracyConfig{};
}

int accuracy_frames(bool quick) { return quick ? 48 : 90; }

}  // namespace vdmsim
