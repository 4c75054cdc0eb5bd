#include "app/studies/calibrate.hpp"

#include "engine/elastic_moduli.hpp"
#include "engine/stopwatch.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

namespace vdmsim {
namespace {

// Displacement residuals (each case relative to its largest FEM displacement, weighted alike).
double displacement_cost(const std::vector<CaseResult>& vdm, const std::vector<CaseResult>& fem, double& rms) {
  double cost = 0, sum = 0;
  long count = 0;
  for (size_t c = 0; c < fem.size(); ++c) {
    double umax = 1e-300;
    for (const auto& u : fem[c].u) umax = std::max(umax, u.cwiseAbs().maxCoeff());
    double case_sum = 0;
    long case_count = 0;
    for (size_t k = 1; k < fem[c].u.size(); ++k) {
      const double d = ((vdm[c].u[k] - fem[c].u[k]) / umax).squaredNorm();
      case_sum += d;
      case_count += fem[c].u[k].size();
    }
    cost += case_sum / std::max(1L, case_count);
    sum += case_sum;
    count += case_count;
  }
  rms = std::sqrt(sum / std::max(1L, count));
  return cost;
}

}  // namespace

CalibrationResult calibrate_vdm(const vdm::SurfaceMesh& surface, const std::vector<LoadCase>& cases,
                                const std::vector<CaseResult>& fem, const VdmParams& start,
                                const CalibrationProgress& progress) {
  // Under prescribed motion the VDM displacements depend only on the ratio rho = B_ij / B and
  // its constraint forces scale with the moduli. Stage 1 fits rho to the displacements (a
  // grid a decade apart, then golden section on log rho within a decade of its best point,
  // to 2 % in rho: the cost is flat there, and each evaluation runs every case); stage 2 the
  // scale to the work of the driven nodes, in closed form.
  CalibrationResult out;
  std::vector<CaseResult> runs;
  auto run = [&](double log_rho) {
    const auto t0 = vdm::Clock::now();
    VdmParams q = start;
    q.connectivity = q.bulk * std::exp(log_rho);
    runs.clear();
    for (const LoadCase& c : cases) runs.push_back(run_vdm_case(surface, q, c));
    ++out.evaluations;
    double rms = 0;
    const double cost = displacement_cost(runs, fem, rms);
    if (progress) {
      char line[160];
      std::snprintf(line, sizeof line, "calibrate: VDM run %d: B_ij / B = %.4g, RMS displacement difference %.2f %% (%.1f s)",
                    out.evaluations, std::exp(log_rho), 100 * rms, vdm::ms_since(t0) / 1000);
      progress(line);
    }
    return cost;
  };
  const double lo = std::log(1e-4), hi = std::log(1e4);
  const int grid = 9;
  double best = lo, best_cost = std::numeric_limits<double>::infinity();
  for (int i = 0; i < grid; ++i) {
    const double x = lo + (hi - lo) * i / (grid - 1);
    const double cst = run(x);
    if (cst < best_cost) best_cost = cst, best = x;
  }
  const double h = (hi - lo) / (grid - 1), g = (std::sqrt(5.0) - 1) / 2;
  double a = best - h, b = best + h;
  double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = run(x1), f2 = run(x2);
  while (b - a > 0.02) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = run(x1);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = run(x2);
    }
  }
  const double log_rho = f1 < f2 ? x1 : x2;
  run(log_rho);
  // Stage 2: scale s minimising sum (s W_vdm - W_fem)^2 over cases and steps (each case
  // relative to its largest FEM work).
  double num = 0, den = 0;
  for (size_t c = 0; c < fem.size(); ++c) {
    double wmax = 1e-300;
    for (double w : fem[c].work) wmax = std::max(wmax, std::abs(w));
    for (size_t k = 1; k < fem[c].work.size(); ++k) {
      num += runs[c].work[k] * fem[c].work[k] / (wmax * wmax);
      den += runs[c].work[k] * runs[c].work[k] / (wmax * wmax);
    }
  }
  const double scale = den > 0 ? num / den : 1.0;
  VdmParams fitted = start;
  fitted.bulk = start.bulk * scale;
  fitted.connectivity = start.bulk * std::exp(log_rho) * scale;
  const int searched = out.evaluations;
  out = evaluate_vdm(surface, cases, fem, fitted);
  out.evaluations += searched;
  return out;
}

CalibrationResult evaluate_vdm(const vdm::SurfaceMesh& surface, const std::vector<LoadCase>& cases,
                               const std::vector<CaseResult>& fem, const VdmParams& params) {
  CalibrationResult out;
  out.params = params;
  std::vector<CaseResult> runs;
  for (const LoadCase& c : cases) runs.push_back(run_vdm_case(surface, params, c));
  out.evaluations = 1;
  out.cost = displacement_cost(runs, fem, out.rms_displacement);
  double sw = 0;
  long nw = 0;
  for (size_t c = 0; c < fem.size(); ++c) {
    double wmax = 1e-300;
    for (double w : fem[c].work) wmax = std::max(wmax, std::abs(w));
    for (size_t k = 1; k < fem[c].work.size(); ++k, ++nw) sw += std::pow((runs[c].work[k] - fem[c].work[k]) / wmax, 2);
    out.mean_relative_difference.push_back(mean_relative_difference(runs[c], fem[c]));
  }
  out.rms_work = std::sqrt(sw / std::max(1L, nw));
  return out;
}

bool calibrate_organ(const vdm::SurfaceMesh& surface, const vdm::fem::TetMesh& tets, double young, double poisson,
                     int steps, OrganCalibration& out, const CalibrationProgress& progress) {
  const std::vector<LoadCase> cases = organ_load_cases(surface, steps);
  if (cases.empty() || cases[0].moved.empty()) return false;
  std::vector<CaseResult> fem;
  for (const LoadCase& c : cases) {
    const auto t0 = vdm::Clock::now();
    fem.push_back(run_fem_case(tets, young, poisson, c));
    if (progress) {
      char line[160];
      std::snprintf(line, sizeof line, "calibrate: FEM case %d of %d (%s) done (%.1f s)", int(fem.size()),
                    int(cases.size()), c.name.c_str(), vdm::ms_since(t0) / 1000);
      progress(line);
    }
  }
  VdmParams start;
  start.solver.method = vdm::SolverMethod::direct;
  start.bulk = young;
  start.connectivity = young / 10;
  out.fit = calibrate_vdm(surface, cases, fem, start, progress);
  VdmParams rule = start;
  const vdm::VdmModuli moduli = vdm::vdm_moduli_from_elastic(young, poisson);
  rule.bulk = moduli.bulk;
  rule.connectivity = moduli.connectivity;
  out.rule = evaluate_vdm(surface, cases, fem, rule);
  return true;
}

std::vector<LoadCase> organ_load_cases(const vdm::SurfaceMesh& s, int steps, double depth, double base, double patch) {
  const vdm::NodeMat& X = s.positions;
  const vdm::Vec3 lo = X.colwise().minCoeff(), hi = X.colwise().maxCoeff();
  const double height = hi.z() - lo.z(), size = (hi - lo).norm();
  const int n = s.node_count();
  // The top's centre: the highest node; the patch around it.
  int top = 0;
  for (int i = 0; i < n; ++i)
    if (X(i, 2) > X(top, 2)) top = i;
  vdm::FlagMat fixed = vdm::FlagMat::Zero(n, 3);
  std::vector<int> moved, all;
  for (int i = 0; i < n; ++i) {
    all.push_back(i);
    if (X(i, 2) < lo.z() + base * height) fixed.row(i).setOnes();
    else if (X(i, 2) > hi.z() - patch * height && (X.row(i) - X.row(top)).norm() < patch * size) moved.push_back(i);
  }
  std::vector<LoadCase> cases;
  const vdm::Vec3 dirs[2] = {vdm::Vec3(0, 0, -1), vdm::Vec3(1, 0, 0)};
  const char* names[2] = {"press", "pull"};
  for (int c = 0; c < 2; ++c) {
    LoadCase lc;
    lc.name = names[c];
    lc.fixed = fixed;
    lc.moved = moved;
    lc.tracked = all;
    for (int k = 1; k <= steps; ++k) {
      vdm::NodeMat t(moved.size(), 3);
      for (Eigen::Index j = 0; j < t.rows(); ++j) t.row(j) = (depth * height * k / steps) * dirs[c].transpose();
      lc.targets.push_back(t);
    }
    cases.push_back(lc);
  }
  return cases;
}

bool write_calibration_yaml(const std::string& path, const CalibrationResult& r, double young, double poisson,
                            const std::string& source, std::string& error) {
  std::ofstream f(path);
  if (!f) return error = path + ": cannot open for writing", false;
  f.precision(6);
  f << "# VDM moduli fitted to a corotational FEM reference (E = " << young << " Pa, nu = " << poisson
    << ") by `vdmsim calibrate`\n# on " << source << "; RMS displacement difference " << r.rms_displacement
    << " of the largest, RMS work difference " << r.rms_work << "\n";
  f << "material: {bulk_modulus: " << r.params.bulk << ", connectivity_modulus: " << r.params.connectivity << "}\n";
  f << "fit:\n  rms_displacement: " << r.rms_displacement << "\n  rms_work: " << r.rms_work << "\n  evaluations: "
    << r.evaluations << "\n  mean_relative_difference: [";
  for (size_t c = 0; c < r.mean_relative_difference.size(); ++c) f << (c ? ", " : "") << r.mean_relative_difference[c];
  f << "]\n";
  f.flush();
  if (!f) return error = path + ": write failed", false;
  return true;
}

}  // namespace vdmsim
