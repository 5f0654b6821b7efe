// SPDX-License-Identifier: MIT
// src/io/read_ply.cpp: the PLY reader of trivcon/io.h (ascii, binary_little_endian, binary_big_endian): the
// header's types, elements and properties, and one body loop over both encodings (PlyAsciiSource,
// PlyBinarySource). Why hand-written, and the scanner the header and ASCII data are read with:
// src/io/text_scanner.h.
#include "trivcon/io.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh_rules.h"
#include "io/text_scanner.h"

namespace trivcon {

using namespace io;

namespace {

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

bool parse_ply_type(std::string_view name, PlyType& type) {
  struct Entry {
    const char* old_name;
    const char* new_name;
    PlyType type;
  };
  static const Entry kTypes[] = {
      {"char", "int8", PlyType::kInt8},        {"uchar", "uint8", PlyType::kUInt8},      {"short", "int16", PlyType::kInt16},
      {"ushort", "uint16", PlyType::kUInt16},  {"int", "int32", PlyType::kInt32},        {"uint", "uint32", PlyType::kUInt32},
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
    case PlyType::kInt8:
    case PlyType::kUInt8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUInt16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUInt32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool is_integer_type(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType type = PlyType::kFloat32;      // the value type (list items for a list)
  PlyType count_type = PlyType::kUInt8;  // lists only
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
      in_.fail("file ends after " + std::to_string(index) + " of " + std::to_string(element.count) + " '" + element.name +
               "' elements (truncated?)");
    }
  }
  void end() {
    std::string_view token;
    if (in_.next_token(token)) fail("unexpected extra value " + quoted(token) + " for " + where());
  }
  double read_double(PlyType) { return in_.number(token()); }
  long long read_integer(PlyType) { return in_.integer(token()); }
  void skip(PlyType) { token(); }
  // The list's values follow on the element's line; a count beyond them ends there, at the latest.
  void begin_list(const PlyProperty&, long long count) {
    list_count_ = count;
    list_read_ = 0;
  }
  long long read_list_integer(const PlyProperty& property) {
    std::string_view token;
    if (!in_.next_token(token)) fail_list(property);
    ++list_read_;
    return in_.integer(token);
  }
  void skip_list(const PlyProperty& property, long long count) {
    begin_list(property, count);
    std::string_view token;
    for (long long i = 0; i < count; ++i, ++list_read_) {
      if (!in_.next_token(token)) fail_list(property);
    }
  }
  [[noreturn]] void fail(const std::string& message) const { in_.fail(message); }
  std::string where() const { return element_->name + " " + std::to_string(index_); }

 private:
  std::string_view token() {
    std::string_view token;
    if (!in_.next_token(token)) fail("too few values for " + where() + " (the header lists more properties)");
    return token;
  }

  [[noreturn]] void fail_list(const PlyProperty& property) const {
    fail(where() + " announces " + std::to_string(list_count_) + " '" + property.name + "' but lists " + std::to_string(list_read_));
  }

  TextScanner& in_;
  const PlyElement* element_ = nullptr;
  unsigned long long index_ = 0;
  long long list_count_ = 0, list_read_ = 0;
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
      case PlyType::kFloat32:
        return bit_cast_from<float>(load<std::uint32_t>());
      case PlyType::kFloat64:
        return bit_cast_from<double>(load<std::uint64_t>());
      default:
        return static_cast<double>(read_integer(type));
    }
  }

  long long read_integer(PlyType type) {
    switch (type) {
      case PlyType::kInt8:
        return static_cast<std::int8_t>(load<std::uint8_t>());
      case PlyType::kUInt8:
        return load<std::uint8_t>();
      case PlyType::kInt16:
        return static_cast<std::int16_t>(load<std::uint16_t>());
      case PlyType::kUInt16:
        return load<std::uint16_t>();
      case PlyType::kInt32:
        return static_cast<std::int32_t>(load<std::uint32_t>());
      case PlyType::kUInt32:
        return load<std::uint32_t>();
      default:
        return 0;  // the header check allows only integer types here
    }
  }

  void skip(PlyType type) { skip_bytes(ply_type_size(type)); }

  // A list's items must fit in the rest of the data; checked before any is read, so that a count of
  // billions is reported at once. The byte named is where the first item that is not there would start.
  void begin_list(const PlyProperty& property, long long count) {
    const std::size_t item = ply_type_size(property.type);
    const std::size_t left = size_ - pos_;
    if (static_cast<unsigned long long>(count) > left / item) {
      io::fail(name_, "truncated binary data at byte " + std::to_string(pos_ + left / item * item) + " (" + element_->name + " " +
                              std::to_string(index_) + " of " + std::to_string(element_->count) + "; its '" + property.name +
                              "' list claims " + std::to_string(count) + " items of " + std::to_string(item) + " bytes, but only " +
                              std::to_string(left) + " bytes follow the count)");
    }
  }
  long long read_list_integer(const PlyProperty& property) { return read_integer(property.type); }
  void skip_list(const PlyProperty& property, long long count) {
    begin_list(property, count);
    pos_ += static_cast<std::size_t>(count) * ply_type_size(property.type);
  }

  [[noreturn]] void fail(const std::string& message) const { io::fail(name_, message + " (at byte " + std::to_string(start_) + ")"); }
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
    io::fail(name_, "truncated binary data at byte " + std::to_string(pos_) + " (" + element_->name + " " + std::to_string(index_) +
                            " of " + std::to_string(element_->count) + ")");
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
void read_ply_body(Source& source, const std::vector<PlyElement>& elements, const PlyLayout& layout, MeshData& mesh, FaceCollector& faces) {
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
            source.skip_list(property, count);
            continue;
          }
          source.begin_list(property, count);
          corners.clear();
          for (long long j = 0; j < count; ++j) {  // bounded by the data: every read is checked
            const long long index = source.read_list_integer(property);
            if (index < 0 || index >= vertex_count) {
              source.fail(out_of_range_message(index, vertex_count) + " in " + source.where());
            }
            corners.push_back(static_cast<int>(index));
          }
          const std::string problem = faces.problem(corners, [&](const std::string& p) { source.fail(p); });
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
      minimum += ascii              ? 2 * (1 + items)
                 : property.is_list ? ply_type_size(property.count_type) + items * ply_type_size(property.type)
                                    : ply_type_size(property.type);
    }
    if (minimum == 0) fail_at_line(name, element.line, "element '" + element.name + "' has no properties");
    if (element.count > data_bytes / minimum) {
      const std::string plural = e == layout.vertex_element ? "vertices"
                                 : e == layout.face_element ? "faces"
                                                            : "'" + element.name + "' elements";
      const std::string singular = e == layout.vertex_element ? "a vertex" : e == layout.face_element ? "a face" : "an element";
      fail_at_line(name, element.line,
                   "header claims " + std::to_string(element.count) + " " + plural + ", but the file has only " +
                       std::to_string(buffer.size() - data_offset) + " bytes after the header (" + singular + " needs at least " +
                       std::to_string(minimum) + ")");
    }
  }
  if (vertex_element.count > static_cast<unsigned long long>(kMaxCount) ||
      face_element.count > static_cast<unsigned long long>(kMaxCount)) {
    fail(name, "too many vertices or faces (" + std::to_string(vertex_element.count) + ", " + std::to_string(face_element.count) + ")");
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

}  // namespace trivcon
