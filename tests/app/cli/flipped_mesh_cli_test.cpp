// Issue 31: an inward (flipped) organ mesh is reported the same way by every command that loads
// an organ (run, check, mesh-info): a warning line naming the file and saying it was flipped.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;

TEST(FlippedMeshCli, EveryCommandLoadingTheOrganWarnsOfTheFlip) {
  const fs::path dir = vdmsim::test::scratch_dir("flipped_mesh_cli");
  // The octahedron with every triangle wound inward (10 cm across).
  const std::string mesh = (dir / "inward.obj").string();
  std::ofstream(mesh) << "v 0.05 0 0\nv -0.05 0 0\nv 0 0.05 0\nv 0 -0.05 0\nv 0 0 0.05\nv 0 0 -0.05\n"
                         "f 1 5 3\nf 3 5 2\nf 2 5 4\nf 4 5 1\nf 3 6 1\nf 2 6 3\nf 4 6 2\nf 1 6 4\n";
  const std::string scene = (dir / "inward.yaml").string();
  std::ofstream(scene) << "name: inward\norgan:\n  mesh: " << mesh << "\nsimulation: {frames: 1}\n";
  const std::string said = "warning: ";
  const std::string what = mesh + ": the surface is oriented inward (its triangles face into the organ): it is used flipped outward";
  for (const std::string& args : {"mesh-info " + mesh, "check " + scene,
                                  "run " + scene + " --no-render --out " + (dir / "out").string()}) {
    const vdmsim::test::CliResult r = vdmsim::test::run_cli(VDMSIM_BINARY, args);
    EXPECT_EQ(r.code, 0) << args << "\n" << r.output;
    const size_t at = r.output.find(what);
    ASSERT_NE(at, std::string::npos) << args << "\n" << r.output;
    const size_t line = r.output.rfind('\n', at) + 1;  // (npos + 1 = 0: the first line)
    EXPECT_EQ(r.output.compare(line, 8, "vdmsim: "), 0) << args << "\n" << r.output;
    EXPECT_NE(r.output.substr(line, at - line).find(said), std::string::npos) << args << "\n" << r.output;
  }
}

}  // namespace
