#include "app/studies/accuracy_errors.hpp"

#include <algorithm>
#include <cmath>

#include "app/studies/quantile.hpp"

namespace vdmsim {

std::vector<int> loaded_frames(const Trajectory& ref) {
  double peak = 0;
  for (const vdm::Vec3& f : ref.force) peak = std::max(peak, f.norm());
  std::vector<int> loaded;
  for (size_t f = 0; f < ref.force.size(); ++f)
    if (ref.force[f].norm() >= 0.01 * peak) loaded.push_back(static_cast<int>(f));
  return loaded;
}

void compare_with_reference(const Trajectory& ref, const std::vector<int>& loaded, const Trajectory& tr,
                            double force_scale, AccuracyRow& row) {
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
  row.measured_median_ms = quantile(ms, 0.5);
  row.median_ms = row.measured_median_ms;
  row.p95_ms = quantile(ms, 0.95);
  row.nodes = tr.nodes;
}

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

double matching_scale(const Trajectory& ref, const std::vector<int>& loaded, const Trajectory& tr) {
  double num = 0, den = 0;
  for (int f : loaded) {
    const auto k = static_cast<size_t>(f);
    num += tr.force[k].dot(ref.force[k]);
    den += tr.force[k].squaredNorm();
  }
  return den > 0 ? num / den : 1.0;
}

}  // namespace vdmsim
