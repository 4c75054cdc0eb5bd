#include "app/studies/accuracy_trajectory.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include "app/run/output_dir.hpp"
#include "app/scene/organ_generator.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "app/studies/surface_samples.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

constexpr int kSampleLevel = 3;  // the common surface points: the level-3 liver's nodes
const char kMagic[] = "vdmsim accuracy trajectory 1\n";

void put_int(std::string& out, std::int64_t v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); }
void put_double(std::string& out, double v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); }

// Reads the bytes of a trajectory in order; `ok` falls to false at the first short read.
struct Reader {
  const std::string& bytes;
  size_t at = 0;
  bool ok = true;
  template <typename T>
  T get() {
    T v{};
    if (at + sizeof v > bytes.size()) {
      ok = false;
      return v;
    }
    std::memcpy(&v, bytes.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
};

}  // namespace

vdm::NodeMat accuracy_sample_points() { return make_liver_mesh(kSampleLevel).positions; }

Trajectory simulate_trajectory(const std::string& path, const vdm::NodeMat& points) {
  Trajectory tr;
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  if (!prepare_scene(path, ps, problems)) {
    tr.failed = true;
    tr.failure = problems.empty() ? "the scene did not load" : problems.front().where + ": " + problems.front().message;
    return tr;
  }
  tr.nodes = ps.organ().model.n;
  const SurfaceSamples samples(ps.organ().model.rest, points);
  SceneSimulation sim(ps);
  const vdm::FlagMat& fixed = ps.organ().model.held;  // fixed (or infinitely stiff): not the instruments' doing
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
    for (int i = 0; i < ps.organ().model.n; ++i) {
      const bool held = fixed.rows() == ps.organ().model.n && fixed.row(i).any();
      if (!held && s.reaction.rows() == ps.organ().model.n) force -= s.reaction.row(i).transpose();
    }
    tr.force.push_back(force);
    tr.step_ms.push_back(sim.frame_step_ms());
    if (!s.stats.converged || (sim.contact_simulated() && !sim.contact_report().converged)) ++tr.unconverged;
    tr.volume_rel.push_back(s.volume_rel_error);
  }
  return tr;
}

bool write_trajectory(const fs::path& path, const Trajectory& tr, std::string& error) {
  std::string out(kMagic);
  const std::int64_t frames = std::int64_t(tr.u.size());
  const std::int64_t samples = tr.u.empty() ? 0 : std::int64_t(tr.u.front().rows());
  put_int(out, frames);
  put_int(out, samples);
  put_int(out, tr.nodes);
  put_int(out, tr.unconverged);
  for (size_t f = 0; f < tr.u.size(); ++f) {
    for (int s = 0; s < tr.u[f].rows(); ++s)
      for (int k = 0; k < 3; ++k) put_double(out, tr.u[f](s, k));
    for (int k = 0; k < 3; ++k) put_double(out, tr.force[f](k));
    put_double(out, tr.step_ms[f]);
    put_double(out, tr.volume_rel[f]);
  }
  return write_file_atomically(path, out, error);
}

bool read_trajectory(const fs::path& path, Trajectory& tr, std::string& error) {
  tr = Trajectory{};
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = path.string() + ": cannot be read";
    return false;
  }
  std::ostringstream text;
  text << in.rdbuf();
  const std::string bytes = text.str();
  const size_t magic = sizeof kMagic - 1;
  if (bytes.compare(0, magic, kMagic) != 0) {
    error = path.string() + ": not a trajectory of `vdmsim accuracy`";
    return false;
  }
  Reader r{bytes, magic};
  const auto frames = r.get<std::int64_t>(), samples = r.get<std::int64_t>();
  tr.nodes = int(r.get<std::int64_t>());
  tr.unconverged = int(r.get<std::int64_t>());
  const std::int64_t per_frame = samples * 3 + 5;
  if (!r.ok || frames < 0 || samples < 0 ||
      bytes.size() - r.at != size_t(frames) * size_t(per_frame) * sizeof(double)) {
    error = path.string() + ": cut short or of another size than its header says";
    return false;
  }
  for (std::int64_t f = 0; f < frames; ++f) {
    vdm::NodeMat u(samples, 3);
    for (std::int64_t s = 0; s < samples; ++s)
      for (int k = 0; k < 3; ++k) u(s, k) = r.get<double>();
    vdm::Vec3 force;
    for (int k = 0; k < 3; ++k) force(k) = r.get<double>();
    tr.u.push_back(u);
    tr.force.push_back(force);
    tr.step_ms.push_back(r.get<double>());
    tr.volume_rel.push_back(r.get<double>());
  }
  return true;
}

}  // namespace vdmsim
