// SPDX-License-Identifier: MIT
// src/io/text_scanner.h (internal): what the text mesh readers (OBJ, OFF, ASCII PLY) share: the
// line and token scanner, number parsing, and quoting tokens for messages. The PLY header is text too.
//
// The parsers are hand-written instead of using a library (tinyobjloader, rply, happly, Assimp):
// we must keep the file's vertex order and ids exactly (no merging, no dropping of unreferenced
// vertices), report every error with the file and the 1-based line or byte offset, survive hostile
// input (truncation, 10^12-element headers) without crashing or allocating by a header's word, and
// read large ASCII files fast (BENCHMARKS.md, "Against the targets"). The libraries Debian ships give none of these
// together. All parsing works on the whole file in memory: lines are found with memchr and numbers
// parsed with std::from_chars (correctly rounded, locale-independent, and many times faster than
// iostream >>).
#pragma once
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>

#include "io/file_error.h"

namespace trivcon::io {

// Quotes a token for a message; binary garbage is escaped and long tokens are cut.
std::string quoted(std::string_view text);

// Parses the whole token as a double. std::from_chars rejects a leading '+', which some writers
// emit, so we skip one; it also leaves the value unset on overflow/underflow, which we map to ±inf
// (rejected later as non-finite) and ±0 (the correctly rounded result).
bool parse_double(std::string_view token, double& value);

// Parses the whole token as an integer; one leading '+' is allowed.
bool parse_integer(std::string_view token, long long& value);

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Walks a text buffer line by line (LF or CRLF) and splits lines into whitespace-separated tokens,
// keeping the 1-based line number for messages.
class TextScanner {
 public:
  // `hash_comments`: a token starting with '#' ends the line (OBJ, OFF). `continuation`: a line
  // ending in a backslash continues on the next one (OBJ); messages then name its first line.
  TextScanner(std::string_view text, const std::string& name, bool hash_comments, bool continuation = false)
      : text_(text), name_(name), hash_comments_(hash_comments), continuation_(continuation) {}

  // Moves to the next line; false at the end of the text (line_number() stays at the last line).
  bool next_line() {
    if (next_ >= text_.size()) return false;
    line_ = take_physical_line();
    line_number_ = physical_lines_;
    if (continuation_ && ends_with_backslash(line_)) join_continued_lines();
    pos_ = 0;
    return true;
  }

  // The next token on the current line; false when only whitespace or a comment is left.
  bool next_token(std::string_view& token) {
    while (pos_ < line_.size() && is_space(line_[pos_])) ++pos_;
    if (pos_ == line_.size() || (hash_comments_ && line_[pos_] == '#')) return false;
    const std::size_t start = pos_;
    while (pos_ < line_.size() && !is_space(line_[pos_])) ++pos_;
    token = line_.substr(start, pos_ - start);
    return true;
  }

  // True when no token is left on the current line (the cursor does not move past a token).
  bool at_line_end() {
    while (pos_ < line_.size() && is_space(line_[pos_])) ++pos_;
    return pos_ == line_.size() || (hash_comments_ && line_[pos_] == '#');
  }

  // Moves to the next line that holds a token; false at the end of the text.
  bool next_content_line() {
    while (next_line()) {
      if (!at_line_end()) return true;
    }
    return false;
  }

  double number(std::string_view token) const {
    double value;
    if (!parse_double(token, value)) fail("malformed number " + quoted(token));
    return value;
  }

  long long integer(std::string_view token) const {
    long long value;
    if (!parse_integer(token, value)) fail("malformed integer " + quoted(token));
    return value;
  }

  std::size_t line_number() const { return line_number_; }
  std::size_t next_offset() const { return next_; }  // where the line after the current one starts
  std::size_t bytes_left() const { return text_.size() - next_; }

  [[noreturn]] void fail(const std::string& message) const { fail_at_line(name_, line_number_, message); }

 private:
  std::string_view take_physical_line() {
    const char* begin = text_.data() + next_;
    const std::size_t available = text_.size() - next_;
    const void* newline = std::memchr(begin, '\n', available);
    const std::size_t length = newline ? static_cast<const char*>(newline) - begin : available;
    next_ += length + (newline ? 1 : 0);
    ++physical_lines_;
    return {begin, length};
  }

  static bool ends_with_backslash(std::string_view line) {
    std::size_t end = line.size();
    while (end > 0 && is_space(line[end - 1])) --end;
    return end > 0 && line[end - 1] == '\\';
  }

  void join_continued_lines() {
    joined_.clear();
    std::string_view line = line_;
    while (ends_with_backslash(line)) {
      joined_.append(line.substr(0, line.find_last_of('\\')));
      joined_ += ' ';
      if (next_ >= text_.size()) {
        line = {};
        break;
      }
      line = take_physical_line();
    }
    joined_.append(line);
    line_ = joined_;
  }

  std::string_view text_;
  const std::string& name_;
  bool hash_comments_;
  bool continuation_;
  std::string_view line_;
  std::size_t pos_ = 0;   // cursor in line_
  std::size_t next_ = 0;  // offset of the next physical line in text_
  std::size_t physical_lines_ = 0;
  std::size_t line_number_ = 0;  // first physical line of the current logical line
  std::string joined_;           // storage for a line joined from backslash continuations
};

}  // namespace trivcon::io
