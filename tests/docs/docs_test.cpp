// The manual is true to the project: every relative link of README.md and docs/ reaches a
// file (and a heading, when it names one), and docs/cli.md documents every command and
// option that `vdmsim --help` lists.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/binary.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path kSource = VDMSIM_SOURCE_DIR;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<fs::path> pages() {
  std::vector<fs::path> out = {kSource / "README.md"};
  for (const auto& e : fs::recursive_directory_iterator(kSource / "docs"))
    if (e.path().extension() == ".md") out.push_back(e.path());
  return out;
}

// GitHub's anchors of a page's headings (outside code blocks).
std::set<std::string> anchors(const fs::path& page) {
  std::set<std::string> out;
  std::istringstream in(read(page));
  std::string line;
  bool code = false;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) code = !code;
    if (code || line.empty() || line[0] != '#') continue;
    const size_t start = line.find_first_not_of('#');
    if (start == std::string::npos) continue;
    std::string a;
    for (char c : line.substr(start)) {
      const unsigned char u = static_cast<unsigned char>(c);
      if (std::isalnum(u) || c == '_' || c == '-') a += static_cast<char>(std::tolower(u));
      else if (u >= 0x80) a += c;  // non-ASCII letters stay, as on GitHub
      else if (c == ' ') a += '-';
    }
    while (!a.empty() && a[0] == '-') a.erase(0, 1);
    out.insert(a);
  }
  return out;
}

// Markdown links and images [text](target) and HTML src="target", outside code blocks. (Plain
// string scanning: std::regex draws false warnings from GCC 12 in the sanitizer build.)
std::vector<std::string> links(const fs::path& page) {
  std::vector<std::string> out;
  std::istringstream in(read(page));
  std::string line;
  bool code = false;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) code = !code;
    if (code) continue;
    for (size_t at = line.find("]("); at != std::string::npos; at = line.find("](", at + 2)) {
      const size_t b = at + 2, e = line.find_first_of(") \t", b);
      if (e == std::string::npos || e == b) continue;
      if (line[e] == ')' || line.find(')', e) != std::string::npos) out.push_back(line.substr(b, e - b));
    }
    for (size_t at = line.find("src=\""); at != std::string::npos; at = line.find("src=\"", at + 5)) {
      const size_t b = at + 5, e = line.find('"', b);
      if (e != std::string::npos && e > b) out.push_back(line.substr(b, e - b));
    }
  }
  return out;
}

TEST(Docs, EveryRelativeLinkResolves) {
  int checked = 0;
  for (const fs::path& page : pages()) {
    for (const std::string& link : links(page)) {
      if (link.rfind("http://", 0) == 0 || link.rfind("https://", 0) == 0 || link.rfind("mailto:", 0) == 0) continue;
      ++checked;
      const size_t hash = link.find('#');
      const std::string file = link.substr(0, hash), fragment = hash == std::string::npos ? "" : link.substr(hash + 1);
      const fs::path target = file.empty() ? page : page.parent_path() / file;
      if (!fs::exists(target)) {
        ADD_FAILURE() << page.lexically_relative(kSource) << ": link to " << link << ": no such file " << target;
        continue;
      }
      if (!fragment.empty() && target.extension() == ".md" && !anchors(target).count(fragment))
        ADD_FAILURE() << page.lexically_relative(kSource) << ": link to " << link << ": no heading #" << fragment << " in "
                      << target.lexically_relative(kSource);
    }
  }
  EXPECT_GT(checked, 20);
}

// The subcommands `vdmsim --help` lists.
std::vector<std::string> subcommands() {
  const vdmsim::test::CliResult r = vdmsim::test::run_cli(VDMSIM_BINARY, "--help");
  std::vector<std::string> out;
  std::istringstream in(r.output);
  std::string line;
  bool listing = false;
  while (std::getline(in, line)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      listing = true;
      continue;
    }
    if (!listing) continue;
    std::istringstream words(line);
    std::string name;
    if (line.rfind("  ", 0) == 0 && words >> name) out.push_back(name);
  }
  return out;
}

// The section of docs/cli.md that starts at the heading "## `vdmsim NAME`...".
std::string section(const std::string& cli, const std::string& name) {
  const std::string head = "## `vdmsim " + name;
  size_t start = cli.find(head + "`");
  if (start == std::string::npos) start = cli.find(head + " ");
  if (start == std::string::npos) return "";
  const size_t end = cli.find("\n## ", start + 1);
  return cli.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

TEST(Docs, CliReferenceHasEveryCommandAndOption) {
  const std::string cli = read(kSource / "docs/cli.md");
  ASSERT_FALSE(cli.empty()) << "docs/cli.md is missing";
  const std::vector<std::string> commands = subcommands();
  ASSERT_GE(commands.size(), 8u);
  for (const std::string& c : commands) {
    const std::string text = section(cli, c);
    if (text.empty()) {
      ADD_FAILURE() << "docs/cli.md has no section \"## `vdmsim " << c << " ...`\"";
      continue;
    }
    const std::string help = vdmsim::test::run_cli(VDMSIM_BINARY, c + " --help").output;
    for (size_t at = help.find("--"); at != std::string::npos; at = help.find("--", at + 2)) {
      size_t e = at + 2;
      if (e >= help.size() || !std::islower(static_cast<unsigned char>(help[e]))) continue;
      while (e < help.size() && (std::islower(static_cast<unsigned char>(help[e])) || help[e] == '-')) ++e;
      const std::string o = help.substr(at, e - at);
      if (o == "--help") continue;
      EXPECT_NE(text.find("`" + o), std::string::npos) << "docs/cli.md's section on " << c << " does not document " << o;
    }
  }
}

}  // namespace
