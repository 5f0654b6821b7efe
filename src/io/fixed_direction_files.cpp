// SPDX-License-Identifier: MIT
// trivcon/constraints.h: the text of fixed directions: --fix specs and files of 'FACE x y z' / 'FACE angle=A'.
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/readers.h"
#include "io/text_scanner.h"
#include "trivcon/constraints.h"
#include "trivcon/error.h"
#include "trivcon/io.h"

namespace trivcon {

namespace {

int parse_face(const std::string& text, const Topology& t, const std::string& where, const FaceIdMap& face_id) {
  long long f = 0;
  if (!io::parse_integer(text, f)) throw Error(where + ": malformed face id '" + text + "'");
  if (face_id) {
    if (f < std::numeric_limits<int>::min() || f > std::numeric_limits<int>::max())
      throw Error(where + ": face " + text + " out of range");
    try {
      return face_id(static_cast<int>(f));
    } catch (const Error& e) {
      throw Error(where + ": " + e.what());
    }
  }
  if (f < 0 || f >= t.num_faces)
    throw Error(where + ": face " + text + " out of range (mesh has " + std::to_string(t.num_faces) + " faces)");
  return static_cast<int>(f);
}

double parse_number(const std::string& text, const std::string& where) {
  double v = 0;
  if (!io::parse_double(text, v)) throw Error(where + ": malformed number '" + text + "'");
  if (!std::isfinite(v)) throw Error(where + ": number '" + text + "' is not finite");
  return v;
}

// "angle=A" or three numbers → angle in the face's frame.
double parse_direction(const std::vector<std::string>& fields, int face, const Geometry& g, const std::string& where) {
  if (fields.size() == 1 && fields[0].rfind("angle=", 0) == 0) return parse_number(fields[0].substr(6), where);
  if (fields.size() != 3) throw Error(where + ": expected 'x y z' or 'angle=A' after the face id");
  const Eigen::Vector3d d(parse_number(fields[0], where), parse_number(fields[1], where), parse_number(fields[2], where));
  try {
    return fixed_angle_from_direction(g, face, d);
  } catch (const Error& e) {
    throw Error(where + ": " + e.what());
  }
}

void insert_fixed(std::map<int, double>& fixed, int face, double angle, const std::string& where) {
  if (!fixed.emplace(face, angle).second) throw Error(where + ": face " + std::to_string(face) + " is fixed twice");
}

}  // namespace

void read_fixed_directions(const std::string& path, const Topology& t, const Geometry& g, std::map<int, double>& fixed,
                           const FaceIdMap& face_id) {
  io::read_fixed_directions_from(read_file_bytes(path), path, t, g, fixed, face_id);
}

void io::read_fixed_directions_from(const std::string& bytes, const std::string& path, const Topology& t, const Geometry& g,
                                        std::map<int, double>& fixed, const FaceIdMap& face_id) {
  std::istringstream in(bytes);
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const std::string where = path + ":" + std::to_string(line_no);
    std::istringstream fields(line.substr(0, line.find('#')));
    std::vector<std::string> tokens;
    for (std::string tok; fields >> tok;) tokens.push_back(tok);
    if (tokens.empty()) continue;
    const int face = parse_face(tokens[0], t, where, face_id);
    insert_fixed(fixed, face, parse_direction({tokens.begin() + 1, tokens.end()}, face, g, where), where);
  }
}

void add_fixed_direction(const std::string& spec, const Topology& t, const Geometry& g, std::map<int, double>& fixed,
                         const FaceIdMap& face_id) {
  const std::string where = "--fix " + spec;
  const size_t colon = spec.find(':');
  if (colon == std::string::npos) throw Error(where + ": expected F:x,y,z or F:angle=A");
  const int face = parse_face(spec.substr(0, colon), t, where, face_id);
  std::vector<std::string> tokens;
  std::istringstream rest(spec.substr(colon + 1));
  for (std::string tok; std::getline(rest, tok, ',');) tokens.push_back(tok);
  insert_fixed(fixed, face, parse_direction(tokens, face, g, where), where);
}

}  // namespace trivcon
