// trivcon/repair.h: duplicates dropped, non-manifold edges cut into sheets, fans split into vertices.
#include "trivcon/repair.h"

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>

#include "trivcon/error.h"

namespace trivcon {

namespace {

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

struct PairHash {
  std::size_t operator()(const std::pair<int, int>& p) const {
    return std::hash<long long>()((static_cast<long long>(p.first) << 32) ^ static_cast<unsigned>(p.second));
  }
};

struct TripleHash {
  std::size_t operator()(const std::array<int, 3>& t) const {
    return std::hash<long long>()((static_cast<long long>(t[0]) * 73856093) ^ (static_cast<long long>(t[1]) * 19349663) ^
                                  (static_cast<long long>(t[2]) * 83492791));
  }
};

}  // namespace

RepairedMesh repair_mesh(const MatrixX3d& V, const MatrixX3i& F) {
  const int nV = static_cast<int>(V.rows()), nF = static_cast<int>(F.rows());
  for (int f = 0; f < nF; ++f) {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) < 0 || F(f, k) >= nV)
        throw Error("vertex index " + std::to_string(F(f, k)) + " out of range in face " + std::to_string(f) + " (mesh has " +
                    std::to_string(nV) + " vertices)");
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2))
      throw Error("face " + std::to_string(f) + " has a repeated vertex (" + std::to_string(F(f, 0)) + ", " + std::to_string(F(f, 1)) +
                  ", " + std::to_string(F(f, 2)) + ")");
  }
  RepairedMesh out;
  out.face_of_input.assign(nF, -1);

  // Duplicates: the same three vertices in any order.
  std::unordered_map<std::array<int, 3>, int, TripleHash> first_with;
  std::vector<int> kept;
  for (int f = 0; f < nF; ++f) {
    std::array<int, 3> key{F(f, 0), F(f, 1), F(f, 2)};
    std::sort(key.begin(), key.end());
    const auto [it, inserted] = first_with.emplace(key, f);
    if (inserted) {
      out.face_of_input[f] = static_cast<int>(kept.size());
      kept.push_back(f);
    } else {
      out.duplicates.emplace_back(f, it->second);
    }
  }
  for (const auto& [f, original] : out.duplicates) out.face_of_input[f] = out.face_of_input[original];
  const int nK = static_cast<int>(kept.size());

  // The faces (kept, in order) around each edge, with the direction in which each holds it.
  struct Holder {
    int face;   // index into kept
    int corner; // the corner k holding i → j or j → i as its edge k → k+1
    bool forward;  // holds i → j (i < j)
  };
  std::unordered_map<std::pair<int, int>, std::vector<Holder>, PairHash> holders;
  holders.reserve(3 * static_cast<size_t>(nK));
  for (int q = 0; q < nK; ++q) {
    const int f = kept[q];
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      holders[{std::min(a, b), std::max(a, b)}].push_back({q, k, a < b});
    }
  }
  // Corners (3 per kept face) joined across paired edges: their groups around a vertex are its fans.
  std::vector<int> parent(3 * static_cast<size_t>(nK));
  std::iota(parent.begin(), parent.end(), 0);
  auto join = [&](const Holder& x, const Holder& y, int i, int j) {
    // Corner of face x at vertex v: k if F(x, k) == v.
    for (int v : {i, j}) {
      int cx = -1, cy = -1;
      for (int k = 0; k < 3; ++k) {
        if (F(kept[x.face], k) == v) cx = 3 * x.face + k;
        if (F(kept[y.face], k) == v) cy = 3 * y.face + k;
      }
      const int rx = find_root(parent, cx), ry = find_root(parent, cy);
      if (rx != ry) parent[std::max(rx, ry)] = std::min(rx, ry);
    }
  };
  std::vector<std::pair<std::pair<int, int>, const std::vector<Holder>*>> edges;
  edges.reserve(holders.size());
  for (const auto& [edge, list] : holders) edges.emplace_back(edge, &list);
  std::sort(edges.begin(), edges.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [edge, list_ptr] : edges) {
    const std::vector<Holder>& list = *list_ptr;
    if (list.size() == 2) {
      join(list[0], list[1], edge.first, edge.second);
      continue;
    }
    if (list.size() < 2) continue;
    out.cut_edges.push_back(edge);
    // Pairs: consistently oriented ones first (a forward holder with a backward one), in file order.
    std::vector<char> used(list.size(), 0);
    for (size_t a = 0; a < list.size(); ++a) {
      if (used[a]) continue;
      for (size_t b = a + 1; b < list.size(); ++b)
        if (!used[b] && list[a].forward != list[b].forward) {
          used[a] = used[b] = 1;
          join(list[a], list[b], edge.first, edge.second);
          break;
        }
    }
    for (size_t a = 0; a < list.size(); ++a) {
      if (used[a]) continue;
      for (size_t b = a + 1; b < list.size(); ++b)
        if (!used[b]) {
          used[a] = used[b] = 1;
          join(list[a], list[b], edge.first, edge.second);
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

  // What splitting cannot separate (sheets that meet again elsewhere around both ends) stays refused.
  std::unordered_map<std::pair<int, int>, int, PairHash> count;
  for (int q = 0; q < nK; ++q)
    for (int k = 0; k < 3; ++k) {
      const int a = out.F(q, k), b = out.F(q, (k + 1) % 3);
      if (++count[{std::min(a, b), std::max(a, b)}] == 3)
        throw Error("repair: the edge (" + std::to_string(out.vertex_origin[std::min(a, b)]) + ", " +
                    std::to_string(out.vertex_origin[std::max(a, b)]) +
                    ") has more than two faces whose sheets meet again around both its ends, which cutting it cannot separate");
    }
  return out;
}

std::string repair_summary(const RepairedMesh& r) {
  if (!r.changed()) return "";
  std::string s = "repaired:";
  std::string sep = " ";
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

}  // namespace trivcon
