// The PLY reader: every encoding, every count and index type, skipped properties and elements,
// and one test per class of broken file (each message checked for its line or byte offset).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "app/scene/mesh_io.hpp"
#include "app/scene/ply_reader.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

// A small PLY writer for the tests (independent of the reader): typed values in either byte
// order or as text.
class PlyWriter {
 public:
  enum Enc { ascii, le, be };
  explicit PlyWriter(Enc enc) : enc_(enc) {}

  void header(const std::string& h) {
    out_ = "ply\nformat ";
    out_ += enc_ == ascii ? "ascii" : enc_ == le ? "binary_little_endian" : "binary_big_endian";
    out_ += " 1.0\n" + h + "end_header\n";
  }
  // One value of the named type; `last` ends the ascii line.
  void put(std::string type, double v, bool last = false) {
    static const char* const kAlias[][2] = {{"int8", "char"},   {"uint8", "uchar"}, {"int16", "short"},
                                           {"uint16", "ushort"}, {"int32", "int"},  {"uint32", "uint"},
                                           {"float32", "float"}, {"float64", "double"}};
    for (const auto& a : kAlias)
      if (type == a[0]) type = a[1];
    if (enc_ == ascii) {
      char buf[64];
      if (type == "float" || type == "double")
        std::snprintf(buf, sizeof buf, "%.17g", v);
      else
        std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(v));
      out_ += buf;
      out_ += last ? '\n' : ' ';
      return;
    }
    unsigned char b[8];
    size_t n = 0;
    auto raw = [&](const auto x) {
      n = sizeof x;
      std::memcpy(b, &x, n);
    };
    if (type == "char") raw(static_cast<std::int8_t>(v));
    else if (type == "uchar") raw(static_cast<std::uint8_t>(v));
    else if (type == "short") raw(static_cast<std::int16_t>(v));
    else if (type == "ushort") raw(static_cast<std::uint16_t>(v));
    else if (type == "int") raw(static_cast<std::int32_t>(v));
    else if (type == "uint") raw(static_cast<std::uint32_t>(v));
    else if (type == "float") raw(static_cast<float>(v));
    else raw(v);
    const std::uint16_t probe = 1;
    const bool host_le = *reinterpret_cast<const unsigned char*>(&probe) == 1;
    if ((enc_ == be) == host_le) std::reverse(b, b + n);
    out_.append(reinterpret_cast<const char*>(b), n);
  }
  const std::string& bytes() const { return out_; }

 private:
  Enc enc_;
  std::string out_;
};

// A square pyramid: 5 vertices, 4 triangles and a quad base (fanned into two triangles).
const double kPyramid[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0.75}};
const std::vector<std::vector<int>> kPyramidFaces = {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};

struct Types {
  const char* coord;
  const char* count;
  const char* index;
};

// The pyramid with extra vertex properties before and after the coordinates, an extra face
// property and list, and an "edge" element, in the given encoding and types.
std::string pyramid(PlyWriter::Enc enc, const Types& t) {
  PlyWriter w(enc);
  w.header(std::string("comment made by the test\nelement vertex 5\nproperty uchar flag\nproperty ") + t.coord +
           " x\nproperty " + t.coord + " y\nproperty " + t.coord + " z\nproperty short s\nproperty double d\n"
           "property list uchar ushort tags\nproperty ushort tail\nelement face 5\nproperty char pre\nproperty list " + t.count + " " +
           t.index + " vertex_indices\nproperty list int float weights\nelement edge 2\nproperty int a\n"
           "property uint b\n");
  for (int i = 0; i < 5; ++i) {
    w.put("uchar", 200 + i);
    for (int d = 0; d < 3; ++d) w.put(t.coord, kPyramid[i][d]);
    w.put("short", -300 - i);
    w.put("double", 1e300);
    w.put("uchar", i % 3);
    for (int k = 0; k < i % 3; ++k) w.put("ushort", 60000 + k);
    w.put("ushort", 7, true);  // "tail", the last value of the line
  }
  for (const auto& f : kPyramidFaces) {
    w.put("char", -5);
    w.put(t.count, static_cast<double>(f.size()));
    for (int c : f) w.put(t.index, c);
    w.put("int", 2);
    w.put("float", 0.25);
    w.put("float", 0.75, true);
  }
  for (int e = 0; e < 2; ++e) {
    w.put("int", -e);
    w.put("uint", 4000000000.0, true);
  }
  return w.bytes();
}

void expect_pyramid(const vdm::SurfaceMesh& m, bool float_coords) {
  ASSERT_EQ(m.node_count(), 5);
  ASSERT_EQ(m.triangle_count(), 6);
  for (int i = 0; i < 5; ++i)
    for (int d = 0; d < 3; ++d) {
      const double want = float_coords ? static_cast<double>(static_cast<float>(kPyramid[i][d])) : kPyramid[i][d];
      EXPECT_EQ(m.positions(i, d), want) << i << ' ' << d;
    }
  // The quad base fanned from its first corner, then the four sides as written.
  const int want[6][3] = {{0, 3, 2}, {0, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  for (int k = 0; k < 6; ++k)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(m.triangles(k, c), want[k][c]) << k << ' ' << c;
  // Closed and outward: the enclosed volume is the pyramid's, 1/3 * base * height.
  EXPECT_NEAR(vdm::enclosed_volume(m.positions, m.triangles, vdm::Vec3(0.5, 0.5, 0.2)), 0.25, 1e-7);
}

TEST(PlyReader, EveryEncodingCoordinateCountAndIndexType) {
  int cases = 0;
  for (PlyWriter::Enc enc : {PlyWriter::ascii, PlyWriter::le, PlyWriter::be})
    for (const char* coord : {"float", "double", "float32", "float64"})
      for (const char* count : {"uchar", "ushort", "uint", "int", "uint8"})
        for (const char* index : {"int", "uint", "short", "ushort", "uchar", "int32"}) {
          SCOPED_TRACE(std::to_string(enc) + " " + coord + " " + count + " " + index);
          const std::string bytes = pyramid(enc, {coord, count, index});
          vdm::SurfaceMesh m;
          std::string error;
          ASSERT_TRUE(parse_ply(bytes, m, error)) << error;
          const bool single = std::string(coord) == "float" || std::string(coord) == "float32";
          expect_pyramid(m, single && enc != PlyWriter::ascii);  // ascii keeps the written digits
          ++cases;
        }
  EXPECT_EQ(cases, 3 * 4 * 5 * 6);
}

TEST(PlyReader, CrLfLinesAndBlankLinesInAscii) {
  std::string s = pyramid(PlyWriter::ascii, {"double", "uchar", "int"});
  std::string crlf;
  for (char c : s) {
    if (c == '\n') crlf += "\r\n";
    else crlf += c;
  }
  crlf.insert(crlf.find("end_header\r\n") + 12, "\r\n");  // a blank line before the data
  vdm::SurfaceMesh m;
  std::string error;
  ASSERT_TRUE(parse_ply(crlf, m, error)) << error;
  expect_pyramid(m, false);
}

TEST(PlyReader, BinaryCubeThroughTheLoaderIsAValidOrgan) {
  const vdm::SurfaceMesh box = vdm::make_box(vdm::Vec3(0.02, 0.03, 0.04), 3, 3, 3);
  PlyWriter w(PlyWriter::be);
  w.header("element vertex " + std::to_string(box.node_count()) +
           "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
           std::to_string(box.triangle_count()) + "\nproperty list uchar uint vertex_indices\n");
  for (int i = 0; i < box.node_count(); ++i)
    for (int d = 0; d < 3; ++d) w.put("double", box.positions(i, d));
  for (int k = 0; k < box.triangle_count(); ++k) {
    w.put("uchar", 3);
    for (int c = 0; c < 3; ++c) w.put("uint", box.triangles(k, c));
  }
  const fs::path p = fs::temp_directory_path() / ("vdmsim_ply_" + std::to_string(::getpid()) + "_box.ply");
  std::ofstream(p, std::ios::binary) << w.bytes();
  const MeshLoadResult r = load_surface_mesh(p.string());
  fs::remove(p);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.mesh.positions, box.positions);  // file order and double precision kept
  EXPECT_EQ(r.mesh.triangles, box.triangles);
  EXPECT_NEAR(vdm::enclosed_volume(r.mesh.positions, r.mesh.triangles, vdm::Vec3::Zero()), 0.02 * 0.03 * 0.04, 1e-15);
}

// --- broken files: each error names where ---

std::string parse_error(const std::string& bytes) {
  vdm::SurfaceMesh m;
  std::string error;
  EXPECT_FALSE(parse_ply(bytes, m, error));
  EXPECT_FALSE(error.empty());
  return error;
}

#define EXPECT_HAS(haystack, needle) EXPECT_NE((haystack).find(needle), std::string::npos) << (haystack)

const std::string kAsciiHead =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
const std::string kAsciiVerts = "0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0 0.0\n0.0 0.0 1.0\n";
const std::string kAsciiFaces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

TEST(PlyReaderErrors, TheTetrahedronItselfIsFine) {
  vdm::SurfaceMesh m;
  std::string error;
  EXPECT_TRUE(parse_ply(kAsciiHead + kAsciiVerts + kAsciiFaces, m, error)) << error;
  EXPECT_EQ(m.triangle_count(), 4);
}

TEST(PlyReaderErrors, HugeCountClaimRefusedBeforeAllocating) {
  // 5 GB of vertices claimed (binary: 12 bytes each) in a file of a few hundred bytes.
  const std::string e = parse_error(
      "ply\nformat binary_little_endian 1.0\nelement vertex 416666667\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" + std::string(64, '\0'));
  EXPECT_HAS(e, "line 3: element 'vertex' declares 416666667 items of at least 12 bytes each");
  EXPECT_HAS(e, "64 bytes after the header");
  // A claim past 64 bits is not a number of items.
  EXPECT_HAS(parse_error("ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nend_header\n"),
             "line 3: element 'vertex': count '99999999999999999999999' is not a whole number");
  // The face element too (each face at least a count and three indices).
  std::string head = kAsciiHead;
  head.replace(head.find("element face 4"), 14, "element face 4000000");
  EXPECT_HAS(parse_error(head + kAsciiVerts + kAsciiFaces), "line 7: element 'face' declares 4000000 items");
  // An element with items but nothing to read in them could never end.
  EXPECT_HAS(parse_error("ply\nformat binary_little_endian 1.0\nelement nothing 1000000000000\n" +
                         kAsciiHead.substr(kAsciiHead.find("element vertex"))),
             "line 3: element 'nothing' has items but no properties");
}

TEST(PlyReaderErrors, TruncatedAscii) {
  const std::string e = parse_error(kAsciiHead + kAsciiVerts + "3 0 2 1\n3 0 1 3\n");
  EXPECT_HAS(e, "line 16 (face 2): the file ends here: 4 face items declared, 2 found");
  EXPECT_HAS(parse_error(kAsciiHead + kAsciiVerts + kAsciiFaces.substr(0, kAsciiFaces.size() - 3)),
             "line 17 (face 3): fewer values than the face element's properties");
}

TEST(PlyReaderErrors, EveryTruncationOfABinaryFileIsAnErrorNamingTheOffset) {
  const std::string full = pyramid(PlyWriter::le, {"float", "uchar", "int"});
  const size_t data = full.find("end_header\n") + 11;
  vdm::SurfaceMesh m;
  std::string error;
  ASSERT_TRUE(parse_ply(full, m, error)) << error;
  for (size_t n = 0; n < full.size(); ++n) {
    error.clear();
    ASSERT_FALSE(parse_ply(std::string_view(full).substr(0, n), m, error)) << n;
    if (n >= data) {
      // Either refused from the header's counts or caught at the item where the bytes run out.
      const bool named = error.find("byte offset") != std::string::npos || error.find("declares") != std::string::npos;
      EXPECT_TRUE(named) << n << ": " << error;
    }
  }
  // One cut in the middle of the faces, exactly.
  const std::string cut = full.substr(0, full.size() - 30);
  EXPECT_HAS(parse_error(cut), "truncated");
}

TEST(PlyReaderErrors, IndexOutOfRange) {
  EXPECT_HAS(parse_error(kAsciiHead + kAsciiVerts + "3 0 2 1\n3 0 1 3\n3 0 3 999999\n3 1 2 3\n"),
             "line 16 (face 2): vertex index 999999 is out of range (the file has 4 vertices)");
  EXPECT_HAS(parse_error(kAsciiHead + kAsciiVerts + "3 0 2 1\n3 0 -1 3\n3 0 3 2\n3 1 2 3\n"),
             "line 15 (face 1): vertex index -1 is out of range");
  // Binary: a uint index past int's range; the offset is the face's first byte.
  PlyWriter w(PlyWriter::le);
  w.header("element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
           "property list uchar uint vertex_indices\n");
  for (int i = 0; i < 9; ++i) w.put("float", i);
  w.put("uchar", 3);
  w.put("uint", 0);
  w.put("uint", 1);
  w.put("uint", 4000000000.0);
  const size_t face_offset = w.bytes().size() - 13;
  EXPECT_HAS(parse_error(w.bytes()), "face 0 (byte offset " + std::to_string(face_offset) +
                                         "): vertex index 4000000000 is out of range (the file has 3 vertices)");
}

TEST(PlyReaderErrors, NonFiniteCoordinates) {
  EXPECT_HAS(parse_error(kAsciiHead + "0 0 0\n1 nan 0\n0 1 0\n0 0 1\n" + kAsciiFaces),
             "line 11 (vertex 1): non-finite coordinate (1, nan, 0)");
  EXPECT_HAS(parse_error(kAsciiHead + "0 0 0\n1 0 0\n0 1 0\n0 0 -inf\n" + kAsciiFaces),
             "line 13 (vertex 3): non-finite coordinate (0, 0, -inf)");
  // Past a float's range in a float property is infinite too.
  EXPECT_HAS(parse_error(kAsciiHead + "0 0 0\n1e39 0 0\n0 1 0\n0 0 1\n" + kAsciiFaces), "line 11 (vertex 1): non-finite");
  for (PlyWriter::Enc enc : {PlyWriter::le, PlyWriter::be}) {
    PlyWriter w(enc);
    w.header("element vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\n"
             "property list uchar int vertex_indices\n");
    const size_t data = w.bytes().size();
    for (int i = 0; i < 9; ++i) w.put("double", i == 5 ? std::numeric_limits<double>::quiet_NaN() : i);
    w.put("uchar", 3);
    for (int c = 0; c < 3; ++c) w.put("int", c);
    EXPECT_HAS(parse_error(w.bytes()), "vertex 1 (byte offset " + std::to_string(data + 24) + "): non-finite coordinate (3, 4, nan)");
  }
}

TEST(PlyReaderErrors, HeaderProblemsNameTheLine) {
  EXPECT_HAS(parse_error(kAsciiHead.substr(0, kAsciiHead.find("end_header"))), "line 8: the header has no end_header line");
  EXPECT_HAS(parse_error("plY\nformat ascii 1.0\n"), "line 1: not a PLY file: the first line must be 'ply', not 'plY'");
  auto with = [](const std::string& from, const std::string& to) {
    std::string s = kAsciiHead + kAsciiVerts + kAsciiFaces;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_HAS(parse_error(with("format ascii 1.0", "format binary_middle_endian 1.0")),
             "line 2: unsupported format 'binary_middle_endian'");
  EXPECT_HAS(parse_error(with("format ascii 1.0", "format ascii 2.0")), "line 2: unsupported PLY version '2.0'");
  EXPECT_HAS(parse_error(with("property float y", "property half y")), "line 5: unknown property type 'half'");
  EXPECT_HAS(parse_error(with("list uchar int", "list float int")), "line 8: a list count must have an integer type");
  EXPECT_HAS(parse_error(with("list uchar int", "list uchar float")), "line 8: face vertex indices must have an integer type");
  EXPECT_HAS(parse_error(with("property float z", "property float w")), "line 3: the vertex element has no property 'z'");
  EXPECT_HAS(parse_error(with("element face 4", "element facet 4")), "the header declares no 'face' element");
  EXPECT_HAS(parse_error(with("vertex_indices", "corners")), "line 7: the face element has no 'vertex_indices' list");
  EXPECT_HAS(parse_error(with("property float x", "propertee float x")), "line 4: unknown header line 'propertee float x'");
  EXPECT_HAS(parse_error(with("format ascii 1.0\n", "")), "line 2: an element before the format line");
}

TEST(PlyReaderErrors, DataProblemsNameTheLine) {
  EXPECT_HAS(parse_error(kAsciiHead + kAsciiVerts + "3 0 2 1\n2 0 1\n3 0 3 2\n3 1 2 3\n"),
             "line 15 (face 1): a face with 2 corners (at least three needed)");
  EXPECT_HAS(parse_error(kAsciiHead + kAsciiVerts + "3 0 2 1\n300 0 1 3\n3 0 3 2\n3 1 2 3\n"),
             "line 15 (face 1): 300 does not fit the type uchar");
  EXPECT_HAS(parse_error(kAsciiHead + "0 0 0\n1 0 0 7\n0 1 0\n0 0 1\n" + kAsciiFaces),
             "line 11 (vertex 1): more values than the vertex element's properties ('7')");
  EXPECT_HAS(parse_error(kAsciiHead + "0 0 0\n1 zero 0\n0 1 0\n0 0 1\n" + kAsciiFaces),
             "line 11 (vertex 1): 'zero' is not a number");
  EXPECT_HAS(parse_error(kAsciiHead + kAsciiVerts + "3 0 2 1\n3 0 1.5 3\n3 0 3 2\n3 1 2 3\n"),
             "line 15 (face 1): '1.5' is not a whole number (type int)");
  EXPECT_HAS(parse_error(kAsciiHead + kAsciiVerts + kAsciiFaces + "3 1 2 3\n"),
             "line 18: data after the last element");
}

TEST(PlyReaderErrors, ThroughTheLoaderTheFileIsNamedWhateverItsExtension) {
  const fs::path p = fs::temp_directory_path() / ("vdmsim_ply_" + std::to_string(::getpid()) + "_tetra.data");
  std::ofstream(p, std::ios::binary) << kAsciiHead + kAsciiVerts + "3 0 2 1\n3 0 1 3\n3 0 3 7\n3 1 2 3\n";
  const MeshLoadResult r = load_surface_mesh(p.string());
  fs::remove(p);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, p.string() + ": line 16 (face 2): vertex index 7 is out of range (the file has 4 vertices)");
}

TEST(PlyReaderErrors, RandomByteFlipsNeverCrash) {
  // Damaged copies of a valid binary and ascii file: each parses or fails with a message.
  std::mt19937 rng(11);
  int failures = 0, total = 0;
  for (PlyWriter::Enc enc : {PlyWriter::ascii, PlyWriter::le, PlyWriter::be}) {
    const std::string good = pyramid(enc, {"float", "ushort", "int"});
    for (int trial = 0; trial < 400; ++trial) {
      std::string s = good;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int f = 0; f < flips; ++f) s[rng() % s.size()] = static_cast<char>(rng() & 0xff);
      vdm::SurfaceMesh m;
      std::string error;
      if (parse_ply(s, m, error)) {
        EXPECT_TRUE(m.positions.allFinite());
        EXPECT_TRUE((m.triangles.array() >= 0).all() && (m.triangles.array() < m.node_count()).all());
      } else {
        EXPECT_FALSE(error.empty());
        ++failures;
      }
      ++total;
    }
  }
  EXPECT_GT(failures, total / 4);  // the damage is mostly caught
}

}  // namespace
}  // namespace vdmsim
