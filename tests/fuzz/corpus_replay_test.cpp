// Replays the committed fuzzing corpus (seeds and every input that once crashed) through the
// fuzz targets' own entry points, in every build, without clang.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "fuzz/fuzz_entries.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

template <class F>
int replay(const char* sub, F entry) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(fs::path(VDMSIM_SOURCE_DIR) / "tests/fuzz/corpus" / sub)) {
    const auto b = bytes(e.path());
    SCOPED_TRACE(e.path().string());
    entry(b.data(), b.size());
    ++n;
  }
  return n;
}

TEST(FuzzCorpus, SceneInputsLoadWithoutCrashing) { EXPECT_GT(replay("scene", vdmsim::fuzz::scene_input), 5); }

TEST(FuzzCorpus, MeshInputsLoadWithoutCrashing) { EXPECT_GT(replay("mesh", vdmsim::fuzz::mesh_input), 3); }

// Includes the issue-46 sweep whose value with a line break became the run scene's render: key
// (sweep_input aborts on that).
TEST(FuzzCorpus, SweepInputsReadWithoutCrashing) { EXPECT_GT(replay("sweep", vdmsim::fuzz::sweep_input), 5); }

}  // namespace
