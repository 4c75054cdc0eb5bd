#include "app/run/mesh_export.hpp"

#include "app/run/frame_output.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/vtk_xml.hpp"
#include "engine/stopwatch.hpp"

#include <algorithm>

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// Where an organ's files go, relative to DIR: one organ's in mesh/ and mesh.pvd; with
// several, organ `name`'s in mesh/<name>/ and <name>.pvd.
std::string organ_folder(const std::vector<std::string>& organs, size_t i) {
  return organs.size() > 1 ? "mesh/" + organs[i] + "/" : "mesh/";
}
std::string organ_pvd(const std::vector<std::string>& organs, size_t i) {
  return organs.size() > 1 ? organs[i] + ".pvd" : "mesh.pvd";
}
// The .pvd's reference to frame f, relative to DIR.
std::string relative_frame_file(const std::vector<std::string>& organs, size_t i, int f) {
  return organ_folder(organs, i) + frame_file_name("frame", f, ".vtu");
}

}  // namespace

std::vector<render::Quantity> exported_scalars(bool stress_computed) {
  std::vector<render::Quantity> out;
  for (render::Quantity q : render::all_quantities())
    if (q != render::Quantity::displacement && (stress_computed || !render::quantity_needs_stress(q))) out.push_back(q);
  return out;
}

std::vector<std::string> organ_names(const PreparedScene& ps) {
  std::vector<std::string> names;
  for (const OrganDef& o : ps.scene.organs) names.push_back(o.name);
  return names;
}

void remove_mesh_export(const fs::path& dir, const std::vector<std::string>& organs) {
  std::error_code ec;
  for (size_t i = 0; i < std::max<size_t>(organs.size(), 1); ++i) {
    const std::string pvd = organs.empty() ? "mesh.pvd" : organ_pvd(organs, i);
    fs::remove(dir / pvd, ec);
    fs::remove(dir / (pvd + ".tmp"), ec);
    for (const auto& entry : fs::directory_iterator(dir / (organs.empty() ? "mesh/" : organ_folder(organs, i)), ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("frame_", 0) == 0 && (ends_with(name, ".vtu") || ends_with(name, ".vtu.tmp")))
        fs::remove(entry.path(), ec);
    }
  }
}

std::vector<int> missing_export_frames(const fs::path& dir, int frames, const std::vector<std::string>& organs) {
  std::vector<int> missing;
  std::error_code ec;
  for (int f = 0; f < frames; ++f)
    for (size_t i = 0; i < std::max<size_t>(organs.size(), 1); ++i)
      if (!fs::exists(dir / (organs.empty() ? "mesh/" + frame_file_name("frame", f, ".vtu") : relative_frame_file(organs, i, f)),
                      ec)) {
        missing.push_back(f);
        break;
      }
  return missing;
}

bool MeshExport::open(const PreparedScene& ps, const fs::path& dir, int start, std::string& error) {
  dir_ = dir;
  organs_ = organ_names(ps);
  std::error_code ec;
  for (size_t i = 0; i < organs_.size(); ++i) {
    fs::create_directories(dir / organ_folder(organs_, i), ec);
    if (ec) {
      error = (dir / organ_folder(organs_, i)).string() + ": cannot create the folder (" + ec.message() + ")";
      return false;
    }
  }
  ps_ = &ps;
  // The stress quantities when every organ computes stress (one set of arrays in every file).
  bool stress = true;
  const OrganDef* without = nullptr;
  for (size_t i = 0; i < ps.organs.size(); ++i)
    if (!ps.organs[i].model.compute_stress) {
      stress = false;
      if (!without && !organ_model(ps.scene.organs[i].model).surface_stress) without = &ps.scene.organs[i];
    }
  scalars_ = exported_scalars(stress);
  values_.assign(scalars_.size(), {});
  if (!stress)
    omitted_reason_ = without ? without->field + ".model " + std::string(vdm::to_string(without->model)) +
                                    " computes no stress at the surface"
                              : "the scene computes no stress (simulation.effects lacks stress)";
  // A resume: the earlier run's frames before `start` stay, those still on disk are listed.
  for (int f = 0; f < start; ++f) {
    bool all = true;
    for (size_t i = 0; i < organs_.size(); ++i) all = all && fs::exists(frame_path(f, i), ec);
    if (all) listed_.push_back(f);
  }
  return true;
}

fs::path MeshExport::frame_path(int f, size_t organ) const { return dir_ / relative_frame_file(organs_, organ, f); }

std::vector<std::string> MeshExport::point_data() const {
  std::vector<std::string> names{"displacement"};
  for (render::Quantity q : scalars_) names.push_back(render::to_string(q));
  return names;
}

bool MeshExport::write(int f, const SceneSimulation& sim, std::string& error) {
  if (!active()) return true;
  const auto t0 = vdm::Clock::now();
  for (size_t i = 0; i < sim.organ_count(); ++i) {
    const vdm::SimState& st = sim.state(i);
    std::vector<VtuScalars> scalars;
    for (size_t k = 0; k < scalars_.size(); ++k) {
      render::scalar_field(scalars_[k], st, values_[k]);  // as the stress view colours them
      scalars.push_back({render::to_string(scalars_[k]), &values_[k]});
    }
    const std::string body = vtu_text(st.x, ps_->organs[i].model.rest.triangles, {{"displacement", &st.u}}, scalars);
    if (!write_file_atomically(frame_path(f, i), body, error)) return false;
  }
  if (listed_.empty() || listed_.back() < f) listed_.push_back(f);
  const bool ok = write_pvd(error);
  write_ms_ += vdm::ms_since(t0);
  return ok;
}

bool MeshExport::keep_frames(int frames, std::string& error) {
  if (!active()) return true;
  std::error_code ec;
  while (!listed_.empty() && listed_.back() >= frames) {
    for (size_t i = 0; i < organs_.size(); ++i) fs::remove(frame_path(listed_.back(), i), ec);
    listed_.pop_back();
  }
  return write_pvd(error);
}

bool MeshExport::write_pvd(std::string& error) const {
  for (size_t i = 0; i < organs_.size(); ++i) {
    std::vector<PvdDataSet> sets;
    for (int f : listed_)
      sets.push_back({SceneSimulation::frame_time(f, ps_->scene.dt), relative_frame_file(organs_, i, f)});
    if (!write_file_atomically(dir_ / organ_pvd(organs_, i), pvd_text(sets), error)) return false;
  }
  return true;
}

}  // namespace vdmsim
