#include "app/tet_mesher.hpp"

#include <gmsh.h>

#include <exception>
#include <map>
#include <vector>

namespace vdmsim {

bool tetrahedralize(const vdm::SurfaceMesh& surface, double max_size, vdm::fem::TetMesh& out, std::string& error) {
  const int ns = surface.node_count();
  std::vector<std::size_t> tags(static_cast<size_t>(ns));
  std::vector<double> coords(3 * static_cast<size_t>(ns));
  for (int i = 0; i < ns; ++i) {
    tags[static_cast<size_t>(i)] = static_cast<std::size_t>(i + 1);
    for (int d = 0; d < 3; ++d) coords[3 * static_cast<size_t>(i) + d] = surface.positions(i, d);
  }
  std::vector<std::size_t> tri;
  tri.reserve(3 * static_cast<size_t>(surface.triangle_count()));
  for (int t = 0; t < surface.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) tri.push_back(static_cast<std::size_t>(surface.triangles(t, c) + 1));
  std::vector<std::size_t> node_tags, tet_tags, tet_nodes;
  std::vector<double> node_xyz, param;
  try {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 0);
    gmsh::model::add("organ");
    const int s = gmsh::model::addDiscreteEntity(2);
    gmsh::model::mesh::addNodes(2, s, tags, coords);
    gmsh::model::mesh::addElementsByType(s, 2, {}, tri);  // 2 = 3-node triangle
    const int loop = gmsh::model::geo::addSurfaceLoop({s});
    gmsh::model::geo::addVolume({loop});
    gmsh::model::geo::synchronize();
    if (max_size > 0) gmsh::option::setNumber("Mesh.MeshSizeMax", max_size);
    gmsh::option::setNumber("Mesh.Optimize", 1);
    gmsh::model::mesh::generate(3);
    gmsh::model::mesh::getNodes(node_tags, node_xyz, param, -1, -1, true, false);
    std::vector<std::size_t> elem_tags;
    gmsh::model::mesh::getElementsByType(4, elem_tags, tet_nodes);  // 4 = 4-node tetrahedron
    gmsh::finalize();
  } catch (const std::exception& e) {
    error = std::string("gmsh: ") + e.what();
    gmsh::finalize();
    return false;
  } catch (...) {
    error = "gmsh failed to mesh the volume (is the surface closed and free of self-intersections?)";
    gmsh::finalize();
    return false;
  }
  if (tet_nodes.empty()) return error = "gmsh made no tetrahedra (is the surface closed?)", false;
  // Surface nodes keep their index; gmsh's new (interior) nodes follow.
  std::map<std::size_t, int> index;
  std::vector<vdm::Vec3> extra;
  for (size_t k = 0; k < node_tags.size(); ++k) {
    const std::size_t tag = node_tags[k];
    if (tag >= 1 && tag <= static_cast<std::size_t>(ns)) {
      index[tag] = static_cast<int>(tag) - 1;
    } else {
      index[tag] = ns + static_cast<int>(extra.size());
      extra.emplace_back(node_xyz[3 * k], node_xyz[3 * k + 1], node_xyz[3 * k + 2]);
    }
  }
  out = vdm::fem::TetMesh{};
  out.surface_nodes = ns;
  out.positions.resize(ns + static_cast<int>(extra.size()), 3);
  out.positions.topRows(ns) = surface.positions;
  for (size_t k = 0; k < extra.size(); ++k) out.positions.row(ns + static_cast<Eigen::Index>(k)) = extra[k];
  const int nt = static_cast<int>(tet_nodes.size() / 4);
  out.tets.resize(nt, 4);
  for (int t = 0; t < nt; ++t) {
    for (int q = 0; q < 4; ++q) {
      const auto it = index.find(tet_nodes[4 * static_cast<size_t>(t) + q]);
      if (it == index.end()) return error = "gmsh returned a tet with an unknown node", false;
      out.tets(t, q) = it->second;
    }
    const vdm::Vec3 a = out.positions.row(out.tets(t, 0)), b = out.positions.row(out.tets(t, 1)),
                    c = out.positions.row(out.tets(t, 2)), d = out.positions.row(out.tets(t, 3));
    if (vdm::fem::tet_volume(a, b, c, d) < 0) std::swap(out.tets(t, 0), out.tets(t, 1));
  }
  out.surface = surface;
  return vdm::fem::check_tet_mesh(out, error);
}

}  // namespace vdmsim
