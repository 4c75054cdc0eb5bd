#include "app/simulation/tet_mesher.hpp"

#include "app/simulation/tet_budget.hpp"

#include <dlfcn.h>
#include <gmshc.h>  // the C API's declarations only: the library is opened on first use

#include <algorithm>
#include <array>
#include <cstdio>
#include <map>
#include <vector>

namespace vdmsim {
namespace {

// libgmsh is opened (dlopen) on the first tet mesh rather than linked: linked, it and the
// libraries behind it (OpenCASCADE, FLTK, ...) were loaded into every vdmsim process, about
// 36 MB resident from relocations alone, though only the FEM reference meshes with it.
// VDMSIM_GMSH_LIBRARY (app/CMakeLists.txt) is the soname of the libgmsh found at build time.
struct GmshApi {
  decltype(&gmshInitialize) initialize = nullptr;
  decltype(&gmshFinalize) finalize = nullptr;
  decltype(&gmshOptionSetNumber) set_number = nullptr;
  decltype(&gmshModelAdd) model_add = nullptr;
  decltype(&gmshModelAddDiscreteEntity) add_discrete_entity = nullptr;
  decltype(&gmshModelMeshAddNodes) add_nodes = nullptr;
  decltype(&gmshModelMeshAddElementsByType) add_elements_by_type = nullptr;
  decltype(&gmshModelGeoAddSurfaceLoop) add_surface_loop = nullptr;
  decltype(&gmshModelGeoAddVolume) add_volume = nullptr;
  decltype(&gmshModelGeoSynchronize) synchronize = nullptr;
  decltype(&gmshModelMeshGenerate) generate = nullptr;
  decltype(&gmshModelMeshGetNodes) get_nodes = nullptr;
  decltype(&gmshModelMeshGetElementsByType) get_elements_by_type = nullptr;
  decltype(&gmshModelOccAddBox) occ_add_box = nullptr;
  decltype(&gmshModelOccAddDisk) occ_add_disk = nullptr;
  decltype(&gmshModelOccFragment) occ_fragment = nullptr;
  decltype(&gmshModelOccSynchronize) occ_synchronize = nullptr;
  decltype(&gmshModelMeshFieldAdd) field_add = nullptr;
  decltype(&gmshModelMeshFieldSetString) field_set_string = nullptr;
  decltype(&gmshModelMeshFieldSetNumbers) field_set_numbers = nullptr;
  decltype(&gmshModelMeshFieldSetAsBackgroundMesh) field_background = nullptr;
  decltype(&gmshLoggerGetLastError) last_error = nullptr;
  decltype(&gmshFree) free = nullptr;
  std::string error;  // why the library cannot be used (empty when it can)
};

template <typename F>
void bind(void* lib, const char* name, F& f, std::string& error) {
  f = reinterpret_cast<F>(dlsym(lib, name));
  if (!f && error.empty()) error = std::string("gmsh: ") + VDMSIM_GMSH_LIBRARY + " has no " + name;
}

const GmshApi& gmsh_api() {
  static const GmshApi api = [] {
    GmshApi g;
    void* lib = dlopen(VDMSIM_GMSH_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      const char* why = dlerror();
      g.error = std::string("gmsh: cannot load ") + VDMSIM_GMSH_LIBRARY + (why ? std::string(" (") + why + ")" : "");
      return g;
    }
    bind(lib, "gmshInitialize", g.initialize, g.error);
    bind(lib, "gmshFinalize", g.finalize, g.error);
    bind(lib, "gmshOptionSetNumber", g.set_number, g.error);
    bind(lib, "gmshModelAdd", g.model_add, g.error);
    bind(lib, "gmshModelAddDiscreteEntity", g.add_discrete_entity, g.error);
    bind(lib, "gmshModelMeshAddNodes", g.add_nodes, g.error);
    bind(lib, "gmshModelMeshAddElementsByType", g.add_elements_by_type, g.error);
    bind(lib, "gmshModelGeoAddSurfaceLoop", g.add_surface_loop, g.error);
    bind(lib, "gmshModelGeoAddVolume", g.add_volume, g.error);
    bind(lib, "gmshModelGeoSynchronize", g.synchronize, g.error);
    bind(lib, "gmshModelMeshGenerate", g.generate, g.error);
    bind(lib, "gmshModelMeshGetNodes", g.get_nodes, g.error);
    bind(lib, "gmshModelMeshGetElementsByType", g.get_elements_by_type, g.error);
    bind(lib, "gmshModelOccAddBox", g.occ_add_box, g.error);
    bind(lib, "gmshModelOccAddDisk", g.occ_add_disk, g.error);
    bind(lib, "gmshModelOccFragment", g.occ_fragment, g.error);
    bind(lib, "gmshModelOccSynchronize", g.occ_synchronize, g.error);
    bind(lib, "gmshModelMeshFieldAdd", g.field_add, g.error);
    bind(lib, "gmshModelMeshFieldSetString", g.field_set_string, g.error);
    bind(lib, "gmshModelMeshFieldSetNumbers", g.field_set_numbers, g.error);
    bind(lib, "gmshModelMeshFieldSetAsBackgroundMesh", g.field_background, g.error);
    bind(lib, "gmshLoggerGetLastError", g.last_error, g.error);
    bind(lib, "gmshFree", g.free, g.error);
    return g;  // the library stays loaded
  }();
  return api;
}

// gmsh's message for the call that set `ierr`.
std::string gmsh_error(const GmshApi& g) {
  char* text = nullptr;
  int ierr = 0;
  g.last_error(&text, &ierr);
  std::string out = ierr == 0 && text && *text ? std::string("gmsh: ") + text : std::string();
  if (text) g.free(text);
  return out;
}

// The mesh's nodes (tags, coordinates) and its 4-node tets as gmsh returned them.
struct GmshVolumeMesh {
  std::vector<std::size_t> node_tags, tet_nodes;
  std::vector<double> node_xyz;
};

// Reads the generated mesh's nodes and tets; false (ierr set) on a failed call.
void read_volume_mesh(const GmshApi& g, GmshVolumeMesh& out, int& ierr) {
  std::size_t *ntags = nullptr, *etags = nullptr, *enodes = nullptr;
  double *xyz = nullptr, *param = nullptr;
  std::size_t ntags_n = 0, xyz_n = 0, param_n = 0, etags_n = 0, enodes_n = 0;
  g.get_nodes(&ntags, &ntags_n, &xyz, &xyz_n, &param, &param_n, -1, -1, 1, 0, &ierr);
  if (!ierr) g.get_elements_by_type(4, &etags, &etags_n, &enodes, &enodes_n, -1, 0, 1, &ierr);  // 4 = 4-node tet
  if (!ierr) {
    out.node_tags.assign(ntags, ntags + ntags_n);
    out.node_xyz.assign(xyz, xyz + xyz_n);
    out.tet_nodes.assign(enodes, enodes + enodes_n);
  }
  for (void* p : {static_cast<void*>(ntags), static_cast<void*>(xyz), static_cast<void*>(param),
                  static_cast<void*>(etags), static_cast<void*>(enodes)})
    if (p) g.free(p);
}

}  // namespace

bool mesh_box_with_disk(const BoxWithDisk& c, vdm::fem::TetMesh& out, std::string& error) {
  if (!(c.size.minCoeff() > 0) || !(c.disk_radius > 0) || !(2 * c.disk_radius < std::min(c.size.x(), c.size.y())) ||
      !(c.h_min > 0) || !(c.grade >= 0) || !(c.h_max >= c.h_min))
    return error = "mesh_box_with_disk: a size, radius or mesh size out of range", false;
  const GmshApi& g = gmsh_api();
  if (!g.error.empty()) return error = g.error, false;
  const vdm::Vec3 lo = c.center - 0.5 * c.size;
  const double top = c.center.z() + 0.5 * c.size.z();
  // h = min(h_max, h_min + grade * distance from the rim), the rim the circle of radius R
  // about the top's centre.
  char formula[512];
  std::snprintf(formula, sizeof formula, "%.17g + %.17g * Sqrt((Sqrt((x - %.17g)^2 + (y - %.17g)^2) - %.17g)^2 + (z - %.17g)^2)",
                c.h_min, c.grade, c.center.x(), c.center.y(), c.disk_radius, top);
  char cap[64];
  std::snprintf(cap, sizeof cap, "%.17g", c.h_max);
  GmshVolumeMesh mesh;
  int ierr = 0;  // each call sets it, nonzero on failure: no call after a failed one
  g.initialize(0, nullptr, 1, &ierr);
  if (!ierr) g.set_number("General.Terminal", 0, &ierr);
  if (!ierr) g.set_number("General.Verbosity", 0, &ierr);
  if (!ierr) g.model_add("box_with_disk", &ierr);
  const int box = ierr ? 0 : g.occ_add_box(lo.x(), lo.y(), lo.z(), c.size.x(), c.size.y(), c.size.z(), -1, &ierr);
  const int disk = ierr ? 0 : g.occ_add_disk(c.center.x(), c.center.y(), top, c.disk_radius, c.disk_radius, -1, &ierr);
  if (!ierr) {
    int object[2] = {3, box}, tool[2] = {2, disk};
    int* out_tags = nullptr;
    int** map = nullptr;
    std::size_t out_n = 0, map_nn = 0;
    std::size_t* map_n = nullptr;
    g.occ_fragment(object, 2, tool, 2, &out_tags, &out_n, &map, &map_n, &map_nn, -1, 1, 1, &ierr);
    if (out_tags) g.free(out_tags);
    if (map) {
      for (std::size_t k = 0; k < map_nn; ++k)
        if (map[k]) g.free(map[k]);
      g.free(map);
    }
    if (map_n) g.free(map_n);
  }
  if (!ierr) g.occ_synchronize(&ierr);
  const int graded = ierr ? 0 : g.field_add("MathEval", -1, &ierr);
  if (!ierr) g.field_set_string(graded, "F", formula, &ierr);
  const int capped = ierr ? 0 : g.field_add("MathEval", -1, &ierr);
  if (!ierr) g.field_set_string(capped, "F", cap, &ierr);
  const int size_field = ierr ? 0 : g.field_add("Min", -1, &ierr);
  double both[2] = {double(graded), double(capped)};
  if (!ierr) g.field_set_numbers(size_field, "FieldsList", both, 2, &ierr);
  if (!ierr) g.field_background(size_field, &ierr);
  for (const char* option : {"Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints", "Mesh.MeshSizeFromCurvature"})
    if (!ierr) g.set_number(option, 0, &ierr);
  if (!ierr) g.set_number("Mesh.Optimize", 1, &ierr);
  if (!ierr) g.generate(3, &ierr);
  if (!ierr) read_volume_mesh(g, mesh, ierr);
  if (ierr) {
    error = gmsh_error(g);
    if (error.empty()) error = "gmsh failed to mesh the box";
  }
  int finalize_err = 0;
  g.finalize(&finalize_err);
  if (ierr) return false;
  if (mesh.tet_nodes.empty()) return error = "gmsh made no tetrahedra", false;
  // Node tags -> gmsh's order; then the boundary's nodes (faces of one tet) first.
  std::map<std::size_t, int> order;
  for (size_t k = 0; k < mesh.node_tags.size(); ++k) order[mesh.node_tags[k]] = static_cast<int>(k);
  const int nt = static_cast<int>(mesh.tet_nodes.size() / 4);
  std::vector<std::array<int, 4>> tets(static_cast<size_t>(nt));
  for (int t = 0; t < nt; ++t)
    for (int q = 0; q < 4; ++q) {
      const auto it = order.find(mesh.tet_nodes[4 * static_cast<size_t>(t) + q]);
      if (it == order.end()) return error = "gmsh returned a tet with an unknown node", false;
      tets[static_cast<size_t>(t)][static_cast<size_t>(q)] = it->second;
    }
  std::map<std::array<int, 3>, int> face_count;
  for (const auto& e : tets)
    for (const auto& f : {std::array<int, 3>{e[0], e[1], e[2]}, std::array<int, 3>{e[0], e[1], e[3]},
                          std::array<int, 3>{e[0], e[2], e[3]}, std::array<int, 3>{e[1], e[2], e[3]}}) {
      std::array<int, 3> key = f;
      std::sort(key.begin(), key.end());
      ++face_count[key];
    }
  // 0: in no tet (gmsh's nodes of geometry the volume does not use), 1: inside, 2: on the boundary.
  const int all = static_cast<int>(mesh.node_tags.size());
  std::vector<char> kind(static_cast<size_t>(all), 0);
  for (const auto& e : tets)
    for (const int v : e) kind[static_cast<size_t>(v)] = 1;
  for (const auto& [key, count] : face_count)
    if (count == 1)
      for (const int v : key) kind[static_cast<size_t>(v)] = 2;
  std::vector<int> index(static_cast<size_t>(all), -1);
  int next = 0;
  for (const char pass : {2, 1})
    for (int v = 0; v < all; ++v)
      if (kind[static_cast<size_t>(v)] == pass) index[static_cast<size_t>(v)] = next++;
  out = vdm::fem::TetMesh{};
  out.surface_nodes = static_cast<int>(std::count(kind.begin(), kind.end(), 2));
  out.positions.resize(next, 3);
  for (int v = 0; v < all; ++v)
    if (index[static_cast<size_t>(v)] >= 0)
      for (int d = 0; d < 3; ++d) out.positions(index[static_cast<size_t>(v)], d) = mesh.node_xyz[3 * static_cast<size_t>(v) + d];
  out.tets.resize(nt, 4);
  for (int t = 0; t < nt; ++t) {
    for (int q = 0; q < 4; ++q) out.tets(t, q) = index[static_cast<size_t>(tets[static_cast<size_t>(t)][static_cast<size_t>(q)])];
    const vdm::Vec3 a = out.positions.row(out.tets(t, 0)), b = out.positions.row(out.tets(t, 1)),
                    cc = out.positions.row(out.tets(t, 2)), d = out.positions.row(out.tets(t, 3));
    if (vdm::fem::tet_volume(a, b, cc, d) < 0) std::swap(out.tets(t, 0), out.tets(t, 1));
  }
  out.surface.positions = out.positions.topRows(out.surface_nodes);
  return vdm::fem::check_tet_mesh(out, error);  // fills the surface's outward triangles
}

bool tetrahedralize(const vdm::SurfaceMesh& surface, double max_size, vdm::fem::TetMesh& out, std::string& error,
                    TetInterior interior) {
  if (!check_tet_budget(surface, max_size, error)) return false;
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
  const GmshApi& g = gmsh_api();
  if (!g.error.empty()) return error = g.error, false;
  int ierr = 0;  // each call sets it, nonzero on failure: no call after a failed one
  g.initialize(0, nullptr, 1, &ierr);
  if (!ierr) g.set_number("General.Terminal", 0, &ierr);
  if (!ierr) g.set_number("General.Verbosity", 0, &ierr);
  if (!ierr) g.model_add("organ", &ierr);
  int s = ierr ? 0 : g.add_discrete_entity(2, -1, nullptr, 0, &ierr);
  if (!ierr) g.add_nodes(2, s, tags.data(), tags.size(), coords.data(), coords.size(), nullptr, 0, &ierr);
  if (!ierr) g.add_elements_by_type(s, 2, nullptr, 0, tri.data(), tri.size(), &ierr);  // 2 = 3-node triangle
  int loop = ierr ? 0 : g.add_surface_loop(&s, 1, -1, &ierr);
  if (!ierr) g.add_volume(&loop, 1, -1, &ierr);
  if (!ierr) g.synchronize(&ierr);
  if (!ierr && max_size > 0) g.set_number("Mesh.MeshSizeMax", max_size, &ierr);
  // A coarse interior: the sizes inside no longer follow the surface's edges, they grow to max_size.
  if (!ierr && max_size > 0 && interior == TetInterior::coarse) g.set_number("Mesh.MeshSizeExtendFromBoundary", 0, &ierr);
  if (!ierr) g.set_number("Mesh.Optimize", 1, &ierr);
  GmshVolumeMesh mesh;
  if (!ierr) g.generate(3, &ierr);
  if (!ierr) read_volume_mesh(g, mesh, ierr);
  if (ierr) {
    error = gmsh_error(g);
    if (error.empty()) error = "gmsh failed to mesh the volume (is the surface closed and free of self-intersections?)";
  }
  int finalize_err = 0;
  g.finalize(&finalize_err);
  if (ierr) return false;
  if (mesh.tet_nodes.empty()) return error = "gmsh made no tetrahedra (is the surface closed?)", false;
  const std::vector<std::size_t>& node_tags = mesh.node_tags;
  const std::vector<std::size_t>& tet_nodes = mesh.tet_nodes;
  const std::vector<double>& node_xyz = mesh.node_xyz;
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
