#include "app/sweep/scene_path.hpp"

#include <algorithm>
#include <cctype>

namespace vdmsim {
namespace {

std::string join(const std::vector<std::string>& words) {
  std::string s;
  for (size_t i = 0; i < words.size(); ++i) s += (i ? ", " : "") + words[i];
  return s;
}

const SceneKey* table_key(const std::string& path) {
  for (const SceneKey& k : kSceneKeys)
    if (path == k.path) return &k;
  return nullptr;
}

// Looks up without adding: operator[] of a non-const node adds the key it does not find.
YAML::Node lookup(const YAML::Node& n, const std::string& key) { return n[key]; }
YAML::Node lookup(const YAML::Node& n, size_t index) { return n[index]; }

bool is_value(KeyType t) { return t != KeyType::section && t != KeyType::list && t != KeyType::region_list; }

// The path's steps up to and including step `i`, as written ("instruments[0].radius").
std::string prefix(const ScenePath& p, size_t i) {
  std::string s;
  for (size_t k = 0; k <= i; ++k) {
    s += (k ? "." : "") + p.steps[k].name;
    if (p.steps[k].index >= 0) s += "[" + std::to_string(p.steps[k].index) + "]";
  }
  return s;
}

}  // namespace

bool parse_scene_path(const std::string& text, ScenePath& path, std::string& error) {
  path = ScenePath{};
  path.text = text;
  size_t i = 0;
  auto bad = [&](const std::string& why) {
    error = "'" + text + "' is not a scene key path (" + why + "); write keys joined by dots, list items as [i], "
            "e.g. organ.material.bulk_modulus or instruments[0].radius";
    return false;
  };
  if (text.empty()) return bad("empty");
  while (i < text.size()) {
    ScenePath::Step step;
    while (i < text.size() && (std::isalnum(static_cast<unsigned char>(text[i])) || text[i] == '_')) step.name += text[i++];
    if (step.name.empty()) return bad("a key name expected at character " + std::to_string(i + 1));
    if (i < text.size() && text[i] == '[') {
      std::string digits;
      ++i;
      while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) digits += text[i++];
      if (digits.empty() || i >= text.size() || text[i] != ']' || digits.size() > 6)
        return bad("a list index [0], [1], ... expected after '" + step.name + "'");
      step.index = std::stoi(digits);
      ++i;
    }
    path.steps.push_back(step);
    if (i == text.size()) break;
    if (text[i] != '.') return bad(std::string("unexpected '") + text[i] + "' at character " + std::to_string(i + 1));
    if (++i == text.size()) return bad("it ends with a dot");
  }
  return true;
}

bool check_scene_path(ScenePath& path, const YAML::Node& base, std::string& error) {
  std::string parent;         // the table's path of the mapping the step is in ("" at the top)
  bool region_item = false;   // the mapping is an item of a region list (organ.fixed[i], ...)
  YAML::Node node = base;     // the base scene's node there, when `have`
  bool have = true;
  for (size_t i = 0; i < path.steps.size(); ++i) {
    const ScenePath::Step& step = path.steps[i];
    const std::string where = i ? prefix(path, i - 1) : std::string();
    std::vector<std::string> known = scene_key_names(parent);
    std::vector<std::string> region_keys;
    if (region_item) region_keys = scene_key_names("region");
    known.insert(known.end(), region_keys.begin(), region_keys.end());
    if (std::find(known.begin(), known.end(), step.name) == known.end()) {
      const std::string near = closest_name(step.name, known);
      error = "unknown scene key '" + step.name + "'" + (where.empty() ? std::string() : " in " + where) +
              (near.empty() ? std::string() : " (did you mean '" + near + "'?)") + "; known keys there: " + join(known);
      return false;
    }
    const bool in_region = std::find(region_keys.begin(), region_keys.end(), step.name) != region_keys.end();
    const std::string table = in_region ? "region." + step.name : parent.empty() ? step.name : parent + "." + step.name;
    const SceneKey* key = table_key(table);
    if (!key) {
      error = "'" + step.name + "' has no entry in the scene key table";
      return false;
    }
    const bool last = i + 1 == path.steps.size();
    // (reset(): assigning a YAML::Node would write into the tree it refers to)
    have = have && node.IsMap() && lookup(node, step.name);
    if (have) node.reset(lookup(node, step.name));
    const std::string here = prefix(path, i);
    if (step.index >= 0) {
      if (key->type == KeyType::section) {
        error = here + ": " + step.name + " is a mapping, not a list: leave out [" + std::to_string(step.index) + "]";
        return false;
      }
      if (is_value(key->type) && !last) {
        error = here + ": " + step.name + " is a value: it has no keys below it";
        return false;
      }
      if (!have || !node.IsSequence()) {
        error = here + ": the base scene has no list " + (where.empty() ? step.name : where + "." + step.name) +
                " to take item " + std::to_string(step.index) + " of";
        return false;
      }
      if (static_cast<size_t>(step.index) >= node.size()) {
        error = here + ": the base scene's " + step.name + " has " + std::to_string(node.size()) +
                (node.size() == 1 ? " item" : " items") + " (indices from 0)";
        return false;
      }
      node.reset(lookup(node, static_cast<size_t>(step.index)));
      region_item = key->type == KeyType::region_list;
      parent = table + "[]";
    } else {
      if (!last && is_value(key->type)) {
        error = here + ": " + step.name + " is a value: it has no keys below it";
        return false;
      }
      if (!last && (key->type == KeyType::list || key->type == KeyType::region_list)) {
        error = here + ": " + step.name + " is a list: name one item, e.g. " + here + "[0]";
        return false;
      }
      region_item = false;
      parent = table;
    }
    path.table_path = table;
    path.type = key->type;
  }
  return true;
}

void set_scene_value(YAML::Node root, const ScenePath& path, const YAML::Node& value) {
  YAML::Node node = root;
  for (size_t i = 0; i < path.steps.size(); ++i) {
    const ScenePath::Step& step = path.steps[i];
    const bool last = i + 1 == path.steps.size();
    if (last && step.index < 0) {
      node[step.name] = YAML::Clone(value);
      return;
    }
    YAML::Node child = node[step.name];
    if (step.index >= 0) {
      if (last) {
        child[static_cast<size_t>(step.index)] = YAML::Clone(value);
        return;
      }
      child.reset(child[static_cast<size_t>(step.index)]);
    }
    node.reset(child);
  }
}

}  // namespace vdmsim
