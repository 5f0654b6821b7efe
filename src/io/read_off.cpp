// SPDX-License-Identifier: MIT
// src/io/read_off.cpp: the Geomview OFF reader of trivcon/io.h (ASCII [ST][C][N]OFF, 3-D).
// Why hand-written, and the scanner it shares with the other text readers: src/io/text_scanner.h.
#include "trivcon/io.h"

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh_rules.h"
#include "io/text_scanner.h"

namespace trivcon {

using namespace io;

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
  const auto check_count = [&](long long count, unsigned long long min_bytes, const char* plural, const char* singular) {
    if (static_cast<unsigned long long>(count) > bytes_left / min_bytes) {
      in.fail("header claims " + std::to_string(count) + " " + plural + ", but the file has only " + std::to_string(in.bytes_left()) +
              " bytes after the header (" + singular + " needs at least " + std::to_string(min_bytes) + ")");
    }
  };
  check_count(vertex_count, 6, "vertices", "a vertex");
  check_count(face_count, 8, "faces", "a face");
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
        in.fail("face " + std::to_string(f) + " announces " + std::to_string(corner_count) + " corners but lists " + std::to_string(c));
      }
      const long long index = in.integer(token);
      if (index < 0 || index >= vertex_count) in.fail(out_of_range_message(index, vertex_count));
      corners.push_back(static_cast<int>(index));
    }
    // A face colour may follow; it is not ours.
    const std::string problem = faces.problem(corners, [&](const std::string& p) { in.fail(p); });
    if (!problem.empty()) in.fail(problem);
    faces.add(corners);
  }
  // Anything after the announced faces is ignored, as other OFF readers do.
  faces.move_into(mesh);
  mesh.format = "off";
  return mesh;
}

}  // namespace trivcon
