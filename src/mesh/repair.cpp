// SPDX-License-Identifier: MIT
// trivcon/repair.h: duplicates dropped, non-manifold edges cut into sheets, fans split into vertices.
#include "trivcon/repair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <cstdint>

#include "trivcon/error.h"

namespace trivcon {

namespace {

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// Sorts (edge key, corner) pairs as std::sort would: a counting sort by the key's first vertex (its high 32 bits,
// < nV), then a sort within each vertex's few entries. Linear in practice, several times faster than std::sort.
void sort_by_first_vertex(std::vector<std::pair<std::uint64_t, int>>& items, int nV) {
  std::vector<int> begin(static_cast<size_t>(nV) + 1, 0);
  for (const auto& it : items) ++begin[(it.first >> 32) + 1];
  for (int v = 0; v < nV; ++v) begin[v + 1] += begin[v];
  std::vector<std::pair<std::uint64_t, int>> sorted(items.size());
  std::vector<int> next(begin.begin(), begin.end() - 1);
  for (const auto& it : items) sorted[next[it.first >> 32]++] = it;
  for (int v = 0; v < nV; ++v)
    if (begin[v + 1] - begin[v] > 1) std::sort(sorted.begin() + begin[v], sorted.begin() + begin[v + 1]);
  items.swap(sorted);
}

}  // namespace

namespace {

// One pass of repair_mesh with the `excluded` faces left out. Where the sheets of a cut edge meet again around
// both its ends (splitting cannot separate them), the faces beyond the first two on the edge that still has more
// than two are put into `exclude` and the result is not valid: the caller runs again without them.
RepairedMesh repair_pass(const MatrixX3d& V, const MatrixX3i& F, const std::vector<char>& excluded, std::vector<int>& exclude) {
  // Sorted arrays rather than hash maps: a mesh that needs nothing costs a few sorts of its faces and edges.
  const int nV = static_cast<int>(V.rows()), nF = static_cast<int>(F.rows());
  RepairedMesh out;
  out.input_vertices = nV, out.input_faces = nF;
  out.face_of_input.assign(nF, -1);

  // Faces with a repeated vertex have no direction: dropped.
  std::vector<int> kept;  // the faces kept, in file order
  kept.reserve(nF);
  for (int f = 0; f < nF; ++f) {
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2))
      out.degenerate_faces.push_back(f);
    else if (!excluded[f])
      kept.push_back(f);
  }
  if (kept.empty() && nF > 0) {
    const int f = out.degenerate_faces[0];
    throw Error("no faces left: every face has a repeated vertex (first: face " + std::to_string(f) + ", (" + std::to_string(F(f, 0)) +
                ", " + std::to_string(F(f, 1)) + ", " + std::to_string(F(f, 2)) + "))");
  }

  // The faces (kept, in order) around each edge: (edge key, corner 3q + k holding it as its edge k → k+1), sorted,
  // so each edge's holders are consecutive and in file order.
  struct Holder {
    int face;      // index into kept
    int corner;    // the corner k holding i → j or j → i as its edge k → k+1
    bool forward;  // holds i → j (i < j)
  };
  auto edge_key = [](int a, int b) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b))) << 32 | static_cast<std::uint32_t>(std::max(a, b));
  };
  std::vector<std::pair<std::uint64_t, int>> half_edges;
  auto collect_half_edges = [&] {
    half_edges.resize(3 * kept.size());
    for (size_t q = 0; q < kept.size(); ++q)
      for (int k = 0; k < 3; ++k)
        half_edges[3 * q + k] = {edge_key(F(kept[q], k), F(kept[q], (k + 1) % 3)), static_cast<int>(3 * q) + k};
    sort_by_first_vertex(half_edges, nV);
  };
  collect_half_edges();

  // Duplicates: the same three vertices in any order. Only possible where an edge has more than two faces or
  // its two faces have the same third vertex; then faces are sorted by their sorted corners (the first in file
  // order is the one kept) and the edges collected again without the duplicates.
  bool suspect = false;
  for (size_t begin = 0, end = 0; begin < half_edges.size() && !suspect; begin = end) {
    end = begin + 1;
    while (end < half_edges.size() && half_edges[end].first == half_edges[begin].first) ++end;
    const auto third = [&](size_t i) { return F(kept[half_edges[i].second / 3], (half_edges[i].second % 3 + 2) % 3); };
    suspect = end - begin > 2 || (end - begin == 2 && third(begin) == third(begin + 1));
  }
  if (suspect) {
    std::vector<std::array<int, 4>> by_corners;  // sorted corners, face
    by_corners.reserve(kept.size());
    for (int f : kept) {
      std::array<int, 4> key{F(f, 0), F(f, 1), F(f, 2), f};
      std::sort(key.begin(), key.begin() + 3);
      by_corners.push_back(key);
    }
    std::sort(by_corners.begin(), by_corners.end());
    std::vector<char> duplicate(nF, 0);
    for (size_t i = 1; i < by_corners.size(); ++i)
      if (std::equal(by_corners[i].begin(), by_corners[i].begin() + 3, by_corners[i - 1].begin())) {
        size_t original = i;
        while (original > 0 && std::equal(by_corners[original - 1].begin(), by_corners[original - 1].begin() + 3, by_corners[i].begin()))
          --original;
        duplicate[by_corners[i][3]] = 1;
        out.duplicates.emplace_back(by_corners[i][3], by_corners[original][3]);
      }
    if (!out.duplicates.empty()) {
      std::sort(out.duplicates.begin(), out.duplicates.end());
      kept.erase(std::remove_if(kept.begin(), kept.end(), [&](int f) { return duplicate[f] != 0; }), kept.end());
      collect_half_edges();
    }
  }
  for (size_t q = 0; q < kept.size(); ++q) out.face_of_input[kept[q]] = static_cast<int>(q);
  for (const auto& [f, original] : out.duplicates) out.face_of_input[f] = out.face_of_input[original];
  const int nK = static_cast<int>(kept.size());
  auto holder = [&](size_t i) {
    const int q = half_edges[i].second / 3, k = half_edges[i].second % 3;
    return Holder{q, k, F(kept[q], k) < F(kept[q], (k + 1) % 3)};
  };
  // Corners (3 per kept face) joined across paired edges: their groups around a vertex are its fans.
  std::vector<int> parent(3 * static_cast<size_t>(nK));
  std::iota(parent.begin(), parent.end(), 0);
  auto join = [&](const Holder& x, const Holder& y) {
    // Corner k of x is vertex a and k+1 is b; y holds the same edge, either way round.
    const int fx = kept[x.face], fy = kept[y.face];
    for (int end = 0; end < 2; ++end) {
      const int v = F(fx, (x.corner + end) % 3);
      const int cy = F(fy, y.corner) == v ? y.corner : (y.corner + 1) % 3;
      const int rx = find_root(parent, 3 * x.face + (x.corner + end) % 3), ry = find_root(parent, 3 * y.face + cy);
      if (rx != ry) parent[std::max(rx, ry)] = std::min(rx, ry);
    }
  };
  std::vector<std::pair<size_t, size_t>> cut_ranges;  // [begin, end) in half_edges of each cut edge
  std::vector<Holder> list;
  for (size_t begin = 0, end = 0; begin < half_edges.size(); begin = end) {
    end = begin + 1;
    while (end < half_edges.size() && half_edges[end].first == half_edges[begin].first) ++end;
    if (end - begin == 1) continue;
    if (end - begin == 2) {
      join(holder(begin), holder(begin + 1));
      continue;
    }
    const std::uint64_t key = half_edges[begin].first;
    out.cut_edges.emplace_back(static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu));
    cut_ranges.emplace_back(begin, end);
    list.clear();
    for (size_t i = begin; i < end; ++i) list.push_back(holder(i));
    // Pairs: consistently oriented ones first (a forward holder with a backward one), in file order.
    std::vector<char> used(list.size(), 0);
    for (size_t a = 0; a < list.size(); ++a) {
      if (used[a]) continue;
      for (size_t b = a + 1; b < list.size(); ++b)
        if (!used[b] && list[a].forward != list[b].forward) {
          used[a] = used[b] = 1;
          join(list[a], list[b]);
          break;
        }
    }
    for (size_t a = 0; a < list.size(); ++a) {
      if (used[a]) continue;
      for (size_t b = a + 1; b < list.size(); ++b)
        if (!used[b]) {
          used[a] = used[b] = 1;
          join(list[a], list[b]);
          break;
        }
      if (!used[a]) out.unpaired_faces.push_back(kept[list[a].face]);
    }
  }
  std::sort(out.unpaired_faces.begin(), out.unpaired_faces.end());

  // Fans: the groups of each vertex's corners. The group of the first corner in file order keeps the id.
  out.V = V;
  out.vertex_origin.resize(nV);
  std::iota(out.vertex_origin.begin(), out.vertex_origin.end(), 0);
  std::vector<int> vertex_of_group(3 * static_cast<size_t>(nK), -1);
  std::vector<int> fans(nV, 0);
  std::vector<std::array<double, 3>> appended;
  out.F.resize(nK, 3);
  for (int q = 0; q < nK; ++q)
    for (int k = 0; k < 3; ++k) {
      const int v = F(kept[q], k), root = find_root(parent, 3 * q + k);
      if (vertex_of_group[root] < 0) {
        if (fans[v]++ == 0) {
          vertex_of_group[root] = v;
        } else {
          vertex_of_group[root] = nV + static_cast<int>(appended.size());
          appended.push_back({V(v, 0), V(v, 1), V(v, 2)});
          out.vertex_origin.push_back(v);
        }
      }
      out.F(q, k) = vertex_of_group[root];
    }
  if (!appended.empty()) {
    out.V.conservativeResize(nV + static_cast<Eigen::Index>(appended.size()), 3);
    for (size_t i = 0; i < appended.size(); ++i)
      for (int a = 0; a < 3; ++a) out.V(nV + static_cast<Eigen::Index>(i), a) = appended[i][a];
  }
  for (int v = 0; v < nV; ++v)
    if (fans[v] > 1) out.split_vertices.emplace_back(v, fans[v]);
  out.input_face = kept;

  // Sheets that meet again elsewhere around both ends of a cut edge share it still: only the faces of cut edges
  // can. The faces beyond the first two (in file order) on such an edge are left out, and the pass runs again.
  std::vector<std::pair<std::uint64_t, int>> copies;  // (edge of the repaired mesh, face in file order)
  for (const auto& [begin, end] : cut_ranges) {
    copies.clear();
    for (size_t i = begin; i < end; ++i) {
      const Holder h = holder(i);
      copies.emplace_back(edge_key(out.F(h.face, h.corner), out.F(h.face, (h.corner + 1) % 3)), kept[h.face]);
    }
    std::sort(copies.begin(), copies.end());
    for (size_t i = 2; i < copies.size(); ++i)
      if (copies[i].first == copies[i - 2].first) exclude.push_back(copies[i].second);
  }
  if (!exclude.empty()) return out;
  // A dropped face (repeated vertex, or left out above) reads the field of a face sharing an edge, else one
  // sharing a vertex (none: −1).
  std::vector<int> face_at(nV, -1);  // a kept face at each input vertex
  for (int q = nK - 1; q >= 0; --q)
    for (int k = 0; k < 3; ++k) face_at[F(kept[q], k)] = q;
  for (int f = 0; f < nF; ++f) {
    if (out.face_of_input[f] >= 0) continue;
    int q = -1;
    for (int k = 0; k < 3 && q < 0; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (a == b) continue;
      const auto it = std::lower_bound(half_edges.begin(), half_edges.end(), std::make_pair(edge_key(a, b), -1));
      if (it != half_edges.end() && it->first == edge_key(a, b)) q = it->second / 3;
    }
    for (int k = 0; k < 3 && q < 0; ++k) q = face_at[F(f, k)];
    out.face_of_input[f] = q;
  }
  return out;
}

}  // namespace

RepairedMesh repair_mesh(const MatrixX3d& V, const MatrixX3i& F) {
  const int nV = static_cast<int>(V.rows()), nF = static_cast<int>(F.rows());
  for (int f = 0; f < nF; ++f) {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= nV)
        throw Error("vertex index " + std::to_string(F(f, k)) + " out of range in face " + std::to_string(f) + " (mesh has " +
                    std::to_string(nV) + " vertices)");
  }
  std::vector<char> excluded(nF, 0);
  for (;;) {  // each pass leaves out at least one more face, so this ends
    std::vector<int> exclude;
    RepairedMesh out = repair_pass(V, F, excluded, exclude);
    if (exclude.empty()) {
      for (int f = 0; f < nF; ++f)
        if (excluded[f]) out.unseparated_faces.push_back(f);
      return out;
    }
    for (int f : exclude) excluded[f] = 1;
  }
}

std::string repair_summary(const RepairedMesh& r) {
  if (!r.changed()) return "";
  std::string s = "repaired:";
  std::string sep = " ";
  if (!r.degenerate_faces.empty()) {
    s += sep + std::to_string(r.degenerate_faces.size()) + " face" + (r.degenerate_faces.size() > 1 ? "s" : "") +
         " with a repeated vertex dropped (first: face " + std::to_string(r.degenerate_faces[0]) + ")";
    sep = "; ";
  }
  if (!r.unseparated_faces.empty()) {
    s += sep + std::to_string(r.unseparated_faces.size()) + " face" + (r.unseparated_faces.size() > 1 ? "s" : "") +
         " dropped where sheets of an edge with more than two faces meet again (first: face " + std::to_string(r.unseparated_faces[0]) + ")";
    sep = "; ";
  }
  if (!r.duplicates.empty()) {
    s += sep + std::to_string(r.duplicates.size()) + " duplicate face" + (r.duplicates.size() > 1 ? "s" : "") + " dropped (first: face " +
         std::to_string(r.duplicates[0].first) + ", a copy of face " + std::to_string(r.duplicates[0].second) + ")";
    sep = "; ";
  }
  if (!r.cut_edges.empty()) {
    s += sep + std::to_string(r.cut_edges.size()) + " edge" + (r.cut_edges.size() > 1 ? "s" : "") + " with more than two faces cut (first: (" +
         std::to_string(r.cut_edges[0].first) + ", " + std::to_string(r.cut_edges[0].second) + "))";
    sep = "; ";
  }
  if (!r.split_vertices.empty())
    s += sep + std::to_string(r.split_vertices.size()) + (r.split_vertices.size() > 1 ? " vertices" : " vertex") +
         " split into separate fans (first: vertex " + std::to_string(r.split_vertices[0].first) + ", " +
         std::to_string(r.split_vertices[0].second) + " fans)";
  return s;
}

std::vector<int> fan_faces(const RepairedMesh& r, int input_vertex) {
  std::vector<int> out;
  std::map<int, int> first_face;  // repaired vertex -> first input face using it
  for (int q = 0; q < static_cast<int>(r.F.rows()); ++q)
    for (int k = 0; k < 3; ++k) {
      const int v = r.F(q, k);
      if (r.vertex_origin[v] == input_vertex) first_face.emplace(v, r.input_face[q]);
    }
  if (first_face.size() < 2) return out;
  for (const auto& [v, f] : first_face) out.push_back(f);
  return out;
}

int repaired_vertex(const RepairedMesh& r, int v, const std::string& what) {
  if (v < 0 || v >= r.input_vertices)
    throw Error(what + " " + std::to_string(v) + " out of range (mesh has " + std::to_string(r.input_vertices) + " vertices)");
  const auto split = std::lower_bound(r.split_vertices.begin(), r.split_vertices.end(), std::make_pair(v, 0));
  if (split != r.split_vertices.end() && split->first == v) {
    const std::vector<int> fans = fan_faces(r, v);
    std::string faces;
    for (size_t k = 0; k < fans.size(); ++k) faces += (k ? ", " : "") + std::to_string(fans[k]);
    throw Error(what + " " + std::to_string(v) + " is where " + std::to_string(fans.size()) +
                " sheets of the mesh touch (repair split it into one vertex per fan; first faces of the fans: " + faces +
                "): which one is meant cannot be told; place it on the repaired mesh (--mesh-out), where each fan has its own vertex");
  }
  return v;
}

int repaired_face(const RepairedMesh& r, int f, const std::string& what) {
  if (f < 0 || f >= r.input_faces)
    throw Error(what + " " + std::to_string(f) + " out of range (mesh has " + std::to_string(r.input_faces) + " faces)");
  if (std::binary_search(r.degenerate_faces.begin(), r.degenerate_faces.end(), f))
    throw Error(what + " " + std::to_string(f) + " has a repeated vertex and has no direction (repair dropped it)");
  return r.face_of_input[f];
}

namespace {

// Row q of the result is row input_face[q] of `input_rows` (a kept face keeps its corners in the input's order).
template <class Matrix>
Matrix gather_input_rows(const RepairedMesh& r, const Matrix& input_rows, const char* what) {
  if (input_rows.rows() != r.input_faces)
    throw Error(std::string(what) + ": " + std::to_string(input_rows.rows()) + " rows for " + std::to_string(r.input_faces) + " input faces");
  Matrix out(static_cast<Eigen::Index>(r.input_face.size()), input_rows.cols());
  for (size_t q = 0; q < r.input_face.size(); ++q) out.row(static_cast<Eigen::Index>(q)) = input_rows.row(r.input_face[q]);
  return out;
}

}  // namespace

MatrixX3d rows_on_repaired(const RepairedMesh& r, const MatrixX3d& input_rows) {
  return gather_input_rows(r, input_rows, "rows_on_repaired");
}

Eigen::MatrixXd corner_rows_on_input(const RepairedMesh& r, const MatrixX3i& input_F, const Eigen::MatrixXd& rows) {
  if (rows.rows() != r.F.rows() || rows.cols() % 3 != 0 || input_F.rows() != r.input_faces)
    throw Error("corner_rows_on_input: " + std::to_string(rows.rows()) + " x " + std::to_string(rows.cols()) + " rows for " +
                std::to_string(r.F.rows()) + " faces (3 corners each) and " + std::to_string(input_F.rows()) + " input faces");
  const Eigen::Index w = rows.cols() / 3;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(input_F.rows(), rows.cols());
  for (Eigen::Index f = 0; f < input_F.rows(); ++f) {
    const int q = r.face_of_input[f];
    if (q < 0) continue;
    int first = -1;
    for (int k = 0; k < 3; ++k) {
      int j = 0;
      while (j < 3 && r.vertex_origin[r.F(q, j)] != input_F(f, k)) ++j;
      if (j == 3) j = first >= 0 ? first : 0;
      if (first < 0) first = j;
      out.block(f, k * w, 1, w) = rows.block(q, j * w, 1, w);
    }
  }
  return out;
}

Eigen::MatrixXd corner_rows_on_repaired(const RepairedMesh& r, const Eigen::MatrixXd& input_rows) {
  return gather_input_rows(r, input_rows, "corner_rows_on_repaired");
}

std::map<int, int> singularities_on_repaired(const RepairedMesh& r, const std::map<int, int>& input_vertex) {
  std::map<int, int> out;
  for (const auto& [v, n] : input_vertex) out[repaired_vertex(r, v, "singular vertex")] = n;
  return out;
}

std::map<int, int> values_on_input(const RepairedMesh& r, const std::map<int, int>& per_vertex) {
  std::map<int, int> out;
  for (const auto& [v, n] : per_vertex) out[r.vertex_origin[v]] += n;
  for (auto it = out.begin(); it != out.end();) it = it->second == 0 ? out.erase(it) : std::next(it);
  return out;
}

std::vector<int> vertex_copies(const RepairedMesh& r, int v) {
  std::vector<int> out{v};
  for (size_t u = r.input_vertices; u < r.vertex_origin.size(); ++u)
    if (r.vertex_origin[u] == v) out.push_back(static_cast<int>(u));
  return out;
}

}  // namespace trivcon
