// SPDX-License-Identifier: MIT
#include "quad/fill.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "quad/quad_shape.h"
#include "quad/surface_grid.h"

namespace trivcon::quad {

int fill_faces(const FieldDesigner& designer, const Parametrization& param, QuadMesh& quads) {
  if (quads.other_faces.empty()) return 0;
  const Topology& t = designer.topology();
  const MatrixX3d& Vin = designer.V();
  const int nV = static_cast<int>(quads.V.rows());
  if (quads.vertex_face.size() != nV || quads.vertex_barycentric.rows() != nV || quads.vertex_cone.size() != nV) return 0;
  // Each vertex's neighbours in the traced graph (quads and other faces), and the valence it should have.
  std::vector<std::set<int>> neighbours(nV);
  auto add_face = [&](const int* ids, size_t k) {
    for (size_t j = 0; j < k; ++j) {
      const int a = ids[j], b = ids[(j + 1) % k];
      neighbours[a].insert(b), neighbours[b].insert(a);
    }
  };
  for (int i = 0; i < quads.Q.rows(); ++i) {
    const int ids[4] = {quads.Q(i, 0), quads.Q(i, 1), quads.Q(i, 2), quads.Q(i, 3)};
    add_face(ids, 4);
  }
  for (const auto& face : quads.other_faces) add_face(face.data(), face.size());
  const std::vector<int> cone_of = cone_quarters(param, t.num_vertices);
  auto wanted = [&](int v) {
    const int c = quads.vertex_cone[v];
    return 4 - (c >= 0 && c < t.num_vertices ? cone_of[c] : 0);
  };
  // The worst corner of a quad: the sine of its angle about the quad's own normal.
  auto worst_corner = [](const std::array<Eigen::Vector3d, 4>& p) {
    const Eigen::Vector3d n = quad_normal(p);
    if (!(n.norm() > 0)) return -1.0;
    double worst = 1;
    for (int k = 0; k < 4; ++k) worst = std::min(worst, corner_sine(p, k, n.normalized()));
    return worst;
  };

  SurfaceGrid grid(Vin, t.F, 1000LL * (static_cast<long long>(quads.other_faces.size()) + t.num_faces) + 10000000);
  std::vector<std::vector<int>> kept;
  std::vector<std::array<int, 4>> added;
  std::vector<Eigen::Vector3d> points, barycentric;
  std::vector<int> faces;
  int filled = 0;
  // A trace that ended nowhere can leave an edge into a face and back (… a, b, a …): such spurs go. Returns the
  // edges taken out of `neighbours`.
  auto strip_spurs = [&](std::vector<int>& face) {
    std::vector<std::pair<int, int>> out;
    for (bool spur = true; spur && face.size() >= 3;) {
      spur = false;
      const size_t n = face.size();
      for (size_t j = 0; j < n && !spur; ++j)
        if (face[j] == face[(j + 2) % n]) {
          const size_t tip = (j + 1) % n, back = (j + 2) % n;
          neighbours[face[j]].erase(face[tip]), neighbours[face[tip]].erase(face[j]);
          out.emplace_back(face[j], face[tip]);
          std::vector<int> rest;
          for (size_t i = 0; i < n; ++i)
            if (i != tip && i != back) rest.push_back(face[i]);
          face = std::move(rest);
          spur = true;
        }
    }
    return out;
  };
  // A vertex's valence: its neighbours, and the spokes of the fans filled so far.
  std::vector<int> spokes(nV, 0);
  auto valence = [&](int v) { return static_cast<int>(neighbours[v].size()) + spokes[v]; };
  std::vector<std::vector<int>> walks = quads.other_faces;
  for (std::vector<int>& face : walks) strip_spurs(face);
  auto is_simple = [](const std::vector<int>& face) { return std::set<int>(face.begin(), face.end()).size() == face.size(); };
  // Two faces with an odd number of sides and an edge in common become one with an even number without it (and
  // without the spurs that leaves), when that one has no repeated vertex (the first such edge of each, in order).
  {
    std::map<std::pair<int, int>, int> side;  // (a, b) → the odd face running a → b
    for (size_t i = 0; i < walks.size(); ++i)
      if (walks[i].size() % 2 == 1 && is_simple(walks[i]))
        for (size_t j = 0; j < walks[i].size(); ++j) side[{walks[i][j], walks[i][(j + 1) % walks[i].size()]}] = static_cast<int>(i);
    std::vector<char> merged(walks.size(), 0);
    for (size_t i = 0; i < walks.size(); ++i) {
      const std::vector<int>& a = walks[i];
      if (merged[i] || a.size() % 2 == 0 || !is_simple(a)) continue;
      for (size_t j = 0; j < a.size(); ++j) {
        const int u = a[j], v = a[(j + 1) % a.size()];
        const auto it = side.find({v, u});
        if (it == side.end() || it->second == static_cast<int>(i) || merged[it->second] || walks[it->second].size() % 2 == 0) continue;
        const std::vector<int>& b = walks[it->second];
        // a from v round to u, then b from after u round to before v.
        std::vector<int> both;
        for (size_t m = 0; m < a.size(); ++m) both.push_back(a[(j + 1 + m) % a.size()]);
        const size_t at = std::find(b.begin(), b.end(), u) - b.begin();
        for (size_t m = 1; m + 1 < b.size(); ++m) both.push_back(b[(at + m) % b.size()]);
        // (Where the two share a path of several edges, the rest of it is a spur now.)
        const std::vector<std::pair<int, int>> taken = strip_spurs(both);
        if (!is_simple(both) || both.size() % 2 != 0) {
          for (auto [p, q] : taken) neighbours[p].insert(q), neighbours[q].insert(p);
          continue;
        }
        neighbours[u].erase(v), neighbours[v].erase(u);
        merged[it->second] = 1;
        walks[i] = std::move(both);
        break;
      }
    }
    std::vector<std::vector<int>> left;
    for (size_t i = 0; i < walks.size(); ++i)
      if (!merged[i]) left.push_back(std::move(walks[i]));
    walks = std::move(left);
  }
  for (const std::vector<int>& face : walks) {
    const int k = static_cast<int>(face.size());
    if (k < 6 || k % 2 != 0 || !is_simple(face)) {
      kept.push_back(face);
      continue;
    }
    // The new vertex: the surface's point nearest the corners' mean, on the component of the first corner (no
    // further from the mean than the nearest corner, which lies on the surface).
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int v : face) mean += quads.V.row(v).transpose();
    mean /= k;
    double limit = std::numeric_limits<double>::infinity();
    for (int v : face) limit = std::min(limit, (quads.V.row(v).transpose() - mean).norm());
    const int component = t.face_component[quads.vertex_face[face[0]]];
    const int found = grid.nearest(mean, limit, component, t.face_component).first;
    if (found < 0) {
      kept.push_back(face);
      continue;
    }
    Eigen::Vector3d bary;
    const Eigen::Vector3d c = closest_on_triangle(mean, Vin.row(t.F(found, 0)), Vin.row(t.F(found, 1)), Vin.row(t.F(found, 2)), &bary);
    int best_parity = 0, best_valences = -1;
    double best_corner = -std::numeric_limits<double>::infinity();
    for (int parity = 0; parity < 2; ++parity) {
      int valences = 0;
      double corner = 1;
      for (int j = 0; j < k; ++j) {
        const int v = face[j];
        valences += valence(v) + ((j - parity) % 2 == 0 ? 1 : 0) == wanted(v);
      }
      for (int j = parity; j < k; j += 2)
        corner = std::min(corner, worst_corner({c, quads.V.row(face[j]).transpose(), quads.V.row(face[(j + 1) % k]).transpose(),
                                                quads.V.row(face[(j + 2) % k]).transpose()}));
      if (valences > best_valences || (valences == best_valences && corner > best_corner))
        best_parity = parity, best_valences = valences, best_corner = corner;
    }
    // A hexagon may instead be two quads split by a diagonal v_i v_{i+3} (no new vertex, whose valence 3 would
    // not be the map's): taken when it leaves fewer corners with the wrong valence than the fan leaves vertices,
    // or as many and a better worst corner; never along an edge that exists already.
    int best_diagonal = -1;
    if (k == 6) {
      int fewest = k - best_valences + 1;  // the fan's: its corners and its new vertex
      double corner_then = best_corner;
      for (int i = 0; i < 3; ++i) {
        const int a = face[i], b = face[i + 3];
        if (neighbours[a].count(b)) continue;
        int wrong = 0;
        for (int j = 0; j < k; ++j) wrong += valence(face[j]) + (j == i || j == i + 3 ? 1 : 0) != wanted(face[j]);
        auto at = [&](int j) { return Eigen::Vector3d(quads.V.row(face[(i + j) % k]).transpose()); };
        const double corner = std::min(worst_corner({at(0), at(1), at(2), at(3)}), worst_corner({at(3), at(4), at(5), at(0)}));
        if (wrong < fewest || (wrong == fewest && corner > corner_then)) fewest = wrong, corner_then = corner, best_diagonal = i;
      }
    }
    if (best_diagonal >= 0) {
      const int i = best_diagonal;
      added.push_back({face[i], face[i + 1], face[i + 2], face[i + 3]});
      added.push_back({face[i + 3], face[(i + 4) % k], face[(i + 5) % k], face[i]});
      neighbours[face[i]].insert(face[i + 3]), neighbours[face[i + 3]].insert(face[i]);
    } else {
      const int id = nV + static_cast<int>(points.size());
      points.push_back(c), barycentric.push_back(bary), faces.push_back(found);
      for (int j = best_parity; j < k; j += 2) added.push_back({id, face[j], face[(j + 1) % k], face[(j + 2) % k]}), ++spokes[face[j]];
    }
    ++filled;
  }
  if (filled == 0) return 0;
  const int nAdd = static_cast<int>(points.size()), nQ = static_cast<int>(quads.Q.rows());
  quads.V.conservativeResize(nV + nAdd, 3);
  quads.vertex_face.conservativeResize(nV + nAdd);
  quads.vertex_barycentric.conservativeResize(nV + nAdd, 3);
  quads.vertex_cone.conservativeResize(nV + nAdd);
  for (int i = 0; i < nAdd; ++i) {
    quads.V.row(nV + i) = points[i].transpose();
    quads.vertex_face[nV + i] = faces[i];
    quads.vertex_barycentric.row(nV + i) = barycentric[i].transpose();
    quads.vertex_cone[nV + i] = -1;
  }
  quads.Q.conservativeResize(nQ + static_cast<int>(added.size()), 4);
  for (size_t i = 0; i < added.size(); ++i) quads.Q.row(nQ + static_cast<int>(i)) << added[i][0], added[i][1], added[i][2], added[i][3];
  quads.other_faces = std::move(kept);
  // The tips of the spurs taken out may be in no face now: they go, and the rest are numbered anew in order.
  std::vector<int> index(quads.V.rows(), -1);
  for (int i = 0; i < quads.Q.rows(); ++i)
    for (int k = 0; k < 4; ++k) index[quads.Q(i, k)] = 0;
  for (const auto& face : quads.other_faces)
    for (int v : face) index[v] = 0;
  int used = 0;
  for (int& i : index)
    if (i == 0) i = used++;
  if (used < quads.V.rows()) {
    for (int v = 0; v < static_cast<int>(index.size()); ++v)
      if (index[v] >= 0) {
        quads.V.row(index[v]) = quads.V.row(v);
        quads.vertex_face[index[v]] = quads.vertex_face[v];
        quads.vertex_barycentric.row(index[v]) = quads.vertex_barycentric.row(v);
        quads.vertex_cone[index[v]] = quads.vertex_cone[v];
      }
    quads.V.conservativeResize(used, 3);
    quads.vertex_face.conservativeResize(used);
    quads.vertex_barycentric.conservativeResize(used, 3);
    quads.vertex_cone.conservativeResize(used);
    for (int i = 0; i < quads.Q.rows(); ++i)
      for (int k = 0; k < 4; ++k) quads.Q(i, k) = index[quads.Q(i, k)];
    for (auto& face : quads.other_faces)
      for (int& v : face) v = index[v];
  }
  return filled;
}

}  // namespace trivcon::quad
