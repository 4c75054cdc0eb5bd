#include "app/scene/obj_reader.hpp"

#include <array>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace vdmsim {

bool read_obj(const std::string& path, vdm::SurfaceMesh& mesh, std::string& error) {
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    error = "cannot open the file";
    return false;
  }
  std::vector<vdm::Vec3> v;
  std::vector<std::array<int, 3>> tris;
  std::vector<int> poly;
  std::string line;
  long line_no = 0;
  auto fail = [&](const std::string& what) {
    std::ostringstream s;
    s << "line " << line_no << ": " << what;
    error = s.str();
    return false;
  };
  while (std::getline(f, line)) {
    ++line_no;
    if (line.size() < 2) continue;
    if (line[0] == 'v' && (line[1] == ' ' || line[1] == '\t')) {
      const char* p = line.c_str() + 2;
      vdm::Vec3 x;
      for (int d = 0; d < 3; ++d) {
        char* end = nullptr;
        errno = 0;
        x[d] = std::strtod(p, &end);
        if (end == p) return fail("a vertex needs three numbers: '" + line.substr(0, 80) + "'");
        p = end;
      }
      v.push_back(x);
    } else if (line[0] == 'f' && (line[1] == ' ' || line[1] == '\t')) {
      poly.clear();
      std::istringstream ls(line.substr(2));
      std::string tok;
      while (ls >> tok) {
        char* end = nullptr;
        const long idx = std::strtol(tok.c_str(), &end, 10);  // "i", "i/t", "i//n", "i/t/n"
        if (end == tok.c_str() || (*end != '\0' && *end != '/'))
          return fail("bad face index '" + tok.substr(0, 40) + "'");
        const long resolved = idx > 0 ? idx - 1 : static_cast<long>(v.size()) + idx;  // negative: relative
        if (idx == 0 || resolved < 0 || resolved >= static_cast<long>(v.size())) {
          std::ostringstream m;
          m << "face refers to vertex " << idx << " but " << v.size() << " vertices are defined so far";
          return fail(m.str());
        }
        poly.push_back(static_cast<int>(resolved));
      }
      if (poly.size() < 3) return fail("a face needs at least three vertices");
      for (size_t k = 1; k + 1 < poly.size(); ++k) tris.push_back({poly[0], poly[k], poly[k + 1]});
    }
  }
  if (f.bad()) return fail("read error");
  mesh.positions.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (size_t i = 0; i < v.size(); ++i) mesh.positions.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  mesh.triangles.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t k = 0; k < tris.size(); ++k)
    for (int c = 0; c < 3; ++c) mesh.triangles(static_cast<Eigen::Index>(k), c) = tris[k][c];
  return true;
}

}  // namespace vdmsim
