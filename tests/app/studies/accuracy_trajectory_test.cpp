// A configuration's trajectory written by its task and read back by the study: bit for bit,
// and a file cut short or of another kind refused with its name.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "app/studies/accuracy_trajectory.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

Trajectory made_up(int frames, int samples) {
  Trajectory tr;
  tr.nodes = 2562;
  tr.unconverged = 3;
  for (int f = 0; f < frames; ++f) {
    vdm::NodeMat u(samples, 3);
    for (int s = 0; s < samples; ++s)
      for (int k = 0; k < 3; ++k) u(s, k) = std::sin(1.0 + f * 0.37 + s * 1.3 + k * 0.1) * 1e-3 / 3.0;
    tr.u.push_back(u);
    tr.force.emplace_back(0.1 * f, -1.0 / 3.0, std::nextafter(1.0, 2.0));
    tr.step_ms.push_back(0.5 + f);
    tr.volume_rel.push_back(1e-12 * f);
  }
  return tr;
}

TEST(AccuracyTrajectory, ReadsBackBitForBit) {
  const fs::path file = test::scratch_dir("accuracy_trajectory") / "trajectory.bin";
  const Trajectory written = made_up(7, 5);
  std::string error;
  ASSERT_TRUE(write_trajectory(file, written, error)) << error;
  Trajectory read;
  ASSERT_TRUE(read_trajectory(file, read, error)) << error;
  EXPECT_EQ(read.nodes, 2562);
  EXPECT_EQ(read.unconverged, 3);
  ASSERT_EQ(read.u.size(), 7u);
  for (size_t f = 0; f < 7; ++f) {
    EXPECT_TRUE(read.u[f] == written.u[f]) << f;  // exact equality: no rounding on the way
    EXPECT_TRUE(read.force[f] == written.force[f]) << f;
    EXPECT_EQ(read.step_ms[f], written.step_ms[f]);
    EXPECT_EQ(read.volume_rel[f], written.volume_rel[f]);
  }
}

TEST(AccuracyTrajectory, ACutOrForeignFileIsRefusedWithItsName) {
  const fs::path d = test::scratch_dir("accuracy_trajectory");
  std::string error;
  ASSERT_TRUE(write_trajectory(d / "whole.bin", made_up(3, 4), error)) << error;
  const auto size = fs::file_size(d / "whole.bin");
  fs::copy_file(d / "whole.bin", d / "cut.bin", fs::copy_options::overwrite_existing);
  fs::resize_file(d / "cut.bin", size - 8);
  Trajectory tr;
  EXPECT_FALSE(read_trajectory(d / "cut.bin", tr, error));
  EXPECT_NE(error.find("cut.bin: cut short"), std::string::npos) << error;
  std::ofstream(d / "other.bin") << "frame,step_ms\n0,1.5\n";
  EXPECT_FALSE(read_trajectory(d / "other.bin", tr, error));
  EXPECT_NE(error.find("other.bin: not a trajectory"), std::string::npos) << error;
  EXPECT_FALSE(read_trajectory(d / "absent.bin", tr, error));
  EXPECT_NE(error.find("absent.bin: cannot be read"), std::string::npos) << error;
}

}  // namespace
}  // namespace vdmsim
