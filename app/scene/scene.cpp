#include "app/scene/scene.hpp"

#include "app/scene/utf8.hpp"
#include "app/scene/yaml_documents.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <fstream>
#include <iterator>
#include <sstream>

#include "app/scene/scene_keys.hpp"
#include "engine/elastic_moduli.hpp"

namespace vdmsim {
namespace {

const double kInf = std::numeric_limits<double>::infinity();

// The table's entry of a key path (app/scene/scene_keys.hpp); an unknown path does not compile.
#define KEY(path) VDMSIM_SCENE_KEY(path)

std::string closest(const std::string& word, const std::vector<std::string>& known) { return closest_name(word, known); }

std::string join(const std::vector<std::string>& words) {
  std::string s;
  for (size_t i = 0; i < words.size(); ++i) s += (i ? ", " : "") + words[i];
  return s;
}

// Reads typed values out of YAML nodes, recording every problem with its position.
class Reader {
 public:
  Reader(std::string file, std::vector<SceneProblem>& out) : file_(std::move(file)), out_(out) {}

  std::string where(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    std::ostringstream s;
    s << file_;
    if (m.line >= 0) s << ':' << m.line + 1 << ':' << m.column + 1;
    return s.str();
  }
  void error(const YAML::Node& at, const std::string& field, const std::string& msg) {
    out_.push_back({where(at), field, msg, false});
  }
  void warn(const YAML::Node& at, const std::string& field, const std::string& msg) {
    out_.push_back({where(at), field, msg, true});
  }
  static std::string sub(const std::string& parent, const std::string& key) {
    return parent.empty() ? key : parent + "." + key;
  }
  static std::string item(const std::string& parent, size_t i) {
    return parent + "[" + std::to_string(i) + "]";
  }

  // Warns about keys that `map` should not have, suggesting the closest known one.
  void check_keys(const YAML::Node& map, const std::string& field, const std::vector<std::string>& known) {
    if (!map.IsMap()) return;
    std::vector<std::pair<std::string, int>> seen;  // key, its line (from 1)
    for (auto it = map.begin(); it != map.end(); ++it) {
      const std::string key = it->first.Scalar();
      // YAML tools disagree on which of two equal keys wins (this reader took the first,
      // others the last): a scene says it once.
      const auto first = std::find_if(seen.begin(), seen.end(), [&](const auto& k) { return k.first == key; });
      if (first != seen.end()) {
        error(it->first, sub(field, key),
              "duplicate key '" + key + "' (first at line " + std::to_string(first->second) + "): give it once");
        continue;
      }
      seen.emplace_back(key, it->first.Mark().line + 1);
      if (key == "<<") {
        error(it->first, field, "YAML merge keys (<<) are not supported: write the keys out");
        continue;
      }
      if (std::find(known.begin(), known.end(), key) != known.end()) continue;
      const std::string near = closest(key, known);
      warn(it->first, sub(field, key),
           "unknown key '" + key + "', ignored" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
               "; known keys: " + join(known));
    }
  }

  // The keys of the table's mapping `table_path` (scene_keys.hpp), and for a region those of
  // `extra` (the list's own keys) after them; for instruments[].shape those of `shape`.
  void check_keys(const YAML::Node& map, const std::string& field, const char* table_path, const char* shape = nullptr,
                  const char* extra = nullptr) {
    if (!map.IsMap()) return;
    std::vector<std::string> known = scene_key_names(table_path, shape);
    if (extra) {
      const std::vector<std::string> more = scene_key_names(extra);
      known.insert(known.end(), more.begin(), more.end());
    }
    check_keys(map, field, known);
  }

  bool require_map(const YAML::Node& n, const std::string& field) {
    if (n.IsMap()) return true;
    error(n, field, std::string("expected a mapping (key: value lines), got ") + kind(n));
    return false;
  }
  bool require_sequence(const YAML::Node& n, const std::string& field) {
    if (n.IsSequence()) return true;
    error(n, field, std::string("expected a list, got ") + kind(n));
    return false;
  }
  static const char* kind(const YAML::Node& n) {
    switch (n.Type()) {
      case YAML::NodeType::Null: return "nothing";
      case YAML::NodeType::Scalar: return "a single value";
      case YAML::NodeType::Sequence: return "a list";
      case YAML::NodeType::Map: return "a mapping";
      default: return "an undefined value";
    }
  }

  // A number in [lo, hi] (SI units, said in `unit`); "inf" only when `allow_inf`.
  bool number(const YAML::Node& n, const std::string& field, double& out, double lo, double hi,
              const char* unit, bool allow_inf = false, bool lo_open = false) {
    if (!n.IsScalar()) {
      error(n, field, std::string("expected a number") + unit_text(unit) + ", got " + kind(n));
      return false;
    }
    const std::string text = n.Scalar();
    double v = 0;
    if (allow_inf && (text == "inf" || text == ".inf" || text == "infinity")) {
      v = kInf;
    } else {
      char* end = nullptr;
      errno = 0;
      v = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) {
        std::string msg = std::string("expected a number") + unit_text(unit) + ", got '" + text + "'";
        if (end != text.c_str() && *end != '\0') msg += " (write plain SI numbers, without units)";
        error(n, field, msg);
        return false;
      }
    }
    if (!(lo_open ? v > lo : v >= lo) || v > hi) {
      std::ostringstream m;
      m << "value " << text << " is out of range: expected " << (lo_open ? "> " : ">= ") << lo;
      if (hi < kInf) m << " and <= " << hi;
      if (allow_inf) m << " (or inf)";
      m << unit_text(unit);
      error(n, field, m.str());
      return false;
    }
    out = v;
    return true;
  }

  // A number in the range and unit the table gives the key.
  bool number(const YAML::Node& n, const std::string& field, double& out, const SceneKey& k) {
    return number(n, field, out, k.lo, k.hi, k.unit, k.allow_inf, k.lo_open);
  }
  // A whole number in the table's range (messages name no unit).
  bool integer(const YAML::Node& n, const std::string& field, int& out, const SceneKey& k) {
    return integer(n, field, out, static_cast<long>(k.lo), static_cast<long>(k.hi));
  }
  bool vec3(const YAML::Node& n, const std::string& field, vdm::Vec3& out, const SceneKey& k) {
    return vec3(n, field, out, k.unit);
  }

  bool integer(const YAML::Node& n, const std::string& field, int& out, long lo, long hi) {
    double v = 0;
    if (!number(n, field, v, static_cast<double>(lo), static_cast<double>(hi), "")) return false;
    if (v != std::floor(v)) {
      error(n, field, "expected a whole number, got '" + n.Scalar() + "'");
      return false;
    }
    out = static_cast<int>(v);
    return true;
  }

  bool vec3(const YAML::Node& n, const std::string& field, vdm::Vec3& out, const char* unit) {
    if (!n.IsSequence() || n.size() != 3) {
      error(n, field, std::string("expected three numbers [x, y, z]") + unit_text(unit) + ", got " +
                          (n.IsSequence() ? std::to_string(n.size()) + " values" : kind(n)));
      return false;
    }
    bool ok = true;
    for (int d = 0; d < 3; ++d)
      ok = number(n[d], item(field, d), out[d], -kInf, kInf, unit) && ok;
    return ok;
  }

  bool text(const YAML::Node& n, const std::string& field, std::string& out) {
    if (!n.IsScalar()) {
      error(n, field, std::string("expected a text value, got ") + kind(n));
      return false;
    }
    out = n.Scalar();
    return true;
  }

  bool boolean(const YAML::Node& n, const std::string& field, bool& out) {
    if (n.IsScalar()) {
      const std::string t = n.Scalar();
      if (t == "true" || t == "yes" || t == "on") return out = true, true;
      if (t == "false" || t == "no" || t == "off") return out = false, true;
    }
    error(n, field, "expected true or false");
    return false;
  }

  // A required key: reports its absence at the parent's position.
  YAML::Node required(const YAML::Node& map, const char* key, const std::string& field, const char* what) {
    const YAML::Node n = map[key];
    if (!n) error(map, sub(field, key), std::string("missing required field '") + key + "': " + what);
    return n;
  }

 private:
  static std::string unit_text(const char* unit) {
    return unit && *unit ? std::string(" (") + unit + ")" : std::string();
  }
  std::string file_;
  std::vector<SceneProblem>& out_;
};

// A region; `list_item` is the table path of the list's items (organ.fixed[], ...), whose own
// keys are allowed beside the region's.
void read_region(Reader& r, const YAML::Node& n, const std::string& field, Region& out, const char* list_item) {
  out.where = r.where(n);
  r.check_keys(n, field, "region", nullptr, list_item);
  int kinds = 0;
  if (const YAML::Node b = n["box"]) {
    ++kinds;
    out.kind = Region::Kind::box;
    if (r.require_map(b, Reader::sub(field, "box"))) {
      r.check_keys(b, Reader::sub(field, "box"), "region.box");
      const YAML::Node mn = r.required(b, "min", Reader::sub(field, "box"), "the box's lower corner [x, y, z] (m)");
      const YAML::Node mx = r.required(b, "max", Reader::sub(field, "box"), "the box's upper corner [x, y, z] (m)");
      if (mn && mx && r.vec3(mn, Reader::sub(field, "box.min"), out.min, KEY("region.box.min")) &&
          r.vec3(mx, Reader::sub(field, "box.max"), out.max, KEY("region.box.max")) && (out.max - out.min).minCoeff() < 0)
        r.error(mx, Reader::sub(field, "box.max"), "each coordinate of max must be >= the same coordinate of min");
    }
  }
  if (const YAML::Node s = n["sphere"]) {
    ++kinds;
    out.kind = Region::Kind::sphere;
    if (r.require_map(s, Reader::sub(field, "sphere"))) {
      r.check_keys(s, Reader::sub(field, "sphere"), "region.sphere");
      const YAML::Node c = r.required(s, "center", Reader::sub(field, "sphere"), "[x, y, z] (m)");
      const YAML::Node rad = r.required(s, "radius", Reader::sub(field, "sphere"), "a radius > 0 (m)");
      if (c) r.vec3(c, Reader::sub(field, "sphere.center"), out.center, KEY("region.sphere.center"));
      if (rad) r.number(rad, Reader::sub(field, "sphere.radius"), out.radius, KEY("region.sphere.radius"));
    }
  }
  if (const YAML::Node list = n["nodes"]) {
    ++kinds;
    out.kind = Region::Kind::nodes;
    if (r.require_sequence(list, Reader::sub(field, "nodes"))) {
      for (size_t i = 0; i < list.size(); ++i) {
        int id = 0;
        if (r.integer(list[i], Reader::item(Reader::sub(field, "nodes"), i), id, KEY("region.nodes"))) out.nodes.push_back(id);
      }
      if (list.size() == 0) r.error(list, Reader::sub(field, "nodes"), "the node list is empty");
    }
  }
  if (const YAML::Node a = n["all"]) {
    ++kinds;
    out.kind = Region::Kind::all;
    bool yes = false;
    if (r.boolean(a, Reader::sub(field, "all"), yes) && !yes)
      r.error(a, Reader::sub(field, "all"), "'all: false' selects nothing; remove the entry instead");
  }
  if (kinds != 1)
    r.error(n, field,
            kinds == 0 ? "expected a region: one of box: {min, max}, sphere: {center, radius}, nodes: [...], all: true"
                       : "give exactly one region (box, sphere, nodes or all), not several");
}

void read_ramp(Reader& r, const YAML::Node& n, const std::string& field, const SceneKey& key, double& t0, double& t1) {
  const YAML::Node t = n["t"];
  if (!t) return;  // default [0, 0]: applied in full from the start
  if (!t.IsSequence() || t.size() != 2) {
    r.error(t, Reader::sub(field, "t"), "expected [t_start, t_end] (s)");
    return;
  }
  if (r.number(t[0], Reader::sub(field, "t[0]"), t0, key) && r.number(t[1], Reader::sub(field, "t[1]"), t1, key) && t1 < t0)
    r.error(t, Reader::sub(field, "t"), "t_end must not come before t_start");
}

// VDM's moduli must couple the nodes: with the skin's modulus far below the bulk term (above
// kMaxBulkToConnectivity) the pressure's rank-one coupling cancels in floating point and the
// free nodes are thrown centimetres out under a probe held still (measured on the 2.5k liver
// probe: ratios 1e4, 1e6 and 1e8 give the probe's 14.1 mm dent, 1e10 gives 48 mm, 5e11 gives
// 163 mm); with none (0) the nodes are not coupled at all.
constexpr double kMaxBulkToConnectivity = 1e9;
void check_vdm_conditioning(Reader& r, const YAML::Node& mat, const OrganDef& o) {
  const std::string& f = o.field;
  double bulk = 0;
  for (int d = 0; d < 3; ++d)
    if (std::isfinite(o.bulk_modulus[d])) bulk = std::max(bulk, o.bulk_modulus[d]);
  const YAML::Node at = mat["connectivity_modulus"] ? mat["connectivity_modulus"] : mat;
  if (o.connectivity_modulus == 0.0) {
    r.error(at, f + ".material.connectivity_modulus",
            "must be > 0 for model vdm: without the skin's modulus no node is coupled to its neighbours (a tenth of "
            "bulk_modulus is a usual start)");
  } else if (bulk / o.connectivity_modulus > kMaxBulkToConnectivity) {
    std::ostringstream msg;
    msg << "bulk_modulus / connectivity_modulus = " << bulk / o.connectivity_modulus << " is above "
        << kMaxBulkToConnectivity << ": the system cannot be solved reliably (its pressure coupling cancels in floating "
        << "point); raise connectivity_modulus or lower bulk_modulus";
    r.error(at, f + ".material.connectivity_modulus", msg.str());
  }
}

// Below it, a Poisson's ratio on the core is warned: the core cannot compress.
constexpr double kCoreLeastPoissonRatio = 0.4;

// The node at a dotted path under `at` (undefined when a key on the way is missing or not a map).
YAML::Node node_at(const YAML::Node& at, const std::string& path, size_t from = 0) {
  if (!at.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const size_t dot = std::min(path.find('.', from), path.size());
  const YAML::Node next = at[path.substr(from, dot - from)];
  if (!next || dot == path.size()) return next;
  return node_at(next, path, dot + 1);
}

// Warns about the keys that an organ's model does not use (they would change nothing): the
// outermost of them present, once (a section, not also each key in it). An organ's own keys
// (organ.*) are looked up in its mapping `organ` (named by its field); the others (a section
// of the scene's that only some models use) in `root`, warned when no organ's model uses them.
void warn_unused_by_model(Reader& r, const YAML::Node& root, const YAML::Node& organ, const OrganDef& o,
                          const SceneDef& s) {
  const OrganModel& m = organ_model(o.model);
  const std::string prefix = "organ.";
  const bool first = &o == &s.organ();
  std::string warned;  // the last key warned about
  for (const std::string& path : model_specific_keys()) {
    if (m.uses(path)) continue;
    if (!warned.empty() && path.compare(0, warned.size() + 1, warned + ".") == 0) continue;
    const bool own = path.compare(0, prefix.size(), prefix) == 0;
    if (!own && (!first || std::any_of(s.organs.begin(), s.organs.end(),
                                       [&](const OrganDef& other) { return organ_model(other.model).uses(path); })))
      continue;
    const YAML::Node n = own ? node_at(organ, path, prefix.size()) : node_at(root, path);
    if (!n) continue;
    r.warn(n, own ? o.field + path.substr(prefix.size() - 1) : path,
           "ignored by " + o.field + ".model " + m.name() + " (docs/scene-reference.md says which models use it)");
    warned = path;
  }
}

// Without organ.model, a material key only the paper's model uses (its moduli, its capsule's)
// keeps that model, with a note; every other material (E and nu, or none) gets the default.
void select_model_by_material(Reader& r, const YAML::Node& organ, OrganDef& o) {
  const YAML::Node mat = organ["material"];
  if (!mat || !mat.IsMap()) return;
  const auto only_vdm = [](const std::string& path) {
    return std::none_of(organ_models().begin(), organ_models().end(),
                        [&](const OrganModel& m) { return m.kind != vdm::ModelKind::vdm && m.uses(path); });
  };
  for (auto it = mat.begin(); it != mat.end(); ++it) {  // the first such key in the file
    const std::string key = it->first.as<std::string>("");
    if (!only_vdm("organ.material." + key)) continue;
    o.model = vdm::ModelKind::vdm;
    r.warn(it->second, o.field + ".material." + key,
           std::string("selects the paper's model (organ.model: vdm); the default model ") +
               vdm::to_string(kDefaultOrganModel) +
               " takes young_modulus and poisson_ratio (docs/model.md); write organ.model: vdm to keep this one "
               "without this note");
    return;
  }
}

void read_organ(Reader& r, const YAML::Node& organ, OrganDef& o, const std::filesystem::path& base) {
  const std::string& f = o.field;
  if (!r.require_map(organ, f)) return;
  r.check_keys(organ, f, "organ", nullptr, f == "organ" ? nullptr : "organs[]");
  if (const YAML::Node m = r.required(organ, "mesh", f, "the organ's surface mesh file (relative to the scene)")) {
    std::string rel;
    if (r.text(m, f + ".mesh", rel)) {
      const std::filesystem::path p = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : base / rel;
      o.mesh_path = p.lexically_normal().string();
      std::error_code ec;
      if (!std::filesystem::is_regular_file(o.mesh_path, ec))
        r.error(m, f + ".mesh", "mesh file not found: " + o.mesh_path);
    }
  }
  if (const YAML::Node n = organ["look"]) {
    std::string look;
    if (r.text(n, f + ".look", look)) {
      if (look == "liver" || look == "gallbladder") o.gallbladder_look = look == "gallbladder";
      else r.error(n, f + ".look", "unknown look '" + look + "'; expected liver or gallbladder");
    }
  }
  if (const YAML::Node n = organ["scale"]) r.number(n, f + ".scale", o.scale, KEY("organ.scale"));
  if (const YAML::Node n = organ["rotate_deg"]) r.vec3(n, f + ".rotate_deg", o.rotate_deg, KEY("organ.rotate_deg"));
  if (const YAML::Node n = organ["translate"]) r.vec3(n, f + ".translate", o.translate, KEY("organ.translate"));
  if (const YAML::Node n = organ["model"]) {
    std::string model;
    if (r.text(n, f + ".model", model) && !vdm::parse_model_kind(model, o.model)) {
      const std::string near = closest(model, organ_model_names());
      r.error(n, f + ".model", "unknown model '" + model + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                    "; expected " + or_list(organ_model_names()));
    }
  }
  if (!organ["model"]) select_model_by_material(r, organ, o);
  if (const YAML::Node n = organ["tet_size"]) r.number(n, f + ".tet_size", o.tet_size, KEY("organ.tet_size"));
  if (const YAML::Node n = organ["cell_size"]) {
    r.number(n, f + ".cell_size", o.cell_size, KEY("organ.cell_size"));
    o.cell_size_where = r.where(n);
  }
  if (const YAML::Node mat = organ["material"]) {
    if (r.require_map(mat, f + ".material")) {
      r.check_keys(mat, f + ".material", "organ.material");
      if (const YAML::Node n = mat["young_modulus"])
        r.number(n, f + ".material.young_modulus", o.young_modulus, KEY("organ.material.young_modulus"));
      if (const YAML::Node n = mat["poisson_ratio"]) {
        double nu = 0;
        if (r.number(n, f + ".material.poisson_ratio", nu, KEY("organ.material.poisson_ratio"))) {
          if (nu >= 0.5)
            r.error(n, f + ".material.poisson_ratio",
                    "value " + n.Scalar() + " is out of range: expected >= 0 and < 0.5 (0.5 is exactly incompressible; use up to 0.49)");
          else
            o.poisson_ratio = nu;
        }
      }
      if (const YAML::Node n = mat["thickness"]) r.number(n, f + ".material.thickness", o.thickness, KEY("organ.material.thickness"));
      if (const YAML::Node n = mat["volume_modulus"]) r.number(n, f + ".material.volume_modulus", o.volume_modulus, KEY("organ.material.volume_modulus"));
      if (const YAML::Node b = mat["bulk_modulus"]) {
        if (b.IsSequence()) {
          if (b.size() != 3) {
            r.error(b, f + ".material.bulk_modulus", "expected one modulus or three [bx, by, bz] (Pa)");
          } else {
            for (int d = 0; d < 3; ++d)
              r.number(b[d], Reader::item(f + ".material.bulk_modulus", d), o.bulk_modulus[d], KEY("organ.material.bulk_modulus"));
          }
        } else {
          double v = 0;
          if (r.number(b, f + ".material.bulk_modulus", v, KEY("organ.material.bulk_modulus"))) o.bulk_modulus.setConstant(v);
        }
      }
      if (const YAML::Node n = mat["connectivity_modulus"])
        r.number(n, f + ".material.connectivity_modulus", o.connectivity_modulus, KEY("organ.material.connectivity_modulus"));
      if (const YAML::Node n = mat["capsule"]) {
        std::string form;
        if (r.text(n, f + ".material.capsule", form) && !vdm::parse_capsule_form(form, o.capsule))
          r.error(n, f + ".material.capsule", "unknown capsule '" + form + "'; expected membrane, corotational or paper");
      }
      if (const YAML::Node n = mat["bending_modulus"]) {
        if (r.number(n, f + ".material.bending_modulus", o.bending_modulus, KEY("organ.material.bending_modulus")) &&
            o.bending_modulus > 0 && o.capsule == vdm::CapsuleForm::paper)
          r.error(n, f + ".material.bending_modulus",
                  "needs a membrane capsule (capsule: membrane or corotational); the paper's capsule has no bending term");
      }
      if (const YAML::Node n = mat["density"]) r.number(n, f + ".material.density", o.density, KEY("organ.material.density"));
      if (const YAML::Node n = mat["damping"]) r.number(n, f + ".material.damping", o.damping, KEY("organ.material.damping"));
      // VDM from E and nu: the documented rule (engine/elastic_moduli.hpp); one form or the other.
      if (organ_model(o.model).vdm_moduli && (mat["young_modulus"] || mat["poisson_ratio"])) {
        if (mat["bulk_modulus"] || mat["connectivity_modulus"]) {
          r.error(mat, f + ".material",
                  "give either young_modulus and poisson_ratio (mapped to VDM's moduli, docs/model.md) or bulk_modulus "
                  "and connectivity_modulus, not both");
        } else if (!mat["young_modulus"]) {
          r.error(mat, f + ".material", "poisson_ratio needs young_modulus (Pa) beside it");
        } else {
          const vdm::VdmModuli moduli = vdm::vdm_moduli_from_elastic(o.young_modulus, o.poisson_ratio);
          o.bulk_modulus.setConstant(moduli.bulk);
          o.connectivity_modulus = moduli.connectivity;
          o.moduli_from_elastic = true;
        }
      }
      if (organ_model(o.model).vdm_moduli) check_vdm_conditioning(r, mat, o);
      // The core keeps the organ's volume whatever nu is (its fluid is incompressible).
      if (o.model == vdm::ModelKind::vdm_core && mat["poisson_ratio"] && o.poisson_ratio < kCoreLeastPoissonRatio)
        r.warn(mat["poisson_ratio"], f + ".material.poisson_ratio",
               "model vdm_core keeps the organ's volume (nearly incompressible tissue, nu 0.45-0.49); a compressible "
               "material needs organ.model: fem");
      o.material_given = true;
    }
  }
  if (const YAML::Node list = organ["fixed"]) {
    if (r.require_sequence(list, f + ".fixed"))
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string fi = Reader::item(f + ".fixed", i);
        if (!r.require_map(list[i], fi)) continue;
        FixedDef fd;
        read_region(r, list[i], fi, fd.region, "organ.fixed[]");
        if (const YAML::Node axes = list[i]["axes"]) {
          fd.axes = {false, false, false};
          if (r.require_sequence(axes, Reader::sub(fi, "axes")))
            for (size_t a = 0; a < axes.size(); ++a) {
              const std::string name = axes[a].IsScalar() ? axes[a].Scalar() : "";
              if (name == "x" || name == "y" || name == "z") fd.axes[name[0] - 'x'] = true;
              else r.error(axes[a], Reader::item(Reader::sub(fi, "axes"), a), "expected x, y or z");
            }
        }
        o.fixed.push_back(fd);
      }
  }
  if (const YAML::Node list = organ["loads"]) {
    if (r.require_sequence(list, f + ".loads"))
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string fi = Reader::item(f + ".loads", i);
        if (!r.require_map(list[i], fi)) continue;
        LoadDef ld;
        read_region(r, list[i], fi, ld.region, "organ.loads[]");
        if (const YAML::Node fo = r.required(list[i], "force", fi, "the total force [fx, fy, fz] (N)"))
          r.vec3(fo, Reader::sub(fi, "force"), ld.force, KEY("organ.loads[].force"));
        read_ramp(r, list[i], fi, KEY("organ.loads[].t"), ld.t0, ld.t1);
        o.loads.push_back(ld);
      }
  }
  if (const YAML::Node list = organ["prescribed"]) {
    if (r.require_sequence(list, f + ".prescribed"))
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string fi = Reader::item(f + ".prescribed", i);
        if (!r.require_map(list[i], fi)) continue;
        PrescribedDef pd;
        read_region(r, list[i], fi, pd.region, "organ.prescribed[]");
        if (const YAML::Node n = list[i]["translate"]) r.vec3(n, Reader::sub(fi, "translate"), pd.translate, KEY("organ.prescribed[].translate"));
        if (const YAML::Node n = list[i]["rotate_deg"]) r.vec3(n, Reader::sub(fi, "rotate_deg"), pd.rotate_deg, KEY("organ.prescribed[].rotate_deg"));
        if (const YAML::Node n = list[i]["about"]) {
          vdm::Vec3 c;
          if (r.vec3(n, Reader::sub(fi, "about"), c, KEY("organ.prescribed[].about"))) pd.about = c;
        }
        if (!list[i]["translate"] && !list[i]["rotate_deg"])
          r.error(list[i], fi, "a prescribed motion needs translate: [dx, dy, dz] (m) and/or rotate_deg: [ax, ay, az]");
        read_ramp(r, list[i], fi, KEY("organ.prescribed[].t"), pd.t0, pd.t1);
        o.prescribed.push_back(pd);
      }
  }
}

// `organs:`, a list of organs: each an organ mapping with a `name` of its own.
void read_organs(Reader& r, const YAML::Node& list, SceneDef& s, const std::filesystem::path& base) {
  if (!r.require_sequence(list, "organs")) return;
  if (list.size() == 0) {
    r.error(list, "organs", "expected at least one organ");
    return;
  }
  s.organs.clear();
  for (size_t i = 0; i < list.size(); ++i) {
    OrganDef o;
    o.field = Reader::item("organs", i);
    o.name.clear();
    if (list[i].IsMap())
      if (const YAML::Node n = r.required(list[i], "name", o.field, "the organ's name, unique in the scene")) {
        const std::string field = o.field + ".name";
        if (r.text(n, field, o.name)) {
          const bool word = !o.name.empty() && std::all_of(o.name.begin(), o.name.end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
          });
          const auto same = std::find_if(s.organs.begin(), s.organs.end(), [&](const OrganDef& e) { return e.name == o.name; });
          if (!word)
            r.error(n, field, "'" + o.name + "': expected letters, digits, _ and - only (it names the organ's files and columns)");
          else if (same != s.organs.end())
            r.error(n, field, "'" + o.name + "' is the name of " + same->field + " already: names are unique");
        }
      }
    read_organ(r, list[i], o, base);
    s.organs.push_back(o);
  }
}

// `attachments:`, ties between the organs named.
void read_attachments(Reader& r, const YAML::Node& list, SceneDef& s) {
  if (!r.require_sequence(list, "attachments")) return;
  for (size_t i = 0; i < list.size(); ++i) {
    AttachmentDef a;
    a.field = Reader::item("attachments", i);
    const YAML::Node n = list[i];
    if (!r.require_map(n, a.field)) continue;
    r.check_keys(n, a.field, "attachments[]");
    bool ok = true;
    if (const YAML::Node b = r.required(n, "between", a.field, "[organ name, organ name]")) {
      const std::string fb = Reader::sub(a.field, "between");
      if (!b.IsSequence() || b.size() != 2) {
        r.error(b, fb, "expected two organ names: [first, second] (the first's nodes are tied to the second's surface)");
        ok = false;
      } else {
        std::vector<std::string> names;
        for (const OrganDef& o : s.organs) names.push_back(o.name);
        for (size_t k = 0; k < 2; ++k) {
          std::string name;
          if (!r.text(b[k], Reader::item(fb, k), name)) {
            ok = false;
            continue;
          }
          const auto at = std::find(names.begin(), names.end(), name);
          if (at == names.end()) {
            const std::string near = closest_name(name, names);
            r.error(b[k], Reader::item(fb, k), "no organ is named '" + name + "'" +
                                                   (near.empty() ? "" : " (did you mean '" + near + "'?)"));
            ok = false;
          } else {
            (k == 0 ? a.first : a.second) = static_cast<int>(at - names.begin());
          }
        }
        if (ok && a.first == a.second) {
          r.error(b, fb, "an organ is not attached to itself: name two different organs");
          ok = false;
        }
      }
    } else {
      ok = false;
    }
    if (const YAML::Node w = r.required(n, "within", a.field, "how near (m)"))
      ok = r.number(w, Reader::sub(a.field, "within"), a.within, KEY("attachments[].within")) && ok;
    else
      ok = false;
    if (const YAML::Node k = n["stiffness"])
      ok = r.number(k, Reader::sub(a.field, "stiffness"), a.stiffness, KEY("attachments[].stiffness")) && ok;
    if (const YAML::Node t = n["tear_force"])
      ok = r.number(t, Reader::sub(a.field, "tear_force"), a.tear_force, KEY("attachments[].tear_force")) && ok;
    if (ok) s.attachments.push_back(a);
  }
}

// The first organ whose model lacks `flag` (organ_model_table.hpp), or null.
const OrganDef* first_without(const SceneDef& s, bool OrganModel::*flag) {
  for (const OrganDef& o : s.organs)
    if (!(organ_model(o.model).*flag)) return &o;
  return nullptr;
}

// An organ's model in a message: its name, and with several organs which organ has it.
std::string model_named(const SceneDef& s, const OrganDef& o) {
  const std::string model = vdm::to_string(o.model);
  return s.organs.size() > 1 ? o.field + ".model " + model : model;
}

void read_simulation(Reader& r, const YAML::Node& sim, SceneDef& s) {
  const std::string f = "simulation";
  if (!r.require_map(sim, f)) return;
  r.check_keys(sim, f, "simulation");
  if (const YAML::Node n = sim["frames"]) r.integer(n, "simulation.frames", s.frames, KEY("simulation.frames"));
  if (const YAML::Node n = sim["dt"]) r.number(n, "simulation.dt", s.dt, KEY("simulation.dt"));
  if (const YAML::Node n = sim["gravity"]) r.vec3(n, "simulation.gravity", s.gravity, KEY("simulation.gravity"));
  if (const YAML::Node n = sim["volume_constraint"]) r.boolean(n, "simulation.volume_constraint", s.volume_constraint);
  if (const YAML::Node list = sim["effects"]) {
    const std::vector<std::string> known = KEY("simulation.effects").values();  // in the order of Effect
    if (r.require_sequence(list, "simulation.effects"))
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string fi = Reader::item("simulation.effects", i);
        std::string name;
        if (!r.text(list[i], fi, name)) continue;
        const auto it = std::find(known.begin(), known.end(), name);
        if (it == known.end()) {
          const std::string near = closest(name, known);
          r.error(list[i], fi, "unknown effect '" + name + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                   "; known effects: " + join(known));
          continue;
        }
        const Effect e = static_cast<Effect>(it - known.begin());
        if (std::find(s.effects.begin(), s.effects.end(), e) == s.effects.end()) s.effects.push_back(e);
        if (const OrganDef* o = first_without(s, &OrganModel::inertia); e == Effect::inertia && o)
          r.warn(list[i], fi,
                 "ignored by " + o->field + ".model " + vdm::to_string(o->model) + ": its steps are static (inertia needs organ.model " +
                     or_list(organ_model_names(&OrganModel::inertia)) + ")");
      }
  }
  if (const YAML::Node sol = sim["solver"]) {
    if (r.require_map(sol, "simulation.solver")) {
      r.check_keys(sol, "simulation.solver", "simulation.solver");
      if (const YAML::Node n = sol["method"]) {
        std::string m;
        if (r.text(n, "simulation.solver.method", m) && !vdm::parse_solver_method(m, s.solver.method))
          r.error(n, "simulation.solver.method", "unknown solver '" + m + "' (expected reference, structured or direct)");
      }
      if (const YAML::Node n = sol["tolerance"])
        r.number(n, "simulation.solver.tolerance", s.solver.tolerance, KEY("simulation.solver.tolerance"));
      if (const YAML::Node n = sol["max_iterations"]) r.integer(n, "simulation.solver.max_iterations", s.solver.max_iterations, KEY("simulation.solver.max_iterations"));
      if (const YAML::Node n = sol["refresh_every"]) r.integer(n, "simulation.solver.refresh_every", s.solver.refresh_every, KEY("simulation.solver.refresh_every"));
      if (const YAML::Node n = sol["nonlinear_iterations"])
        r.integer(n, "simulation.solver.nonlinear_iterations", s.solver.nonlinear_iterations, KEY("simulation.solver.nonlinear_iterations"));
      if (const YAML::Node n = sol["volume_corrections"])
        r.integer(n, "simulation.solver.volume_corrections", s.solver.volume_corrections, KEY("simulation.solver.volume_corrections"));
      if (const YAML::Node n = sol["volume_tolerance"])
        r.number(n, "simulation.solver.volume_tolerance", s.solver.volume_tolerance, KEY("simulation.solver.volume_tolerance"));
      if (const YAML::Node n = sol["warm_start"]) r.boolean(n, "simulation.solver.warm_start", s.solver.warm_start);
    }
  }
  // The model's own contact method unless the scene names one (organ_model_table.hpp).
  if (!(sim["contact"] && sim["contact"].IsMap() && sim["contact"]["method"]))
    s.contact.method = organ_model(s.organ().model).contact;
  if (const YAML::Node con = sim["contact"]) {
    const std::string fc = "simulation.contact";
    if (r.require_map(con, fc)) {
      r.check_keys(con, fc, "simulation.contact");
      vdm::ContactSettings& cs = s.contact;
      if (const YAML::Node n = con["method"]) {
        std::string m;
        const std::vector<std::string> methods = {"constraint", "kinematic", "penalty"};
        if (r.text(n, fc + ".method", m)) {
          if (m == "constraint") {
            cs.method = vdm::ContactSettings::Method::constraint;
          } else if (m == "kinematic") {
            cs.method = vdm::ContactSettings::Method::kinematic;
          } else if (m == "penalty") {
            cs.method = vdm::ContactSettings::Method::penalty;
            if (const OrganDef* o = first_without(s, &OrganModel::penalty_contact))
              r.error(n, fc + ".method",
                      "penalty contact needs organ.model " + or_list(organ_model_names(&OrganModel::penalty_contact)) +
                          " (" + model_named(s, *o) + " takes kinematic or constraint contact)");
          } else {
            const std::string near = closest(m, methods);
            r.error(n, fc + ".method", "unknown contact method '" + m + "'" +
                                           (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                           "; expected constraint, kinematic or penalty");
          }
        }
      }
      if (const YAML::Node n = con["stiffness"]) {
        r.number(n, fc + ".stiffness", cs.penalty_stiffness, KEY("simulation.contact.stiffness"));
        if (cs.method != vdm::ContactSettings::Method::penalty)
          r.warn(n, fc + ".stiffness", "used by the penalty method only (method: penalty)");
      }
      if (const YAML::Node n = con["friction"]) {
        r.number(n, fc + ".friction", cs.friction, KEY("simulation.contact.friction"));
        if (cs.method != vdm::ContactSettings::Method::constraint)
          r.warn(n, fc + ".friction", "used by the constraint method only (method: constraint)");
      }
      if (const YAML::Node n = con["max_iterations"]) {
        r.integer(n, fc + ".max_iterations", cs.max_penalty_iterations, KEY("simulation.contact.max_iterations"));
        cs.max_constraint_iterations = cs.max_penalty_iterations;
        if (cs.method == vdm::ContactSettings::Method::kinematic)
          r.warn(n, fc + ".max_iterations", "used by the constraint and penalty methods only");
      }
      if (!s.has(Effect::contact))
        r.warn(con, fc, "has no effect: contact is not in simulation.effects");
    }
  }
}

// A probe's collision shape: capsule | cylinder | box | convex, or a mapping {type, ...}.
void read_shape(Reader& r, const YAML::Node& n, const std::string& f, InstrumentDef& in, ConvexDef& convex,
                const std::filesystem::path& base) {
  using Kind = tools::ProbeShape::Kind;
  const std::vector<std::string> kinds = KEY("instruments[].shape.type").values();  // in the order of Kind
  // (A YAML::Node assigned to another changes the node it refers to: one const per node.)
  const YAML::Node type_node = n.IsMap() ? r.required(n, "type", f, "capsule, cylinder, box or convex") : n;
  if (!type_node) return;
  if (!n.IsMap() && !n.IsScalar()) {
    r.error(n, f, std::string("expected capsule, cylinder, box or convex, or a mapping {type: ..., ...}, got ") + Reader::kind(n));
    return;
  }
  std::string type;
  if (!r.text(type_node, n.IsMap() ? Reader::sub(f, "type") : f, type)) return;
  const auto it = std::find(kinds.begin(), kinds.end(), type);
  if (it == kinds.end()) {
    const std::string near = closest(type, kinds);
    r.error(type_node, n.IsMap() ? Reader::sub(f, "type") : f,
            "unknown shape '" + type + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                "; expected capsule, cylinder, box or convex");
    return;
  }
  in.shape.kind = static_cast<Kind>(it - kinds.begin());
  if (in.type != InstrumentDef::Type::probe) {
    r.error(n, f, "a shape is for probes only (a grasper's jaws are boxes of its radius and jaw_length)");
    return;
  }
  r.check_keys(n, f, "instruments[].shape", kinds[static_cast<size_t>(in.shape.kind)].c_str());
  if (in.shape.kind == Kind::box) {
    if (!n.IsMap()) r.error(n, f, "a box needs its sizes: shape: {type: box, size: [x, y, z]} (m)");
    if (const YAML::Node size = n.IsMap() ? r.required(n, "size", f, "the box's sizes [x, y, z] (m), z along the axis")
                                          : YAML::Node(YAML::NodeType::Undefined);
        size.IsDefined()) {
      if (!size.IsSequence() || size.size() != 3) {
        r.error(size, Reader::sub(f, "size"), "expected three sizes [x, y, z] (m)");
      } else {
        for (int d = 0; d < 3; ++d)
          r.number(size[d], Reader::item(Reader::sub(f, "size"), d), in.shape.size[d], KEY("instruments[].shape.size"));
      }
    }
  }
  if (in.shape.kind == Kind::cylinder || in.shape.kind == Kind::box) {
    if (const YAML::Node v = n.IsMap() ? n["rounding"] : YAML::Node(YAML::NodeType::Undefined); v.IsDefined()) {
      const double limit = in.shape.kind == Kind::cylinder ? std::min(in.radius, 0.5 * std::max(in.length, 2 * in.radius))
                                                          : 0.5 * in.shape.size.minCoeff();
      if (r.number(v, Reader::sub(f, "rounding"), in.shape.rounding, KEY("instruments[].shape.rounding")) &&
          in.shape.rounding > limit) {
        std::ostringstream m;
        m << "value " << v.Scalar() << " is out of range: the rounding must be <= "
          << (in.shape.kind == Kind::cylinder ? "the radius (" : "half the smallest size (") << limit << " m)";
        r.error(v, Reader::sub(f, "rounding"), m.str());
      }
    }
  }
  if (in.shape.kind == Kind::convex) {
    convex.present = true;
    if (!n.IsMap()) {
      r.error(n, f, "a convex shape needs its mesh: shape: {type: convex, mesh: FILE} (the mesh's convex hull collides)");
      return;
    }
    if (const YAML::Node m = r.required(n, "mesh", f, "the mesh file whose convex hull is the shape (relative to the scene)")) {
      std::string rel;
      if (r.text(m, Reader::sub(f, "mesh"), rel)) {
        const std::filesystem::path p = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : base / rel;
        convex.mesh = p.lexically_normal().string();
        convex.where = r.where(m);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(convex.mesh, ec))
          r.error(m, Reader::sub(f, "mesh"), "no such mesh file: " + convex.mesh);
      }
    }
    if (const YAML::Node v = n["scale"]) r.number(v, Reader::sub(f, "scale"), convex.scale, KEY("instruments[].shape.scale"));
    if (const YAML::Node v = n["origin"]) r.vec3(v, Reader::sub(f, "origin"), convex.origin, KEY("instruments[].shape.origin"));
    if (const YAML::Node v = n["rotate_deg"]) r.vec3(v, Reader::sub(f, "rotate_deg"), convex.rotate_deg, KEY("instruments[].shape.rotate_deg"));
  }
}

// The port coordinates carried from keyframe to keyframe (a keyframe that leaves one out keeps
// it): from the last keyframe's port coordinates or its tip.
struct PortCarry {
  bool known = false;
  double pan_deg = 0, tilt_deg = 0, depth = 0;
};

// With instruments[].port: the keyframe's tip from its port coordinates (pan_deg, tilt_deg,
// depth), or its tip checked against the port; no axis (the port gives it). Without a port,
// pan_deg and tilt_deg are refused.
void read_port_keyframe(Reader& r, const YAML::Node& kf, const std::string& fk, const InstrumentDef& in, Keyframe& key,
                        PortCarry& carry) {
  const bool on_surface = bool(kf["on_surface"]);
  const YAML::Node pan = kf["pan_deg"], tilt = kf["tilt_deg"], depth = on_surface ? YAML::Node() : kf["depth"];
  if (!in.port) {
    if (pan) r.error(pan, Reader::sub(fk, "pan_deg"), "port coordinates need the instrument's port: add port: [x, y, z]");
    if (tilt) r.error(tilt, Reader::sub(fk, "tilt_deg"), "port coordinates need the instrument's port: add port: [x, y, z]");
    return;
  }
  const vdm::Vec3 port = *in.port;
  if (const YAML::Node axis = kf["axis"])
    r.error(axis, Reader::sub(fk, "axis"), "the instrument has a port: its axis runs from the port through the tip; leave axis out");
  if (const YAML::Node align = kf["align"])
    r.error(align, Reader::sub(fk, "align"), "the instrument has a port: its axis runs from the port through the tip; leave align out");
  if (pan || tilt || depth) {
    if (key.tip || on_surface) {
      const YAML::Node first = pan ? pan : tilt ? tilt : depth;
      r.error(first, Reader::sub(fk, pan ? "pan_deg" : tilt ? "tilt_deg" : "depth"),
              "give the tip (tip or on_surface) or port coordinates (pan_deg, tilt_deg, depth), not both");
      return;
    }
    PortCarry next = carry;
    bool ok = true;
    if (pan) ok = r.number(pan, Reader::sub(fk, "pan_deg"), next.pan_deg, KEY("instruments[].script[].pan_deg")) && ok;
    if (tilt) ok = r.number(tilt, Reader::sub(fk, "tilt_deg"), next.tilt_deg, KEY("instruments[].script[].tilt_deg")) && ok;
    if (depth) ok = r.number(depth, Reader::sub(fk, "depth"), next.depth, KEY("instruments[].script[].depth")) && ok;
    if (!ok) return;
    if (!carry.known && !(pan && tilt && depth)) {
      r.error(kf, fk, "the first keyframe in port coordinates gives pan_deg, tilt_deg and depth (no earlier keyframe to keep them from)");
      return;
    }
    if (!(next.depth > 0)) {
      r.error(depth ? depth : kf, Reader::sub(fk, "depth"),
              "the tip must be past the port: depth " + std::to_string(next.depth) + " m is at or behind it");
      return;
    }
    next.known = true;
    carry = next;
    key.tip = port + next.depth * tools::port_direction(next.pan_deg, next.tilt_deg);
  } else if (key.tip) {
    const vdm::Vec3 d = *key.tip - port;
    if (d.norm() < 1e-3) {
      r.error(kf["tip"], Reader::sub(fk, "tip"), "the tip is at the port: the shaft has no direction");
      return;
    }
    const double kDeg = 180.0 / 3.14159265358979323846;
    carry = {true, std::atan2(d.y(), d.x()) * kDeg, std::asin(std::clamp(-d.z() / d.norm(), -1.0, 1.0)) * kDeg, d.norm()};
  } else if (on_surface) {
    carry.known = false;  // a tip found later: nothing to keep port coordinates from
  }
  if (key.tip && (*key.tip - port).norm() > in.length)
    r.error(kf, fk,
            "the tip is " + std::to_string((*key.tip - port).norm()) + " m from the port: farther than the instrument is long (" +
                std::to_string(in.length) + " m)");
}

// A keyframe's on_surface, depth and align (a tip placed on the organ, resolved when the organ
// is loaded): appended to `out` for instruments[instrument].script[keyframe].
void read_surface_placement(Reader& r, const YAML::Node& kf, const std::string& fk, size_t instrument, size_t keyframe,
                            bool port, std::vector<SurfacePlacement>& out) {
  const YAML::Node on = kf["on_surface"];
  if (!on) {
    for (const char* k : {"depth", "align"})
      if (const YAML::Node n = kf[k]; n && !(port && std::string(k) == "depth"))
        r.error(n, Reader::sub(fk, k),
                std::string(k) + " places the tip relative to the surface: give on_surface: {from: [x, y, z], toward: "
                "[dx, dy, dz]} beside it");
    return;
  }
  const std::string fo = Reader::sub(fk, "on_surface");
  if (!r.require_map(on, fo)) return;
  r.check_keys(on, fo, "instruments[].script[].on_surface");
  SurfacePlacement p;
  p.instrument = instrument;
  p.keyframe = keyframe;
  p.where = r.where(on);
  bool ok = true;
  if (kf["tip"]) {
    r.error(kf["tip"], Reader::sub(fk, "tip"), "give tip or on_surface, not both (on_surface places the tip)");
    ok = false;
  }
  const YAML::Node from = r.required(on, "from", fo, "where the ray starts, outside the organ [x, y, z] (m)");
  const YAML::Node toward = r.required(on, "toward", fo, "the ray's direction [dx, dy, dz]");
  ok = from && r.vec3(from, Reader::sub(fo, "from"), p.from, KEY("instruments[].script[].on_surface.from")) && ok;
  ok = toward && r.vec3(toward, Reader::sub(fo, "toward"), p.toward, KEY("instruments[].script[].on_surface.toward")) && ok;
  if (toward && ok && !(p.toward.norm() > 0)) {
    r.error(toward, Reader::sub(fo, "toward"), "the direction must not be zero");
    ok = false;
  }
  if (const YAML::Node n = kf["depth"]) ok = r.number(n, Reader::sub(fk, "depth"), p.depth, KEY("instruments[].script[].depth")) && ok;
  if (const YAML::Node n = kf["align"]) {
    ok = r.boolean(n, Reader::sub(fk, "align"), p.align) && ok;
    if (p.align && kf["axis"]) {
      r.error(n, Reader::sub(fk, "align"), "give axis or align, not both (align sets the axis along the inward normal)");
      ok = false;
    }
  }
  if (ok) out.push_back(p);
}

void read_instruments(Reader& r, const YAML::Node& list, SceneDef& s, const std::filesystem::path& base) {
  if (!r.require_sequence(list, "instruments")) return;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string fi = Reader::item("instruments", i);
    const YAML::Node n = list[i];
    if (!r.require_map(n, fi)) continue;
    r.check_keys(n, fi, "instruments[]");
    InstrumentDef in;
    s.instrument_where.push_back(r.where(n));
    if (const YAML::Node t = r.required(n, "type", fi, "probe or grasper")) {
      std::string type;
      if (r.text(t, Reader::sub(fi, "type"), type)) {
        if (type == "probe") in.type = InstrumentDef::Type::probe;
        else if (type == "grasper") in.type = InstrumentDef::Type::grasper;
        else {
          const std::string near = closest(type, {"probe", "grasper"});
          r.error(t, Reader::sub(fi, "type"), "unknown instrument '" + type + "'" +
                                                  (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                                  "; expected probe or grasper");
        }
      }
    }
    if (const YAML::Node v = n["radius"]) r.number(v, Reader::sub(fi, "radius"), in.radius, KEY("instruments[].radius"));
    if (const YAML::Node v = n["length"]) r.number(v, Reader::sub(fi, "length"), in.length, KEY("instruments[].length"));
    if (const YAML::Node v = n["jaw_length"]) r.number(v, Reader::sub(fi, "jaw_length"), in.jaw_length, KEY("instruments[].jaw_length"));
    if (const YAML::Node v = n["grasp_width"]) r.number(v, Reader::sub(fi, "grasp_width"), in.grasp_width, KEY("instruments[].grasp_width"));
    if (const YAML::Node v = n["jaws"]) {
      std::string look;
      if (r.text(v, Reader::sub(fi, "jaws"), look)) {
        if (look == "box") in.jaw_look = InstrumentDef::JawLook::box;
        else if (look == "fenestrated") in.jaw_look = InstrumentDef::JawLook::fenestrated;
        else if (look == "maryland") in.jaw_look = InstrumentDef::JawLook::maryland;
        else {
          const std::string near = closest(look, {"box", "fenestrated", "maryland"});
          r.error(v, Reader::sub(fi, "jaws"), "unknown jaws '" + look + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                                  "; expected box, fenestrated or maryland");
        }
        if (in.type != InstrumentDef::Type::grasper) r.warn(v, Reader::sub(fi, "jaws"), "a probe has no jaws: ignored");
      }
    }
    if (const YAML::Node v = n["path"]) {
      std::string p;
      if (r.text(v, Reader::sub(fi, "path"), p)) {
        if (p == "linear") in.path = InstrumentDef::Path::linear;
        else if (p == "spline") in.path = InstrumentDef::Path::spline;
        else r.error(v, Reader::sub(fi, "path"), "unknown path '" + p + "': expected linear or spline");
      }
    }
    ConvexDef convex;
    if (const YAML::Node sh = n["shape"]) read_shape(r, sh, Reader::sub(fi, "shape"), in, convex, base);
    if (const YAML::Node v = n["look"]) {
      std::string look;
      if (r.text(v, Reader::sub(fi, "look"), look)) {
        if (look == "plain") in.probe_look = InstrumentDef::ProbeLook::plain;
        else if (look == "hook") in.probe_look = InstrumentDef::ProbeLook::hook;
        else {
          const std::string near = closest(look, {"plain", "hook"});
          r.error(v, Reader::sub(fi, "look"), "unknown look '" + look + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                                  "; expected plain or hook");
        }
        if (in.type != InstrumentDef::Type::probe)
          r.warn(v, Reader::sub(fi, "look"), "a grasper's look is its jaws (`jaws`): ignored");
        else if (in.probe_look == InstrumentDef::ProbeLook::hook && in.shape.kind != tools::ProbeShape::Kind::capsule)
          r.warn(v, Reader::sub(fi, "look"), "a hook is drawn on a capsule probe only; this probe is drawn as its shape");
      }
    }
    SkinDef skin;
    if (const YAML::Node sk = n["skin"]; sk && r.require_map(sk, Reader::sub(fi, "skin"))) {
      const std::string fs = Reader::sub(fi, "skin");
      r.check_keys(sk, fs, "instruments[].skin");
      skin.present = true;
      skin.where = r.where(sk);
      auto file = [&](const YAML::Node& v, const std::string& field, std::string& out) {
        std::string rel;
        if (!r.text(v, field, rel)) return;
        out = (base / rel).lexically_normal().string();
        std::error_code ec;
        if (!std::filesystem::is_regular_file(out, ec)) r.error(v, field, "no such mesh file: " + out);
      };
      if (const YAML::Node v = sk["body"]) file(v, Reader::sub(fs, "body"), skin.body);
      if (const YAML::Node j = sk["jaws"]) {
        if (!j.IsSequence() || j.size() != 2) r.error(j, Reader::sub(fs, "jaws"), "expected two mesh files [upper, lower]");
        else
          for (size_t k = 0; k < 2; ++k) file(j[k], Reader::item(Reader::sub(fs, "jaws"), k), skin.jaws[k]);
      }
      if (const YAML::Node v = sk["scale"]) r.number(v, Reader::sub(fs, "scale"), skin.scale, KEY("instruments[].skin.scale"));
      if (const YAML::Node v = sk["origin"]) r.vec3(v, Reader::sub(fs, "origin"), skin.origin, KEY("instruments[].skin.origin"));
      if (const YAML::Node v = sk["rotate_deg"]) r.vec3(v, Reader::sub(fs, "rotate_deg"), skin.rotate_deg, KEY("instruments[].skin.rotate_deg"));
      if (!sk["body"] && !sk["jaws"]) r.error(sk, fs, "give body: MESH and/or jaws: [MESH, MESH]");
    }
    if (const YAML::Node v = n["port"]) {
      vdm::Vec3 port;
      if (r.vec3(v, Reader::sub(fi, "port"), port, KEY("instruments[].port"))) in.port = port;
    }
    const YAML::Node script = r.required(n, "script", fi, "a timeline of keyframes [{t, tip, axis, jaw}, ...]");
    if (!script || !r.require_sequence(script, Reader::sub(fi, "script"))) continue;
    if (script.size() == 0) r.error(script, Reader::sub(fi, "script"), "the timeline is empty: give at least one keyframe");
    PortCarry carry;
    s.keyframe_where.emplace_back();
    for (size_t k = 0; k < script.size(); ++k) {
      const std::string fk = Reader::item(Reader::sub(fi, "script"), k);
      const YAML::Node kf = script[k];
      if (!r.require_map(kf, fk)) continue;
      r.check_keys(kf, fk, "instruments[].script[]");
      s.keyframe_where.back().push_back(r.where(kf));
      Keyframe key;
      if (const YAML::Node t = r.required(kf, "t", fk, "the keyframe's time (s)"))
        r.number(t, Reader::sub(fk, "t"), key.t, KEY("instruments[].script[].t"));
      if (!in.script.empty() && !(key.t > in.script.back().t))
        r.error(kf["t"] ? kf["t"] : kf, Reader::sub(fk, "t"),
                "keyframe times must increase: " + std::to_string(key.t) + " s does not come after " +
                    std::to_string(in.script.back().t) + " s");
      vdm::Vec3 v;
      if (const YAML::Node tip = kf["tip"]; tip && r.vec3(tip, Reader::sub(fk, "tip"), v, KEY("instruments[].script[].tip"))) key.tip = v;
      if (const YAML::Node ax = kf["axis"]; ax && r.vec3(ax, Reader::sub(fk, "axis"), v, KEY("instruments[].script[].axis"))) {
        if (v.norm() < 1e-9) r.error(ax, Reader::sub(fk, "axis"), "the axis must not be zero");
        else key.axis = v.normalized();
      }
      read_surface_placement(r, kf, fk, s.instruments.size(), in.script.size(), bool(in.port), s.surface_keyframes);
      read_port_keyframe(r, kf, fk, in, key, carry);
      if (const YAML::Node v = kf["roll_deg"]) {
        double roll = 0;
        if (r.number(v, Reader::sub(fk, "roll_deg"), roll, KEY("instruments[].script[].roll_deg"))) key.roll_deg = roll;
      }
      if (const YAML::Node jaw = kf["jaw"]) {
        const std::string j = jaw.IsScalar() ? jaw.Scalar() : "";
        if (j == "open" || j == "closed") key.jaw_closed = j == "closed";
        else r.error(jaw, Reader::sub(fk, "jaw"), "expected open or closed");
      }
      in.script.push_back(key);
    }
    const bool first_on_surface = script.size() > 0 && script[0].IsMap() && script[0]["on_surface"];
    if (!in.script.empty() && !in.script.front().tip && !first_on_surface)
      r.error(script[0], Reader::sub(Reader::item(Reader::sub(fi, "script"), 0), "tip"),
              "the first keyframe must give the tip position [x, y, z] (m), or place it with on_surface (or, with a "
              "port, pan_deg, tilt_deg and depth)");
    s.instruments.push_back(in);
    s.instrument_skins.push_back(skin);
    s.instrument_convex.push_back(convex);
  }
}

// render.antialias (edge, msaa or none; default edge) and render.samples (MSAA samples per
// pixel). A scene from before `antialias` existed gave `samples` alone: samples 2-16 still
// mean multisampling, samples 1 no anti-aliasing.
void read_antialias(Reader& r, const YAML::Node& n, render::RenderSettings& rs) {
  const YAML::Node aa = n["antialias"], samples = n["samples"];
  bool samples_ok = false;
  if (samples) {
    samples_ok = r.integer(samples, "render.samples", rs.samples, KEY("render.samples"));
    if (samples_ok && (rs.samples & (rs.samples - 1))) {
      r.error(samples, "render.samples", "expected 1, 2, 4, 8 or 16 (samples per pixel for anti-aliasing)");
      samples_ok = false;
    }
  }
  if (!aa) {
    if (samples_ok) rs.antialias = rs.samples > 1 ? render::Antialias::msaa : render::Antialias::none;
    return;
  }
  std::string t;
  if (!r.text(aa, "render.antialias", t)) return;
  if (t == "edge") {
    rs.antialias = render::Antialias::edge;
  } else if (t == "msaa") {
    rs.antialias = render::Antialias::msaa;
  } else if (t == "none") {
    rs.antialias = render::Antialias::none;
  } else {
    r.error(aa, "render.antialias", "unknown method '" + t + "': expected edge (smoothed edges, the default), msaa (multisampling, with samples) or none");
    return;
  }
  if (!samples_ok) return;
  if (rs.antialias == render::Antialias::msaa && rs.samples < 2)
    r.error(samples, "render.samples", "antialias: msaa needs 2, 4, 8 or 16 samples per pixel");
  else if (rs.antialias != render::Antialias::msaa && rs.samples > 1)
    r.error(samples, "render.samples", "samples are for antialias: msaa (antialias is " + t + ")");
}

void read_views_and_stress(Reader& r, const YAML::Node& n, SceneDef& s);

// render.camera.type: true for the endoscope.
bool read_camera_type(Reader& r, const YAML::Node& cam, render::RenderSettings& rs) {
  const YAML::Node type = cam["type"];
  std::string t;
  if (!type || !r.text(type, "render.camera.type", t)) return false;
  if (t == "endoscope") {
    rs.camera_type = render::CameraType::endoscope;
    return true;
  }
  if (t != "framing") {
    const std::string near = closest(t, {"framing", "endoscope"});
    r.error(type, "render.camera.type",
            "unknown camera type '" + t + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                "; expected framing or endoscope");
  }
  return false;
}

// A look_at that leaves the shaft a direction: not at the port.
void check_aim(Reader& r, const YAML::Node& at, const std::string& field, const vdm::Vec3& port, const vdm::Vec3& look_at) {
  if ((look_at - port).norm() < 1e-6)
    r.error(at, field, "the shaft is aimed at its own port: look_at must be away from the port");
}

// The endoscope's keys (render.camera with type: endoscope); the framing camera's are refused.
void read_endoscope(Reader& r, const YAML::Node& cam, const YAML::Node& render_node, render::RenderSettings& rs) {
  tools::EndoscopeDef& e = rs.endoscope;
  rs.auto_camera = false;
  rs.floor = false;  // the abdomen's wall is behind the organ
  for (const char* framing : {"eye", "target", "up", "focus"})
    if (const YAML::Node v = cam[framing])
      r.error(v, std::string("render.camera.") + framing,
              "is for the framing camera: an endoscope is placed by port, look_at, depth, angle_deg and roll_deg");
  if (const YAML::Node v = render_node["floor"]; v && v.IsScalar() && v.Scalar() == "true")
    r.warn(v, "render.floor", "the endoscope's picture has the abdomen's wall behind the organ, not a floor: ignored");
  const YAML::Node port = r.required(cam, "port", "render.camera", "where the scope passes the abdominal wall [x, y, z] (m)");
  const YAML::Node look = r.required(cam, "look_at", "render.camera", "the point the scope is aimed at [x, y, z] (m)");
  const bool placed = port && r.vec3(port, "render.camera.port", e.port, KEY("render.camera.port")) && look &&
                      r.vec3(look, "render.camera.look_at", e.look_at, KEY("render.camera.look_at"));
  if (placed) check_aim(r, look, "render.camera.look_at", e.port, e.look_at);
  if (const YAML::Node v = cam["depth"]) r.number(v, "render.camera.depth", e.depth, KEY("render.camera.depth"));
  if (const YAML::Node v = cam["angle_deg"]) r.number(v, "render.camera.angle_deg", e.angle_deg, KEY("render.camera.angle_deg"));
  if (const YAML::Node v = cam["roll_deg"]) r.number(v, "render.camera.roll_deg", e.roll_deg, KEY("render.camera.roll_deg"));
  if (const YAML::Node v = cam["fov_deg"]) r.number(v, "render.camera.fov_deg", e.fov_deg, KEY("render.camera.fov_deg"));
  const YAML::Node script = cam["script"];
  if (!script || !r.require_sequence(script, "render.camera.script")) return;
  double last_t = 0;
  for (size_t k = 0; k < script.size(); ++k) {
    const std::string fk = Reader::item("render.camera.script", k);
    const YAML::Node kf = script[k];
    if (!r.require_map(kf, fk)) continue;
    r.check_keys(kf, fk, "render.camera.script[]");
    tools::EndoscopeKeyframe key;
    if (const YAML::Node t = r.required(kf, "t", fk, "the keyframe's time (s)");
        t && r.number(t, Reader::sub(fk, "t"), key.t, KEY("render.camera.script[].t")) && !(key.t > last_t))
      r.error(t, Reader::sub(fk, "t"),
              k == 0 ? "the first keyframe's time must be after 0 s (the scope starts at port, look_at, depth and roll_deg)"
                     : "keyframe times must increase: " + std::to_string(key.t) + " s does not come after " +
                           std::to_string(last_t) + " s");
    last_t = std::max(last_t, key.t);
    vdm::Vec3 v;
    if (const YAML::Node at = kf["look_at"];
        at && r.vec3(at, Reader::sub(fk, "look_at"), v, KEY("render.camera.script[].look_at"))) {
      key.look_at = v;
      if (placed) check_aim(r, at, Reader::sub(fk, "look_at"), e.port, v);
    }
    double x = 0;
    if (const YAML::Node d = kf["depth"]; d && r.number(d, Reader::sub(fk, "depth"), x, KEY("render.camera.script[].depth")))
      key.depth = x;
    if (const YAML::Node d = kf["roll_deg"];
        d && r.number(d, Reader::sub(fk, "roll_deg"), x, KEY("render.camera.script[].roll_deg")))
      key.roll_deg = x;
    e.script.push_back(key);
  }
}

void read_render(Reader& r, const YAML::Node& n, SceneDef& s) {
  RenderDef& d = s.render;
  if (!r.require_map(n, "render")) return;
  r.check_keys(n, "render", "render");
  if (const YAML::Node v = n["width"]) r.integer(v, "render.width", d.settings.width, KEY("render.width"));
  if (const YAML::Node v = n["height"]) r.integer(v, "render.height", d.settings.height, KEY("render.height"));
  read_antialias(r, n, d.settings);
  if (const YAML::Node v = n["hud"]) r.boolean(v, "render.hud", d.hud);
  if (const YAML::Node v = n["hud_step_time"]) r.boolean(v, "render.hud_step_time", d.hud_step_time);
  if (const YAML::Node v = n["floor"]) r.boolean(v, "render.floor", d.settings.floor);
  if (const YAML::Node v = n["shadows"]) r.boolean(v, "render.shadows", d.settings.shadows);
  if (const YAML::Node v = n["gizmo"]) r.boolean(v, "render.gizmo", d.settings.gizmo);
  if (const YAML::Node v = n["png_compression"]) r.integer(v, "render.png_compression", d.png_compression, KEY("render.png_compression"));
  if (const YAML::Node v = n["fps"]) r.number(v, "render.fps", d.fps, KEY("render.fps"));
  if (const YAML::Node cam = n["camera"]; cam && r.require_map(cam, "render.camera")) {
    r.check_keys(cam, "render.camera", "render.camera");
    if (read_camera_type(r, cam, d.settings)) {
      read_endoscope(r, cam, n, d.settings);
      return read_views_and_stress(r, n, s);
    }
    for (const char* scope : {"port", "look_at", "depth", "angle_deg", "roll_deg", "script"})
      if (const YAML::Node v = cam[scope])
        r.error(v, std::string("render.camera.") + scope, "is for the endoscope: add type: endoscope to the camera");
    render::Camera& c = d.settings.camera;
    if (const YAML::Node v = cam["fov_deg"]) r.number(v, "render.camera.fov_deg", c.fov_deg, KEY("render.camera.fov_deg"));
    const YAML::Node eye = cam["eye"], target = cam["target"];
    if (eye || target) {
      d.settings.auto_camera = false;
      if (!eye) r.error(cam, "render.camera.eye", "missing: give eye and target together (or neither, for automatic framing)");
      if (!target) r.error(cam, "render.camera.target", "missing: give eye and target together (or neither, for automatic framing)");
      if (eye) r.vec3(eye, "render.camera.eye", c.eye, KEY("render.camera.eye"));
      if (target) r.vec3(target, "render.camera.target", c.target, KEY("render.camera.target"));
      if (eye && target && (c.eye - c.target).norm() < 1e-9)
        r.error(target, "render.camera.target", "the target must differ from the eye");
    }
    if (const YAML::Node f = cam["focus"]) {
      std::string t;
      if (r.text(f, "render.camera.focus", t)) {
        if (t == "organ") d.settings.focus = render::CameraFocus::organ;
        else if (t == "instruments") d.settings.focus = render::CameraFocus::instruments;
        else {
          const std::string near = closest(t, {"organ", "instruments"});
          r.error(f, "render.camera.focus", "unknown focus '" + t + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                                "; expected organ or instruments");
        }
      }
      if (!d.settings.auto_camera)
        r.error(f, "render.camera.focus", "is for the automatic camera: give eye and target, or focus, not both");
      else if (d.settings.focus == render::CameraFocus::instruments && s.instruments.empty())
        r.warn(f, "render.camera.focus", "the scene has no instruments: the organ is framed");
    }
    if (const YAML::Node up = cam["up"]; up && r.vec3(up, "render.camera.up", c.up, KEY("render.camera.up")) && c.up.norm() < 1e-9)
      r.error(up, "render.camera.up", "the up vector must not be zero");
  }
  read_views_and_stress(r, n, s);
}

void read_views_and_stress(Reader& r, const YAML::Node& n, SceneDef& s) {
  RenderDef& d = s.render;
  if (const YAML::Node views = n["views"]; views && r.require_sequence(views, "render.views")) {
    std::vector<bool> asked(render::view_table().size(), false);
    for (size_t i = 0; i < views.size(); ++i) {
      std::string v;
      if (!r.text(views[i], Reader::item("render.views", i), v)) continue;
      render::View view;
      if (render::parse_view(v, view)) {
        asked[static_cast<size_t>(view)] = true;
      } else {
        const std::string near = closest(v, render::view_names());
        r.error(views[i], Reader::item("render.views", i),
                "unknown view '" + v + "': expected " + or_list(render::view_names()) +
                    (near.empty() ? "" : " (did you mean '" + near + "'?)"));
      }
    }
    d.views.clear();
    for (const render::ViewRow& row : render::view_table())
      if (asked[static_cast<size_t>(row.view)]) d.views.push_back(row.view);
  }
  if (const YAML::Node st = n["stress"]; st && r.require_map(st, "render.stress")) {
    r.check_keys(st, "render.stress", "render.stress");
    render::StressView& v = d.stress_view;
    if (const YAML::Node q = st["quantity"]) {
      std::string t;
      if (r.text(q, "render.stress.quantity", t) && !render::parse_quantity(t, v.quantity))
        r.error(q, "render.stress.quantity", "unknown quantity '" + t + "': expected one of " + join(render::quantity_names()));
    }
    if (quantity_is_signed(v.quantity)) v.colormap = render::ColorMapName::coolwarm;
    if (const YAML::Node c = st["colormap"]) {
      std::string t;
      if (r.text(c, "render.stress.colormap", t) && !render::parse_colormap(t, v.colormap))
        r.error(c, "render.stress.colormap", "unknown colour map '" + t + "': expected one of " + join(render::colormap_names()));
    }
    if (const YAML::Node range = st["range"]) {
      if (range.IsScalar() && range.Scalar() == "auto") {
        d.range_auto = true;
      } else if (!range.IsSequence() || range.size() != 2) {
        r.error(range, "render.stress.range", "expected [low, high] in the quantity's SI unit, or auto");
      } else if (r.number(range[0], "render.stress.range[0]", v.lo, KEY("render.stress.range")) &&
                 r.number(range[1], "render.stress.range[1]", v.hi, KEY("render.stress.range"))) {
        d.range_auto = false;
        if (!(v.hi > v.lo)) r.error(range[1], "render.stress.range[1]", "the high end must be above the low end");
        else if (v.hi - v.lo < 1e-9 * std::max(std::abs(v.lo), std::abs(v.hi)))
          r.error(range[1], "render.stress.range[1]", "the range is too narrow to colour (less than 1e-9 of its values)");
      }
    }
  }
  const bool stress_quantity = render::quantity_needs_stress(d.stress_view.quantity);
  if (const OrganDef* o = first_without(s, &OrganModel::surface_stress);
      d.has(render::View::stress) && stress_quantity && o)
    r.error(n["views"], "render.views",
            std::string("the stress view of '") + render::to_string(d.stress_view.quantity) + "' needs organ.model " +
                or_list(organ_model_names(&OrganModel::surface_stress)) + " (" + model_named(s, *o) +
                " computes no stress at the surface): colour by displacement or contact_pressure");
  if (d.has(render::View::stress) && !s.has(Effect::stress) && stress_quantity)
    r.error(n["views"], "render.views",
            std::string("the stress view of '") + render::to_string(d.stress_view.quantity) +
                "' needs the stress effect: add stress to simulation.effects (or colour by displacement or "
                "contact_pressure)");
  const int most = render::kMaxInstrumentsWithIds - (static_cast<int>(s.organs.size()) - 1);
  if (d.has(render::View::segmentation) && s.instruments.size() > size_t(std::max(most, 0)))
    r.error(n["views"], "render.views",
            "the segmentation view's 8-bit ids name at most " + std::to_string(most) + " instruments" +
                (s.organs.size() > 1 ? " beside " + std::to_string(s.organs.size()) + " organs" : std::string()) +
                "; the scene has " + std::to_string(s.instruments.size()));
}

}  // namespace

Eigen::Matrix3d rotation_from_degrees(const vdm::Vec3& deg) {
  const double k = 3.14159265358979323846 / 180.0;
  return (Eigen::AngleAxisd(deg.z() * k, vdm::Vec3::UnitZ()) * Eigen::AngleAxisd(deg.y() * k, vdm::Vec3::UnitY()) *
          Eigen::AngleAxisd(deg.x() * k, vdm::Vec3::UnitX()))
      .toRotationMatrix();
}

const char* to_string(Effect e) {
  switch (e) {
    case Effect::contact: return "contact";
    case Effect::grasp: return "grasp";
    case Effect::gravity: return "gravity";
    case Effect::inertia: return "inertia";
    case Effect::stress: return "stress";
  }
  return "unknown";
}

bool SceneDef::has(Effect e) const { return std::find(effects.begin(), effects.end(), e) != effects.end(); }

bool RenderDef::has(render::View v) const { return std::find(views.begin(), views.end(), v) != views.end(); }

bool RenderDef::has_ground_truth() const {
  return std::any_of(views.begin(), views.end(),
                     [](render::View v) { return render::view_row(v).pass == render::ViewPass::ground_truth; });
}

bool RenderDef::has_picture() const {
  return std::any_of(views.begin(), views.end(),
                     [](render::View v) { return render::view_row(v).pass == render::ViewPass::picture; });
}

void RenderDef::remove(render::View v) { views.erase(std::remove(views.begin(), views.end(), v), views.end()); }

std::string SceneProblem::text() const {
  return where + ": " + (warning ? "warning: " : "") + field + ": " + message;
}

bool SceneLoadResult::ok() const {
  return std::none_of(problems.begin(), problems.end(), [](const SceneProblem& p) { return !p.warning; });
}

SceneLoadResult load_scene(const std::string& path) {
  SceneLoadResult res;
  SceneDef& s = res.scene;
  s.file = path;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    res.problems.push_back({path, "scene", "no such scene file", false});
    return res;
  }
  // Bounded before parsing: the YAML tree of a large file takes about 80 times its size.
  if (const auto bytes = std::filesystem::file_size(path, ec); !ec && bytes > kMaxSceneFileBytes) {
    res.problems.push_back({path, "scene",
                            "the file is " + std::to_string(bytes) + " bytes, more than the limit of " +
                                std::to_string(kMaxSceneFileBytes) + " (10 MB) for a scene file",
                            false});
    return res;
  }
  YAML::Node root;
  try {
    // One document: yaml-cpp 0.7's LoadAll loops forever on some inputs (the fuzz pass found
    // ",p, 2"), so the first document is parsed alone and the others found from their markers.
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    int second_line = 0;
    const int documents = count_yaml_documents(text, second_line);
    if (documents > 1) {
      std::ostringstream where;
      where << path << ':' << second_line << ":1";
      res.problems.push_back({where.str(), "scene",
                              "the file holds " + std::to_string(documents) +
                                  " YAML documents (separated by '---'); a scene is one",
                              false});
      return res;
    }
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream where;
    where << path << ':' << e.mark.line + 1 << ':' << e.mark.column + 1;
    res.problems.push_back({where.str(), "scene", "not valid YAML: " + e.msg, false});
    return res;
  }
  Reader r(path, res.problems);
  if (!root.IsMap()) {
    r.error(root, "scene", std::string("expected a mapping with name, organ, simulation, ... at the top, got ") + Reader::kind(root));
    return res;
  }
  r.check_keys(root, "", "");
  const std::filesystem::path base = std::filesystem::path(path).parent_path();
  if (const YAML::Node n = root["name"]) {
    // Into run.json, messages and the default folder name: UTF-8 only.
    if (r.text(n, "name", s.name))
      if (const size_t bad = invalid_utf8_at(s.name); bad != std::string::npos) {
        r.error(n, "name", "not valid UTF-8 (byte " + std::to_string(bad + 1) + " of the name): save the scene as UTF-8");
        s.name.clear();
      }
  }
  if (s.name.empty()) s.name = std::filesystem::path(path).stem().string();
  const YAML::Node organs = root["organs"];
  if (organs && root["organ"])
    r.error(organs, "organs", "give organ (one organ) or organs (a list of organs), not both");
  else if (organs)
    read_organs(r, organs, s, base);
  else if (const YAML::Node organ = r.required(root, "organ", "", "the organ: {mesh, material, ...} (or organs: a list of them)"))
    read_organ(r, organ, s.organ(), base);
  if (s.organs.empty()) s.organs.resize(1);  // an empty or refused list: the rest reads on a default organ
  if (const YAML::Node sim = root["simulation"]) read_simulation(r, sim, s);
  for (size_t i = 0; i < s.organs.size(); ++i)
    warn_unused_by_model(r, root, !organs ? root["organ"] : organs.IsSequence() && i < organs.size() ? organs[i] : YAML::Node(),
                         s.organs[i], s);
  if (const YAML::Node ins = root["instruments"]) read_instruments(r, ins, s, base);
  if (const YAML::Node att = root["attachments"]) {
    if (!organs) {
      r.error(att, "attachments", "attachments tie organs together: give the organs as a list, organs: [...]");
    } else {
      read_attachments(r, att, s);
      // Ties are forces between organs solved with their contact: every organ on the core,
      // with constraint contact.
      const auto off_core = std::find_if(s.organs.begin(), s.organs.end(),
                                         [](const OrganDef& o) { return o.model != vdm::ModelKind::vdm_core; });
      if (!s.attachments.empty() && off_core != s.organs.end())
        r.error(att, "attachments", "attachments need every organ on model: vdm_core (" + off_core->field + " is not)");
      else if (!s.attachments.empty() && (!s.has(Effect::contact) || s.contact.method != vdm::ContactSettings::Method::constraint))
        r.error(att, "attachments", "attachments are solved with the contact between organs: add contact to "
                                    "simulation.effects (with the default constraint contact)");
    }
  }
  if (const YAML::Node render = root["render"]) {
    s.has_render = true;
    read_render(r, render, s);
  }
  return res;
}

bool report_problems(const std::vector<SceneProblem>& problems, std::ostream& err) {
  bool ok = true;
  for (const SceneProblem& p : problems) {
    err << (p.warning ? "vdmsim: " : "vdmsim: error: ") << p.text() << "\n";
    ok = ok && p.warning;
  }
  return ok;
}

}  // namespace vdmsim
