#include "app/sweep/sweep_plan.hpp"

#include <cstring>

#include "app/run/output_dir.hpp"

namespace vdmsim {
namespace {

// A run's short name: each varied key's last name with its value ("bulk_modulus-20000").
std::string short_name(const SweepFile& sweep, const std::vector<std::pair<size_t, const SweepValue*>>& settings) {
  std::string name;
  for (const auto& [key, value] : settings) {
    const std::string& leaf = sweep.keys[key].path.steps.back().name;
    const int index = sweep.keys[key].path.steps.back().index;
    const bool file = sweep.keys[key].path.type == KeyType::file;  // a mesh: its file name
    name += (name.empty() ? "" : "_") + leaf + (index >= 0 ? std::to_string(index) : "") + "-" +
            (file ? std::filesystem::path(value->text).filename().string() : value->text);
  }
  std::string safe = safe_folder_name(name.empty() ? "base" : name);
  if (safe.size() > 60) safe.resize(60);
  return safe;
}

// `text` for a one-line comment: a line break (or another control character) written as an
// escape, so that nothing after it becomes YAML of the scene.
std::string comment_text(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (u < 0x20 || u == 0x7f) out += '?';
    else out += c;
  }
  // Unicode's line and paragraph separators and NEL, which some YAML readers take for breaks.
  for (const char* brk : {"\u2028", "\u2029", "\xC2\x85"})
    for (size_t at = out.find(brk); at != std::string::npos; at = out.find(brk, at)) out.replace(at, std::strlen(brk), "?");
  return out;
}

PlannedRun make_run(const SweepFile& sweep, int index, int digits,
                    const std::vector<std::pair<size_t, const SweepValue*>>& settings) {
  PlannedRun run;
  run.index = index;
  std::string number = std::to_string(index);
  number.insert(0, size_t(std::max(0, digits - int(number.size()))), '0');
  run.folder = number + "_" + short_name(sweep, settings);
  run.values.assign(sweep.keys.size(), "");
  run.wheres.assign(sweep.keys.size(), "");
  YAML::Node scene = YAML::Clone(sweep.base_yaml);
  std::string said;
  for (const auto& [key, value] : settings) {
    set_scene_value(scene, sweep.keys[key].path, value->node);
    run.values[key] = value->text;
    run.wheres[key] = value->where;
    said += (said.empty() ? "" : ", ") + sweep.keys[key].path.text + " = " + value->text;
  }
  run.scene_text = "# " + comment_text("vdmsim sweep " + sweep.file.string() + ", run " + std::to_string(index) + ": " +
                                        sweep.base.string() + (said.empty() ? std::string() : " with " + said)) +
                   "\n" + yaml_text_keeping_quotes(scene) + "\n";
  return run;
}

}  // namespace

SweepPlan plan_sweep(const SweepFile& sweep) {
  SweepPlan plan;
  plan.sweep_file = sweep.file;
  for (const SweepKey& k : sweep.keys) plan.columns.push_back(k.path.text);
  size_t count = sweep.cases.size();
  if (!sweep.axes.empty()) {
    count = 1;
    for (const SweepAxis& a : sweep.axes) count *= a.size();
  }
  const int digits = std::max(3, int(std::to_string(count == 0 ? 0 : count - 1).size()));
  if (!sweep.axes.empty()) {
    for (size_t r = 0; r < count; ++r) {
      // The combination's position on each axis, the last axis fastest.
      std::vector<std::pair<size_t, const SweepValue*>> settings;
      size_t rest = r, stride = count;
      for (const SweepAxis& a : sweep.axes) {
        stride /= a.size();
        const size_t at = rest / stride;
        rest %= stride;
        for (size_t k = 0; k < a.keys.size(); ++k) settings.emplace_back(a.keys[k], &a.values[k][at]);
      }
      plan.runs.push_back(make_run(sweep, int(r), digits, settings));
    }
  } else {
    for (size_t r = 0; r < sweep.cases.size(); ++r) {
      std::vector<std::pair<size_t, const SweepValue*>> settings;
      for (const auto& [key, value] : sweep.cases[r].settings) settings.emplace_back(key, &value);
      plan.runs.push_back(make_run(sweep, int(r), digits, settings));
    }
  }
  return plan;
}

}  // namespace vdmsim
