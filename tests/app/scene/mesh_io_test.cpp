#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "app/scene/mesh_io.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;
using vdm::MeshProblem;

fs::path temp_dir() {
  return vdmsim::test::scratch_dir("mesh_io");
}

fs::path write_text(const std::string& name, const std::string& text) {
  const fs::path p = temp_dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

std::string obj_text(const vdm::SurfaceMesh& m) {
  std::ostringstream s;
  s.precision(17);
  for (int i = 0; i < m.node_count(); ++i)
    s << "v " << m.positions(i, 0) << ' ' << m.positions(i, 1) << ' ' << m.positions(i, 2) << '\n';
  for (int k = 0; k < m.triangle_count(); ++k)
    s << "f " << m.triangles(k, 0) + 1 << ' ' << m.triangles(k, 1) + 1 << ' ' << m.triangles(k, 2) + 1 << '\n';
  return s.str();
}

// STL stores three corners per facet: the loader must weld them back together.
std::string stl_text(const vdm::SurfaceMesh& m) {
  std::ostringstream s;
  s.precision(17);
  s << "solid test\n";
  for (int k = 0; k < m.triangle_count(); ++k) {
    s << " facet normal 0 0 0\n  outer loop\n";
    for (int c = 0; c < 3; ++c) {
      const int i = m.triangles(k, c);
      s << "   vertex " << m.positions(i, 0) << ' ' << m.positions(i, 1) << ' ' << m.positions(i, 2) << '\n';
    }
    s << "  endloop\n endfacet\n";
  }
  s << "endsolid test\n";
  return s.str();
}

std::string ply_text(const vdm::SurfaceMesh& m) {
  std::ostringstream s;
  s.precision(17);
  s << "ply\nformat ascii 1.0\nelement vertex " << m.node_count()
    << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.triangle_count()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < m.node_count(); ++i)
    s << m.positions(i, 0) << ' ' << m.positions(i, 1) << ' ' << m.positions(i, 2) << '\n';
  for (int k = 0; k < m.triangle_count(); ++k)
    s << "3 " << m.triangles(k, 0) << ' ' << m.triangles(k, 1) << ' ' << m.triangles(k, 2) << '\n';
  return s.str();
}

std::string base64(const std::vector<unsigned char>& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8) | in[i + 2];
    for (int k = 3; k >= 0; --k) out += t[(v >> (6 * k)) & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = in[i] << 16;
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += t[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string gltf_text(const vdm::SurfaceMesh& m) {
  std::vector<unsigned char> buf;
  auto put = [&](const void* p, size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    buf.insert(buf.end(), c, c + n);
  };
  for (int i = 0; i < m.node_count(); ++i)
    for (int d = 0; d < 3; ++d) {
      const float f = static_cast<float>(m.positions(i, d));
      put(&f, 4);
    }
  const size_t pos_bytes = buf.size();
  for (int k = 0; k < m.triangle_count(); ++k)
    for (int c = 0; c < 3; ++c) {
      const unsigned u = static_cast<unsigned>(m.triangles(k, c));
      put(&u, 4);
    }
  const vdm::Vec3 lo = m.positions.colwise().minCoeff(), hi = m.positions.colwise().maxCoeff();
  std::ostringstream s;
  s << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
    << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":4}]}],)"
    << R"("buffers":[{"byteLength":)" << buf.size()
    << R"(,"uri":"data:application/octet-stream;base64,)" << base64(buf) << R"("}],)"
    << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << pos_bytes
    << R"(},{"buffer":0,"byteOffset":)" << pos_bytes << R"(,"byteLength":)" << buf.size() - pos_bytes << "}],"
    << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << m.node_count()
    << R"(,"type":"VEC3","min":[)" << lo.x() << ',' << lo.y() << ',' << lo.z() << R"(],"max":[)"
    << hi.x() << ',' << hi.y() << ',' << hi.z() << "]},"
    << R"({"bufferView":1,"componentType":5125,"count":)" << 3 * m.triangle_count()
    << R"(,"type":"SCALAR"}]})";
  return s.str();
}

const vdm::SurfaceMesh& reference_box() {
  static const vdm::SurfaceMesh box = vdm::make_box(vdm::Vec3(2, 1, 0.5), 2, 2, 1);
  return box;
}

void expect_same_box(const MeshLoadResult& r) {
  ASSERT_TRUE(r.ok) << r.error;
  const vdm::SurfaceMesh& box = reference_box();
  EXPECT_EQ(r.mesh.node_count(), box.node_count());
  EXPECT_EQ(r.mesh.triangle_count(), box.triangle_count());
  EXPECT_NEAR(vdm::enclosed_volume(r.mesh.positions, r.mesh.triangles, vdm::Vec3::Zero()), 1.0, 1e-6);
}

TEST(MeshIo, LoadsObj) { expect_same_box(load_surface_mesh(write_text("box.obj", obj_text(reference_box())).string())); }

TEST(MeshIo, LoadsAndWeldsStl) {
  // Three corners per facet in the file; the node count proves they were welded back.
  const MeshLoadResult r = load_surface_mesh(write_text("box.stl", stl_text(reference_box())).string());
  expect_same_box(r);
}

TEST(MeshIo, LoadsPly) { expect_same_box(load_surface_mesh(write_text("box.ply", ply_text(reference_box())).string())); }

TEST(MeshIo, LoadsGltf) { expect_same_box(load_surface_mesh(write_text("box.gltf", gltf_text(reference_box())).string())); }

TEST(MeshIo, ScaleConvertsUnits) {
  MeshLoadOptions opt;
  opt.scale = 0.01;
  const MeshLoadResult r = load_surface_mesh(write_text("box_cm.obj", obj_text(reference_box())).string(), opt);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_NEAR(vdm::enclosed_volume(r.mesh.positions, r.mesh.triangles, vdm::Vec3::Zero()), 1e-6, 1e-12);
}

TEST(MeshIo, InwardFileIsFlipped) {
  vdm::SurfaceMesh inward = reference_box();
  for (int k = 0; k < inward.triangle_count(); ++k) std::swap(inward.triangles(k, 1), inward.triangles(k, 2));
  const MeshLoadResult r = load_surface_mesh(write_text("inward.obj", obj_text(inward)).string());
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.flipped);
  EXPECT_GT(vdm::enclosed_volume(r.mesh.positions, r.mesh.triangles, vdm::Vec3::Zero()), 0.99);
}

TEST(MeshIo, UnreferencedVerticesAreDropped) {
  const std::string text = "v 9 9 9\n" + obj_text(reference_box());
  // Shift face indices by one for the extra leading vertex.
  std::ostringstream shifted;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("f ", 0) == 0) {
      int a, b, c;
      std::sscanf(line.c_str(), "f %d %d %d", &a, &b, &c);
      shifted << "f " << a + 1 << ' ' << b + 1 << ' ' << c + 1 << '\n';
    } else {
      shifted << line << '\n';
    }
  }
  const MeshLoadResult r = load_surface_mesh(write_text("extra.obj", shifted.str()).string());
  expect_same_box(r);
}

// --- broken meshes: each class gets its own clear error naming the file ---

void expect_error(const MeshLoadResult& r, const std::string& path, const std::string& fragment) {
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find(path), std::string::npos) << r.error;
  EXPECT_NE(r.error.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << r.error;
}

TEST(MeshIoErrors, MissingFile) {
  const std::string p = (temp_dir() / "nope.obj").string();
  expect_error(load_surface_mesh(p), p, "no such file");
}

TEST(MeshIoErrors, EmptyFile) {
  const std::string p = write_text("empty.obj", "").string();
  expect_error(load_surface_mesh(p), p, "empty");
}

TEST(MeshIoErrors, BinaryGarbage) {
  std::mt19937 rng(7);
  std::string junk(4096, '\0');
  for (char& c : junk) c = static_cast<char>(rng() & 0xff);
  for (const char* ext : {"obj", "stl", "ply", "glb"}) {
    const std::string p = write_text(std::string("garbage.") + ext, junk).string();
    const MeshLoadResult r = load_surface_mesh(p);
    EXPECT_FALSE(r.ok) << ext;
    EXPECT_NE(r.error.find(p), std::string::npos) << r.error;
  }
}

TEST(MeshIoErrors, NanCoordinate) {
  std::string text = obj_text(reference_box());
  text.replace(text.find("v ") + 2, 0, "nan ");
  // The first vertex line now has four numbers; rebuild it as "v nan y z".
  const std::string p = write_text("nan.obj", "v nan 0 0\n" + text.substr(text.find('\n') + 1)).string();
  expect_error(load_surface_mesh(p), p, "non-finite");
}

TEST(MeshIoErrors, ObjNumberWithTrailingCharactersNamesTheLine) {
  // Issue 31: "0.05abc" was read as 0.05. Each case breaks line 3 of the octahedron.
  const std::string verts[] = {"v 1 0 0", "v -1 0 0", "v 0 1 0", "v 0 -1 0", "v 0 0 1", "v 0 0 -1"};
  const std::string faces = "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
  for (const std::string& bad : {std::string("v 0 1 0.05abc"), std::string("v 0abc 1 0"), std::string("v 0 1,5 0"),
                                 std::string("v 0 1 0 1x")}) {
    std::string text;
    for (int i = 0; i < 6; ++i) text += (i == 2 ? bad : verts[i]) + "\n";
    const std::string p = write_text("trailing.obj", text + faces).string();
    const MeshLoadResult r = load_surface_mesh(p);
    expect_error(r, p + ": line 3: ", "is not a number");
  }
  for (const std::string& bad : {std::string("f 1 3 5x"), std::string("f 1/2abc 3 5"), std::string("f 1//x 3 5")}) {
    std::string text;
    for (const std::string& v : verts) text += v + "\n";
    const std::string p = write_text("trailing_face.obj", text + bad + "\n" + faces.substr(faces.find('\n') + 1)).string();
    expect_error(load_surface_mesh(p), p + ": line 7: ", "bad face index");
  }
  // What OBJ allows stays valid: a w coordinate, a colour, texture and normal indices, CRLF.
  std::string ok;
  for (const std::string& v : verts) ok += v + " 1\r\n";
  ok += "vt 0 0\nvn 0 0 1\nf 1/1/1 3//1 5/1\r\n" + faces.substr(faces.find('\n') + 1);
  const MeshLoadResult r = load_surface_mesh(write_text("allowed.obj", ok).string());
  EXPECT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.mesh.node_count(), 6);
}

TEST(MeshIoErrors, OpenSurface) {
  vdm::SurfaceMesh m = reference_box();
  m.triangles.conservativeResize(m.triangle_count() - 2, 3);
  const std::string p = write_text("open.obj", obj_text(m)).string();
  const MeshLoadResult r = load_surface_mesh(p);
  expect_error(r, p, "open surface");
  EXPECT_EQ(r.problem, MeshProblem::open_boundary);
}

TEST(MeshIoErrors, NonManifoldEdge) {
  vdm::SurfaceMesh m = reference_box();
  // A fin: one more triangle on an existing edge, out to a new node.
  const int a = m.triangles(0, 0), b = m.triangles(0, 1);
  m.positions.conservativeResize(m.node_count() + 1, 3);
  m.positions.row(m.node_count() - 1) << 5, 5, 5;
  m.triangles.conservativeResize(m.triangle_count() + 1, 3);
  m.triangles.row(m.triangle_count() - 1) << a, b, m.node_count() - 1;
  const std::string p = write_text("fin.obj", obj_text(m)).string();
  const MeshLoadResult r = load_surface_mesh(p);
  expect_error(r, p, "non-manifold edge");
  EXPECT_EQ(r.problem, MeshProblem::non_manifold_edge);
}

TEST(MeshIoErrors, InconsistentOrientation) {
  vdm::SurfaceMesh m = reference_box();
  std::swap(m.triangles(3, 1), m.triangles(3, 2));
  const std::string p = write_text("inconsistent.obj", obj_text(m)).string();
  const MeshLoadResult r = load_surface_mesh(p);
  expect_error(r, p, "inconsistent orientation");
  EXPECT_EQ(r.problem, MeshProblem::inconsistent_orientation);
}

TEST(MeshIoErrors, TwoComponents) {
  const vdm::SurfaceMesh a = reference_box();
  vdm::SurfaceMesh m;
  m.positions.resize(2 * a.node_count(), 3);
  m.positions << a.positions, (a.positions.rowwise() + vdm::Vec3(10, 0, 0).transpose());
  m.triangles.resize(2 * a.triangle_count(), 3);
  m.triangles << a.triangles, (a.triangles.array() + a.node_count()).matrix();
  const std::string p = write_text("two.obj", obj_text(m)).string();
  const MeshLoadResult r = load_surface_mesh(p);
  expect_error(r, p, "2 separate connected pieces");
  EXPECT_EQ(r.problem, MeshProblem::multiple_components);
}

TEST(MeshIoErrors, DegenerateTriangleIsNamed) {
  vdm::SurfaceMesh m = reference_box();
  const int a = m.triangles(4, 0), b = m.triangles(4, 1), c = m.triangles(4, 2);
  m.positions.row(c) = 0.5 * (m.positions.row(a) + m.positions.row(b));
  const std::string p = write_text("degenerate.obj", obj_text(m)).string();
  const MeshLoadResult r = load_surface_mesh(p);
  expect_error(r, p, "zero area");
  EXPECT_EQ(r.problem, MeshProblem::degenerate_triangle);
}

TEST(MeshIoErrors, HugeHeaderClaimIsRefusedWithoutCrash) {
  // A PLY header that claims two billion vertices (tens of GB) but holds three.
  const std::string p = write_text("huge.ply",
      "ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").string();
  const MeshLoadResult r = load_surface_mesh(p);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find(p), std::string::npos) << r.error;
}

// --- third-party organ meshes (../shared/assets), skipped when absent ---

// SOFA's liver passes through itself where a triangle is folded over its neighbours (near
// (-2.1, 4.0, -1.0)): it is refused as an organ, naming the triangles, and read as it is when
// not validated.
TEST(MeshIoShared, LiverSmoothIsRefusedForItsSelfIntersection) {
  const fs::path p = fs::path(VDMSIM_SHARED_ASSETS) / "organs/liver-smooth.obj";
  if (!fs::exists(p)) GTEST_SKIP() << "shared assets absent (" << p << "): skipping";
  const MeshLoadResult r = load_surface_mesh(p.string());
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.problem, vdm::MeshProblem::self_intersection);
  EXPECT_NE(r.error.find("self-intersection"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("triangles 811 and 1958"), std::string::npos) << r.error;
  MeshLoadOptions raw;
  raw.validate = false;
  const MeshLoadResult q = load_surface_mesh(p.string(), raw);
  ASSERT_TRUE(q.ok) << q.error;
  EXPECT_EQ(q.mesh.node_count(), 2194);
  EXPECT_EQ(q.mesh.triangle_count(), 4384);
  EXPECT_NEAR(vdm::enclosed_volume(q.mesh.positions, q.mesh.triangles, q.mesh.positions.colwise().mean().transpose()),
              39.27, 0.01);
}

TEST(MeshIoShared, LiverCoarseDropsInteriorNodes) {
  const fs::path p = fs::path(VDMSIM_SHARED_ASSETS) / "organs/liver-coarse.obj";
  if (!fs::exists(p)) GTEST_SKIP() << "shared assets absent (" << p << "): skipping";
  const MeshLoadResult r = load_surface_mesh(p.string());
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.mesh.node_count(), 139);
  EXPECT_EQ(r.mesh.triangle_count(), 274);
}

// Every shared organ is read, and either valid or refused for its self-intersection only.
TEST(MeshIoShared, EveryOrganIsValidOrSelfIntersecting) {
  const fs::path dir = fs::path(VDMSIM_SHARED_ASSETS) / "organs";
  if (!fs::exists(dir)) GTEST_SKIP() << "shared assets absent (" << dir << "): skipping";
  int seen = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".obj") continue;
    const MeshLoadResult r = load_surface_mesh(e.path().string());
    EXPECT_TRUE(r.ok || r.problem == vdm::MeshProblem::self_intersection) << r.error;
    ++seen;
  }
  EXPECT_GE(seen, 2);
}

}  // namespace
}  // namespace vdmsim

namespace vdmsim {
namespace {

TEST(MeshIoErrors, ObjFaceIndexOutOfRangeNamesTheLine) {
  const std::string p = write_text("badindex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n# comment\nf 1 2 9\n").string();
  expect_error(load_surface_mesh(p), p, "line 5: face refers to vertex 9 but 3 vertices are defined");
}

TEST(MeshIo, ObjKeepsFileVertexOrderAndPrecision) {
  const std::string p = write_text("order.obj",
      "v 0.1234567890123 0 0\nv 0 0 0\nv 0 1 0\nv 0 0 1\nf 2 3 1\nf 2 1 4\nf 2 4 3\nf 1 3 4\n").string();
  const MeshLoadResult r = load_surface_mesh(p);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.mesh.positions(0, 0), 0.1234567890123);
  EXPECT_EQ(r.mesh.positions(3, 2), 1.0);
}

}  // namespace
}  // namespace vdmsim

namespace vdmsim {
namespace {

TEST(MeshIoErrors, FaceIndexPastTheVerticesInPlyIsAnErrorNotACrash) {
  const std::string p = write_text("badindex.ply",
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 1 2 999999\n").string();
  const MeshLoadResult r = load_surface_mesh(p);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find(p), std::string::npos) << r.error;
}

TEST(MeshIoErrors, NanInStlIsRejectedBeforeWelding) {
  const std::string p = write_text("nan.stl",
      "solid t\n facet normal 0 0 0\n  outer loop\n   vertex nan 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
      "  endloop\n endfacet\nendsolid t\n").string();
  MeshLoadOptions opt;
  opt.validate = false;  // as mesh-info loads
  const MeshLoadResult r = load_surface_mesh(p, opt);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("non-finite"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace vdmsim
