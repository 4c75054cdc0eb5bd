#pragma once
// A path into a scene file, as a sweep names what it varies: dots into mappings, [i] into
// lists ("organ.material.bulk_modulus", "instruments[0].radius", "organ.fixed[0].box.min").
// Checked against the scene reader's table of keys (app/scene/scene_keys.hpp) and against the
// base scene (a list item must be there); set into a copy of the base scene's YAML.
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "app/scene/scene_keys.hpp"

namespace vdmsim {

struct ScenePath {
  struct Step {
    std::string name;
    int index = -1;  // [i] after the name; -1 when none
  };
  std::string text;         // as written
  std::vector<Step> steps;
  std::string table_path;   // the key table's path of the last key ("instruments[].radius")
  KeyType type = KeyType::section;
};

// Splits `text` into steps; false with `error` when it is not name(.name)*, each name
// optionally followed by [index].
bool parse_scene_path(const std::string& text, ScenePath& path, std::string& error);

// Checks every step against the key table (an unknown name: the closest known key suggested
// and the known keys listed) and the base scene (a list index within the base's list; a value
// has no keys). Sets path.table_path and path.type. False with `error`.
bool check_scene_path(ScenePath& path, const YAML::Node& base, std::string& error);

// Sets `value` (copied) at `path` in `root`, creating missing mappings on the way.
void set_scene_value(YAML::Node root, const ScenePath& path, const YAML::Node& value);

}  // namespace vdmsim
