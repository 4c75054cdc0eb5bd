#include "app/sweep/run_folder.hpp"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>

#include "app/run/checkpoint.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/run_setup.hpp"
#include "app/scene/scene.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// run.json's status ("" when there is none or it cannot be read).
std::string run_status(const fs::path& dir) {
  try {
    const YAML::Node js = YAML::LoadFile((dir / "run.json").string());
    return js["status"] ? js["status"].as<std::string>() : "";
  } catch (const YAML::Exception&) {
    return "";
  }
}

}  // namespace

const char* to_string(RunFolderState s) {
  switch (s) {
    case RunFolderState::finished: return "finished";
    case RunFolderState::resumable: return "resumable";
    case RunFolderState::fresh: return "fresh";
  }
  return "fresh";
}

void clear_run_results(const fs::path& dir) {
  std::error_code ec;
  for (const char* old : {"run.json", "checkpoint.json", "state.bin", "run.log"}) fs::remove(dir / old, ec);
}

bool open_sweep_dir(const std::string& out, bool task, std::filesystem::path& dir, OutputLock& lock,
                    std::string& error) {
  if (out.empty()) {  // (absolute("") is the current folder)
    error = "--out: empty: name the folder (an unset shell variable?)";
    return false;
  }
  std::error_code ec;
  dir = std::filesystem::absolute(out, ec).lexically_normal();
  if (!prepare_output_dir((dir / "runs").string(), error)) return false;
  return task || lock.acquire(dir, error);
}

bool write_run_scene(const fs::path& dir, const std::string& scene_text, std::string& error) {
  const fs::path scene = dir / "scene.yaml";
  std::error_code ec;
  if (fs::exists(scene, ec) && read_text(scene) == scene_text) return true;
  if (!prepare_output_dir(dir.string(), error)) return false;
  clear_run_results(dir);
  return write_file_atomically(scene, scene_text, error);
}

RunFolderState run_folder_state(const fs::path& dir, const RunOptions& options) {
  const SceneLoadResult scene = load_scene((dir / "scene.yaml").string());
  if (!scene.ok()) return RunFolderState::fresh;
  Checkpoint cp;
  std::string error;
  if (!read_checkpoint((dir / "checkpoint.json").string(), cp, error)) return RunFolderState::fresh;
  if (cp.run_hash != run_inputs(scene.scene, options).hash()) {
    clear_run_results(dir);  // of another mesh, other options or another program
    return RunFolderState::fresh;
  }
  const int frames = run_frames(scene.scene, options);
  const std::string status = run_status(dir);
  if (status == "completed" && cp.frame + 1 == frames) {
    const RenderDef& rd = scene.scene.render;
    std::error_code ec;
    bool videos = true;
    for (render::View v : rd.views)
      if (const std::string video = render::video_file_name(rd.views, v); options.video && !video.empty())
        videos = videos && fs::exists(dir / video, ec);
    return videos ? RunFolderState::finished : RunFolderState::fresh;
  }
  if ((status == "interrupted" || status.empty()) && cp.frame + 1 < frames) return RunFolderState::resumable;
  return RunFolderState::fresh;
}

}  // namespace vdmsim
