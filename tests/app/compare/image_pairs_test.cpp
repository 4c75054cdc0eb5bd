// Pairing the images of two folders for vdmsim compare: by relative path, PNGs only, the
// diff folder left out, what one folder lacks listed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/compare/image_pairs.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;

fs::path dir(const std::string& name) {
  const fs::path d = vdmsim::test::scratch_dir("image_pairs") / name;
  fs::remove_all(d);
  return d;
}

void touch(const fs::path& p) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << "x";
}

std::vector<std::string> names(const vdmsim::ImagePairing& r) {
  std::vector<std::string> out;
  for (const vdmsim::ImagePair& p : r.pairs) out.push_back(p.name);
  return out;
}

TEST(ImagePairs, FoldersArePairedByRelativePathAndSorted) {
  const fs::path d = dir("paired");
  for (const char* side : {"e", "a"})
    for (const char* f : {"stress/stress_00000.png", "frames/frame_00001.png", "frames/frame_00000.png", "sheet.PNG"})
      touch(d / side / f);
  touch(d / "e" / "metrics.csv");
  touch(d / "a" / "frames" / "frame_00002.png.tmp");
  const vdmsim::ImagePairing r = vdmsim::pair_images((d / "e").string(), (d / "a").string());
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_TRUE(r.folders);
  EXPECT_EQ(names(r), (std::vector<std::string>{"frames/frame_00000.png", "frames/frame_00001.png", "sheet.PNG",
                                                "stress/stress_00000.png"}));
  EXPECT_EQ(r.pairs[0].expected, (d / "e" / "frames/frame_00000.png").string());
  EXPECT_EQ(r.pairs[0].actual, (d / "a" / "frames/frame_00000.png").string());
  EXPECT_TRUE(r.missing_in_actual.empty());
  EXPECT_TRUE(r.missing_in_expected.empty());
}

TEST(ImagePairs, WhatOneFolderLacksIsListed) {
  const fs::path d = dir("lacking");
  touch(d / "e" / "frames/frame_00000.png");
  touch(d / "e" / "frames/frame_00001.png");
  touch(d / "a" / "frames/frame_00000.png");
  touch(d / "a" / "stress/stress_00000.png");
  const vdmsim::ImagePairing r = vdmsim::pair_images((d / "e").string(), (d / "a").string());
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(names(r), std::vector<std::string>{"frames/frame_00000.png"});
  EXPECT_EQ(r.missing_in_actual, std::vector<std::string>{"frames/frame_00001.png"});
  EXPECT_EQ(r.missing_in_expected, std::vector<std::string>{"stress/stress_00000.png"});
}

TEST(ImagePairs, TwoFilesAreOnePairNamedForTheActualFile) {
  const fs::path d = dir("files");
  touch(d / "x.png");
  touch(d / "y.png");
  const vdmsim::ImagePairing r = vdmsim::pair_images((d / "x.png").string(), (d / "y.png").string());
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_FALSE(r.folders);
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_EQ(r.pairs[0].name, (d / "y.png").string());
}

TEST(ImagePairs, BadInputIsNamed) {
  const fs::path d = dir("bad");
  touch(d / "x.png");
  fs::create_directories(d / "empty");
  fs::create_directories(d / "other");
  EXPECT_EQ(vdmsim::pair_images((d / "x.png").string(), (d / "none.png").string()).error,
            (d / "none.png").string() + ": no such file or folder");
  EXPECT_EQ(vdmsim::pair_images((d / "empty").string(), (d / "other").string()).error,
            (d / "empty").string() + ": no PNG images in the folder or its subfolders");
  EXPECT_NE(vdmsim::pair_images((d / "empty").string(), (d / "x.png").string()).error.find("is a folder"),
            std::string::npos);
}

}  // namespace
