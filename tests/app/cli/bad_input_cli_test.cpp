// Every class of bad input of issue 7 through the real binary: exit code 2 and one message
// naming the file and the problem (`vdmsim mesh-info` for meshes, `vdmsim check` / `run` for
// scenes). The library-level tests (mesh_io_test, scene_test) check the details.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <sys/wait.h>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;

vdmsim::test::CliResult run(const std::string& args) { return vdmsim::test::run_cli(VDMSIM_BINARY, args); }

fs::path bad_input_dir() {
  return vdmsim::test::scratch_dir("bad_input_cli");
}

std::string write(const std::string& name, const std::string& text) {
  const fs::path p = bad_input_dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// A closed, outward octahedron; the bad meshes are edits of it.
const char* kVerts = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n";
const char* kFaces = "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

struct MeshCase {
  const char* name;
  std::string text;
  const char* problem;  // what the message must say
};

// A binary tetrahedron (each vertex with a 2-float list after x y z) cut inside face 2: the
// header's counts fit the bytes left (the lists could be empty), so the data reader finds it.
std::string truncated_binary_ply() {
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty list uchar float extra\nelement face 4\n"
      "property list uchar int vertex_indices\nend_header\n";
  const size_t header = s.size();  // 201 bytes
  auto put = [&](auto v) { s.append(reinterpret_cast<const char*>(&v), sizeof v); };  // x86: little endian
  const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& v : p) {
    for (float c : v) put(c);
    put(static_cast<unsigned char>(2));
    put(0.5f);
    put(0.25f);
  }
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& t : f) {
    put(static_cast<unsigned char>(3));
    for (int i : t) put(i);
  }
  s.resize(header + 120);  // vertices 84 bytes, faces from 285, 13 bytes each: ends inside face 2
  return s;
}

TEST(BadInputCli, EveryBrokenMeshExitsWith2NamingFileAndProblem) {
  std::mt19937 rng(3);
  std::string junk(4096, '\0');
  for (char& c : junk) c = static_cast<char>(rng() & 0xff);
  const std::string faces = kFaces;
  std::string second;  // the octahedron moved by 10 along x, as a second piece
  for (const char* v : {"v 11 0 0\n", "v 9 0 0\n", "v 10 1 0\n", "v 10 -1 0\n", "v 10 0 1\n", "v 10 0 -1\n"}) second += v;
  second += "f 7 9 11\nf 9 8 11\nf 8 10 11\nf 10 7 11\nf 9 7 12\nf 8 9 12\nf 10 8 12\nf 7 10 12\n";
  const std::vector<MeshCase> cases = {
      {"empty.obj", "", "empty"},
      {"garbage.stl", junk, ""},
      {"nan.obj", std::string("v nan 0 0\n") + (kVerts + 8) + faces, "non-finite"},
      {"open.obj", kVerts + faces.substr(0, faces.rfind("f ")), "open surface"},
      {"fin.obj", std::string(kVerts) + "v 3 3 3\n" + faces + "f 1 3 7\n", "non-manifold edge"},
      {"inconsistent.obj", std::string(kVerts) + "f 1 5 3\n" + faces.substr(faces.find('\n') + 1), "inconsistent orientation"},
      {"two.obj", std::string(kVerts) + faces + second, "separate connected pieces"},
      // node 5 on the midpoint of edge 1-3: triangle 1 3 5 has zero area
      {"degenerate.obj", "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0.5 0.5 0\nv 0 0 -1\n" + faces, "zero area"},
      {"huge.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 400000000\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
       "declares"},
      // Our PLY reader (app/ply_reader): the line, or the item and byte offset, is named.
      {"truncated.ply", truncated_binary_ply(), "face 2 (byte offset 311): a list of 3 values runs past the end of the file"},
      {"nan.ply",
       "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 nan\n0 1 0\n0 0 1\n"
       "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
       "line 11 (vertex 1): non-finite coordinate"},
      {"index.ply",
       "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
       "3 0 2 1\n3 0 1 3\n3 0 3 4\n3 1 2 3\n",
       "line 16 (face 2): vertex index 4 is out of range"},
  };
  for (const MeshCase& c : cases) {
    const std::string p = write(c.name, c.text);
    const vdmsim::test::CliResult r = run("mesh-info " + p);
    if (std::getenv("VDMSIM_SHOW")) std::printf("%s -> %d: %s\n", c.name, r.code, r.output.c_str());
    EXPECT_EQ(r.code, 2) << c.name << ":\n" << r.output;
    EXPECT_NE(r.output.find(p), std::string::npos) << c.name << ":\n" << r.output;
    EXPECT_NE(r.output.find("error"), std::string::npos) << c.name << ":\n" << r.output;
    if (*c.problem) {
      EXPECT_NE(r.output.find(c.problem), std::string::npos) << c.name << ":\n" << r.output;
    }
  }
}

std::string scene(const std::string& organ_extra, const std::string& sim, const std::string& tail = "") {
  return "name: bad\norgan:\n  mesh: " + (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string() +
         "\n" + organ_extra + "simulation:\n" + sim + tail;
}

struct SceneCase {
  const char* name;
  std::string text;
  const char* problem;
};

TEST(BadInputCli, EveryBrokenSceneExitsWith2NamingFileAndProblem) {
  const std::string ok_sim = "  frames: 2\n  dt: 0.04\n";
  const std::string probe = "instruments:\n  - type: probe\n    radius: 0.004\n    script:\n";
  const std::vector<SceneCase> cases = {
      {"missing.yaml", "name: x\nsimulation:\n" + ok_sim, "organ"},
      {"wrong_type.yaml", scene("", "  frames: many\n  dt: 0.04\n"), "simulation.frames"},
      {"units.yaml", scene("", "  frames: 2\n  dt: 40ms\n"), "without units"},
      {"negative_modulus.yaml", scene("  material: {bulk_modulus: -5}\n", ok_sim), "organ.material.bulk_modulus"},
      {"zero_modulus.yaml", scene("  material: {bulk_modulus: [20000, 0, 20000]}\n", ok_sim), "organ.material.bulk_modulus"},
      {"zero_dt.yaml", scene("", "  frames: 2\n  dt: 0\n"), "simulation.dt"},
      {"negative_dt.yaml", scene("", "  frames: 2\n  dt: -0.01\n"), "simulation.dt"},
      {"order.yaml", scene("", ok_sim, probe + "      - {t: 0.5, tip: [0, 0, 0.1]}\n      - {t: 0.2, tip: [0, 0, 0.05]}\n"),
       "instruments[0].script"},
      {"radius.yaml",
       scene("", ok_sim, "instruments:\n  - type: probe\n    radius: 0\n    script: [{t: 0, tip: [0, 0, 0.1]}]\n"),
       "instruments[0].radius"},
      {"not_yaml.yaml", "organ: [unclosed\n", "not valid YAML"},
      {"antialias.yaml", scene("", ok_sim, "render: {antialias: fxaa}\n"), "render.antialias"},
      {"view.yaml", scene("", ok_sim, "render: {views: [shaded, dept]}\n"), "render.views[1]: unknown view 'dept'"},
      // Issue 31: a Latin-1 name made run.json invalid JSON.
      {"latin1_name.yaml", "name: caf\xe9" + scene("", ok_sim).substr(9), "name: not valid UTF-8"},
  };
  for (const SceneCase& c : cases) {
    const std::string p = write(c.name, c.text);
    const vdmsim::test::CliResult r = run("check " + p);
    if (std::getenv("VDMSIM_SHOW")) std::printf("%s -> %d: %s\n", c.name, r.code, r.output.c_str());
    EXPECT_EQ(r.code, 2) << c.name << ":\n" << r.output;
    EXPECT_NE(r.output.find(p), std::string::npos) << c.name << ":\n" << r.output;
    EXPECT_NE(r.output.find(c.problem), std::string::npos) << c.name << ":\n" << r.output;
  }
}

TEST(BadInputCli, UnknownKeyIsWarnedWithTheClosestKnownKey) {
  const std::string p = write("typo.yaml", scene("", "  frames: 2\n  dt: 0.04\n  volume_constrant: true\n"));
  const vdmsim::test::CliResult r = run("check " + p);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find(p), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("did you mean 'volume_constraint'?"), std::string::npos) << r.output;
}

TEST(BadInputCli, OutputFolderThatCannotBeWrittenExitsWith2) {
  const std::string p = write("good.yaml", scene("", "  frames: 1\n  dt: 0.04\n"));
  const std::string blocker = write("a_file", "not a folder");
  const vdmsim::test::CliResult r = run("run " + p + " --out " + blocker + "/out --no-render");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(blocker), std::string::npos) << r.output;
}

}  // namespace
