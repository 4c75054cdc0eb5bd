#pragma once
// A sweep file (docs/sweeps.md): a base scene and what to vary in it, as a grid (`vary:`,
// every combination), lists varied together (`zip:`, one group or a list of groups, each an
// axis of the grid), or an explicit list of runs (`cases:`). Every problem is named with the sweep file's line and column and the field.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>
#include <vector>

#include "app/scene/scene.hpp"
#include "app/sweep/scene_path.hpp"

namespace vdmsim {

// One value a key takes, as written in the sweep file.
struct SweepValue {
  YAML::Node node;
  std::string text;   // the value in one line of YAML ("20000", "[0, 0, 0.05]")
  std::string where;  // file:line:col
};

// A varied key: the path into the scene, named in the summary exactly as written.
struct SweepKey {
  ScenePath path;
  std::string where;  // file:line:col of the key in the sweep file
};

// A grid axis: one key of `vary:`, or all the keys of a `zip:` group (their values taken together).
struct SweepAxis {
  std::vector<size_t> keys;                     // into SweepFile::keys
  std::vector<std::vector<SweepValue>> values;  // per key, the same count each
  size_t size() const { return values.empty() ? 0 : values[0].size(); }
};

// A run of `cases:`: some keys, each with one value.
struct SweepCase {
  std::vector<std::pair<size_t, SweepValue>> settings;
};

struct SweepFile {
  std::filesystem::path file;       // the sweep file (absolute)
  std::filesystem::path base;       // the base scene (absolute)
  YAML::Node base_yaml;             // the base scene's YAML, its file paths made absolute
  std::vector<SweepKey> keys;       // every varied key, in the order first written
  std::vector<SweepAxis> axes;      // vary's keys, then zip's groups (the grid: the first axis slowest)
  std::vector<SweepCase> cases;     // or these
};

// Reads and checks `path`: its own keys, the base scene (which must be valid itself), every
// varied key against the scene's keys and the base. False when there is an error (`problems`
// says what, where); warnings do not stop it.
bool read_sweep_file(const std::string& path, SweepFile& sweep, std::vector<SceneProblem>& problems);

// Makes the file paths of `scene` (YAML of a scene: organ.mesh, probe meshes, skins) absolute,
// relative ones taken against `folder`.
void rebase_scene_files(YAML::Node scene, const std::filesystem::path& folder);

// A value in one line of YAML (flow style).
std::string one_line_yaml(const YAML::Node& node);

// A node as YAML text, in the styles it was read with (block or flow), its quoted scalars
// quoted: "0.5" stays a string, 'yes' stays a string (yaml-cpp's own emitter drops the quotes).
std::string yaml_text_keeping_quotes(const YAML::Node& node);

}  // namespace vdmsim
