// SPDX-License-Identifier: MIT
// trivcon/features.h: the text of feature edges: 'i j' files (--features) and QuadWild's .sharp.
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "io/text_lines.h"
#include "trivcon/error.h"
#include "trivcon/features.h"
#include "trivcon/io.h"

namespace trivcon {

namespace {

using Lines = io::TextLines;


std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> out;
  if (separator == ' ') {
    std::istringstream fields(line);
    std::string token;
    while (fields >> token) out.push_back(token);
    return out;
  }
  std::string token;
  std::istringstream fields(line);
  while (std::getline(fields, token, separator)) {
    const size_t a = token.find_first_not_of(" \t"), b = token.find_last_not_of(" \t");
    out.push_back(a == std::string::npos ? "" : token.substr(a, b - a + 1));
  }
  return out;
}

}  // namespace

std::vector<int> read_feature_edges(const std::string& path, const Topology& t) {
  Lines lines(read_file_bytes(path), path);
  std::vector<int> line_of(t.num_edges, 0);  // the line that listed each edge (0: none)
  std::vector<int> out;
  while (lines.next()) {
    const std::vector<std::string> tokens = split(lines.line, ' ');
    if (tokens.size() != 2)
      throw Error(lines.where() + ": expected two vertex ids 'i j', got " + std::to_string(tokens.size()) + " fields");
    const int i = static_cast<int>(io::whole_number(tokens[0], lines, 0, t.num_vertices - 1, "vertex id"));
    const int j = static_cast<int>(io::whole_number(tokens[1], lines, 0, t.num_vertices - 1, "vertex id"));
    const std::string pair = "(" + std::to_string(i) + ", " + std::to_string(j) + ")";
    const int e = i == j ? -1 : edge_between(t, i, j);
    if (e < 0) throw Error(lines.where() + ": " + pair + " is not an edge of the mesh");
    if (t.is_boundary_edge(e))
      throw Error(lines.where() + ": " + pair + " is a boundary edge; features are interior edges (use --align-boundary for the boundary)");
    if (line_of[e]) throw Error(lines.where() + ": edge " + pair + " is listed twice (first at line " + std::to_string(line_of[e]) + ")");
    line_of[e] = lines.number;
    out.push_back(e);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void write_sharp(const std::string& path, const MatrixX3i& F, const Topology& t, const std::vector<int>& edges,
                 const std::vector<char>& convex, const std::vector<int>& input_face) {
  if (convex.size() != edges.size())
    throw Error("write_sharp: " + std::to_string(convex.size()) + " convexity flags for " + std::to_string(edges.size()) + " edges");
  if (F.rows() != t.num_faces) throw Error("write_sharp: the faces given are not those of the topology");
  std::vector<SharpFaceEdge> rows;
  for (size_t n = 0; n < edges.size(); ++n) {
    const int e = edges[n];
    if (e < 0 || e >= t.num_edges || t.is_boundary_edge(e))
      throw Error("write_sharp: edge " + std::to_string(e) + " is not an interior edge of the mesh");
    const int i = t.edge_vertices(e, 0), j = t.edge_vertices(e, 1);
    for (int side = 0; side < 2; ++side) {
      const int f = t.edge_faces(e, side);
      // The edge index in the face as given (a re-oriented face lists its corners in another order).
      int k = 0;
      while (k < 3 && !(std::min(F(f, k), F(f, (k + 1) % 3)) == i && std::max(F(f, k), F(f, (k + 1) % 3)) == j)) ++k;
      rows.push_back({convex[n] ? 1 : 0, input_face.empty() ? f : input_face[f], k});
    }
  }
  write_file_atomically(path, [&](std::ostream& out) {
    out << rows.size() << "\n";
    for (const SharpFaceEdge& r : rows) out << r.convex << "," << r.face << "," << r.edge << "\n";
  });
}

std::vector<SharpFaceEdge> read_sharp(const std::string& path, int num_faces) {
  Lines lines(read_file_bytes(path), path);
  if (!lines.next()) throw Error(path + ": empty .sharp file (expected the count on the first line)");
  const std::vector<std::string> head = split(lines.line, ' ');
  if (head.size() != 1) throw Error(lines.where() + ": expected the number of sharp face-edges alone on the first line");
  const long long count = io::whole_number(head[0], lines, 0, 3LL * num_faces, "the count");
  std::vector<SharpFaceEdge> out;
  out.reserve(static_cast<size_t>(count));
  for (long long n = 0; n < count; ++n) {
    if (!lines.next()) throw Error(path + ": ends after " + std::to_string(n) + " of the " + std::to_string(count) + " lines announced");
    const std::vector<std::string> fields = split(lines.line, ',');
    if (fields.size() != 3)
      throw Error(lines.where() + ": expected 'convexity,face,edge', got " + std::to_string(fields.size()) + " comma-separated fields");
    SharpFaceEdge r;
    r.convex = static_cast<int>(io::whole_number(fields[0], lines, 0, 1, "convexity"));
    r.face = static_cast<int>(io::whole_number(fields[1], lines, 0, num_faces - 1, "face"));
    r.edge = static_cast<int>(io::whole_number(fields[2], lines, 0, 2, "edge"));
    out.push_back(r);
  }
  if (lines.next()) throw Error(lines.where() + ": text after the " + std::to_string(count) + " lines the first line announced");
  return out;
}

}  // namespace trivcon
