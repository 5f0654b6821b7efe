// src/io.cpp: reading and writing triangle meshes (OBJ, OFF, PLY, gzipped or not); see trivcon/io.h.
//
// The parsers are hand-written instead of using a library (tinyobjloader, rply, happly, Assimp):
// we must keep the file's vertex order and ids exactly (no merging, no dropping of unreferenced
// vertices), report every error with the file and the 1-based line or byte offset, survive hostile
// input (truncation, 10^12-element headers) without crashing or allocating by a header's word, and
// read a 33 MB ASCII PLY in a fraction of a second. The libraries Debian ships give none of these
// together. All parsing works on the whole file in memory: lines are found with memchr and numbers
// parsed with std::from_chars (correctly rounded, locale-independent, and many times faster than
// iostream >>).
//
// Vertex ids in messages are 0-based like everywhere in trivcon; polygons ("face 4") are counted
// 0-based in file order; an index that is out of range is quoted as written in the file.
#include "trivcon/io.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string_view>
#include <system_error>
#include <type_traits>

#include "trivcon/error.h"

namespace trivcon {
namespace {

constexpr long long kMaxCount = std::numeric_limits<int>::max();  // ids are int (MatrixX3i)

// ------------------------------------------------------------------------------------------------
// Messages

// Quotes a token for a message; binary garbage is escaped and long tokens are cut.
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

[[noreturn]] void fail(const std::string& name, const std::string& message) {
  throw Error(name + ": " + message);
}

[[noreturn]] void fail_at_line(const std::string& name, std::size_t line, const std::string& message) {
  throw Error(name + ":" + std::to_string(line) + ": " + message);
}

std::string out_of_range_message(long long index, long long vertex_count) {
  return "face index " + std::to_string(index) + " out of range (file has " +
         std::to_string(vertex_count) + " vertices)";
}

std::string non_finite_message(long long vertex, double value) {
  return "non-finite coordinate in vertex " + std::to_string(vertex) + " (" +
         (std::isnan(value) ? "nan" : value > 0 ? "inf" : "-inf") + ")";
}

// ------------------------------------------------------------------------------------------------
// Numbers

// Parses the whole token as a double. std::from_chars rejects a leading '+', which some writers
// emit, so we skip one; it also leaves the value unset on overflow/underflow, which we map to ±inf
// (rejected later as non-finite) and ±0 (the correctly rounded result).
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

// ------------------------------------------------------------------------------------------------
// Text scanning, shared by OBJ, OFF and ASCII PLY

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
  std::size_t pos_ = 0;           // cursor in line_
  std::size_t next_ = 0;          // offset of the next physical line in text_
  std::size_t physical_lines_ = 0;
  std::size_t line_number_ = 0;   // first physical line of the current logical line
  std::string joined_;            // storage for a line joined from backslash continuations
};

// ------------------------------------------------------------------------------------------------
// Faces, shared by all readers

// What is wrong with polygon `face` (0-based, range-checked corners), or "" when nothing is.
std::string polygon_problem(const std::vector<int>& corners, long long face) {
  const std::size_t k = corners.size();
  if (k < 3) {
    return "face " + std::to_string(face) + " has " + std::to_string(k) + " corner" + (k == 1 ? "" : "s") +
           " (at least 3 needed)";
  }
  bool repeated = false;
  if (k <= 16) {  // the common case: no allocation
    for (std::size_t i = 1; i < k && !repeated; ++i) {
      for (std::size_t j = 0; j < i && !repeated; ++j) repeated = corners[i] == corners[j];
    }
  } else {
    std::vector<int> sorted = corners;
    std::sort(sorted.begin(), sorted.end());
    repeated = std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
  }
  if (!repeated) return {};
  constexpr std::size_t kMaxListed = 12;
  std::string list;
  for (std::size_t i = 0; i < std::min(k, kMaxListed); ++i) list += (i ? ", " : "") + std::to_string(corners[i]);
  if (k > kMaxListed) list += ", ...";
  return "face " + std::to_string(face) + " has a repeated vertex (" + list + ")";
}

// Collects checked polygons and fan-triangulates them.
class FaceCollector {
 public:
  void reserve_triangles(std::size_t count) {
    triangles_.reserve(3 * count);
    polygon_of_triangle_.reserve(count);
  }

  // What is wrong with `corners` as the next polygon, or "" when nothing is; the caller adds where.
  std::string problem(const std::vector<int>& corners) const { return polygon_problem(corners, polygon_count_); }

  // Adds a polygon that problem() accepted, as the fan (a,b,c), (a,c,d), ...
  void add(const std::vector<int>& corners) {
    for (std::size_t i = 1; i + 1 < corners.size(); ++i) {
      triangles_.insert(triangles_.end(), {corners[0], corners[i], corners[i + 1]});
      polygon_of_triangle_.push_back(polygon_count_);
    }
    ++polygon_count_;
  }

  int polygon_count() const { return polygon_count_; }

  void move_into(MeshData& mesh) {
    const Eigen::Index rows = static_cast<Eigen::Index>(polygon_of_triangle_.size());
    mesh.F = Eigen::Map<const MatrixX3i>(triangles_.data(), rows, 3);
    mesh.polygon_of_triangle = std::move(polygon_of_triangle_);
    mesh.polygon_count = polygon_count_;
  }

 private:
  std::vector<int> triangles_;  // 3 ids per triangle
  std::vector<int> polygon_of_triangle_;
  int polygon_count_ = 0;
};

// ------------------------------------------------------------------------------------------------
// gzip

bool ends_with_ignoring_case(std::string_view text, std::string_view suffix) {
  if (text.size() < suffix.size()) return false;
  return std::equal(suffix.begin(), suffix.end(), text.end() - suffix.size(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
  });
}

// Decompresses a whole gzip file, including several members back to back (what `cat a.gz b.gz`
// gives, and what gzip itself accepts); zero padding after the last member is ignored like gzip does.
std::string gunzip(const std::string& compressed, const std::string& path) {
  if (compressed.empty()) return {};
  z_stream stream{};
  if (inflateInit2(&stream, 16 + MAX_WBITS) != Z_OK) fail(path, "cannot initialise zlib");
  const std::unique_ptr<z_stream, int (*)(z_streamp)> end_stream(&stream, inflateEnd);

  std::string out(3 * compressed.size() + (1 << 16), '\0');  // grows when text compresses better
  std::size_t in_pos = 0;
  std::size_t out_pos = 0;
  constexpr std::size_t kMaxChunk = std::numeric_limits<uInt>::max();  // zlib counts in uInt
  for (;;) {
    if (out_pos == out.size()) out.resize(2 * out.size());
    const std::size_t in_chunk = std::min(compressed.size() - in_pos, kMaxChunk);
    const std::size_t out_chunk = std::min(out.size() - out_pos, kMaxChunk);
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + in_pos));
    stream.avail_in = static_cast<uInt>(in_chunk);
    stream.next_out = reinterpret_cast<Bytef*>(&out[out_pos]);
    stream.avail_out = static_cast<uInt>(out_chunk);
    const int status = inflate(&stream, Z_NO_FLUSH);
    in_pos += in_chunk - stream.avail_in;
    out_pos += out_chunk - stream.avail_out;
    if (status == Z_STREAM_END) {
      const bool only_padding = std::all_of(compressed.begin() + in_pos, compressed.end(),
                                            [](char c) { return c == '\0'; });
      if (only_padding) break;
      inflateReset(&stream);  // another member follows
    } else if (status == Z_BUF_ERROR || status == Z_OK) {
      // No progress with all input consumed means the stream stops in the middle.
      if (status == Z_BUF_ERROR && in_pos == compressed.size() && stream.avail_out > 0) {
        fail(path, "truncated gzip data (ends at byte " + std::to_string(compressed.size()) + ")");
      }
    } else {
      fail(path, "corrupt gzip data near byte " + std::to_string(in_pos) + " (" +
                     (stream.msg ? stream.msg : "zlib error " + std::to_string(status)) + ")");
    }
  }
  out.resize(out_pos);
  return out;
}

// ------------------------------------------------------------------------------------------------
// PLY

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

bool parse_ply_type(std::string_view name, PlyType& type) {
  struct Entry {
    const char* old_name;
    const char* new_name;
    PlyType type;
  };
  static const Entry kTypes[] = {
      {"char", "int8", PlyType::kInt8},        {"uchar", "uint8", PlyType::kUInt8},
      {"short", "int16", PlyType::kInt16},     {"ushort", "uint16", PlyType::kUInt16},
      {"int", "int32", PlyType::kInt32},       {"uint", "uint32", PlyType::kUInt32},
      {"float", "float32", PlyType::kFloat32}, {"double", "float64", PlyType::kFloat64},
  };
  for (const Entry& entry : kTypes) {
    if (name == entry.old_name || name == entry.new_name) {
      type = entry.type;
      return true;
    }
  }
  return false;
}

std::size_t ply_type_size(PlyType type) {
  switch (type) {
    case PlyType::kInt8: case PlyType::kUInt8: return 1;
    case PlyType::kInt16: case PlyType::kUInt16: return 2;
    case PlyType::kInt32: case PlyType::kUInt32: case PlyType::kFloat32: return 4;
    case PlyType::kFloat64: return 8;
  }
  return 0;
}

bool is_integer_type(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType type = PlyType::kFloat32;        // the value type (list items for a list)
  PlyType count_type = PlyType::kUInt8;    // lists only
};

struct PlyElement {
  std::string name;
  unsigned long long count = 0;
  std::vector<PlyProperty> properties;
  std::size_t line = 0;  // header line, for messages
};

enum class PlyFormat { kUnknown, kAscii, kBinaryLittleEndian, kBinaryBigEndian };

// What the body reader must pick out of the elements.
struct PlyLayout {
  std::size_t vertex_element = 0;
  std::size_t face_element = 0;
  std::vector<int> axis_of_property;  // per vertex property: 0, 1, 2 for x, y, z, else -1
  std::size_t index_property = 0;     // the face element's vertex_indices list
};

// Reads ASCII PLY data: one element per line, values separated by whitespace.
class PlyAsciiSource {
 public:
  explicit PlyAsciiSource(TextScanner& in) : in_(in) {}

  void begin(const PlyElement& element, unsigned long long index) {
    element_ = &element;
    index_ = index;
    if (!in_.next_content_line()) {
      in_.fail("file ends after " + std::to_string(index) + " of " + std::to_string(element.count) +
               " '" + element.name + "' elements (truncated?)");
    }
  }
  void end() {
    std::string_view token;
    if (in_.next_token(token)) fail("unexpected extra value " + quoted(token) + " for " + where());
  }
  double read_double(PlyType) { return in_.number(token()); }
  long long read_integer(PlyType) { return in_.integer(token()); }
  void skip(PlyType) { token(); }
  void skip_list(PlyType, long long count) {
    for (long long i = 0; i < count; ++i) token();  // ends at the end of the line at the latest
  }
  [[noreturn]] void fail(const std::string& message) const { in_.fail(message); }
  std::string where() const { return element_->name + " " + std::to_string(index_); }

 private:
  std::string_view token() {
    std::string_view token;
    if (!in_.next_token(token)) fail("too few values for " + where() + " (the header lists more properties)");
    return token;
  }

  TextScanner& in_;
  const PlyElement* element_ = nullptr;
  unsigned long long index_ = 0;
};

// Reads binary PLY data of either byte order; every read is bounds-checked.
class PlyBinarySource {
 public:
  PlyBinarySource(std::string_view data, std::size_t offset, bool big_endian, const std::string& name)
      : data_(reinterpret_cast<const unsigned char*>(data.data())),
        size_(data.size()),
        pos_(offset),
        swap_(big_endian != host_is_big_endian()),
        name_(name) {}

  void begin(const PlyElement& element, unsigned long long index) {
    element_ = &element;
    index_ = index;
    start_ = pos_;
  }
  void end() {}

  double read_double(PlyType type) {
    switch (type) {
      case PlyType::kFloat32: return bit_cast_from<float>(load<std::uint32_t>());
      case PlyType::kFloat64: return bit_cast_from<double>(load<std::uint64_t>());
      default: return static_cast<double>(read_integer(type));
    }
  }

  long long read_integer(PlyType type) {
    switch (type) {
      case PlyType::kInt8: return static_cast<std::int8_t>(load<std::uint8_t>());
      case PlyType::kUInt8: return load<std::uint8_t>();
      case PlyType::kInt16: return static_cast<std::int16_t>(load<std::uint16_t>());
      case PlyType::kUInt16: return load<std::uint16_t>();
      case PlyType::kInt32: return static_cast<std::int32_t>(load<std::uint32_t>());
      case PlyType::kUInt32: return load<std::uint32_t>();
      default: return 0;  // the header check allows only integer types here
    }
  }

  void skip(PlyType type) { skip_bytes(ply_type_size(type)); }

  void skip_list(PlyType type, long long count) {
    const std::size_t item = ply_type_size(type);
    if (static_cast<unsigned long long>(count) > (size_ - pos_) / item) truncated();
    pos_ += static_cast<std::size_t>(count) * item;
  }

  [[noreturn]] void fail(const std::string& message) const {
    ::trivcon::fail(name_, message + " (at byte " + std::to_string(start_) + ")");
  }
  std::string where() const { return element_->name + " " + std::to_string(index_); }

 private:
  static bool host_is_big_endian() {
    const std::uint16_t probe = 1;
    unsigned char first;
    std::memcpy(&first, &probe, 1);
    return first == 0;
  }

  template <class To, class From>
  static To bit_cast_from(From bits) {
    static_assert(sizeof(To) == sizeof(From));
    To value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

  template <class Unsigned>
  Unsigned load() {
    if (size_ - pos_ < sizeof(Unsigned)) truncated();
    Unsigned value;
    std::memcpy(&value, data_ + pos_, sizeof value);  // memcpy: the data is not aligned
    pos_ += sizeof value;
    if (swap_) {
      if constexpr (sizeof value == 2) value = __builtin_bswap16(value);
      if constexpr (sizeof value == 4) value = __builtin_bswap32(value);
      if constexpr (sizeof value == 8) value = __builtin_bswap64(value);
    }
    return value;
  }

  void skip_bytes(std::size_t count) {
    if (size_ - pos_ < count) truncated();
    pos_ += count;
  }

  [[noreturn]] void truncated() const {
    ::trivcon::fail(name_, "truncated binary data at byte " + std::to_string(pos_) + " (" + element_->name +
                               " " + std::to_string(index_) + " of " + std::to_string(element_->count) + ")");
  }

  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_;
  bool swap_;
  const std::string& name_;
  const PlyElement* element_ = nullptr;
  unsigned long long index_ = 0;
  std::size_t start_ = 0;  // where the current element starts
};

// One loop over all elements for both encodings; `Source` hides how values are stored.
template <class Source>
void read_ply_body(Source& source, const std::vector<PlyElement>& elements, const PlyLayout& layout,
                   MeshData& mesh, FaceCollector& faces) {
  const long long vertex_count = mesh.V.rows();
  std::vector<int> corners;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const PlyElement& element = elements[e];
    const bool is_vertex = e == layout.vertex_element;
    const bool is_face = e == layout.face_element;
    for (unsigned long long i = 0; i < element.count; ++i) {
      source.begin(element, i);
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (is_vertex && layout.axis_of_property[p] >= 0) {
          const double value = source.read_double(property.type);
          if (!std::isfinite(value)) source.fail(non_finite_message(static_cast<long long>(i), value));
          mesh.V(static_cast<Eigen::Index>(i), layout.axis_of_property[p]) = value;
        } else if (property.is_list) {
          const long long count = source.read_integer(property.count_type);
          if (count < 0) source.fail("negative list length " + std::to_string(count) + " in " + source.where());
          if (!(is_face && p == layout.index_property)) {
            source.skip_list(property.type, count);
            continue;
          }
          corners.clear();
          for (long long j = 0; j < count; ++j) {  // bounded by the data: every read is checked
            const long long index = source.read_integer(property.type);
            if (index < 0 || index >= vertex_count) {
              source.fail(out_of_range_message(index, vertex_count) + " in " + source.where());
            }
            corners.push_back(static_cast<int>(index));
          }
          const std::string problem = faces.problem(corners);
          if (!problem.empty()) source.fail(problem);
          faces.add(corners);
        } else {
          source.skip(property.type);
        }
      }
      source.end();
    }
  }
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// Readers

MeshData read_obj(const std::string& buffer, const std::string& name) {
  if (buffer.empty()) fail(name, "empty file");
  TextScanner in(buffer, name, /*hash_comments=*/true, /*continuation=*/true);
  std::vector<double> coordinates;
  FaceCollector faces;
  std::vector<int> corners;
  // OBJ lets a face name a vertex defined further down, so an index above the vertices read so far
  // can only be judged at the end. We keep those that raise the running maximum: if any index is
  // out of range, the first such one in the file is among them.
  struct ForwardReference {
    long long index;
    std::size_t line;
  };
  std::vector<ForwardReference> forward_references;
  long long max_forward = -1;

  std::string_view token;
  while (in.next_line()) {
    if (!in.next_token(token)) continue;
    const long long vertex_count = static_cast<long long>(coordinates.size() / 3);
    if (token == "v") {
      if (vertex_count == kMaxCount) in.fail("too many vertices");
      for (int axis = 0; axis < 3; ++axis) {
        if (!in.next_token(token)) in.fail("expected 3 coordinates for vertex " + std::to_string(vertex_count));
        const double value = in.number(token);
        if (!std::isfinite(value)) in.fail(non_finite_message(vertex_count, value));
        coordinates.push_back(value);
      }
      // Whatever follows (w, or the r g b some writers append) is not ours.
    } else if (token == "f" || token == "fo") {  // "fo" is the old spelling of "f"
      if (faces.polygon_count() == kMaxCount) in.fail("too many faces");
      corners.clear();
      while (in.next_token(token)) {
        long long index;  // "v", "v/vt", "v/vt/vn" or "v//vn": only v matters here
        if (!parse_integer(token.substr(0, token.find('/')), index)) in.fail("malformed face corner " + quoted(token));
        long long id;
        if (index > 0) {
          if (index > kMaxCount) in.fail("face index " + std::to_string(index) + " out of range (too large for any file)");
          id = index - 1;
          if (id >= vertex_count && id > max_forward) {
            max_forward = id;
            forward_references.push_back({index, in.line_number()});
          }
        } else if (index < 0) {  // relative: -1 is the last vertex defined so far
          id = vertex_count + index;
          if (id < 0) {
            in.fail("face index " + std::to_string(index) + " out of range (" + std::to_string(vertex_count) +
                    " vertices defined so far)");
          }
        } else {
          in.fail("face index 0 is invalid (OBJ indices start at 1)");
        }
        corners.push_back(static_cast<int>(id));
      }
      const std::string problem = faces.problem(corners);
      if (!problem.empty()) in.fail(problem);
      faces.add(corners);
    }
    // Everything else (vt vn vp o g s usemtl mtllib l p, free-form geometry) carries nothing we use.
  }

  const long long vertex_count = static_cast<long long>(coordinates.size() / 3);
  for (const ForwardReference& reference : forward_references) {
    if (reference.index > vertex_count) {
      fail_at_line(name, reference.line, out_of_range_message(reference.index, vertex_count));
    }
  }
  if (faces.polygon_count() == 0) fail(name, "no faces");

  MeshData mesh;
  mesh.V = Eigen::Map<const MatrixX3d>(coordinates.data(), vertex_count, 3);
  faces.move_into(mesh);
  mesh.format = "obj";
  return mesh;
}

MeshData read_off(const std::string& buffer, const std::string& name) {
  if (buffer.empty()) fail(name, "empty file");
  TextScanner in(buffer, name, /*hash_comments=*/true);
  if (!in.next_content_line()) fail(name, "no OFF header (only comments and blank lines)");

  // Header: [ST][C][N]OFF, optionally followed by the counts on the same line ("OFF 8 12 0"); the
  // keyword itself is optional in Geomview's definition, so a file may start with the counts.
  std::string_view token;
  in.next_token(token);
  const std::size_t keyword = token.rfind("OFF");
  if (keyword != std::string_view::npos && keyword + 3 == token.size()) {
    const std::string_view prefix = token.substr(0, keyword);
    if (prefix.find_first_not_of("STCN") != std::string_view::npos) {
      in.fail("unsupported OFF variant " + quoted(token) + " (only 3-D [ST][C][N]OFF is supported)");
    }
    if (!in.next_token(token)) {
      if (!in.next_content_line()) in.fail("file ends before the vertex and face counts");
      in.next_token(token);
    } else if (token == "BINARY") {
      in.fail("binary OFF is not supported");
    }
  } else {
    long long ignored;
    if (!parse_integer(token, ignored)) in.fail("not an OFF file: expected 'OFF', found " + quoted(token));
  }
  const long long vertex_count = in.integer(token);
  if (!in.next_token(token)) in.fail("expected the face count after the vertex count");
  const long long face_count = in.integer(token);  // an edge count may follow; it is not used
  if (vertex_count < 0 || face_count < 0) in.fail("negative vertex or face count");
  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line 8 ("3 0 1 2\n"). A count that
  // could not fit even with the rest of the file to itself means a corrupt header (or a file cut
  // short); it is caught here, before anything is allocated by it. Each count is checked on its own
  // so that a file cut in the faces is reported at the line where it ends.
  const unsigned long long bytes_left = in.bytes_left() + 1;  // the last line may lack its newline
  const auto check_count = [&](long long count, unsigned long long min_bytes, const char* what) {
    if (static_cast<unsigned long long>(count) > bytes_left / min_bytes) {
      in.fail("header announces " + std::to_string(count) + " " + what + " but the file has only " +
              std::to_string(buffer.size()) + " bytes (truncated file?)");
    }
  };
  check_count(vertex_count, 6, "vertices");
  check_count(face_count, 8, "faces");
  if (vertex_count > kMaxCount || face_count > kMaxCount) {
    in.fail("too many vertices or faces (" + std::to_string(vertex_count) + ", " + std::to_string(face_count) + ")");
  }
  if (face_count == 0) fail(name, "no faces");

  MeshData mesh;
  mesh.V.resize(vertex_count, 3);
  for (long long v = 0; v < vertex_count; ++v) {
    if (!in.next_content_line()) {
      in.fail("file ends after " + std::to_string(v) + " of " + std::to_string(vertex_count) + " vertices (truncated?)");
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (!in.next_token(token)) in.fail("expected 3 coordinates for vertex " + std::to_string(v));
      const double value = in.number(token);
      if (!std::isfinite(value)) in.fail(non_finite_message(v, value));
      mesh.V(v, axis) = value;
    }
    // The rest of the line (COFF colour, NOFF normal, STOFF texture coordinates) is not ours.
  }

  FaceCollector faces;
  faces.reserve_triangles(static_cast<std::size_t>(face_count));
  std::vector<int> corners;
  for (long long f = 0; f < face_count; ++f) {
    if (!in.next_content_line()) {
      in.fail("file ends after " + std::to_string(f) + " of " + std::to_string(face_count) + " faces (truncated?)");
    }
    in.next_token(token);
    const long long corner_count = in.integer(token);
    corners.clear();
    for (long long c = 0; c < corner_count; ++c) {  // a bogus count runs out of tokens, no allocation
      if (!in.next_token(token)) {
        in.fail("face " + std::to_string(f) + " announces " + std::to_string(corner_count) + " corners but lists " +
                std::to_string(c));
      }
      const long long index = in.integer(token);
      if (index < 0 || index >= vertex_count) in.fail(out_of_range_message(index, vertex_count));
      corners.push_back(static_cast<int>(index));
    }
    // A face colour may follow; it is not ours.
    const std::string problem = faces.problem(corners);
    if (!problem.empty()) in.fail(problem);
    faces.add(corners);
  }
  // Anything after the announced faces is ignored, as other OFF readers do.
  faces.move_into(mesh);
  mesh.format = "off";
  return mesh;
}

MeshData read_ply(const std::string& buffer, const std::string& name) {
  if (buffer.empty()) fail(name, "empty file");
  TextScanner in(buffer, name, /*hash_comments=*/false);
  std::string_view token;
  if (!in.next_line() || !in.next_token(token) || token != "ply" || !in.at_line_end()) {
    fail(name, "not a PLY file (the first line is not 'ply')");
  }

  // Header.
  PlyFormat format = PlyFormat::kUnknown;
  std::vector<PlyElement> elements;
  bool header_ended = false;
  while (in.next_line()) {
    if (!in.next_token(token)) continue;
    if (token == "comment" || token == "obj_info") continue;
    if (token == "end_header") {
      header_ended = true;
      break;
    }
    if (token == "format") {
      if (!in.next_token(token)) in.fail("missing PLY format");
      if (token == "ascii") {
        format = PlyFormat::kAscii;
      } else if (token == "binary_little_endian") {
        format = PlyFormat::kBinaryLittleEndian;
      } else if (token == "binary_big_endian") {
        format = PlyFormat::kBinaryBigEndian;
      } else {
        in.fail("unsupported PLY format " + quoted(token));
      }
    } else if (token == "element") {
      PlyElement element;
      element.line = in.line_number();
      if (!in.next_token(token)) in.fail("element without a name");
      element.name = token;
      long long count;
      if (!in.next_token(token) || !parse_integer(token, count) || count < 0) {
        in.fail("element '" + element.name + "' needs a count, found " + quoted(token));
      }
      element.count = static_cast<unsigned long long>(count);
      elements.push_back(std::move(element));
    } else if (token == "property") {
      if (elements.empty()) in.fail("property before any element");
      PlyProperty property;
      if (!in.next_token(token)) in.fail("property without a type");
      if (token == "list") {
        property.is_list = true;
        if (!in.next_token(token) || !parse_ply_type(token, property.count_type)) {
          in.fail("unknown PLY list count type " + quoted(token));
        }
        if (!is_integer_type(property.count_type)) in.fail("list count type must be an integer type");
        if (!in.next_token(token)) in.fail("list property without an item type");
      }
      if (!parse_ply_type(token, property.type)) in.fail("unknown PLY type " + quoted(token));
      if (!in.next_token(token)) in.fail("property without a name");
      property.name = token;
      elements.back().properties.push_back(std::move(property));
    } else {
      in.fail("unexpected PLY header line starting with " + quoted(token));
    }
  }
  if (!header_ended) fail(name, "PLY header has no 'end_header' line");
  if (format == PlyFormat::kUnknown) fail(name, "PLY header has no 'format' line");

  // Find vertex x, y, z and the face index list.
  PlyLayout layout;
  const auto find_element = [&](const char* wanted) {
    std::size_t found = elements.size();
    for (std::size_t e = 0; e < elements.size(); ++e) {
      if (elements[e].name != wanted) continue;
      if (found != elements.size()) fail_at_line(name, elements[e].line, std::string("second '") + wanted + "' element");
      found = e;
    }
    return found;
  };
  layout.vertex_element = find_element("vertex");
  layout.face_element = find_element("face");
  if (layout.vertex_element == elements.size()) fail(name, "PLY header declares no 'vertex' element");
  if (layout.face_element == elements.size() || elements[layout.face_element].count == 0) fail(name, "no faces");
  const PlyElement& vertex_element = elements[layout.vertex_element];
  const PlyElement& face_element = elements[layout.face_element];
  layout.axis_of_property.assign(vertex_element.properties.size(), -1);
  for (int axis = 0; axis < 3; ++axis) {
    const char* axis_name = axis == 0 ? "x" : axis == 1 ? "y" : "z";
    std::size_t found = vertex_element.properties.size();
    for (std::size_t p = 0; p < vertex_element.properties.size(); ++p) {
      if (vertex_element.properties[p].name == axis_name) found = p;
    }
    if (found == vertex_element.properties.size() || vertex_element.properties[found].is_list) {
      fail_at_line(name, vertex_element.line, std::string("vertex element has no scalar property '") + axis_name + "'");
    }
    layout.axis_of_property[found] = axis;
  }
  layout.index_property = face_element.properties.size();
  for (std::size_t p = 0; p < face_element.properties.size(); ++p) {
    const PlyProperty& property = face_element.properties[p];
    if (property.name == "vertex_indices" || property.name == "vertex_index") layout.index_property = p;
  }
  if (layout.index_property == face_element.properties.size() || !face_element.properties[layout.index_property].is_list) {
    fail_at_line(name, face_element.line, "face element has no list property 'vertex_indices'");
  }
  if (!is_integer_type(face_element.properties[layout.index_property].type)) {
    fail_at_line(name, face_element.line, "face vertex_indices must have an integer item type");
  }

  // Every element takes some minimum number of bytes (ASCII: a character and a separator per value;
  // binary: its scalars and list counts; a face also at least 3 indices). A count that could not
  // fit even with all the data to itself means a corrupt header (or a file cut short); it is caught
  // here, before anything is allocated by it. Each element is checked on its own so that a file
  // cut further on is reported at the exact byte or line where it ends.
  const bool ascii = format == PlyFormat::kAscii;
  const std::size_t data_offset = in.next_offset();
  const unsigned long long data_bytes = buffer.size() - data_offset + (ascii ? 1 : 0);  // +1: no final newline
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const PlyElement& element = elements[e];
    if (element.count == 0) continue;
    unsigned long long minimum = 0;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      const unsigned long long items = e == layout.face_element && p == layout.index_property ? 3 : 0;
      minimum += ascii ? 2 * (1 + items)
                       : property.is_list ? ply_type_size(property.count_type) + items * ply_type_size(property.type)
                                          : ply_type_size(property.type);
    }
    if (minimum == 0) fail_at_line(name, element.line, "element '" + element.name + "' has no properties");
    if (element.count > data_bytes / minimum) {
      fail_at_line(name, element.line, "header announces " + std::to_string(element.count) + " '" + element.name +
                                           "' elements but the file has only " +
                                           std::to_string(buffer.size() - data_offset) +
                                           " bytes after the header (truncated file?)");
    }
  }
  if (vertex_element.count > static_cast<unsigned long long>(kMaxCount) ||
      face_element.count > static_cast<unsigned long long>(kMaxCount)) {
    fail(name, "too many vertices or faces (" + std::to_string(vertex_element.count) + ", " +
                   std::to_string(face_element.count) + ")");
  }

  MeshData mesh;
  mesh.V.resize(static_cast<Eigen::Index>(vertex_element.count), 3);
  FaceCollector faces;
  faces.reserve_triangles(face_element.count);
  if (ascii) {
    PlyAsciiSource source(in);
    read_ply_body(source, elements, layout, mesh, faces);
    mesh.format = "ply-ascii";
  } else {
    const bool big_endian = format == PlyFormat::kBinaryBigEndian;
    PlyBinarySource source(buffer, data_offset, big_endian, name);
    read_ply_body(source, elements, layout, mesh, faces);
    mesh.format = big_endian ? "ply-binary-be" : "ply-binary-le";
  }
  faces.move_into(mesh);
  return mesh;
}

std::string read_file_bytes(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw Error("cannot open '" + path + "': " + std::strerror(errno));
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(file, std::fclose);
  std::error_code ignored;
  const std::uintmax_t size_hint = std::filesystem::file_size(path, ignored);
  std::string bytes(ignored ? std::size_t{1} << 16 : static_cast<std::size_t>(size_hint) + 1, '\0');
  std::size_t used = 0;
  for (;;) {
    if (used == bytes.size()) bytes.resize(2 * bytes.size());
    const std::size_t wanted = bytes.size() - used;
    const std::size_t got = std::fread(&bytes[used], 1, wanted, file);
    used += got;
    if (got < wanted) break;
  }
  if (std::ferror(file)) throw Error("cannot read '" + path + "': " + std::strerror(errno));
  bytes.resize(used);
  if (ends_with_ignoring_case(path, ".gz")) return gunzip(bytes, path);
  return bytes;
}

MeshData read_mesh(const std::string& path) {
  std::string_view stem = path;
  if (ends_with_ignoring_case(stem, ".gz")) stem.remove_suffix(3);
  if (ends_with_ignoring_case(stem, ".obj")) return read_obj(read_file_bytes(path), path);
  if (ends_with_ignoring_case(stem, ".off")) return read_off(read_file_bytes(path), path);
  if (ends_with_ignoring_case(stem, ".ply")) return read_ply(read_file_bytes(path), path);
  throw Error("cannot read '" + path +
              "': unknown mesh format (supported: .obj, .off, .ply, each optionally followed by .gz)");
}

// ------------------------------------------------------------------------------------------------
// Writers

namespace {

// Refuses what the readers would reject, so that everything written reads back identically.
void check_writable(const std::string& path, const MatrixX3d& V, const MatrixX3i& F) {
  const auto refuse = [&](const std::string& why) { throw Error("cannot write '" + path + "': " + why); };
  if (V.rows() > kMaxCount) refuse("too many vertices");
  if (F.rows() == 0) refuse("mesh has no faces");
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(V(v, axis))) refuse(non_finite_message(v, V(v, axis)));
    }
  }
  std::vector<int> corners(3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      corners[c] = F(f, c);
      if (corners[c] < 0 || corners[c] >= V.rows()) {
        refuse("face " + std::to_string(f) + " has vertex index " + std::to_string(corners[c]) +
               " out of range (mesh has " + std::to_string(V.rows()) + " vertices)");
      }
    }
    const std::string problem = polygon_problem(corners, f);
    if (!problem.empty()) refuse(problem);
  }
}

template <class T>
void append_number(std::string& out, T value) {
  char digits[32];
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  out.append(digits, result.ptr);
}

// %.17g: 17 significant digits always read back to the same double.
void append_coordinate(std::string& out, double value) {
  char digits[32];
  const auto result = std::to_chars(digits, digits + sizeof digits, value, std::chars_format::general, 17);
  out.append(digits, result.ptr);
}

template <class T>
void append_little_endian(std::string& out, T value) {
  static_assert(std::is_integral_v<T> || std::is_floating_point_v<T>);
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof bytes);
  const std::uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  if (first == 0) std::reverse(bytes, bytes + sizeof bytes);  // big-endian host
  out.append(reinterpret_cast<const char*>(bytes), sizeof bytes);
}

}  // namespace

void write_obj(const std::string& path, const MatrixX3d& V, const MatrixX3i& F) {
  check_writable(path, V, F);
  std::string text = "# trivcon mesh: " + std::to_string(V.rows()) + " vertices, " + std::to_string(F.rows()) + " faces\n";
  text.reserve(text.size() + 64 * V.rows() + 24 * F.rows());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    text += 'v';
    for (int axis = 0; axis < 3; ++axis) {
      text += ' ';
      append_coordinate(text, V(v, axis));
    }
    text += '\n';
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    text += 'f';
    for (int c = 0; c < 3; ++c) {
      text += ' ';
      append_number(text, F(f, c) + 1);
    }
    text += '\n';
  }
  write_file_atomically(path, [&](std::ostream& out) { out.write(text.data(), static_cast<std::streamsize>(text.size())); });
}

void write_ply(const std::string& path, const MatrixX3d& V, const MatrixX3i& F) {
  check_writable(path, V, F);
  std::string data =
      "ply\nformat binary_little_endian 1.0\ncomment written by trivcon\nelement vertex " + std::to_string(V.rows()) +
      "\nproperty double x\nproperty double y\nproperty double z\nelement face " + std::to_string(F.rows()) +
      "\nproperty list uchar int vertex_indices\nend_header\n";
  data.reserve(data.size() + 24 * V.rows() + 13 * F.rows());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    for (int axis = 0; axis < 3; ++axis) append_little_endian(data, V(v, axis));
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    data += static_cast<char>(3);
    for (int c = 0; c < 3; ++c) append_little_endian<std::int32_t>(data, F(f, c));
  }
  write_file_atomically(path, [&](std::ostream& out) { out.write(data.data(), static_cast<std::streamsize>(data.size())); });
}

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& fill) {
  const auto refuse = [&](const std::string& why) { throw Error("cannot write '" + path + "': " + why); };
  // The temporary lives beside the target so that rename() stays on one file system (atomic).
  // O_EXCL with pid + counter gives a fresh name even with several threads or processes.
  static std::atomic<unsigned> counter{0};
  std::string temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) refuse(std::strerror(errno));
  ::close(fd);

  struct RemoveUnlessKept {
    const std::string& file;
    bool keep = false;
    ~RemoveUnlessKept() {
      if (!keep) std::remove(file.c_str());
    }
  } cleanup{temporary};

  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) refuse(std::strerror(errno));
    fill(out);
    errno = 0;
    out.flush();
    const bool wrote = static_cast<bool>(out);
    out.close();
    if (!wrote || out.fail()) refuse(errno ? std::strerror(errno) : "write failed");
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) refuse(std::strerror(errno));
  cleanup.keep = true;
}

}  // namespace trivcon
