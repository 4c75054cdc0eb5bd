#include "app/scene/mesh_io.hpp"

#include "app/mesh_prep/self_intersections.hpp"
#include "app/scene/assimp_import.hpp"

#include "app/scene/obj_reader.hpp"
#include "app/scene/ply_reader.hpp"


#include <array>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

namespace vdmsim {
namespace {

// Whether the file is read by our PLY reader: a .ply name, or "ply" (any case) as its first
// line whatever the name (assimp would otherwise pick its own PLY importer by the content).
bool is_ply(const std::string& path, const std::string& ext) {
  if (ext == ".ply") return true;
  std::ifstream f(path, std::ios::binary);
  char head[5] = {};
  f.read(head, sizeof head);
  return looks_like_ply(std::string_view(head, static_cast<size_t>(f.gcount())));
}

}  // namespace

MeshLoadResult load_surface_mesh(const std::string& path, const MeshLoadOptions& opt) {
  MeshLoadResult out;
  auto fail = [&](const std::string& msg) {
    out.ok = false;
    out.error = path + ": " + msg;
    return out;
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return fail("no such file");
  if (std::filesystem::is_directory(path, ec)) return fail("is a directory, not a mesh file");
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) return fail("cannot read the file size: " + ec.message());
  if (bytes == 0) return fail("the file is empty");
  if (static_cast<long long>(bytes) > opt.max_file_bytes) {
    std::ostringstream s;
    s << "the file is " << bytes << " bytes, more than the limit of " << opt.max_file_bytes;
    return fail(s.str());
  }

  std::vector<vdm::Vec3> points;
  std::vector<std::array<int, 3>> tris;
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  auto take = [&](const vdm::SurfaceMesh& raw) {
    points.resize(static_cast<size_t>(raw.node_count()));
    for (int i = 0; i < raw.node_count(); ++i) points[i] = raw.positions.row(i).transpose();
    tris.resize(static_cast<size_t>(raw.triangle_count()));
    for (int k = 0; k < raw.triangle_count(); ++k) tris[k] = {raw.triangles(k, 0), raw.triangles(k, 1), raw.triangles(k, 2)};
  };
  if (is_ply(path, ext)) {
    // PLY directly (app/ply_reader): strict, file order and double precision kept.
    vdm::SurfaceMesh raw;
    std::string why;
    if (!read_ply(path, raw, why)) return fail(why);
    take(raw);
  } else if (ext == ".obj") {
    // OBJ directly: file order and double precision kept (node indices in scenes refer to it).
    vdm::SurfaceMesh raw;
    std::string why;
    if (!read_obj(path, raw, why)) return fail(why);
    take(raw);
  } else {
    std::string why;
    if (!read_with_assimp(path, points, tris, why)) return fail(why);
  }
  if (tris.empty()) return fail("the file holds no triangles");
  // Before welding (NaN cannot be a map key): finite coordinates and valid indices only.
  for (size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) {
      std::ostringstream s;
      s << "non-finite coordinate: vertex " << i << " is (" << points[i].x() << ", " << points[i].y() << ", "
        << points[i].z() << ")";
      out.problem = vdm::MeshProblem::non_finite;
      return fail(s.str());
    }
  for (size_t k = 0; k < tris.size(); ++k)
    for (int c = 0; c < 3; ++c)
      if (tris[k][c] < 0 || tris[k][c] >= static_cast<int>(points.size())) {
        out.problem = vdm::MeshProblem::bad_index;
        return fail("triangle " + std::to_string(k) + " refers to a vertex that does not exist");
      }
  // Weld nodes at exactly the same position: separate meshes or per-corner attributes
  // duplicate them, and the surface must be one connected node set.
  std::map<std::array<double, 3>, int> index_of;
  std::vector<int> remap(points.size());
  std::vector<vdm::Vec3> unique;
  unique.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const std::array<double, 3> key = {points[i].x(), points[i].y(), points[i].z()};
    auto it = index_of.find(key);
    if (it == index_of.end()) {
      it = index_of.emplace(key, static_cast<int>(unique.size())).first;
      unique.push_back(points[i]);
    }
    remap[i] = it->second;
  }
  out.welded_nodes = static_cast<int>(points.size() - unique.size());
  out.mesh.positions.resize(static_cast<Eigen::Index>(unique.size()), 3);
  for (size_t i = 0; i < unique.size(); ++i)
    out.mesh.positions.row(static_cast<Eigen::Index>(i)) = opt.scale * unique[i].transpose();
  out.mesh.triangles.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t k = 0; k < tris.size(); ++k)
    for (int c = 0; c < 3; ++c) out.mesh.triangles(static_cast<Eigen::Index>(k), c) = remap[tris[k][c]];
  out.dropped_nodes = vdm::drop_unreferenced_nodes(out.mesh);

  if (opt.validate) {
    const vdm::MeshCheck check = vdm::check_and_orient_surface(out.mesh);
    if (!check.ok()) {
      out.problem = check.problem;
      return fail(std::string(vdm::to_string(check.problem)) + ": " + check.message);
    }
    out.flipped = check.flipped;
    // A surface through itself encloses no well-defined volume (O(n log n): about 0.1 s at
    // 40k nodes).
    const SelfIntersections crossing = find_self_intersections(out.mesh, 5);
    if (crossing.any) {
      out.problem = vdm::MeshProblem::self_intersection;
      return fail("self-intersection: the surface passes through itself (" + crossing.text() +
                  "); `vdmsim prepare-mesh` repairs it");
    }
  }
  out.ok = true;
  return out;
}

std::string flipped_surface_note(const std::string& path) {
  return path + ": the surface is oriented inward (its triangles face into the organ): it is used flipped outward";
}

bool save_obj(const vdm::SurfaceMesh& mesh, const std::string& path, const std::string& header,
              std::string& error, bool* at_run_time) {
  namespace fs = std::filesystem;
  if (at_run_time) *at_run_time = false;
  // A file (or a new one) is written beside itself and renamed into place, so that a failed write
  // leaves what was there; a device or a pipe (/dev/stdout) is written directly.
  std::error_code ec;
  const fs::path target = fs::exists(path, ec) ? fs::canonical(path, ec) : fs::path(path);
  const bool replace = !fs::exists(target, ec) || fs::is_regular_file(target, ec);
  const std::string written = replace ? target.string() + ".tmp" : path;
  errno = 0;
  std::ofstream f(written);
  if (!f) {
    error = path + ": cannot open for writing" + (errno ? " (" + std::string(std::strerror(errno)) + ")" : "");
    return false;
  }
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);) f << "# " << line << '\n';
  char buf[128];
  for (int i = 0; i < mesh.node_count(); ++i) {
    std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", mesh.positions(i, 0), mesh.positions(i, 1),
                  mesh.positions(i, 2));
    f << buf;
  }
  for (int k = 0; k < mesh.triangle_count(); ++k)
    f << "f " << mesh.triangles(k, 0) + 1 << ' ' << mesh.triangles(k, 1) + 1 << ' '
      << mesh.triangles(k, 2) + 1 << '\n';
  f.close();  // what close flushes can fail too
  if (!f) {
    // errno is the failing write's; ENOSPC in words ("no space left on the device").
    const int e = errno ? errno : EIO;
    if (at_run_time) *at_run_time = true;
    error = path + ": write failed: " + (e == ENOSPC ? std::string("no space left on the device") : std::strerror(e));
    if (replace) fs::remove(written, ec);
    return false;
  }
  if (replace) {
    fs::rename(written, target, ec);
    if (ec) {
      error = path + ": cannot move the written file into place (" + ec.message() + ")";
      fs::remove(written, ec);
      return false;
    }
  }
  return true;
}

}  // namespace vdmsim
