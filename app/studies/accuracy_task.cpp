#include "app/studies/accuracy_task.hpp"

#include <yaml-cpp/yaml.h>

#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "app/run/json_text.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/run_setup.hpp"
#include "app/scene/scene.hpp"
#include "app/studies/quantile.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

// run.json's fields as text ("" where absent or unreadable).
std::string run_json_field(const fs::path& run_dir, const char* key) {
  try {
    const YAML::Node js = YAML::LoadFile((run_dir / "run.json").string());
    return js[key] && js[key].IsScalar() ? js[key].Scalar() : "";
  } catch (const YAML::Exception&) {
    return "";
  }
}

bool write_run_json(const fs::path& run_dir, const std::string& status, const std::string& inputs, double yardstick_ms,
                    const std::string& reason, std::string& error) {
  std::ostringstream js;
  js << std::setprecision(17) << "{\n  \"status\": \"" << status << "\",\n  \"inputs\": \"" << inputs
     << "\",\n  \"yardstick_ms\": " << yardstick_ms << ",\n  \"reason\": \"" << json_escape(reason) << "\"\n}\n";
  return write_file_atomically(run_dir / "run.json", js.str(), error);
}

Trajectory simulate_safely(const fs::path& scene, const vdm::NodeMat& points) {
  try {
    return simulate_trajectory(scene.string(), points);
  } catch (const std::exception& e) {  // e.g. a reference model that cannot be built
    Trajectory tr;
    tr.failed = true;
    tr.failure = e.what();
    return tr;
  }
}

}  // namespace

std::string config_inputs_hash(const fs::path& scene) {
  const SceneLoadResult loaded = load_scene(scene.string());
  if (!loaded.ok()) return "";
  RunOptions options;
  options.render = false;
  return run_inputs(loaded.scene, options).hash();
}

bool task_finished(const fs::path& run_dir, const std::string& inputs) {
  std::error_code ec;
  if (run_json_field(run_dir, "status") != "completed" || !fs::exists(run_dir / "trajectory.bin", ec)) return false;
  return !inputs.empty() && run_json_field(run_dir, "inputs") == inputs;
}

bool config_finished(const fs::path& run_dir) {
  return task_finished(run_dir, config_inputs_hash(run_dir / "scene.yaml"));
}

int run_config_task(const fs::path& run_dir, const fs::path& yardstick_scene, std::ostream& out) {
  const fs::path scene = run_dir / "scene.yaml";
  const vdm::NodeMat points = accuracy_sample_points();
  return run_task(
      run_dir, config_inputs_hash(scene), [&] { return simulate_safely(scene, points); }, yardstick_scene, out);
}

int run_task(const fs::path& run_dir, const std::string& inputs, const TaskSimulation& simulate,
             const fs::path& yardstick_scene, std::ostream& out) {
  std::error_code ec;
  fs::remove(run_dir / "run.json", ec);
  fs::remove(run_dir / "trajectory.bin", ec);
  Trajectory tr;
  try {
    tr = simulate();
  } catch (const std::exception& e) {  // e.g. a reference model that cannot be built
    tr = Trajectory{};
    tr.failed = true;
    tr.failure = e.what();
  }
  double yardstick_ms = 0;
  if (!tr.failed) {
    // The yardstick right after, in the same process on the same node.
    const Trajectory yardstick = simulate_safely(yardstick_scene, accuracy_sample_points());
    if (yardstick.failed) {
      tr.failed = true;
      tr.failure = "the timing yardstick (" + yardstick_scene.string() + ") failed: " + yardstick.failure;
    }
    yardstick_ms = quantile(yardstick.step_ms, 0.5);
  }
  std::string error;
  if (!tr.failed && !write_trajectory(run_dir / "trajectory.bin", tr, error)) {
    tr.failed = true;
    tr.failure = error;
  }
  if (!write_run_json(run_dir, tr.failed ? "failed" : "completed", inputs, yardstick_ms, tr.failure, error)) {
    out << "vdmsim: error: " << error << "\n";
    return 1;
  }
  if (tr.failed) {
    out << "vdmsim: error: " << run_dir.filename().string() << ": " << tr.failure << "\n";
    return 1;
  }
  out << run_dir.filename().string() << ": completed, " << tr.u.size() << " frames; median step "
      << quantile(tr.step_ms, 0.5) << " ms, the yardstick's " << yardstick_ms << " ms\n";
  return 0;
}

ConfigResult read_config_result(const fs::path& run_dir) {
  ConfigResult r;
  const std::string status = run_json_field(run_dir, "status");
  if (status == "failed") {
    r.status = "failed";
    r.reason = run_json_field(run_dir, "reason");
    return r;
  }
  if (status != "completed") return r;
  std::string error;
  if (!read_trajectory(run_dir / "trajectory.bin", r.trajectory, error)) {
    r.status = "failed";
    r.reason = error;
    return r;
  }
  r.status = "completed";
  r.yardstick_ms = std::strtod(run_json_field(run_dir, "yardstick_ms").c_str(), nullptr);
  return r;
}

}  // namespace vdmsim
