// Golden-image tests (Filament's render-diff manner): small scenes rendered through the real
// pipeline and compared with committed PNGs under tests/golden/ with a per-test tolerance.
// On a mismatch the actual image and a diff image are written to the build's
// test-output/golden/ folder. A missing golden is reported as its own failure.
// Regenerate with tests/golden/update.sh (VDMSIM_UPDATE_GOLDEN=1), which lists what changed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "app/run/scene_run.hpp"
#include "render/image_compare.hpp"
#include "render/png_io.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kGolden = fs::path(VDMSIM_SOURCE_DIR) / "tests" / "golden";
const fs::path kOutput = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "golden";

bool update_mode() {
  const char* v = std::getenv("VDMSIM_UPDATE_GOLDEN");
  return v && std::string(v) == "1";
}

// Runs a golden scene into test-output and returns its output folder.
fs::path render_scene(const std::string& scene, const std::string& tag) {
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  const std::string path = (kGolden / "scenes" / (scene + ".yaml")).string();
  EXPECT_TRUE(vdmsim::prepare_scene(path, ps, problems)) << (problems.empty() ? "" : problems[0].text());
  vdmsim::RunOptions opt;
  opt.out_dir = (kOutput / (scene + "_" + tag)).string();
  std::ostringstream out, err;
  EXPECT_EQ(vdmsim::run_scene(ps, opt, out, err, false), 0) << err.str();
  return opt.out_dir;
}

// Compares `actual_path` with the golden `name`; writes actual and diff images on mismatch.
void expect_matches_golden(const fs::path& actual_path, const std::string& name, const render::CompareTolerance& tol) {
  render::Image actual, expected;
  std::string error;
  ASSERT_TRUE(render::read_png(actual_path.string(), actual, error)) << error;
  const fs::path golden = kGolden / (name + ".png");
  if (update_mode()) {
    render::Image old;
    const bool had = render::read_png(golden.string(), old, error);
    const bool identical = had && render::compare_images(old, actual, {0, 0.0}, nullptr).match;
    if (identical) {
      std::printf("golden %s: unchanged\n", name.c_str());
      return;
    }
    const bool within = had && render::compare_images(old, actual, tol, nullptr).match;
    ASSERT_TRUE(render::write_png(golden.string(), actual, 9, false, error)) << error;
    std::printf("golden %s: %s\n", name.c_str(),
                !had ? "created" : within ? "updated (changed within the test's tolerance)" : "UPDATED (changed beyond the tolerance)");
    return;
  }
  if (!fs::exists(golden)) {
    ADD_FAILURE() << "golden image missing: " << golden.string() << " (the actual image is " << actual_path.string()
                  << "; run tests/golden/update.sh to create it)";
    return;
  }
  ASSERT_TRUE(render::read_png(golden.string(), expected, error)) << error;
  render::Image diff;
  const render::CompareResult r = render::compare_images(expected, actual, tol, &diff);
  if (!r.match) {
    fs::create_directories(kOutput);
    const fs::path actual_copy = kOutput / (name + ".actual.png"), diff_path = kOutput / (name + ".diff.png");
    fs::copy_file(actual_path, actual_copy, fs::copy_options::overwrite_existing);
    if (r.same_size) render::write_png(diff_path.string(), diff, 1, false, error);
    ADD_FAILURE() << name << " differs from its golden: " << r.summary() << " (tolerance: channel difference "
                  << tol.max_channel_diff << ", share " << tol.max_differing_share * 100 << " %); actual "
                  << actual_copy.string() << ", diff " << diff_path.string();
  }
}

// llvmpipe's arithmetic can round differently on another CPU: a few levels on edges.
const render::CompareTolerance kSceneTolerance{6, 0.005};

}  // namespace

TEST(GoldenImages, ProbePressShadedAndStressViews) {
  const fs::path dir = render_scene("probe_small", "a");
  expect_matches_golden(dir / "frames" / "frame_00003.png", "probe_small_shaded_f3", kSceneTolerance);
  expect_matches_golden(dir / "stress" / "stress_00003.png", "probe_small_stress_f3", kSceneTolerance);
  expect_matches_golden(dir / "contact_sheet.png", "probe_small_contact_sheet", kSceneTolerance);
}

TEST(GoldenImages, GraspLiftWithoutHud) {
  const fs::path dir = render_scene("grasp_small", "a");
  expect_matches_golden(dir / "frames" / "frame_00000.png", "grasp_small_shaded_f0", kSceneTolerance);
  expect_matches_golden(dir / "frames" / "frame_00003.png", "grasp_small_shaded_f3", kSceneTolerance);
  expect_matches_golden(dir / "stress" / "stress_00003.png", "grasp_small_stress_f3", kSceneTolerance);
}

// The endoscope's view: the textured tissue under the tip light, the abdomen's wall, black
// shafts through their ports, the fenestrated jaws and the hook, a dent under the hook.
TEST(GoldenImages, LaparoscopicView) {
  const fs::path dir = render_scene("lap_small", "a");
  expect_matches_golden(dir / "frames" / "frame_00001.png", "lap_small_shaded_f1", kSceneTolerance);
  expect_matches_golden(dir / "stress" / "stress_00001.png", "lap_small_stress_f1", kSceneTolerance);
}

// The same scene rendered twice gives identical pixels (not merely within tolerance).
TEST(GoldenImages, SameSceneTwiceGivesIdenticalPixels) {
  const fs::path a = render_scene("probe_small", "twice1"), b = render_scene("probe_small", "twice2");
  for (const char* file : {"frames/frame_00000.png", "frames/frame_00003.png", "stress/stress_00003.png"}) {
    render::Image ia, ib;
    std::string error;
    ASSERT_TRUE(render::read_png((a / file).string(), ia, error)) << error;
    ASSERT_TRUE(render::read_png((b / file).string(), ib, error)) << error;
    const render::CompareResult r = render::compare_images(ia, ib, {0, 0.0}, nullptr);
    EXPECT_TRUE(r.match) << file << ": " << r.summary();
    EXPECT_EQ(r.largest_diff, 0) << file;
  }
}

// The comparison can fail: a pixel-level change to a real frame is caught at the golden
// tolerance, and the diff image marks exactly the changed pixels.
TEST(GoldenImages, ComparisonCatchesAPixelLevelChange) {
  const fs::path dir = render_scene("probe_small", "mutated");
  render::Image frame;
  std::string error;
  ASSERT_TRUE(render::read_png((dir / "frames" / "frame_00003.png").string(), frame, error)) << error;
  render::Image changed = frame;
  // A 6 x 6 block brightened by 40 levels: 36 pixels of 76800.
  for (int y = 100; y < 106; ++y)
    for (int x = 150; x < 156; ++x)
      for (int c = 0; c < 3; ++c) changed.pixel(x, y)[c] = static_cast<std::uint8_t>(std::min(255, changed.pixel(x, y)[c] + 40));
  render::Image diff;
  const render::CompareResult strict = render::compare_images(frame, changed, {6, 0.0}, &diff);
  EXPECT_FALSE(strict.match);
  EXPECT_EQ(strict.differing_pixels, 36);
  EXPECT_GE(strict.largest_diff, 1);
  EXPECT_EQ(diff.pixel(152, 102)[1], 0);    // marked red
  EXPECT_GT(diff.pixel(10, 10)[1], 100);    // untouched: grey
  // The scene tolerance allows 0.5 % of pixels: a 40 x 40 block (2 %) is caught too.
  for (int y = 100; y < 140; ++y)
    for (int x = 150; x < 190; ++x) changed.pixel(x, y)[0] = static_cast<std::uint8_t>(changed.pixel(x, y)[0] ^ 0x80);
  EXPECT_FALSE(render::compare_images(frame, changed, kSceneTolerance, nullptr).match);
  EXPECT_TRUE(render::compare_images(frame, frame, {0, 0.0}, nullptr).match);
}
