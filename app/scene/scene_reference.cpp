#include "app/scene/scene_reference.hpp"

#include <algorithm>
#include <cctype>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "app/scene/scene_keys.hpp"

namespace vdmsim {
namespace {

bool is_container(const SceneKey& k) {
  return k.type == KeyType::section || k.type == KeyType::list || k.type == KeyType::region_list ||
         k.type == KeyType::region;
}

// Where a container's keys live: a list's under path[].
std::string keys_path(const SceneKey& k) {
  return k.type == KeyType::list || k.type == KeyType::region_list ? std::string(k.path) + "[]" : std::string(k.path);
}

std::string heading(const SceneKey& k) { return keys_path(k); }

// GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens.
std::string anchor(const std::string& text) {
  std::string a;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') a += static_cast<char>(std::tolower(c));
    else if (c == ' ') a += '-';
  }
  return a;
}

std::string cell(const std::string& text) {
  std::string s;
  for (char c : text) s += c == '|' ? std::string("\\|") : std::string(1, c);
  return s;
}

std::string code_list(const std::vector<std::string>& words) {
  std::string s;
  for (size_t i = 0; i < words.size(); ++i) s += (i ? ", `" : "`") + words[i] + "`";
  return s;
}

std::string type_of(const SceneKey& k) {
  if (k.type_text) return k.type_text;
  switch (k.type) {
    case KeyType::section: return "mapping";
    case KeyType::list: return "list of mappings";
    case KeyType::region_list: return "list of regions";
    case KeyType::region: return "region";
    case KeyType::number: return "number";
    case KeyType::integer: return "whole number";
    case KeyType::vector3: return "[x, y, z]";
    case KeyType::boolean: return "true or false";
    case KeyType::text: return "text";
    case KeyType::file: return "file";
    case KeyType::choice: return "name";
    case KeyType::choice_list: return "list of names";
  }
  return "";
}

std::string bound(const SceneKey& k, double v) {
  return k.type == KeyType::integer ? std::to_string(static_cast<long long>(v)) : yaml_number(v);
}

std::string allowed_of(const SceneKey& k) {
  if (k.allowed_text) return k.allowed_text;
  if (k.values) return (k.type == KeyType::choice_list ? "each of " : "") + code_list(k.values());
  const double inf = std::numeric_limits<double>::infinity();
  if (k.lo == -inf && k.hi == inf) return "";
  std::string s = (k.lo_open ? "> " : ">= ") + bound(k, k.lo);
  if (k.hi < inf) s += " and <= " + bound(k, k.hi);
  if (k.allow_inf) s += " (or inf)";
  return s;
}

std::string default_of(const SceneKey& k) {
  if (k.required) return "required";
  if (k.default_value) return "`" + k.default_value() + "`";
  if (k.default_text) return k.default_text;
  return "";
}

std::vector<const SceneKey*> children(const std::string& parent) {
  std::vector<const SceneKey*> out;
  for (const SceneKey& k : kSceneKeys)
    if (scene_key_parent(k.path) == parent) out.push_back(&k);
  return out;
}

// "`model: vdm` or `fem` only: " for a key only some organ models use (organ_model_table.hpp).
std::string models_only(const std::string& path) {
  const std::vector<std::string> keys = model_specific_keys();
  if (std::find(keys.begin(), keys.end(), path) == keys.end()) return "";
  std::vector<std::string> names;
  for (const OrganModel& m : organ_models())
    if (m.uses(path)) names.push_back(std::string(names.empty() ? "`model: " : "`") + m.name() + "`");
  return or_list(names) + " only: ";
}

const SceneKey* find(const std::string& path) {
  for (const SceneKey& k : kSceneKeys)
    if (path == k.path) return &k;
  return nullptr;
}

// The sections, depth first: the top, then each container's section followed by its own.
void collect(const std::string& parent, std::vector<const SceneKey*>& out) {
  for (const SceneKey* k : children(parent)) {
    if (!is_container(*k)) continue;
    out.push_back(k);
    collect(keys_path(*k), out);
  }
}

void write_table(std::ostream& out, const std::string& parent) {
  out << "| key | type | unit | default | allowed | meaning | example |\n";
  out << "|---|---|---|---|---|---|---|\n";
  for (const SceneKey* k : children(parent)) {
    if (k->type == KeyType::region) continue;
    const std::string name = parent.empty() ? std::string(k->path) : std::string(k->path).substr(parent.size() + 1);
    std::string key = "`" + name + "`";
    if (is_container(*k)) key = "[" + key + "](#" + anchor(heading(*k)) + ")";
    std::string meaning = k->description;
    if (k->shapes) {
      std::string only;
      std::istringstream words(k->shapes);
      std::string w;
      while (words >> w) only += (only.empty() ? "`" : ", `") + w + "`";
      meaning = only + " only: " + meaning;
    }
    meaning = models_only(k->path) + meaning;
    out << "| " << key << " | " << cell(type_of(*k)) << " | " << cell(k->unit) << " | " << cell(default_of(*k)) << " | "
        << cell(allowed_of(*k)) << " | " << cell(meaning) << " | "
        << (*k->example && !is_container(*k) ? "`" + cell(k->example) + "`" : std::string("below")) << " |\n";
  }
}

}  // namespace

void write_scene_reference(std::ostream& out) {
  std::vector<const SceneKey*> sections;
  collect("", sections);

  out << "<!-- Generated by `vdmsim scene-reference` from the scene reader's own table of keys\n"
         "     (app/scene/scene_keys.hpp). Do not edit: change the table, then run\n"
         "     ./build/vdmsim scene-reference > docs/scene-reference.md\n"
         "     A test fails when this file differs from what the code prints. -->\n"
         "# Scene reference\n\n"
         "A scene is a YAML file that `vdmsim run` simulates and `vdmsim check` validates. Every key of it is\n"
         "below, section by section: its type, unit, default, the values allowed, what it does and an\n"
         "example. The examples are written as the key's own mapping would hold them (with a sibling key\n"
         "where one is needed). A complete scene: [probe_poke.yaml](../assets/scenes/probe_poke.yaml); the\n"
         "other examples are in [assets/scenes/](../assets/scenes/).\n\n"
         "- Units are SI (m, kg, s, N, Pa). Numbers are plain: `0.015`, not `15mm` (an error says so).\n"
         "- File paths are relative to the scene file's folder.\n"
         "- A key that is not in this reference is a warning naming the closest known key; the run goes on\n"
         "  without it. Every other problem is an error with the file, line and column, the key and what was\n"
         "  expected, and the command exits with 2 before anything runs.\n"
         "- `inf` is allowed where the table says so.\n\n"
         "Sections:\n\n"
         "- [The top of the file](#the-top-of-the-file)\n";
  for (const SceneKey* k : sections) out << "- [" << heading(*k) << "](#" << anchor(heading(*k)) << ")\n";

  out << "\n## The top of the file\n\n";
  write_table(out, "");
  for (const SceneKey* k : sections) {
    out << "\n## " << heading(*k) << "\n\n" << k->description << "\n";
    if (k->type == KeyType::region_list) {
      const SceneKey* region = find("region");
      out << "\nEach item is a [region](#" << anchor(region ? region->path : "region") << ")";
      if (!children(keys_path(*k)).empty()) out << ", with these keys beside it";
      out << ".\n";
    }
    if (*k->example) out << "\n```yaml\n" << k->example << "\n```\n";
    if (!children(keys_path(*k)).empty()) {
      out << "\n";
      write_table(out, keys_path(*k));
    }
  }
}

}  // namespace vdmsim
