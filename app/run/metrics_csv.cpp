#include "app/run/metrics_csv.hpp"

#include <iomanip>

namespace vdmsim {

namespace fs = std::filesystem;

int MetricsCsv::open(const fs::path& dir, int start, bool resume, bool stress, std::ostream& err) {
  path_ = dir / "metrics.csv";
  stress_ = stress;
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
           "fallbacks\n";
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
  const vdm::SimState& state = sim.state();
  file_ << f << ',' << sim.time() << ',' << sim.frame_step_ms() << ',' << sim.frame_iterations() << ','
        << state.stats.residual << ',' << state.volume << ',' << state.volume_rel_error << ',' << state.pressure << ',';
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
  file_ << state.u.rowwise().norm().maxCoeff() << ',';
  if (stress_) file_ << state.stress.rowwise().norm().maxCoeff();
  file_ << ',' << sim.frame_fallbacks() << '\n';
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
