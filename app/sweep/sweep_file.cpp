#include "app/sweep/sweep_file.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>

#include "app/scene/yaml_documents.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kSweepKeys = {"base", "vary", "zip", "cases"};
constexpr size_t kMaxRuns = 100000;

std::string where(const std::string& file, const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  std::ostringstream s;
  s << file;
  if (m.line >= 0) s << ':' << m.line + 1 << ':' << m.column + 1;
  return s.str();
}

std::string kind(const YAML::Node& n) {
  if (n.IsMap()) return "a mapping";
  if (n.IsSequence()) return "a list";
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  return "nothing";
}

// Rebases the scalar file names at `node`, which is at `table` in the key table, and below it.
void rebase_below(YAML::Node node, const std::string& table, const fs::path& folder);

void rebase_file(YAML::Node node, const fs::path& folder) {
  if (node.IsScalar()) {
    const fs::path p = node.Scalar();
    if (!p.empty() && p.is_relative()) node = (folder / p).lexically_normal().string();
  } else if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) rebase_file(node[i], folder);
  }
}

// Walks `rest` (a key path's steps below `node`, "[]" expanding over a list's items).
void rebase_path(YAML::Node node, const std::string& rest, const fs::path& folder) {
  if (rest.empty()) return rebase_file(node, folder);
  if (rest.compare(0, 2, "[]") == 0) {
    if (!node.IsSequence()) return;
    const std::string next = rest.size() > 2 && rest[2] == '.' ? rest.substr(3) : rest.substr(2);
    for (size_t i = 0; i < node.size(); ++i) rebase_path(node[i], next, folder);
    return;
  }
  const size_t cut = rest.find_first_of(".[");
  const std::string name = rest.substr(0, cut);
  std::string next = cut == std::string::npos ? "" : rest.substr(cut);
  if (!next.empty() && next[0] == '.') next.erase(0, 1);
  const YAML::Node& view = node;
  if (!node.IsMap() || !view[name]) return;
  rebase_path(node[name], next, folder);
}

void rebase_below(YAML::Node node, const std::string& table, const fs::path& folder) {
  for (const SceneKey& k : kSceneKeys) {
    if (k.type != KeyType::file) continue;
    const std::string path = k.path;
    if (table.empty()) rebase_path(node, path, folder);
    else if (path == table) rebase_file(node, folder);
    else if (path.compare(0, table.size(), table) == 0 && (path[table.size()] == '.' || path[table.size()] == '['))
      rebase_path(node, path.substr(table.size() + (path[table.size()] == '.' ? 1 : 0)), folder);
  }
}

// The key table's path of what a value set at `path` is ("instruments[]" for instruments[0]).
std::string value_table_path(const ScenePath& path) {
  const bool item = path.steps.back().index >= 0 && (path.type == KeyType::list || path.type == KeyType::region_list);
  return item ? path.table_path + "[]" : path.table_path;
}

class SweepReader {
 public:
  // `folder`: the sweep file's folder (absolute), which its relative paths are taken against.
  SweepReader(SweepFile& sweep, fs::path folder, std::vector<SceneProblem>& problems)
      : s_(sweep), folder_(std::move(folder)), problems_(problems) {}

  void error(const YAML::Node& at, const std::string& field, const std::string& message) {
    problems_.push_back({where(s_.file.string(), at), field, message, false});
  }
  void error(const std::string& at, const std::string& field, const std::string& message) {
    problems_.push_back({at, field, message, false});
  }

  // The top: its keys, the base scene, then what varies.
  void read(const YAML::Node& root) {
    if (!root.IsMap()) {
      error(root, "sweep", "expected a mapping with base: and vary:, zip: or cases:, got " + kind(root));
      return;
    }
    std::vector<std::string> seen;
    for (auto it = root.begin(); it != root.end(); ++it) {
      const std::string key = it->first.Scalar();
      if (std::find(seen.begin(), seen.end(), key) != seen.end()) error(it->first, key, "duplicate key '" + key + "': give it once");
      seen.push_back(key);
      if (std::find(kSweepKeys.begin(), kSweepKeys.end(), key) != kSweepKeys.end()) continue;
      const std::string near = closest_name(key, kSweepKeys);
      error(it->first, key,
            "unknown key '" + key + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                "; known keys: base, vary, zip, cases");
    }
    if (!read_base(root)) return;
    const YAML::Node vary = root["vary"], zip = root["zip"], cases = root["cases"];
    if (!vary && !zip && !cases) {
      error(root, "sweep", "nothing varies: give vary: (a grid), zip: (lists taken together) or cases: (a list of runs)");
      return;
    }
    if (cases && (vary || zip)) {
      error(cases, "cases", "give either cases: or vary:/zip:, not both (cases: lists every run itself)");
      return;
    }
    const size_t problems_before = problems_.size();
    if (vary) read_vary(vary);
    if (zip) read_zip(zip);
    if (cases) read_cases(cases);
    // `vary: {}` (or an empty zip:) names nothing to vary: the same answer as no vary: at all.
    if (s_.axes.empty() && s_.cases.empty() && problems_.size() == problems_before) {
      const YAML::Node& at = vary ? vary : zip ? zip : cases;
      const std::string section = vary ? "vary" : zip ? "zip" : "cases";
      error(at, section,
            "nothing varies: " + section + ": is empty; give vary: (a grid), zip: (lists taken together) or cases: (a "
            "list of runs), each with at least one scene key");
      return;
    }
    size_t runs = s_.axes.empty() ? 0 : 1;
    for (const SweepAxis& a : s_.axes) runs = std::min(kMaxRuns + 1, runs * a.size());
    if (runs > kMaxRuns) error(root, "sweep", "more than " + std::to_string(kMaxRuns) + " runs: split the sweep");
  }

 private:
  bool read_base(const YAML::Node& root) {
    const YAML::Node b = root["base"];
    if (!b) {
      error(root, "base", "missing: the base scene, e.g. base: ../scenes/probe.yaml (relative to the sweep file)");
      return false;
    }
    if (!b.IsScalar() || b.Scalar().empty()) {
      error(b, "base", "expected the base scene's file name, got " + kind(b));
      return false;
    }
    s_.base = (folder_ / b.Scalar()).lexically_normal();
    std::error_code ec;
    if (!fs::is_regular_file(s_.base, ec)) {
      const std::string what = !fs::exists(s_.base, ec) ? "no such scene file: " + s_.base.string()
                               : fs::is_directory(s_.base, ec)
                                   ? s_.base.string() + ": a folder, not a scene file"
                                   : s_.base.string() + ": not a regular file (a device or a pipe), not a scene file";
      error(b, "base", what + " (the base is relative to the sweep file)");
      return false;
    }
    // The base must be a valid scene itself: its problems are named in its own file.
    const SceneLoadResult base = load_scene(s_.base.string());
    for (const SceneProblem& p : base.problems) problems_.push_back(p);
    if (!base.ok()) {
      error(b, "base", "the base scene " + s_.base.string() + " has errors (above)");
      return false;
    }
    s_.base_yaml = YAML::LoadFile(s_.base.string());
    rebase_scene_files(s_.base_yaml, s_.base.parent_path());
    return true;
  }

  // The key `k` of the sweep file (at `at`): parsed and checked; its index in s_.keys, or -1.
  int key(const YAML::Node& at, const std::string& section) {
    const std::string text = at.Scalar();
    const std::string field = section + "." + text;
    ScenePath path;
    std::string why;
    if (!parse_scene_path(text, path, why) || !check_scene_path(path, s_.base_yaml, why)) {
      error(at, field, why);
      return -1;
    }
    for (size_t i = 0; i < s_.keys.size(); ++i)
      if (s_.keys[i].path.text == text) {
        if (section.compare(0, 5, "cases") != 0) {  // cases name a key in each run
          error(at, field, "'" + text + "' is varied twice (first at " + s_.keys[i].where + ")");
          return -1;
        }
        return static_cast<int>(i);
      }
    s_.keys.push_back({path, where(s_.file.string(), at)});
    return static_cast<int>(s_.keys.size() - 1);
  }

  SweepValue value(const YAML::Node& n, size_t key) {
    SweepValue v;
    v.node = YAML::Clone(n);
    rebase_below(v.node, value_table_path(s_.keys[key].path), folder_);
    v.text = one_line_yaml(n);
    v.where = where(s_.file.string(), n);
    return v;
  }

  // `section`'s keys, each with a non-empty list of values: an axis each (vary), or one axis
  // of them all (zip, every list as long as the first).
  void read_lists(const YAML::Node& map, const std::string& section, bool together) {
    if (!map.IsMap()) {
      error(map, section, "expected a mapping of scene keys to lists of values, e.g. organ.material.bulk_modulus: [10000, 20000], got " + kind(map));
      return;
    }
    SweepAxis zipped;
    std::string first_where;
    for (auto it = map.begin(); it != map.end(); ++it) {
      const int k = key(it->first, section);
      if (k < 0) continue;
      const std::string field = section + "." + it->first.Scalar();
      const YAML::Node list = it->second;
      if (!list.IsSequence() || list.size() == 0) {
        error(list, field, "expected a non-empty list of values, e.g. [10000, 20000], got " + (list.IsSequence() ? "an empty list" : kind(list)));
        continue;
      }
      std::vector<SweepValue> values;
      for (size_t i = 0; i < list.size(); ++i) values.push_back(value(list[i], size_t(k)));
      if (together && !zipped.values.empty() && values.size() != zipped.size()) {
        error(list, field,
              "zip: lists go together, so each has as many values as the first (" + std::to_string(zipped.size()) +
                  " at " + first_where + "); this one has " + std::to_string(values.size()));
        continue;
      }
      if (together && zipped.values.empty()) first_where = where(s_.file.string(), list);
      SweepAxis& axis = together ? zipped : (s_.axes.emplace_back(), s_.axes.back());
      axis.keys.push_back(size_t(k));
      axis.values.push_back(std::move(values));
    }
    if (together && !zipped.values.empty()) s_.axes.push_back(std::move(zipped));
  }

  void read_vary(const YAML::Node& vary) { read_lists(vary, "vary", false); }

  // One group (a mapping), or several (a list of mappings): an axis of the grid each.
  void read_zip(const YAML::Node& zip) {
    if (!zip.IsSequence()) return read_lists(zip, "zip", true);
    if (zip.size() == 0) {
      error(zip, "zip", "expected a mapping of scene keys to lists (one group), or a list of such mappings (several groups), got an empty list");
      return;
    }
    for (size_t g = 0; g < zip.size(); ++g) read_lists(zip[g], "zip[" + std::to_string(g) + "]", true);
  }

  void read_cases(const YAML::Node& cases) {
    if (!cases.IsSequence() || cases.size() == 0) {
      error(cases, "cases", "expected a non-empty list of runs, e.g. - {organ.material.bulk_modulus: 10000}, got " +
                                (cases.IsSequence() ? std::string("an empty list") : kind(cases)));
      return;
    }
    if (cases.size() > kMaxRuns) error(cases, "cases", "more than " + std::to_string(kMaxRuns) + " runs: split the sweep");
    for (size_t i = 0; i < cases.size() && i <= kMaxRuns; ++i) {
      const YAML::Node c = cases[i];
      const std::string field = "cases[" + std::to_string(i) + "]";
      if (c.IsMap() && c.size() == 0) {
        error(c, field, "an empty mapping: give at least one scene key and its value, e.g. {organ.material.bulk_modulus: 10000}");
        continue;
      }
      if (!c.IsMap()) {
        error(c, field, "expected a mapping of scene keys to values, e.g. {organ.material.bulk_modulus: 10000}, got " + kind(c));
        continue;
      }
      SweepCase run;
      for (auto it = c.begin(); it != c.end(); ++it) {
        const int k = key(it->first, field);
        if (k < 0) continue;
        const bool twice = std::any_of(run.settings.begin(), run.settings.end(), [&](const auto& s) { return s.first == size_t(k); });
        if (twice) error(it->first, field + "." + it->first.Scalar(), "duplicate key: give it once");
        else run.settings.emplace_back(size_t(k), value(it->second, size_t(k)));
      }
      s_.cases.push_back(std::move(run));
    }
  }

  SweepFile& s_;
  fs::path folder_;
  std::vector<SceneProblem>& problems_;
};

}  // namespace

std::string one_line_yaml(const YAML::Node& node) {
  // A scalar as written, unless a line break or another control character would break the
  // line: then double-quoted with YAML's escapes ("trial\nrender: ...").
  if (node.IsScalar()) {
    const std::string& text = node.Scalar();
    const bool controls = std::any_of(text.begin(), text.end(), [](char c) {
      const unsigned char u = static_cast<unsigned char>(c);
      return u < 0x20 || u == 0x7f;
    });
    const bool other_breaks = text.find("\u2028") != std::string::npos || text.find("\u2029") != std::string::npos ||
                              text.find("\xC2\x85") != std::string::npos;
    if (!controls && !other_breaks) return text;
    YAML::Emitter e;
    e.SetOutputCharset(YAML::EscapeNonAscii);
    e << YAML::DoubleQuoted << text;
    return e.c_str();
  }
  YAML::Emitter e;
  e.SetMapFormat(YAML::Flow);
  e.SetSeqFormat(YAML::Flow);
  e << node;
  return e.c_str();
}

namespace {

void emit_keeping_quotes(YAML::Emitter& e, const YAML::Node& node) {
  const std::string& tag = node.Tag();
  if (!tag.empty() && tag != "?" && tag != "!") e << YAML::VerbatimTag(tag);
  if (node.IsMap()) {
    if (node.Style() == YAML::EmitterStyle::Flow) e << YAML::Flow;
    e << YAML::BeginMap;
    for (auto it = node.begin(); it != node.end(); ++it) {
      e << YAML::Key;
      emit_keeping_quotes(e, it->first);
      e << YAML::Value;
      emit_keeping_quotes(e, it->second);
    }
    e << YAML::EndMap;
  } else if (node.IsSequence()) {
    if (node.Style() == YAML::EmitterStyle::Flow) e << YAML::Flow;
    e << YAML::BeginSeq;
    for (size_t i = 0; i < node.size(); ++i) emit_keeping_quotes(e, node[i]);
    e << YAML::EndSeq;
  } else if (node.IsScalar()) {
    // Quoted where it was written ("0.5", 'yes'): the tag "!" marks a quoted scalar.
    if (tag == "!") e << YAML::DoubleQuoted;
    e << node.Scalar();
  } else {
    e << YAML::Null;
  }
}

}  // namespace

std::string yaml_text_keeping_quotes(const YAML::Node& node) {
  YAML::Emitter e;
  emit_keeping_quotes(e, node);
  return e.c_str();
}

void rebase_scene_files(YAML::Node scene, const fs::path& folder) { rebase_below(scene, "", folder); }

bool read_sweep_file(const std::string& path, SweepFile& sweep, std::vector<SceneProblem>& problems) {
  const size_t before = problems.size();
  std::error_code ec;
  sweep = SweepFile{};
  sweep.file = path;  // as given, in the messages
  if (!fs::is_regular_file(path, ec)) {
    problems.push_back({path, "sweep", "no such sweep file", false});
    return false;
  }
  YAML::Node root;
  try {
    // One document, counted from its markers: yaml-cpp's LoadAll loops forever on some inputs.
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    int second_line = 0;
    if (count_yaml_documents(text, second_line) > 1) {
      problems.push_back({path + ":" + std::to_string(second_line) + ":1", "sweep",
                          "the file holds several YAML documents (separated by '---'); a sweep is one", false});
      return false;
    }
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream at;
    at << path << ':' << e.mark.line + 1 << ':' << e.mark.column + 1;
    problems.push_back({at.str(), "sweep", "not valid YAML: " + e.msg, false});
    return false;
  }
  const fs::path absolute = fs::absolute(path, ec).lexically_normal();
  SweepReader reader(sweep, absolute.parent_path(), problems);
  try {
    reader.read(root);
  } catch (const YAML::Exception& e) {
    problems.push_back({path, "sweep", std::string("cannot read: ") + e.what(), false});
  }
  sweep.file = absolute;
  return std::none_of(problems.begin() + long(before), problems.end(), [](const SceneProblem& p) { return !p.warning; });
}

}  // namespace vdmsim
