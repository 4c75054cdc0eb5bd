// The manual's commands run: every `./build/vdmsim ...` line in a code block of README.md and
// docs/ that names real files is run as written (from a folder where `build` and `assets` are
// the project's), and must succeed; where the page shows its output (a `$ ` line followed by
// output lines) of a deterministic command (check, mesh-info), each shown line must be printed.
// Left out: lines with placeholders (SCENE, DIR, a user's my_scene: docs/golden-images.md's
// example runs in its own test; my_organ: docs/your-own-organ.md's, in its own test too), redirections, the example of a bad scene, and the accuracy
// study (minutes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/binary.hpp"

namespace {

namespace fs = std::filesystem;

struct DocCommand {
  fs::path page;
  std::string line;                   // as written, without the prompt and the comment
  std::vector<std::string> expected;  // the output the page shows (after a "$ " prompt)
};

std::vector<DocCommand> doc_commands() {
  const fs::path source = VDMSIM_SOURCE_DIR;
  std::vector<fs::path> pages = {source / "README.md"};
  for (const auto& e : fs::recursive_directory_iterator(source / "docs"))
    if (e.path().extension() == ".md") pages.push_back(e.path());
  std::sort(pages.begin(), pages.end());
  std::vector<DocCommand> out;
  for (const fs::path& page : pages) {
    std::ifstream in(page);
    std::string line;
    bool code = false, prompt = false;
    while (std::getline(in, line)) {
      if (line.rfind("```", 0) == 0) {
        code = !code;
        prompt = false;
        continue;
      }
      if (!code) continue;
      const bool shown = line.rfind("$ ./build/vdmsim ", 0) == 0;
      if (shown || line.rfind("./build/vdmsim ", 0) == 0) {
        std::string cmd = shown ? line.substr(2) : line;
        if (const size_t hash = cmd.find("  #"); hash != std::string::npos) cmd = cmd.substr(0, hash);
        while (!cmd.empty() && cmd.back() == ' ') cmd.pop_back();
        out.push_back({page, cmd, {}});
        prompt = shown;
      } else if (prompt && !line.empty()) {
        out.back().expected.push_back(line);
      } else {
        prompt = false;
      }
    }
  }
  return out;
}

bool runnable(const std::string& cmd) {
  for (const char* skip : {"SCENE", "DIR", "my_scene", "my_organ", ">", "bad_example", " accuracy "})
    if (cmd.find(skip) != std::string::npos) return false;
  return true;
}

TEST(DocsCommands, EveryCommandOfTheManualRuns) {
  const fs::path work = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "docs_commands";
  fs::remove_all(work);
  fs::create_directories(work);
  fs::create_directory_symlink(VDMSIM_BUILD_DIR, work / "build");
  fs::create_directory_symlink(fs::path(VDMSIM_SOURCE_DIR) / "assets", work / "assets");
  const std::vector<DocCommand> commands = doc_commands();
  int ran = 0;
  for (const DocCommand& c : commands) {
    if (!runnable(c.line)) continue;
    ++ran;
    const std::string shell = "cd '" + work.string() + "' && " + c.line + " 2>&1";
    FILE* p = popen(shell.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string output;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
    const int status = pclose(p);
    EXPECT_EQ(WEXITSTATUS(status), 0) << c.page.filename() << ": " << c.line << "\n" << output;
    const bool deterministic = c.line.find(" check ") != std::string::npos || c.line.find(" mesh-info ") != std::string::npos;
    std::printf("%s: %s (%zu lines of output checked)\n", c.page.filename().c_str(), c.line.c_str(),
                deterministic ? c.expected.size() : size_t(0));
    if (deterministic) {
      for (const std::string& want : c.expected)
        EXPECT_NE(output.find(want), std::string::npos)
            << c.page.filename() << ": " << c.line << " should print\n  " << want << "\nbut printed\n" << output;
    }
  }
  EXPECT_GE(ran, 6) << "the manual's commands were not found";
}

}  // namespace
