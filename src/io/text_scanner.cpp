// SPDX-License-Identifier: MIT
// src/io/text_scanner.cpp: quoting and number parsing for the text mesh readers; see src/io/text_scanner.h.
#include "io/text_scanner.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>

namespace trivcon::io {

std::string quoted(std::string_view text) {
  constexpr std::size_t kMaxShown = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < std::min(text.size(), kMaxShown); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 32 && c < 127) {
      out += static_cast<char>(c);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      out += escaped;
    }
  }
  if (text.size() > kMaxShown) out += "...";
  return out + "'";
}

bool parse_double(std::string_view token, double& value) {
  const char* first = token.data();
  const char* const last = first + token.size();
  if (first != last && *first == '+') {
    ++first;
    if (first != last && (*first == '+' || *first == '-')) return false;
  }
  if (first == last) return false;
  const auto [end, error] = std::from_chars(first, last, value);
  if (end != last) return false;
  if (error == std::errc::result_out_of_range) {
    const bool negative = *first == '-';
    bool underflow;
    long double wide = 0;
    if (std::from_chars(first, last, wide).ec == std::errc()) {
      underflow = std::fabs(wide) < 1;
    } else {  // beyond long double too: the exponent's sign decides
      const std::size_t e = std::string_view(first, last - first).find_first_of("eE");
      underflow = e != std::string_view::npos && first + e + 1 < last && first[e + 1] == '-';
    }
    const double magnitude = underflow ? 0.0 : std::numeric_limits<double>::infinity();
    value = negative ? -magnitude : magnitude;
    return true;
  }
  return error == std::errc();
}

bool parse_integer(std::string_view token, long long& value) {
  const char* first = token.data();
  const char* const last = first + token.size();
  if (first != last && *first == '+') {
    ++first;
    if (first != last && *first == '-') return false;
  }
  if (first == last) return false;
  const auto [end, error] = std::from_chars(first, last, value);
  return end == last && error == std::errc();
}

}  // namespace trivcon::io
