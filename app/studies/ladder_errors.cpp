#include "app/studies/ladder_errors.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

#include "app/studies/accuracy_errors.hpp"
#include "app/studies/ladder_cases.hpp"
#include "app/studies/quantile.hpp"

namespace vdmsim {
namespace {

std::string signed_percent(const std::vector<double>& values) {
  std::ostringstream s;
  s << std::showpos << std::fixed << std::setprecision(1);
  for (size_t k = 0; k < values.size(); ++k) s << (k ? "/" : "") << 100 * values[k];
  s << " %";
  return s.str();
}

// The top's mean u_z at each distance from the punch's centre, at the final frame.
std::vector<double> punch_dents(const Trajectory& tr) {
  std::vector<double> dents;
  for (int r = 0; r < kLadderPunchRadii; ++r) {
    double sum = 0;
    for (int a = 0; a < kLadderPunchAzimuths; ++a) sum += tr.u.back()(r * kLadderPunchAzimuths + a, 2);
    dents.push_back(sum / kLadderPunchAzimuths);
  }
  return dents;
}

void measure_punch(const Trajectory& ref, const Trajectory& tr, LadderRow& row) {
  const std::vector<double> d = punch_dents(tr), d_ref = punch_dents(ref);
  std::vector<double> each;
  row.error = 0;
  for (size_t k = 0; k < d.size(); ++k) {
    each.push_back(d[k] / d_ref[k] - 1);
    row.error = std::max(row.error, std::abs(each.back()));
  }
  const double f = tr.force.back().z(), f_ref = ref.force.back().z();
  row.force_error = std::abs(f - f_ref) / std::abs(f_ref);
  std::ostringstream s;
  s << "force " << signed_percent({f / f_ref - 1}) << "; dent at 1.5/2/3/4 a " << signed_percent(each);
  row.detail = s.str();
}

void measure_beam(const Trajectory& ref, const Trajectory& tr, LadderRow& row) {
  std::vector<double> each;
  row.error = 0;
  for (int p = 0; p < ref.u.back().rows(); ++p) {
    const double u = tr.u.back().row(p).norm(), u_ref = ref.u.back().row(p).norm();
    each.push_back(u / u_ref - 1);
    row.error = std::max(row.error, std::abs(each.back()));
  }
  row.detail = "|u| at A/B/C " + signed_percent(each);
}

void measure_liver(const Trajectory& ref, const Trajectory& tr, LadderRow& row) {
  const std::vector<int> loaded = loaded_frames(ref);
  AccuracyRow a;
  compare_with_reference(ref, loaded, tr, 1.0, a);
  double diff2 = 0, ref2 = 0;
  for (int f : loaded) {
    diff2 += (tr.u[size_t(f)] - ref.u[size_t(f)]).squaredNorm();
    ref2 += ref.u[size_t(f)].squaredNorm();
  }
  row.error = ref2 > 0 ? std::sqrt(diff2 / ref2) : 0;
  row.force_error = a.force_rel;
  row.measured_median_ms = a.measured_median_ms;
  std::ostringstream s;
  s << std::setprecision(3) << "displacement RMS " << a.rms_mm << " mm, max " << a.max_mm << " mm; force RMS "
    << 100 * a.force_rel << " % of its peak";
  row.detail = s.str();
}

}  // namespace

void measure_ladder_row(const Trajectory& ref, const Trajectory& tr, LadderRow& row) {
  row.nodes = tr.nodes;
  row.measured_median_ms = quantile(tr.step_ms, 0.5);
  row.volume_rel_error = 0;
  for (double v : tr.volume_rel) row.volume_rel_error = std::max(row.volume_rel_error, std::abs(v));
  if (row.config.scenario == "punch")
    measure_punch(ref, tr, row);
  else if (row.config.scenario == "beams")
    measure_beam(ref, tr, row);
  else
    measure_liver(ref, tr, row);
  row.median_ms = row.measured_median_ms;
}

}  // namespace vdmsim
