// SPDX-License-Identifier: MIT
// src/io/read_obj.cpp: the Wavefront OBJ reader of trivcon/io.h (v and f lines; everything else is skipped).
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
            in.fail("face index " + std::to_string(index) + " out of range (" + std::to_string(vertex_count) + " vertices defined so far)");
          }
        } else {
          in.fail("face index 0 is invalid (OBJ indices start at 1)");
        }
        corners.push_back(static_cast<int>(id));
      }
      const std::string problem = faces.problem(corners, [&](const std::string& p) { in.fail(p); });
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

}  // namespace trivcon
