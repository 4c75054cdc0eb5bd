#include "app/mesh_prep/cgal_surface.hpp"

#include <map>

namespace vdmsim::cgal {

bool to_cgal(const vdm::SurfaceMesh& in, Mesh& out, std::vector<Mesh::Face_index>* face_of_triangle) {
  out.clear();
  std::vector<Mesh::Vertex_index> v(static_cast<size_t>(in.node_count()));
  for (int i = 0; i < in.node_count(); ++i)
    v[i] = out.add_vertex(Point(in.positions(i, 0), in.positions(i, 1), in.positions(i, 2)));
  if (face_of_triangle) face_of_triangle->assign(static_cast<size_t>(in.triangle_count()), Mesh::null_face());
  for (int k = 0; k < in.triangle_count(); ++k) {
    const int a = in.triangles(k, 0), b = in.triangles(k, 1), c = in.triangles(k, 2);
    if (a == b || b == c || a == c) return false;
    const Mesh::Face_index f = out.add_face(v[a], v[b], v[c]);
    if (f == Mesh::null_face()) return false;
    if (face_of_triangle) (*face_of_triangle)[k] = f;
  }
  return true;
}

vdm::SurfaceMesh from_cgal(const Mesh& mesh) {
  vdm::SurfaceMesh out;
  std::map<Mesh::Vertex_index, int> index;
  out.positions.resize(static_cast<Eigen::Index>(mesh.number_of_vertices()), 3);
  int n = 0;
  for (Mesh::Vertex_index v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    out.positions.row(n) = vdm::Vec3(p.x(), p.y(), p.z()).transpose();
    index[v] = n++;
  }
  out.triangles.resize(static_cast<Eigen::Index>(mesh.number_of_faces()), 3);
  int k = 0;
  for (Mesh::Face_index f : mesh.faces()) {
    int c = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (c < 3) out.triangles(k, c) = index[v];
      ++c;
    }
    ++k;
  }
  return out;
}

}  // namespace vdmsim::cgal
