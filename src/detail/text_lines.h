// Internal: the lines of a small text file (field, matching, feature-edge files), for readers that go line by
// line and name "path:line" in their errors.
#pragma once
#include <sstream>
#include <string>

namespace trivcon::detail {

// Lines of a text file with their 1-based numbers, comments ('#') and blank lines skipped, '\r' dropped.
struct TextLines {
  std::istringstream in;
  std::string path, line;
  int number = 0;
  TextLines(const std::string& bytes, const std::string& p) : in(bytes), path(p) {}
  bool next() {
    while (std::getline(in, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const size_t a = line.find_first_not_of(" \t");
      if (a == std::string::npos || line[a] == '#') continue;
      return true;
    }
    return false;
  }
  std::string where() const { return path + ":" + std::to_string(number); }
};

}  // namespace trivcon::detail
