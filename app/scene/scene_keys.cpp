#include "app/scene/scene_keys.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

namespace vdmsim {

std::string yaml_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s << v;
  std::string t = s.str();
  // 1e-08 -> 1e-8, 1e+12 -> 1e12
  const size_t e = t.find('e');
  if (e != std::string::npos) {
    std::string mantissa = t.substr(0, e), exponent = t.substr(e + 1);
    const bool negative = exponent[0] == '-';
    if (exponent[0] == '-' || exponent[0] == '+') exponent.erase(0, 1);
    while (exponent.size() > 1 && exponent[0] == '0') exponent.erase(0, 1);
    t = mantissa + "e" + (negative ? "-" : "") + exponent;
  }
  return t;
}

std::string yaml_vector(const vdm::Vec3& v) {
  return "[" + yaml_number(v.x()) + ", " + yaml_number(v.y()) + ", " + yaml_number(v.z()) + "]";
}

std::string yaml_bool(bool b) { return b ? "true" : "false"; }

std::string scene_key_parent(const std::string& path) {
  const size_t dot = path.rfind('.');
  return dot == std::string::npos ? std::string() : path.substr(0, dot);
}

namespace {
bool has_word(const char* words, const char* word) {
  std::istringstream s(words);
  std::string w;
  while (s >> w)
    if (w == word) return true;
  return false;
}
}  // namespace

namespace {
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}
}  // namespace

std::string closest_name(const std::string& word, const std::vector<std::string>& known) {
  std::string best;
  size_t best_d = 1000;
  for (const auto& k : known) {
    const size_t d = edit_distance(word, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best_d <= std::max<size_t>(2, word.size() / 3) ? best : "";
}

std::vector<std::string> scene_key_names(const std::string& parent, const char* shape) {
  std::vector<std::string> names;
  for (const SceneKey& k : kSceneKeys) {
    if (k.type == KeyType::region) continue;  // not a key of its own
    const std::string path = k.path;
    if (scene_key_parent(path) != parent) continue;
    if (shape && k.shapes && !has_word(k.shapes, shape)) continue;
    names.push_back(parent.empty() ? path : path.substr(parent.size() + 1));
  }
  return names;
}

}  // namespace vdmsim
