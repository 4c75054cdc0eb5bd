#include "app/scene/organ_model_table.hpp"

#include <algorithm>

#include "app/scene/scene_keys.hpp"

namespace vdmsim {
namespace {

// Every key a row names is a key of the scene reader's table: an unknown path does not compile.
template <class Row>
constexpr bool keys_known() {
  for (const char* k : Row::keys) scene_key_index(k);
  for (const char* k : Row::material) scene_key_index(k);
  return true;
}

template <class Row>
OrganModel model_of() {
  static_assert(keys_known<Row>());
  OrganModel m;
  m.kind = Row::kind;
  m.keys.assign(Row::keys.begin(), Row::keys.end());
  m.material.assign(Row::material.begin(), Row::material.end());
  m.vdm_moduli = Row::vdm_moduli;
  m.surface_stress = Row::surface_stress;
  m.penalty_contact = Row::penalty_contact;
  m.inertia = Row::inertia;
  m.contact = Row::contact;
  return m;
}

template <class... Rows>
std::vector<OrganModel> models_of(RowList<Rows...>) {
  return {model_of<Rows>()...};
}

// Whether `path` is one of the keys in `list` or inside one of them (a section's keys).
bool covered(const std::vector<std::string>& list, const std::string& path) {
  return std::any_of(list.begin(), list.end(), [&](const std::string& k) {
    return path == k || (path.size() > k.size() && path.compare(0, k.size(), k) == 0 && path[k.size()] == '.');
  });
}

}  // namespace

const std::vector<OrganModel>& organ_models() {
  static const std::vector<OrganModel> models = models_of(OrganModelRows{});
  return models;
}

const OrganModel& organ_model(vdm::ModelKind kind) {
  const std::vector<OrganModel>& all = organ_models();
  const auto it = std::find_if(all.begin(), all.end(), [&](const OrganModel& m) { return m.kind == kind; });
  return it != all.end() ? *it : all.front();  // every ModelKind has a row (organ_model_table_test)
}

std::vector<std::string> organ_model_names() {
  std::vector<std::string> names;
  for (const OrganModel& m : organ_models()) names.push_back(m.name());
  return names;
}

std::vector<std::string> organ_model_names(bool OrganModel::*flag) {
  std::vector<std::string> names;
  for (const OrganModel& m : organ_models())
    if (m.*flag) names.push_back(m.name());
  return names;
}

std::vector<std::string> model_specific_keys() {
  std::vector<std::string> keys;
  for (const SceneKey& k : kSceneKeys)
    if (std::any_of(organ_models().begin(), organ_models().end(), [&](const OrganModel& m) { return covered(m.keys, k.path); }))
      keys.push_back(k.path);
  return keys;
}

bool OrganModel::uses(const std::string& path) const {
  if (covered(keys, path)) return true;
  return std::none_of(organ_models().begin(), organ_models().end(),
                      [&](const OrganModel& m) { return covered(m.keys, path); });
}

std::string or_list(const std::vector<std::string>& words) {
  std::string s;
  for (size_t i = 0; i < words.size(); ++i) s += (i == 0 ? "" : i + 1 == words.size() ? " or " : ", ") + words[i];
  return s;
}

}  // namespace vdmsim
