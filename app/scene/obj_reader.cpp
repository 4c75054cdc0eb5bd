#include "app/scene/obj_reader.hpp"

#include <array>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace vdmsim {
namespace {

// The whole token as a number (strtod's syntax); false when anything is left after it.
bool parse_number(const std::string& tok, double& out) {
  char* end = nullptr;
  out = std::strtod(tok.c_str(), &end);
  return end != tok.c_str() && *end == '\0';
}

// A whole token as a whole number.
bool parse_integer(const std::string& tok, long& out) {
  char* end = nullptr;
  errno = 0;
  out = std::strtol(tok.c_str(), &end, 10);
  return end != tok.c_str() && *end == '\0' && errno == 0;
}

// A face corner: "i", "i/t", "i//n" or "i/t/n", each part a whole number; `vertex` is i.
bool parse_face_corner(const std::string& tok, long& vertex) {
  std::vector<std::string> parts(1);
  for (const char c : tok) {
    if (c == '/') parts.emplace_back();
    else parts.back() += c;
  }
  if (parts.size() > 3 || !parse_integer(parts[0], vertex)) return false;
  long ignored = 0;
  for (size_t k = 1; k < parts.size(); ++k)
    if (!(k == 1 && parts.size() == 3 && parts[k].empty()) && !parse_integer(parts[k], ignored)) return false;
  return true;
}

}  // namespace

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
      // x y z, then optionally w or a colour: every token a number with nothing after it
      // ("0.05abc" is an error, not 0.05).
      std::istringstream ls(line.substr(2));
      std::string tok;
      vdm::Vec3 x;
      int count = 0;
      while (ls >> tok) {
        double value = 0;
        if (!parse_number(tok, value))
          return fail("'" + tok.substr(0, 40) + "' is not a number (in '" + line.substr(0, 80) + "')");
        if (count < 3) x[count] = value;
        ++count;
      }
      if (count < 3) return fail("a vertex needs three numbers: '" + line.substr(0, 80) + "'");
      v.push_back(x);
    } else if (line[0] == 'f' && (line[1] == ' ' || line[1] == '\t')) {
      poly.clear();
      std::istringstream ls(line.substr(2));
      std::string tok;
      while (ls >> tok) {
        long idx = 0;
        if (!parse_face_corner(tok, idx)) return fail("bad face index '" + tok.substr(0, 40) + "'");
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
