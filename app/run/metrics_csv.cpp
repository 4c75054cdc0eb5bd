#include "app/run/metrics_csv.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>

namespace vdmsim {

namespace fs = std::filesystem;

int MetricsCsv::open(const fs::path& dir, int start, bool resume, bool stress, std::ostream& err,
                     const std::vector<std::string>& organs) {
  path_ = dir / "metrics.csv";
  stress_ = stress;
  organ_columns_ = organs.size() > 1 ? organs.size() : 0;
  std::vector<std::string> kept_rows;
  if (resume) {
    std::ifstream old(path_);
    std::string line;
    std::getline(old, line);  // header
    while (static_cast<int>(kept_rows.size()) < start && std::getline(old, line)) kept_rows.push_back(line);
    if (static_cast<int>(kept_rows.size()) < start) {
      err << "vdmsim: error: " << path_.string() << ": has fewer rows than the checkpoint's " << start
          << " frames: cannot resume\n";
      return 2;
    }
  }
  file_.open(path_);
  if (!file_) {
    err << "vdmsim: error: " << path_.string() << ": cannot open for writing\n";
    return 1;
  }
  file_ << "frame,time_s,step_ms,iterations,residual,volume,volume_rel_error,pressure_pa,contact_nodes,"
           "contact_force_n,contact_force_x,contact_force_y,contact_force_z,max_penetration_m,max_displacement_m,max_stress_pa,"
           "fallbacks";
  for (size_t i = 0; i < organ_columns_; ++i) {
    const std::string& n = organs[i];
    file_ << ',' << n << "_volume," << n << "_volume_rel_error," << n << "_pressure_pa," << n << "_contact_nodes," << n
          << "_contact_force_n," << n << "_max_displacement_m," << n << "_organ_force_n";
  }
  if (organ_columns_ > 0) file_ << ",ties_torn";
  file_ << '\n';
  for (const std::string& row : kept_rows) file_ << row << '\n';
  file_ << std::setprecision(9);
  file_.flush();
  if (!file_) {
    err << "vdmsim: error: " << path_.string() << ": write failed (disk full?)\n";
    return 1;
  }
  good_size_ = rows_base_ = static_cast<std::uintmax_t>(file_.tellp());
  return -1;
}

bool MetricsCsv::write(int f, const SceneSimulation& sim, std::string& reason) {
  // With several organs the scene's columns are over all of them: the volumes summed, the
  // largest residual, volume error (signed), pressure, displacement and stress; each organ's
  // own follow.
  const vdm::SimState& first = sim.state();
  double residual = first.stats.residual, volume = first.volume, volume_error = first.volume_rel_error;
  double pressure = first.pressure, moved = first.u.rowwise().norm().maxCoeff();
  double stress = stress_ ? first.stress.rowwise().norm().maxCoeff() : 0.0;
  for (size_t i = 1; i < sim.organ_count(); ++i) {
    const vdm::SimState& st = sim.state(i);
    residual = std::max(residual, st.stats.residual);
    volume += st.volume;
    if (std::abs(st.volume_rel_error) > std::abs(volume_error)) volume_error = st.volume_rel_error;
    pressure = std::max(pressure, st.pressure);
    moved = std::max(moved, st.u.rowwise().norm().maxCoeff());
    if (stress_ && st.stress.rows() > 0) stress = std::max(stress, st.stress.rowwise().norm().maxCoeff());
  }
  file_ << f << ',' << sim.time() << ',' << sim.frame_step_ms() << ',' << sim.frame_iterations() << ',' << residual
        << ',' << volume << ',' << volume_error << ',' << pressure << ',';
  // Columns of effects that are not simulated stay empty: the contact's nodes and penetration
  // without contact, the force without contact and grasp.
  if (sim.contact_simulated()) file_ << sim.contact_report().nodes;
  file_ << ',';
  if (sim.forces_simulated()) {
    const vdm::Vec3 force = sim.total_force();
    file_ << force.norm() << ',' << force.x() << ',' << force.y() << ',' << force.z() << ',';
  } else {
    file_ << ",,,,";
  }
  if (sim.contact_simulated()) file_ << sim.contact_report().max_penetration;
  file_ << ',';
  file_ << moved << ',';
  if (stress_) file_ << stress;
  file_ << ',' << sim.frame_fallbacks();
  for (size_t i = 0; i < organ_columns_; ++i) {
    const vdm::SimState& st = sim.state(i);
    file_ << ',' << st.volume << ',' << st.volume_rel_error << ',' << st.pressure << ',';
    if (sim.contact_simulated()) file_ << sim.contact_report(i).nodes;
    file_ << ',';
    if (sim.forces_simulated()) file_ << sim.total_force(i).norm();
    file_ << ',' << st.u.rowwise().norm().maxCoeff() << ',';
    if (sim.organ_contact_simulated()) file_ << sim.organ_contact_force(i).norm();
  }
  if (organ_columns_ > 0) {
    file_ << ',';
    if (sim.organ_contact_simulated()) file_ << sim.organ_ties_torn();
  }
  file_ << '\n';
  file_.flush();
  if (!file_) {
    reason = path_.string() + ": write failed at frame " + std::to_string(f) + " (disk full?)";
    file_.close();
    std::error_code ec;
    fs::resize_file(path_, good_size_, ec);
    return false;
  }
  good_size_ = static_cast<std::uintmax_t>(file_.tellp());
  row_end_.push_back(good_size_);
  return true;
}

void MetricsCsv::flush() {
  if (file_.is_open()) file_.flush();
}

void MetricsCsv::cut_back(int rows) {
  if (file_.is_open()) file_.close();
  std::error_code ec;
  fs::resize_file(path_, rows > 0 ? row_end_[static_cast<size_t>(rows - 1)] : rows_base_, ec);
}

}  // namespace vdmsim
