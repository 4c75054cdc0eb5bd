// The installed program: `cmake --install` into a temporary prefix and the Debian package of
// `cpack -G DEB`, each run from a folder of its own, away from the source and build trees.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using vdmsim::test::CliResult;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `command` run by the shell in the folder `cwd`.
CliResult run_in(const fs::path& cwd, const std::string& command) {
  return vdmsim::test::run_cli("cd '" + cwd.string() + "' &&", command);
}

fs::path fresh(const std::string& name) {
  const fs::path d = vdmsim::test::scratch_dir("install") / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return fs::canonical(d);
}

// A closed tetrahedron as ASCII STL: read through the assimp module.
void write_tetrahedron_stl(const fs::path& p) {
  const char* faces[4][3] = {{"0 0 0", "0 1 0", "1 0 0"},
                             {"0 0 0", "1 0 0", "0 0 1"},
                             {"0 0 0", "0 0 1", "0 1 0"},
                             {"1 0 0", "0 1 0", "0 0 1"}};
  std::ofstream out(p);
  out << "solid tetra\n";
  for (const auto& f : faces) {
    out << "facet normal 0 0 0\nouter loop\n";
    for (const char* v : f) out << "vertex " << v << "\n";
    out << "endloop\nendfacet\n";
  }
  out << "endsolid tetra\n";
}

// make-organ and a two-frame run of an installed example scene, from `work`, with the program
// `vdmsim`, whose scenes are in `share`.
void expect_runs_from(const fs::path& work, const fs::path& vdmsim, const fs::path& share) {
  const CliResult organ = run_in(work, vdmsim.string() + " make-organ liver --level 3 --out liver.obj");
  EXPECT_EQ(organ.code, 0) << organ.output;
  EXPECT_TRUE(fs::file_size(work / "liver.obj") > 1000);
  const CliResult run =
      run_in(work, vdmsim.string() + " run " + (share / "scenes/liver_press.yaml").string() + " --frames 2 --no-render");
  EXPECT_EQ(run.code, 0) << run.output;
  const std::string metrics = read(work / "out/liver_press/metrics.csv");
  EXPECT_EQ(std::count(metrics.begin(), metrics.end(), '\n'), 3) << metrics;  // the header and two frames
  EXPECT_TRUE(contains(read(work / "out/liver_press/run.json"), "\"status\": \"completed\""));
}

TEST(Install, InstalledProgramRunsFromAnotherFolder) {
  const fs::path prefix = fresh("prefix"), work = fresh("work");
  const CliResult install =
      vdmsim::test::run_cli(VDMSIM_CMAKE_COMMAND, std::string("--install ") + VDMSIM_BUILD_DIR + " --prefix " + prefix.string());
  ASSERT_EQ(install.code, 0) << install.output;
  const fs::path vdmsim = prefix / "bin/vdmsim", module = prefix / "lib/vdmsim/libvdmsim_assimp.so";
  ASSERT_TRUE(fs::exists(vdmsim));
  EXPECT_TRUE(fs::exists(module));
  EXPECT_TRUE(fs::exists(prefix / "share/vdmsim/meshes/liver_L5.obj"));
  EXPECT_TRUE(fs::exists(prefix / "share/doc/vdmsim/docs/cli.md"));

  expect_runs_from(work, vdmsim, prefix / "share/vdmsim");

  // A mesh only assimp reads: the installed module is the one opened.
  write_tetrahedron_stl(work / "tetra.stl");
  const CliResult stl = run_in(work, "LD_DEBUG=libs " + vdmsim.string() + " mesh-info tetra.stl");
  EXPECT_EQ(stl.code, 0) << stl.output;
  EXPECT_TRUE(contains(stl.output, "triangles:  4")) << stl.output;
  EXPECT_TRUE(contains(stl.output, "calling init: " + module.string())) << stl.output;

  // The installed program draws what the build tree's draws.
  const std::string scene = (prefix / "share/vdmsim/scenes/liver_press.yaml").string();
  const CliResult installed = run_in(work, vdmsim.string() + " run " + scene + " --frames 1 --out installed");
  ASSERT_EQ(installed.code, 0) << installed.output;
  const CliResult built = run_in(work, std::string(VDMSIM_BINARY) + " run " + scene + " --frames 1 --out built");
  ASSERT_EQ(built.code, 0) << built.output;
  const CliResult same = run_in(work, vdmsim.string() + " compare built installed");
  EXPECT_EQ(same.code, 0) << same.output;
  EXPECT_TRUE(contains(same.output, "built vs installed: 3 image pairs, 3 within tolerance")) << same.output;
}

TEST(Install, DebianPackageInstallsARunnableProgram) {
  if (vdmsim::test::run_cli("command -v", "dpkg-deb").code != 0) GTEST_SKIP() << "dpkg-deb absent: not a Debian system";
  const fs::path out = fresh("deb"), root = fresh("root"), work = fresh("deb_work");
  const CliResult pack = vdmsim::test::run_cli(VDMSIM_CPACK_COMMAND, std::string("-G DEB -B ") + out.string() +
                                                                         " --config " + VDMSIM_BUILD_DIR + "/CPackConfig.cmake");
  ASSERT_EQ(pack.code, 0) << pack.output;
  fs::path deb;
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().extension() == ".deb") deb = e.path();
  ASSERT_FALSE(deb.empty()) << pack.output;
  EXPECT_EQ(deb.filename().string().rfind(std::string("vdmsim_") + VDMSIM_VERSION + "_", 0), 0u) << deb;

  const CliResult fields = vdmsim::test::run_cli("dpkg-deb", "-f " + deb.string());
  ASSERT_EQ(fields.code, 0) << fields.output;
  EXPECT_TRUE(contains(fields.output, "Package: vdmsim\n")) << fields.output;
  EXPECT_TRUE(contains(fields.output, std::string("Version: ") + VDMSIM_VERSION + "\n")) << fields.output;
  EXPECT_TRUE(contains(fields.output, "Maintainer: ")) << fields.output;
  EXPECT_TRUE(contains(fields.output, "Section: science")) << fields.output;
  EXPECT_TRUE(contains(fields.output, "Description: soft-tissue surgical simulator")) << fields.output;
  const size_t depends_at = fields.output.find("\nDepends: ");
  ASSERT_NE(depends_at, std::string::npos) << fields.output;
  const std::string depends = fields.output.substr(depends_at + 1, fields.output.find('\n', depends_at + 1) - depends_at - 1);
  for (const char* dep : {"fonts-dejavu-core", "libassimp", "libosmesa6", "libyaml-cpp", "libpng16"})
    EXPECT_TRUE(contains(depends, dep)) << dep << " missing in " << depends;

  const CliResult unpack = vdmsim::test::run_cli("dpkg-deb", "-x " + deb.string() + " " + root.string());
  ASSERT_EQ(unpack.code, 0) << unpack.output;
  EXPECT_TRUE(fs::exists(root / "usr/lib/vdmsim/libvdmsim_assimp.so"));
  expect_runs_from(work, root / "usr/bin/vdmsim", root / "usr/share/vdmsim");
}

}  // namespace
