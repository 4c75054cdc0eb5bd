#include "app/run/mesh_export.hpp"

#include "app/run/frame_output.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/vtk_xml.hpp"
#include "engine/stopwatch.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The .pvd's reference to frame f, relative to DIR.
std::string relative_frame_file(int f) { return "mesh/" + frame_file_name("frame", f, ".vtu"); }

}  // namespace

std::vector<render::Quantity> exported_scalars(bool stress_computed) {
  std::vector<render::Quantity> out;
  for (render::Quantity q : render::all_quantities())
    if (q != render::Quantity::displacement && (stress_computed || !render::quantity_needs_stress(q))) out.push_back(q);
  return out;
}

void remove_mesh_export(const fs::path& dir) {
  std::error_code ec;
  fs::remove(dir / "mesh.pvd", ec);
  fs::remove(dir / "mesh.pvd.tmp", ec);
  for (const auto& entry : fs::directory_iterator(dir / "mesh", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("frame_", 0) == 0 && (ends_with(name, ".vtu") || ends_with(name, ".vtu.tmp")))
      fs::remove(entry.path(), ec);
  }
}

std::vector<int> missing_export_frames(const fs::path& dir, int frames) {
  std::vector<int> missing;
  std::error_code ec;
  for (int f = 0; f < frames; ++f)
    if (!fs::exists(dir / relative_frame_file(f), ec)) missing.push_back(f);
  return missing;
}

bool MeshExport::open(const PreparedScene& ps, const fs::path& dir, int start, std::string& error) {
  dir_ = dir;
  std::error_code ec;
  fs::create_directories(dir / "mesh", ec);
  if (ec) {
    error = (dir / "mesh").string() + ": cannot create the folder (" + ec.message() + ")";
    return false;
  }
  ps_ = &ps;
  const bool stress = ps.model.compute_stress;
  scalars_ = exported_scalars(stress);
  values_.assign(scalars_.size(), {});
  if (!stress)
    omitted_reason_ = !organ_model(ps.scene.model).surface_stress
                          ? "organ.model " + std::string(vdm::to_string(ps.scene.model)) + " computes no stress at the surface"
                          : "the scene computes no stress (simulation.effects lacks stress)";
  // A resume: the earlier run's frames before `start` stay, those still on disk are listed.
  for (int f = 0; f < start; ++f)
    if (fs::exists(frame_path(f), ec)) listed_.push_back(f);
  return true;
}

fs::path MeshExport::frame_path(int f) const { return dir_ / relative_frame_file(f); }

std::vector<std::string> MeshExport::point_data() const {
  std::vector<std::string> names{"displacement"};
  for (render::Quantity q : scalars_) names.push_back(render::to_string(q));
  return names;
}

bool MeshExport::write(int f, const SceneSimulation& sim, std::string& error) {
  if (!active()) return true;
  const auto t0 = vdm::Clock::now();
  const vdm::SimState& st = sim.state();
  std::vector<VtuScalars> scalars;
  for (size_t k = 0; k < scalars_.size(); ++k) {
    render::scalar_field(scalars_[k], st, values_[k]);  // as the stress view colours them
    scalars.push_back({render::to_string(scalars_[k]), &values_[k]});
  }
  const std::string body = vtu_text(st.x, ps_->model.rest.triangles, {{"displacement", &st.u}}, scalars);
  if (!write_file_atomically(frame_path(f), body, error)) return false;
  if (listed_.empty() || listed_.back() < f) listed_.push_back(f);
  const bool ok = write_pvd(error);
  write_ms_ += vdm::ms_since(t0);
  return ok;
}

bool MeshExport::keep_frames(int frames, std::string& error) {
  if (!active()) return true;
  std::error_code ec;
  while (!listed_.empty() && listed_.back() >= frames) {
    fs::remove(frame_path(listed_.back()), ec);
    listed_.pop_back();
  }
  return write_pvd(error);
}

bool MeshExport::write_pvd(std::string& error) const {
  std::vector<PvdDataSet> sets;
  for (int f : listed_) sets.push_back({SceneSimulation::frame_time(f, ps_->scene.dt), relative_frame_file(f)});
  return write_file_atomically(dir_ / "mesh.pvd", pvd_text(sets), error);
}

}  // namespace vdmsim
