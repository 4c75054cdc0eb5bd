#include "app/scene/yaml_documents.hpp"

#include <sstream>

namespace vdmsim {

int count_yaml_documents(const std::string& text, int& second_line) {
  int documents = 1;
  second_line = 0;
  std::istringstream lines(text);
  std::string line;
  bool content = false, ended = false;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    auto marker = [&](const char* m) {
      return line.compare(0, 3, m) == 0 && (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '#');
    };
    const size_t first = line.find_first_not_of(" \t");
    const bool blank = first == std::string::npos || line[first] == '#';
    if (marker("---")) {
      if (content || ended) {
        ++documents;
        if (!second_line) second_line = number;
        ended = false;
      }
      content = line.find_first_not_of(" \t", 3) != std::string::npos && line[line.find_first_not_of(" \t", 3)] != '#';
    } else if (marker("...")) {
      ended = content;
    } else if (!blank && line[0] != '%') {
      if (ended) {
        ++documents;
        if (!second_line) second_line = number;
        ended = false;
      }
      content = true;
    }
  }
  return documents;
}

}  // namespace vdmsim
