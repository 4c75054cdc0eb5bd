#include "app/simulation/prepared_scene.hpp"

#include <algorithm>
#include <memory>
#include <sstream>

#include "app/scene/mesh_io.hpp"
#include "app/simulation/organ_models.hpp"
#include "app/simulation/port_keyframes.hpp"

namespace vdmsim {

std::vector<int> select_nodes(const Region& region, const vdm::NodeMat& rest, const std::string& field,
                              std::vector<SceneProblem>& problems) {
  std::vector<int> out;
  const int n = static_cast<int>(rest.rows());
  switch (region.kind) {
    case Region::Kind::all:
      for (int i = 0; i < n; ++i) out.push_back(i);
      break;
    case Region::Kind::nodes:
      for (int i : region.nodes) {
        if (i >= n) {
          problems.push_back({region.where, field + ".nodes",
                              "node " + std::to_string(i) + " does not exist (the mesh has " + std::to_string(n) + " nodes)",
                              false});
          continue;
        }
        out.push_back(i);
      }
      break;
    case Region::Kind::box:
      for (int i = 0; i < n; ++i) {
        const vdm::Vec3 x = rest.row(i);
        if ((x - region.min).minCoeff() >= 0 && (region.max - x).minCoeff() >= 0) out.push_back(i);
      }
      break;
    case Region::Kind::sphere:
      for (int i = 0; i < n; ++i)
        if ((rest.row(i).transpose() - region.center).norm() <= region.radius) out.push_back(i);
      break;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (out.empty() && region.kind != Region::Kind::nodes) {
    const vdm::Vec3 lo = rest.colwise().minCoeff(), hi = rest.colwise().maxCoeff();
    std::ostringstream m;
    m << "the region selects no node of the organ (the organ spans [" << lo.x() << ", " << lo.y() << ", " << lo.z()
      << "] to [" << hi.x() << ", " << hi.y() << ", " << hi.z() << "] m after scale, rotate_deg and translate)";
    problems.push_back({region.where, field, m.str(), false});
  }
  return out;
}

void place_organ(vdm::NodeMat& x, const vdm::Vec3& rotate_deg, const vdm::Vec3& translate) {
  if (x.rows() == 0 || (rotate_deg.isZero() && translate.isZero())) return;
  const vdm::Vec3 c = 0.5 * (x.colwise().minCoeff() + x.colwise().maxCoeff()).transpose();
  const Eigen::Matrix3d R = rotation_from_degrees(rotate_deg);
  for (Eigen::Index i = 0; i < x.rows(); ++i) x.row(i) = (R * (x.row(i).transpose() - c) + c + translate).transpose();
}

bool prepare_scene(const std::string& path, PreparedScene& out, std::vector<SceneProblem>& problems) {
  SceneLoadResult loaded = load_scene(path);
  problems = loaded.problems;
  if (!loaded.ok()) return false;
  return prepare_scene_def(loaded.scene, out, problems);
}

namespace {
// A skin mesh file as flat-shaded triangles (one normal per facet), placed by the skin's
// scale, rotation and origin in the instrument frame.
std::shared_ptr<render::SkinMesh> load_skin(const SkinDef& def, const std::string& path, std::string& error) {
  if (path.empty()) return nullptr;
  MeshLoadOptions opt;
  opt.scale = def.scale;
  opt.validate = false;
  const MeshLoadResult r = load_surface_mesh(path, opt);
  if (!r.ok) {
    error = r.error;
    return nullptr;
  }
  const Eigen::Matrix3d R = rotation_from_degrees(def.rotate_deg);
  auto skin = std::make_shared<render::SkinMesh>();
  const vdm::TriMat& t = r.mesh.triangles;
  for (Eigen::Index f = 0; f < t.rows(); ++f) {
    vdm::Vec3 p[3];
    for (int c = 0; c < 3; ++c) p[c] = R * r.mesh.positions.row(t(f, c)).transpose() + def.origin;
    const vdm::Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]);
    const Eigen::Vector3f nf = n.norm() > 0 ? Eigen::Vector3f(n.normalized().cast<float>()) : Eigen::Vector3f::UnitZ();
    for (int c = 0; c < 3; ++c) {
      skin->indices.push_back(unsigned(skin->positions.size()));
      skin->positions.push_back(p[c].cast<float>());
      skin->normals.push_back(nf);
    }
  }
  return skin;
}
// A convex probe's hull from its mesh, placed in the instrument frame.
bool load_convex(const ConvexDef& def, std::shared_ptr<const vdm::ConvexHull>& out, std::string& error) {
  MeshLoadOptions opt;
  opt.scale = def.scale;
  opt.validate = false;
  const MeshLoadResult r = load_surface_mesh(def.mesh, opt);
  if (!r.ok) {
    error = r.error;
    return false;
  }
  const Eigen::Matrix3d R = rotation_from_degrees(def.rotate_deg);
  std::vector<vdm::Vec3> points;
  for (Eigen::Index i = 0; i < r.mesh.positions.rows(); ++i)
    points.push_back(R * r.mesh.positions.row(i).transpose() + def.origin);
  auto hull = std::make_shared<vdm::ConvexHull>();
  if (!vdm::convex_hull(points, *hull, error)) {
    error = def.mesh + ": " + error;
    return false;
  }
  out = hull;
  return true;
}
}  // namespace

namespace {
// One organ of the scene on its placed surface: its tissue model, the nodes of its regions, its
// reference model. False (with the problems) when any is wrong.
bool prepare_organ(const SceneDef& s, const OrganDef& od, const vdm::SurfaceMesh& placed, PreparedOrgan& out,
                   std::vector<SceneProblem>& problems) {
  const auto failed = [&] {
    return std::any_of(problems.begin(), problems.end(), [](const SceneProblem& p) { return !p.warning; });
  };
  vdm::TissueDef def = vdm::default_tissue(placed);
  const int n = def.mesh.node_count();
  def.bulk_modulus = vdm::NodeMat(n, 3);
  for (int d = 0; d < 3; ++d) def.bulk_modulus.col(d).setConstant(od.bulk_modulus[d]);
  def.connectivity_modulus = od.connectivity_modulus;
  def.capsule = od.capsule;
  // What the model ignores does not reach the surface it shares: the skin's bending, the stress.
  const OrganModel& row = organ_model(od.model);
  def.bending_modulus = row.uses("organ.material.bending_modulus") ? od.bending_modulus : 0.0;
  def.density = od.density;
  def.dt = s.dt;
  def.gravity = s.gravity;
  def.use_gravity = s.has(Effect::gravity);
  def.use_inertia = s.has(Effect::inertia);
  def.compute_stress = s.has(Effect::stress) && row.surface_stress;
  def.damping = od.damping;
  def.volume_constraint = s.volume_constraint;
  def.solver = s.solver;
  def.fixed = vdm::FlagMat::Zero(n, 3);
  const auto item = [&](const char* list, size_t k) { return od.field + "." + list + "[" + std::to_string(k) + "]"; };
  for (size_t k = 0; k < od.fixed.size(); ++k)
    for (int i : select_nodes(od.fixed[k].region, def.mesh.positions, item("fixed", k), problems))
      for (int d = 0; d < 3; ++d)
        if (od.fixed[k].axes[d]) def.fixed(i, d) = 1;
  for (size_t k = 0; k < od.loads.size(); ++k)
    out.load_nodes.push_back(select_nodes(od.loads[k].region, def.mesh.positions, item("loads", k), problems));
  for (size_t k = 0; k < od.prescribed.size(); ++k) {
    const auto nodes = select_nodes(od.prescribed[k].region, def.mesh.positions, item("prescribed", k), problems);
    vdm::Vec3 c = vdm::Vec3::Zero();
    for (int i : nodes) c += def.mesh.positions.row(i).transpose() / double(nodes.size());
    out.prescribed_about.push_back(od.prescribed[k].about.value_or(c));
    out.prescribed_nodes.push_back(nodes);
  }
  if (failed()) return false;
  std::string error;
  if (!vdm::build_tissue_model(def, out.model, error)) {
    problems.push_back({s.file, od.field, error, false});
    return false;
  }
  organ_model_run(od.model).check_placed(s, od, out.model.rest, problems);
  if (failed()) return false;
  if (!build_reference_model(s, od, out.model, out.reference, error)) {
    problems.push_back({s.file, od.field + ".model", error, false});
    return false;
  }
  return true;
}
}  // namespace

vdm::SurfaceMesh join_surfaces(const std::vector<vdm::SurfaceMesh>& parts) {
  vdm::SurfaceMesh all;
  if (parts.size() == 1) return parts.front();
  int nodes = 0, triangles = 0;
  for (const vdm::SurfaceMesh& p : parts) nodes += p.node_count(), triangles += p.triangle_count();
  all.positions.resize(nodes, 3);
  all.triangles.resize(triangles, 3);
  int n0 = 0, t0 = 0;
  for (const vdm::SurfaceMesh& p : parts) {
    all.positions.middleRows(n0, p.node_count()) = p.positions;
    all.triangles.middleRows(t0, p.triangle_count()) = p.triangles.array() + n0;
    n0 += p.node_count();
    t0 += p.triangle_count();
  }
  return all;
}

bool prepare_scene_def(const SceneDef& scene, PreparedScene& out, std::vector<SceneProblem>& problems) {
  out.scene = scene;
  const SceneDef& s = out.scene;
  // Instrument skins (pictures only): loaded now so that `check` finds a broken file.
  out.skins.assign(s.instruments.size(), InstrumentSkin{});
  for (size_t k = 0; k < s.instrument_skins.size() && k < s.instruments.size(); ++k) {
    const SkinDef& d = s.instrument_skins[k];
    if (!d.present) continue;
    std::string error;
    const std::string field = "instruments[" + std::to_string(k) + "].skin";
    out.skins[k].body = load_skin(d, d.body, error);
    for (int j = 0; j < 2 && error.empty(); ++j) out.skins[k].jaws[j] = load_skin(d, d.jaws[j], error);
    if (!error.empty()) {
      problems.push_back({d.where, field, error, false});
      return false;
    }
  }

  // Convex probes: the hull of their mesh (loaded now so that `check` finds a broken file).
  for (size_t k = 0; k < s.instrument_convex.size() && k < s.instruments.size(); ++k) {
    const ConvexDef& d = s.instrument_convex[k];
    if (!d.present) continue;
    std::string error;
    if (!load_convex(d, out.scene.instruments[k].shape.hull, error)) {
      problems.push_back({d.where, "instruments[" + std::to_string(k) + "].shape.mesh", error, false});
      return false;
    }
  }

  // Every organ's surface, placed; and all of them as one surface (organ i's nodes from
  // node_offset[i]), which keyframes placed on a surface and the picture see.
  std::vector<vdm::SurfaceMesh> placed(s.organs.size());
  out.organs.assign(s.organs.size(), PreparedOrgan{});
  out.node_offset.assign(1, 0);
  for (size_t o = 0; o < s.organs.size(); ++o) {
    const OrganDef& od = s.organs[o];
    MeshLoadOptions mopt;
    mopt.scale = od.scale;
    const MeshLoadResult mesh = load_surface_mesh(od.mesh_path, mopt);
    if (!mesh.ok) {
      problems.push_back({s.file, od.field + ".mesh", mesh.error, false});
      return false;
    }
    if (mesh.flipped) problems.push_back({s.file, od.field + ".mesh", flipped_surface_note(od.mesh_path), true});
    placed[o] = mesh.mesh;
    place_organ(placed[o].positions, od.rotate_deg, od.translate);
    out.node_offset.push_back(out.node_offset.back() + placed[o].node_count());
  }
  out.surface = join_surfaces(placed);
  // Keyframes placed on the organs get their tips before anything reads the scripts.
  if (!resolve_surface_keyframes(out.scene, out.surface, out.surface_hits, problems)) return false;
  if (!check_port_keyframes(out.scene, out.surface, problems)) return false;
  for (size_t o = 0; o < s.organs.size(); ++o)
    if (!prepare_organ(s, s.organs[o], placed[o], out.organs[o], problems)) return false;
  return true;
}

}  // namespace vdmsim
