#include "app/studies/accuracy_report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "render/plot.hpp"

namespace vdmsim {

namespace {

std::string knobs(const AccuracyConfig& c) {
  std::ostringstream s;
  s << vdm::to_string(c.model) << ", liver L" << c.level;
  if (c.model == vdm::ModelKind::vdm)
    s << ", " << vdm::to_string(c.method) << ", tolerance " << c.tolerance << ", refresh every " << c.refresh_every
      << ", " << c.nonlinear_iterations << " nonlinear iteration" << (c.nonlinear_iterations > 1 ? "s" : "")
      << ", " << capsule_label(c) << " capsule";
  return s.str();
}

}  // namespace

bool write_accuracy_csv(const std::string& path, const std::vector<AccuracyRow>& rows, std::string& error) {
  std::ofstream f(path);
  f << "scenario,varied,model,nodes,solver,tolerance,refresh_every,nonlinear_iterations,capsule,median_ms,p95_ms,"
       "measured_median_ms,yardstick_ms,rms_error_mm,max_error_mm,rms_vs_baseline_mm,force_rms_error_n,force_rel_error,volume_rel_error,young_modulus_pa,pareto,"
       "scene,note\n";
  f << std::setprecision(6);
  for (const AccuracyRow& r : rows) {
    const AccuracyConfig& c = r.config;
    f << c.scenario << ',' << c.varied << ',' << vdm::to_string(c.model) << ',' << r.nodes << ',';
    if (c.model == vdm::ModelKind::vdm)
      f << vdm::to_string(c.method) << ',' << c.tolerance << ',' << c.refresh_every << ',' << c.nonlinear_iterations << ','
        << capsule_label(c);
    else
      f << ",,,,";
    // The measured columns, empty when the row failed (or, for rms_vs_baseline_mm and
    // young_modulus_pa, when they do not apply).
    if (r.failed) {
      f << std::string(12, ',');
    } else {
      f << ',' << r.median_ms << ',' << r.p95_ms << ',' << r.measured_median_ms << ',' << r.yardstick_ms << ','
        << r.rms_mm << ',' << r.max_mm << ',';
      if (r.rms_vs_baseline_mm >= 0) f << r.rms_vs_baseline_mm;
      f << ',' << r.force_rms_n << ',' << r.force_rel << ',' << r.volume_rel_error << ',';
      if (r.young_modulus > 0) f << r.young_modulus;
      f << ',' << (r.pareto ? 1 : 0);
    }
    std::string note = r.note;
    std::replace(note.begin(), note.end(), ',', ';');
    std::replace(note.begin(), note.end(), '\n', ' ');
    f << ',' << r.scene_file << ',' << note << '\n';
  }
  f.close();
  if (!f) {
    error = path + ": write failed";
    return false;
  }
  return true;
}

bool write_accuracy_plot(const std::string& path, const std::vector<AccuracyRow>& rows, std::string& error) {
  render::Figure fig;
  fig.title = "Accuracy against time per step (one knob changed from the baseline at a time)";
  fig.columns = 2;
  fig.panel_width = 640;
  fig.panel_height = 460;
  // Errors at round-off (a row identical to the reference) still show on the log axis.
  constexpr double kFloor = 1e-6;
  struct Family {
    const char* varied;
    std::optional<vdm::ModelKind> model;  // empty: any
    const char* label;
    int colour;
  };
  const std::vector<Family> families = {
      {"baseline", {}, "baseline", 0},      {"solver", {}, "solver", 1},        {"tolerance", {}, "tolerance", 2},
      {"refresh", {}, "refresh period", 3}, {"nonlinear", {}, "nonlinear iterations", 4},
      {"mesh", {}, "mesh", 5},
      {"capsule", {}, "capsule form", 9},
      {"model", vdm::ModelKind::fem, "model fem", 6},
      {"model", vdm::ModelKind::mass_spring, "model mass_spring", 7},
  };
  for (const char* scenario : {"probe_poke", "grasp_lift"}) {
    render::Panel p;
    p.title = scenario;
    p.x_label = "median time per step (ms, on the study's typical node)";
    p.y_label = "RMS surface displacement error (mm)";
    p.log_x = p.log_y = true;
    std::vector<std::pair<double, double>> front;
    for (const Family& fam : families) {
      render::Series s;
      s.label = fam.label;
      s.line = false;
      s.markers = true;
      s.color = fam.colour;
      for (const AccuracyRow& r : rows) {
        if (r.failed || r.config.scenario != scenario || r.config.varied != fam.varied) continue;
        if (fam.model && r.config.model != *fam.model) continue;
        s.x.push_back(r.median_ms);
        s.y.push_back(std::max(r.rms_mm, kFloor));
        if (r.pareto) front.emplace_back(r.median_ms, std::max(r.rms_mm, kFloor));
      }
      if (!s.x.empty()) p.series.push_back(std::move(s));
    }
    std::sort(front.begin(), front.end());
    render::Series f;
    f.label = "Pareto front";
    f.color = 8;  // grey
    for (const auto& [x, y] : front) {
      f.x.push_back(x);
      f.y.push_back(y);
    }
    if (!f.x.empty()) p.series.push_back(std::move(f));
    fig.panels.push_back(std::move(p));
  }
  return render::write_figure_png(fig, path, error);
}

const std::vector<UseBudget>& use_budgets() {
  static const std::vector<UseBudget> budgets = {
      {"haptic rate (1 kHz)", 1.0, "a force every millisecond, 95 % of steps; judged by the force error",
       AccuracyMetric::force, true},
      {"video rate (30 fps)", 1000.0 / 30,
       "one frame, 95 % of steps (drawing and encoding run on their own threads); judged by the displacement error",
       AccuracyMetric::displacement, true},
      {"offline accuracy", std::numeric_limits<double>::infinity(), "no time limit; judged by the displacement error",
       AccuracyMetric::displacement, false},
  };
  return budgets;
}

const AccuracyRow* best_within(const std::vector<AccuracyRow>& rows, const std::string& scenario, double budget_ms,
                               AccuracyMetric metric, bool worst_case) {
  auto error = [metric](const AccuracyRow& r) { return metric == AccuracyMetric::force ? r.force_rel : r.rms_mm; };
  auto fits = [&](const AccuracyRow& r) {
    return !r.failed && r.config.scenario == scenario && r.config.varied != "reference" &&
           (worst_case ? r.p95_ms : r.median_ms) <= budget_ms;
  };
  double least = std::numeric_limits<double>::infinity();
  for (const AccuracyRow& r : rows)
    if (fits(r)) least = std::min(least, error(r));
  const AccuracyRow* best = nullptr;
  for (const AccuracyRow& r : rows)
    if (fits(r) && error(r) <= 1.05 * least && (!best || r.median_ms < best->median_ms)) best = &r;
  return best;
}

namespace {
constexpr double kPoorForce = 0.25;  // relative force error above which a haptic pick is flagged
}  // namespace

bool write_recommendations(const std::string& path, const std::vector<AccuracyRow>& rows, bool quick,
                           std::string& error) {
  std::ofstream f(path);
  f << "# Recommended settings (from `vdmsim accuracy" << (quick ? " --quick" : "") << "`)\n\n"
    << "For each use, among the configurations whose time per step fits the budget (the 95th percentile for\n"
    << "real-time uses), the fastest of those within 5 % of the smallest error (the converged reference itself\n"
    << "excluded). Errors are against the reference: RMS / max surface\n"
    << "displacement error and the instrument force's RMS error relative to its peak. Times are per step on\n"
    << "the study's typical node: each configuration's ratio to the timing yardstick run in the same task,\n"
    << "times the yardstick's median over all tasks (docs/accuracy.md).\n\n";
  f << std::setprecision(3);
  for (const char* scenario : {"probe_poke", "grasp_lift"}) {
    f << "## " << scenario << "\n\n";
    for (const UseBudget& u : use_budgets()) {
      f << "- **" << u.name << "** (";
      if (std::isfinite(u.budget_ms))
        f << "<= " << u.budget_ms << " ms per step, " << u.why << "): ";
      else
        f << u.why << "): ";
      const AccuracyRow* r = best_within(rows, scenario, u.budget_ms, u.metric, u.worst_case);
      if (!r) {
        const AccuracyRow* fastest = nullptr;
        for (const AccuracyRow& x : rows)
          if (!x.failed && x.config.scenario == scenario && x.config.varied != "reference" &&
              (!fastest || x.median_ms < fastest->median_ms))
            fastest = &x;
        f << "no configuration fits";
        if (fastest)
          f << "; the fastest is " << knobs(fastest->config) << " at " << fastest->median_ms << " ms (p95 "
            << fastest->p95_ms << " ms), force " << 100 * fastest->force_rel << " % off";
        f << ".\n";
        continue;
      }
      f << knobs(r->config) << ": " << r->median_ms << " ms per step (p95 " << r->p95_ms << " ms), error RMS " << r->rms_mm << " mm, max "
        << r->max_mm << " mm, force " << 100 * r->force_rel << " %.";
      // The best that fits may still be poor: say so rather than recommend it silently.
      if (u.metric == AccuracyMetric::force && r->force_rel > kPoorForce)
        f << " **Its force is more than " << 100 * kPoorForce << " % off: nothing in this study gives a usable force"
          << " within this budget on this machine.**";
      f << "\n";
    }
    f << "\n";
  }
  f.close();
  if (!f) {
    error = path + ": write failed";
    return false;
  }
  return true;
}

}  // namespace vdmsim
