// vdmsim compare through the real binary, on PNG images the tests write: each exit code
// (0 within tolerance, 1 beyond it, 2 bad input), its message, and the diff images.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "render/image.hpp"
#include "render/png_io.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using vdmsim::test::CliResult;

constexpr int kW = 64, kH = 48;  // 3072 pixels: one pixel is a share of 3.26e-4

CliResult compare(const std::string& args) { return vdmsim::test::run_cli(VDMSIM_BINARY, "compare " + args); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A gradient, so that every pixel differs from its neighbours.
render::Image gradient(int w = kW, int h = kH) {
  render::Image im(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = im.pixel(x, y);
      p[0] = std::uint8_t(x * 3);
      p[1] = std::uint8_t(y * 5);
      p[2] = std::uint8_t(100 + x + y);
      p[3] = 255;
    }
  return im;
}

// The gradient with pixel (x, y)'s green channel raised by `by`.
render::Image changed(int x, int y, int by) {
  render::Image im = gradient();
  im.pixel(x, y)[1] = std::uint8_t(im.pixel(x, y)[1] + by);
  return im;
}

std::string write(const fs::path& path, const render::Image& im) {
  fs::create_directories(path.parent_path());
  std::string error;
  EXPECT_TRUE(render::write_png(path.string(), im, 6, false, error)) << error;
  return path.string();
}

fs::path compare_dir(const std::string& name) {
  const fs::path d = vdmsim::test::scratch_dir("compare_cli") / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A run folder as `vdmsim run` writes it: frames/, stress/ and the contact sheet.
void write_run(const fs::path& d, int frames) {
  for (int f = 0; f < frames; ++f) {
    const std::string n = "0000" + std::to_string(f);
    write(d / "frames" / ("frame_" + n + ".png"), gradient());
    write(d / "stress" / ("stress_" + n + ".png"), gradient());
  }
  write(d / "contact_sheet.png", gradient(32, 24));
}

TEST(CompareCli, IdenticalImagesExit0) {
  const fs::path d = compare_dir("identical");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", gradient());
  const CliResult r = compare(a + " " + b);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, b + ": within tolerance: largest channel difference 0, 0 of 3072 pixels")) << r.output;
}

TEST(CompareCli, OnePixelBeyondTheToleranceExits1AndSaysByHowMuch) {
  const fs::path d = compare_dir("one_pixel");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", changed(10, 20, 40));
  const CliResult r = compare(a + " " + b + " --max-diff 2");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, b + ": beyond tolerance: largest channel difference 40, 1 of 3072 pixels (share "
                                     "0.0003255) over --max-diff 2, more than --max-share 0"))
      << r.output;
}

TEST(CompareCli, ADifferenceUpToMaxDiffMatches) {
  const fs::path d = compare_dir("max_diff");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", changed(10, 20, 2));
  EXPECT_EQ(compare(a + " " + b + " --max-diff 2").code, 0);
  const CliResult strict = compare(a + " " + b);  // the default --max-diff is 0
  EXPECT_EQ(strict.code, 1) << strict.output;
  EXPECT_TRUE(contains(strict.output, "largest channel difference 2, 1 of 3072 pixels")) << strict.output;
}

TEST(CompareCli, DifferingPixelsWithinMaxShareMatch) {
  const fs::path d = compare_dir("max_share");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", changed(3, 4, 90));
  const CliResult within = compare(a + " " + b + " --max-share 0.001");  // one pixel: a share of 3.26e-4
  EXPECT_EQ(within.code, 0) << within.output;
  EXPECT_TRUE(contains(within.output, "within tolerance: largest channel difference 90, 1 of 3072 pixels")) << within.output;
  EXPECT_EQ(compare(a + " " + b + " --max-share 0.0003").code, 1);
}

TEST(CompareCli, SizesThatDifferExit2NamingTheFiles) {
  const fs::path d = compare_dir("sizes");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", gradient(kW, kH + 1));
  const CliResult r = compare(a + " " + b);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "vdmsim: error: " + b + ": 64x49 pixels, but " + a + " is 64x48")) << r.output;
}

TEST(CompareCli, AMissingFileExits2NamingIt) {
  const fs::path d = compare_dir("missing");
  const std::string a = write(d / "a.png", gradient());
  const std::string b = (d / "nowhere.png").string();
  const CliResult r = compare(a + " " + b);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "vdmsim: error: " + b + ": no such file or folder")) << r.output;
  EXPECT_EQ(compare(b + " " + a).code, 2);
}

TEST(CompareCli, AFileThatIsNotAPngExits2NamingIt) {
  const fs::path d = compare_dir("not_png");
  const std::string a = write(d / "a.png", gradient());
  const fs::path b = d / "b.png";
  std::ofstream(b) << "not an image\n";
  const CliResult r = compare(a + " " + b.string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "vdmsim: error: " + b.string() + ": not a PNG file")) << r.output;
}

TEST(CompareCli, ATruncatedPngExits2NamingIt) {
  const fs::path d = compare_dir("truncated");
  const std::string a = write(d / "a.png", gradient());
  std::ifstream in(a, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const fs::path b = d / "b.png";
  std::ofstream(b, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const CliResult r = compare(a + " " + b.string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "vdmsim: error: " + b.string() + ": damaged or truncated PNG")) << r.output;
}

TEST(CompareCli, ADiffFolderThatCannotBeMadeExits2Once) {
  const fs::path d = compare_dir("diff_blocked");
  write_run(d / "expected", 2);
  write_run(d / "actual", 2);
  std::ofstream(d / "taken") << "a file\n";
  const CliResult r = compare((d / "expected").string() + " " + (d / "actual").string() + " --diff " + (d / "taken").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "vdmsim: error: " + (d / "taken").string() + ": cannot make the folder for the diff images"))
      << r.output;
  EXPECT_EQ(r.output.find("image pairs"), std::string::npos) << "nothing compared\n" << r.output;
}

TEST(CompareCli, BadToleranceOrAFileBesideAFolderExits2) {
  const fs::path d = compare_dir("bad_usage");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", gradient());
  EXPECT_EQ(compare(a + " " + b + " --max-diff 256").code, 2);
  EXPECT_EQ(compare(a + " " + b + " --max-share 1.5").code, 2);
  EXPECT_EQ(compare(a + " " + b + " --max-share nan").code, 2);
  const CliResult mixed = compare(a + " " + d.string());
  EXPECT_EQ(mixed.code, 2) << mixed.output;
  EXPECT_TRUE(contains(mixed.output, a + ": a file, but " + d.string() + " is a folder")) << mixed.output;
}

TEST(CompareCli, TwoRunFoldersWithTheSameImagesExit0) {
  const fs::path d = compare_dir("same_runs");
  write_run(d / "expected", 3);
  write_run(d / "actual", 3);
  const CliResult r = compare((d / "expected").string() + " " + (d / "actual").string());
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, ": 7 image pairs, 7 within tolerance, 0 beyond")) << r.output;
}

TEST(CompareCli, AFrameMissingFromAFolderExits1NamingIt) {
  const fs::path d = compare_dir("missing_frame");
  write_run(d / "expected", 3);
  write_run(d / "actual", 3);
  fs::remove(d / "actual/frames/frame_00001.png");
  write(d / "actual/stress/stress_00009.png", gradient());
  const std::string e = (d / "expected").string(), a = (d / "actual").string();
  const CliResult r = compare(e + " " + a);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "frames/frame_00001.png: missing in " + a + "\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "stress/stress_00009.png: missing in " + e + " (found only in " + a + ")")) << r.output;
  EXPECT_TRUE(contains(r.output, ": 6 image pairs, 6 within tolerance, 0 beyond; 2 found in one folder only")) << r.output;
}

TEST(CompareCli, AFolderPairBeyondToleranceIsNamed) {
  const fs::path d = compare_dir("folder_beyond");
  write_run(d / "expected", 2);
  write_run(d / "actual", 2);
  write(d / "actual/stress/stress_00001.png", changed(0, 0, 200));
  const CliResult r = compare((d / "expected").string() + " " + (d / "actual").string() + " --max-diff 3");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "stress/stress_00001.png: beyond tolerance: largest channel difference 200, 1 of 3072"))
      << r.output;
  EXPECT_FALSE(contains(r.output, "frame_00000.png:")) << "pairs within tolerance are not listed\n" << r.output;
  EXPECT_TRUE(contains(r.output, ": 5 image pairs, 4 within tolerance, 1 beyond")) << r.output;
}

TEST(CompareCli, AFolderWithoutImagesExits2) {
  const fs::path d = compare_dir("empty_folder");
  fs::create_directories(d / "expected");
  write_run(d / "actual", 1);
  const CliResult r = compare((d / "expected").string() + " " + (d / "actual").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, (d / "expected").string() + ": no PNG images")) << r.output;
}

TEST(CompareCli, DiffImageIsWrittenAndShowsTheDifferingPixelInRed) {
  const fs::path d = compare_dir("diff_file");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", changed(10, 20, 40));
  const fs::path out = d / "made/by/compare/diff.png";
  const CliResult r = compare(a + " " + b + " --diff " + out.string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "diff image: " + out.string())) << r.output;
  render::Image diff;
  std::string error;
  ASSERT_TRUE(render::read_png(out.string(), diff, error)) << error;
  ASSERT_EQ(diff.width, kW);
  ASSERT_EQ(diff.height, kH);
  const std::uint8_t* hit = diff.pixel(10, 20);
  EXPECT_GT(hit[0], 128);
  EXPECT_EQ(hit[1], 0);
  EXPECT_EQ(hit[2], 0);
  const std::uint8_t* same = diff.pixel(11, 20);
  EXPECT_EQ(same[0], same[1]) << "a matching pixel is grey";
  EXPECT_EQ(same[1], same[2]);
}

TEST(CompareCli, DiffFolderHasOneImagePerPairAtItsPath) {
  const fs::path d = compare_dir("diff_folder");
  write_run(d / "expected", 2);
  write_run(d / "actual", 2);
  write(d / "actual/frames/frame_00001.png", changed(5, 5, 60));
  const fs::path out = d / "diffs";
  const CliResult r =
      compare((d / "expected").string() + " " + (d / "actual").string() + " --diff " + out.string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "diff images: 5 in " + out.string())) << r.output;
  for (const char* name : {"frames/frame_00000.png", "frames/frame_00001.png", "stress/stress_00000.png",
                           "stress/stress_00001.png", "contact_sheet.png"}) {
    render::Image im;
    std::string error;
    EXPECT_TRUE(render::read_png((out / name).string(), im, error)) << error;
  }
  render::Image hit;
  std::string error;
  ASSERT_TRUE(render::read_png((out / "frames/frame_00001.png").string(), hit, error)) << error;
  EXPECT_GT(hit.pixel(5, 5)[0], 128);
  EXPECT_EQ(hit.pixel(5, 5)[1], 0);
}

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// --diff naming an input file (as given, through another spelling, or a link to it) is refused
// before anything is written: the golden image stays as it was.
TEST(CompareCli, ADiffImageThatIsAnInputIsRefusedAndTheInputKept) {
  const fs::path d = compare_dir("diff_is_input");
  const std::string a = write(d / "a.png", gradient()), b = write(d / "b.png", changed(10, 20, 40));
  fs::create_symlink(d / "a.png", d / "link.png");
  const std::string golden = bytes(a);
  for (const std::string& target : {a, (d / "." / "a.png").string(), (d / "link.png").string(), b}) {
    const CliResult r = compare(a + " " + b + " --diff " + target);
    EXPECT_EQ(r.code, 2) << target << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "vdmsim: error: --diff " + target + ": is ")) << r.output;
    EXPECT_TRUE(contains(r.output, "choose a path outside both")) << r.output;
    EXPECT_EQ(bytes(a), golden) << target;
  }
}

// --diff naming the expected or the actual folder, or a folder inside either, is refused:
// the reference images stay as they were and nothing is added to either folder.
TEST(CompareCli, ADiffFolderThatIsOrLiesInsideAnInputIsRefused) {
  const fs::path d = compare_dir("diff_in_folder");
  write_run(d / "expected", 2);
  write_run(d / "actual", 1);
  write(d / "actual" / "frames" / "frame_00001.png", changed(1, 1, 90));
  const std::string golden = bytes(d / "expected" / "frames" / "frame_00001.png");
  const std::string args = (d / "expected").string() + " " + (d / "actual").string() + " --diff ";
  for (const fs::path& target : {d / "expected", d / "expected/", d / "expected" / "frames", d / "actual" / "diff"}) {
    const CliResult r = compare(args + target.string());
    EXPECT_EQ(r.code, 2) << target << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "the diff images would overwrite or mix with the images compared")) << r.output;
  }
  EXPECT_EQ(bytes(d / "expected" / "frames" / "frame_00001.png"), golden);
  EXPECT_FALSE(fs::exists(d / "actual" / "diff"));
}

// A diff folder that holds an input (here EXPECTED's parent) would write the diff image of
// frames/f.png over EXPECTED's f.png: refused too.
TEST(CompareCli, ADiffImageLandingOnAnInputImageIsRefused) {
  const fs::path d = compare_dir("diff_holds_input");
  for (const char* side : {"e/frames", "a"}) {
    write(d / side / "f.png", gradient());
    write(d / side / "frames" / "f.png", changed(2, 2, 50));
  }
  const std::string golden = bytes(d / "e" / "frames" / "f.png");
  const CliResult r = compare((d / "e" / "frames").string() + " " + (d / "a").string() + " --diff " + (d / "e").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "the diff image of frames/f.png would overwrite the compared image")) << r.output;
  EXPECT_EQ(bytes(d / "e" / "frames" / "f.png"), golden);
}

}  // namespace
