// `vdmsim make-organ` through the real binary: the gallbladder is written as a valid organ
// mesh that mesh-info accepts; an unknown organ and a scan-like gallbladder are refused (exit 2)
// and write nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using vdmsim::test::CliResult;
using vdmsim::test::run_cli;

bool contains_text(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(MakeOrganCli, TheGallbladderIsWrittenAsAValidOrganAndWhatCannotBeMadeIsRefused) {
  const fs::path dir = vdmsim::test::scratch_dir("make_organ_cli");
  const std::string gb = (dir / "gallbladder.obj").string();
  const CliResult made = run_cli(VDMSIM_BINARY, "make-organ gallbladder --level 3 --out " + gb);
  ASSERT_EQ(made.code, 0) << made.output;
  EXPECT_TRUE(contains_text(made.output, "gallbladder level 3: 642 nodes")) << made.output;
  const CliResult info = run_cli(VDMSIM_BINARY, "mesh-info " + gb);
  EXPECT_EQ(info.code, 0) << info.output;
  EXPECT_TRUE(contains_text(info.output, "642")) << info.output;

  const std::string nothing = (dir / "spleen.obj").string();
  const CliResult unknown = run_cli(VDMSIM_BINARY, "make-organ spleen --out " + nothing);
  EXPECT_EQ(unknown.code, 2);
  EXPECT_TRUE(contains_text(unknown.output, "unknown organ 'spleen' (expected liver or gallbladder)")) << unknown.output;
  const CliResult scan = run_cli(VDMSIM_BINARY, "make-organ gallbladder --scan-like --out " + nothing);
  EXPECT_EQ(scan.code, 2);
  EXPECT_TRUE(contains_text(scan.output, "--scan-like makes a liver only")) << scan.output;
  EXPECT_FALSE(fs::exists(nothing));
}

}  // namespace
