// SPDX-License-Identifier: MIT
// Internal: the lines of a small text file (field, matching, feature-edge files), for readers that go line by
// line and name "path:line" in their errors.
#pragma once
#include <sstream>
#include <string>

#include "io/text_scanner.h"
#include "trivcon/error.h"

namespace trivcon::io {

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

// A whole number token within [lo, hi], or an error naming the line and what it should be.
inline long long whole_number(const std::string& token, const TextLines& lines, long long lo, long long hi, const char* what) {
  long long v = 0;
  if (!parse_integer(token, v) || v < lo || v > hi)
    throw Error(lines.where() + ": " + what + " '" + token + "' is not a whole number in [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "]");
  return v;
}

}  // namespace trivcon::io
