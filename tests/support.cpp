// SPDX-License-Identifier: MIT
#include "support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <limits>
#include <set>
#include <sstream>

#include "trivcon/constraints.h"
#include "trivcon/io.h"
#include "trivcon/error.h"

namespace trivcon::test {

namespace {

std::uint64_t key(int a, int b) { return static_cast<std::uint64_t>(std::min(a, b)) << 32 | static_cast<std::uint32_t>(std::max(a, b)); }

int brute_force_edges(const MatrixX3i& F) {
  std::set<std::uint64_t> edges;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) edges.insert(key(F(f, k), F(f, (k + 1) % 3)));
  return static_cast<int>(edges.size());
}

}  // namespace

std::string shared_mesh(const std::string& name) {
  const std::filesystem::path dir = TRIVCON_SHARED_MESHES;
  if (!std::filesystem::exists(dir / "SOURCES.md")) return "";
  return (dir / name).string();
}

std::string temp_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(TRIVCON_TEST_TMP) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string temp_file(const std::string& name) {
  static int counter = 0;
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string owner = test ? std::string(test->test_suite_name()) + "." + test->name() : "no-test";
  return temp_dir(owner + "-" + std::to_string(counter++)) + "/" + name;
}

Mesh mobius_strip(int n) {
  Mesh m;
  m.V.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const double u = 2 * kPi * i / n;
    const Eigen::Vector3d c(std::cos(u), std::sin(u), 0),
        d(0.3 * std::cos(u / 2) * std::cos(u), 0.3 * std::cos(u / 2) * std::sin(u), 0.3 * std::sin(u / 2));
    m.V.row(2 * i) = c + d;
    m.V.row(2 * i + 1) = c - d;
  }
  std::vector<std::array<int, 3>> f;
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * i + 1;
    const int c = i + 1 < n ? 2 * (i + 1) + 1 : 0, d = i + 1 < n ? 2 * (i + 1) : 1;
    f.push_back({a, b, c});
    f.push_back({a, c, d});
  }
  m.F = faces(f);
  return m;
}

std::string q(const std::string& s) { return "'" + s + "'"; }
std::string test_name_of(const std::string& file) {
  std::string name = file;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}
bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string save(const std::string& dir, const std::string& name, const Mesh& m, bool ply) {
  const std::string path = dir + "/" + name + (ply ? ".ply" : ".obj");
  if (ply) {
    write_ply(path, m.V, m.F);
  } else {
    write_obj(path, m.V, m.F);
  }
  return path;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

CommandResult run_cli(const std::string& args) {
  static int counter = 0;
  const std::string base = temp_dir("cli-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  const std::string out = base + "/out", err = base + "/err";
  const std::string command = std::string("'") + TRIVCON_CLI + "' " + args + " > '" + out + "' 2> '" + err + "' < /dev/null";
  const int raw = std::system(command.c_str());
  CommandResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove_all(base);
  return r;
}

double max_face_optimality(const FieldDesigner& designer, const Connection& c, const std::map<int, double>& skip) {
  const Topology& t = designer.topology();
  const Eigen::VectorXd& w = designer.solver().weights();
  double worst = 0, scale = 1;
  for (int e = 0; e < t.num_edges; ++e)
    if (w(e) > 0) scale = std::max(scale, std::abs(c.x(e) / w(e)));
  for (int f = 0; f < t.num_faces; ++f) {
    if (skip.count(f)) continue;
    double sum = 0;
    bool interior = true;
    for (int k = 0; k < 3; ++k) {
      const int e = t.face_edges(f, k);
      if (t.is_boundary_edge(e) || !(w(e) > 0)) {
        interior = false;
      } else {
        sum += (t.edge_faces(e, 0) == f ? 1 : -1) * c.x(e) / w(e);
      }
    }
    if (interior) worst = std::max(worst, std::abs(sum));
  }
  return worst / scale;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("<not a trivcon::Error: ") + e.what() + ">";
  }
  return "<no error>";
}

Topology topo(const Mesh& m) { return build_topology(m.F, static_cast<int>(m.V.rows())); }

MatrixX3i faces(const std::vector<std::array<int, 3>>& list) {
  MatrixX3i F(static_cast<int>(list.size()), 3);
  for (size_t f = 0; f < list.size(); ++f) F.row(static_cast<int>(f)) << list[f][0], list[f][1], list[f][2];
  return F;
}

std::vector<int> vertices_of_valence(const Mesh& m, int valence) {
  std::vector<int> count(m.V.rows(), 0);
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++count[m.F(f, k)];
  std::vector<int> out;
  for (int v = 0; v < m.V.rows(); ++v)
    if (count[v] == valence) out.push_back(v);
  return out;
}

Mesh sheared_box(int n) {
  // The cube [-1, 1]³, each side an n × n grid of squares, each square a fan of 4 triangles around its centre;
  // vertices shared through their positions (exact: multiples of 1/n and 1/2n).
  std::map<std::array<double, 3>, int> id;
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  auto vertex = [&](const Eigen::Vector3d& p) {
    const auto [it, added] = id.try_emplace({p.x(), p.y(), p.z()}, static_cast<int>(V.size()));
    if (added) V.push_back(p);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1})
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          auto point = [&](double a, double b) {
            Eigen::Vector3d p;
            p[axis] = side, p[(axis + 1) % 3] = -1 + 2 * a / n, p[(axis + 2) % 3] = -1 + 2 * b / n;
            return p;
          };
          std::array<int, 4> q{vertex(point(i, j)), vertex(point(i + 1, j)), vertex(point(i + 1, j + 1)), vertex(point(i, j + 1))};
          if (side < 0) std::swap(q[1], q[3]);  // outward normals
          const int c = vertex(point(i + 0.5, j + 0.5));
          for (int k = 0; k < 4; ++k) F.emplace_back(q[k], q[(k + 1) % 4], c);
        }
  Mesh m;
  m.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (size_t v = 0; v < V.size(); ++v) m.V.row(static_cast<Eigen::Index>(v)) = V[v].transpose() + Eigen::RowVector3d(2.5 * V[v].y(), 0, 0);
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (size_t f = 0; f < F.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) = F[f].transpose();
  return m;
}

SolverOptions sparse_path_options() {
  SolverOptions options;
  options.max_dense_paths = 256;
  return options;
}

IndexPrescription aligned_cross_field(FieldDesigner& designer, const Mesh& m) {
  IndexPrescription p;
  p.N = 4;
  p.fixed = boundary_alignment(m.V, designer.topology(), designer.geometry());
  std::vector<int> fixed;
  for (auto [f, angle] : p.fixed) fixed.push_back(f);
  designer.set_fixed_faces(fixed);
  return p;
}

Mesh unwelded_sphere(int rings, int segments) {
  Mesh m;
  m.V.resize((rings + 1) * (segments + 1), 3);
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const double theta = kPi * i / rings, phi = 2 * kPi * j / segments;
      const double r = i == 0 || i == rings ? 0.0 : std::sin(theta);  // the poles exactly at one point, as files write them
      m.V.row(i * (segments + 1) + j) << r * std::cos(phi), r * std::sin(phi), -std::cos(theta);
    }
  m.F.resize(2 * rings * segments, 3);
  for (int i = 0, f = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * (segments + 1) + j, b = a + 1, c = a + segments + 1, d = c + 1;
      m.F.row(f++) << a, b, d;
      m.F.row(f++) << a, d, c;
    }
  return m;
}

Mesh perforated_plate(int nx, int ny, int m, int layers, double r) {
  std::map<std::pair<long long, long long>, int> id;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> faces;
  auto vertex = [&](double x, double y) {
    const auto key = std::make_pair(std::llround(x * 1e6), std::llround(y * 1e6));
    const auto [it, added] = id.emplace(key, static_cast<int>(points.size()));
    if (added) points.emplace_back(x, y, 0);
    return it->second;
  };
  for (int cx = 0; cx < nx; ++cx)
    for (int cy = 0; cy < ny; ++cy) {
      std::vector<std::array<double, 2>> square;  // counter-clockwise
      for (int side = 0; side < 4; ++side)
        for (int k = 0; k < m; ++k) {
          const double a = static_cast<double>(k) / m;
          const double x[4] = {a, 1, 1 - a, 0}, y[4] = {0, a, 1, 1 - a};
          square.push_back({cx + x[side], cy + y[side]});
        }
      const int n = 4 * m;
      std::vector<std::vector<int>> ring(layers + 1, std::vector<int>(n));
      for (int j = 0; j <= layers; ++j)
        for (int k = 0; k < n; ++k) {
          const double angle = std::atan2(square[k][1] - cy - 0.5, square[k][0] - cx - 0.5), w = static_cast<double>(j) / layers;
          const double hx = cx + 0.5 + r * std::cos(angle), hy = cy + 0.5 + r * std::sin(angle);
          ring[j][k] = vertex((1 - w) * hx + w * square[k][0], (1 - w) * hy + w * square[k][1]);
        }
      for (int j = 0; j < layers; ++j)
        for (int k = 0; k < n; ++k) {
          const int a = ring[j][k], b = ring[j][(k + 1) % n], c = ring[j + 1][(k + 1) % n], d = ring[j + 1][k];
          if ((j + k) % 2) faces.emplace_back(a, b, c), faces.emplace_back(a, c, d);
          else faces.emplace_back(a, b, d), faces.emplace_back(b, c, d);
        }
    }
  Mesh out;
  out.V.resize(static_cast<int>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) out.V.row(static_cast<int>(i)) = points[i].transpose();
  out.F.resize(static_cast<int>(faces.size()), 3);
  for (size_t i = 0; i < faces.size(); ++i) out.F.row(static_cast<int>(i)) = faces[i].transpose();
  return out;
}

Mesh lattice_plate(int nx, int ny, double r, double h) {
  const double width = nx, height = ny;
  const int rows = std::max(2, static_cast<int>(std::lround(height / (h * std::sqrt(3.0) / 2))));
  const int n = std::max(1, static_cast<int>(std::lround(width / h)));
  std::vector<Eigen::Vector2d> p;
  std::vector<std::vector<int>> row(rows + 1);
  for (int j = 0; j <= rows; ++j) {
    const double y = height * j / rows;
    std::vector<double> xs;
    if (j % 2 == 0)
      for (int i = 0; i <= n; ++i) xs.push_back(width * i / n);
    else {
      xs.push_back(0);
      for (int i = 0; i < n; ++i) xs.push_back(width * (i + 0.5) / n);
      xs.push_back(width);
    }
    for (double x : xs) row[j].push_back(static_cast<int>(p.size())), p.emplace_back(x, y);
  }
  std::vector<std::array<int, 3>> faces;
  for (int j = 0; j < rows; ++j) {  // the strip between two rows, advancing along the one whose next point comes first
    const std::vector<int>&a = row[j], &b = row[j + 1];
    size_t i = 0, k = 0;
    while (i + 1 < a.size() || k + 1 < b.size()) {
      if (k + 1 == b.size() || (i + 1 < a.size() && p[a[i + 1]].x() <= p[b[k + 1]].x())) faces.push_back({a[i], a[i + 1], b[k]}), ++i;
      else faces.push_back({a[i], b[k + 1], b[k]}), ++k;
    }
  }
  std::vector<Eigen::Vector2d> centres;
  for (int cx = 0; cx < nx; ++cx)
    for (int cy = 0; cy < ny; ++cy) centres.emplace_back(cx + 0.5, cy + 0.5);
  std::vector<double> d(p.size(), std::numeric_limits<double>::infinity());
  std::vector<int> nearest(p.size(), 0);
  for (size_t v = 0; v < p.size(); ++v)
    for (size_t c = 0; c < centres.size(); ++c)
      if ((p[v] - centres[c]).norm() < d[v]) d[v] = (p[v] - centres[c]).norm(), nearest[v] = static_cast<int>(c);
  std::vector<std::array<int, 3>> kept;
  for (const auto& f : faces)
    if (d[f[0]] >= r + 0.3 * h && d[f[1]] >= r + 0.3 * h && d[f[2]] >= r + 0.3 * h) kept.push_back(f);
  std::map<std::pair<int, int>, int> uses;
  std::vector<std::set<int>> neighbours(p.size());
  for (const auto& f : kept)
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
      neighbours[a].insert(b), neighbours[b].insert(a);
    }
  std::vector<char> rim(p.size(), 0);
  for (const auto& [e, count] : uses)
    if (count == 1) rim[e.first] = rim[e.second] = 1;
  for (size_t v = 0; v < p.size(); ++v)
    if (rim[v] && d[v] < r + 2 * h) {
      const Eigen::Vector2d& c = centres[nearest[v]];
      p[v] = c + r * (p[v] - c).normalized();
    }
  for (int round = 0; round < 15; ++round)
    for (size_t v = 0; v < p.size(); ++v) {
      if (rim[v] || neighbours[v].empty() || d[v] >= r + 3 * h) continue;
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      for (int w : neighbours[v]) sum += p[w];
      p[v] = sum / static_cast<double>(neighbours[v].size());
    }
  std::vector<int> id(p.size(), -1);
  Mesh out;
  int used = 0;
  for (const auto& f : kept)
    for (int v : f)
      if (id[v] < 0) id[v] = used++;
  out.V.resize(used, 3);
  for (size_t v = 0; v < p.size(); ++v)
    if (id[v] >= 0) out.V.row(id[v]) << p[v].x(), p[v].y(), 0;
  out.F.resize(static_cast<int>(kept.size()), 3);
  for (size_t i = 0; i < kept.size(); ++i) out.F.row(static_cast<int>(i)) << id[kept[i][0]], id[kept[i][1]], id[kept[i][2]];
  return out;
}

int boundary_vertex_with_fan(const Topology& topology, size_t faces) {
  std::vector<int> fan;
  for (int v = 0; v < topology.num_vertices; ++v)
    if (topology.is_boundary_vertex(v) && (vertex_fan(topology, v, fan), fan.size() == faces)) return v;
  return -1;
}

Mesh extruded(const Mesh& flat, double height) {
  const int n = static_cast<int>(flat.V.rows()), nf = static_cast<int>(flat.F.rows());
  std::set<std::pair<int, int>> directed;
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) directed.insert({flat.F(f, k), flat.F(f, (k + 1) % 3)});
  std::vector<std::pair<int, int>> boundary;
  for (auto [a, b] : directed)
    if (!directed.count({b, a})) boundary.push_back({a, b});
  Mesh out;
  out.V.resize(2 * n, 3);
  out.V.topRows(n) = flat.V;
  out.V.bottomRows(n) = flat.V;
  out.V.bottomRows(n).col(2).array() -= height;
  out.F.resize(2 * nf + 2 * static_cast<int>(boundary.size()), 3);
  for (int f = 0; f < nf; ++f) {
    out.F.row(f) = flat.F.row(f);
    out.F.row(nf + f) << flat.F(f, 2) + n, flat.F(f, 1) + n, flat.F(f, 0) + n;
  }
  int row = 2 * nf;
  for (auto [a, b] : boundary) {
    out.F.row(row++) << b, a, a + n;
    out.F.row(row++) << b, a + n, b + n;
  }
  return out;
}

Mesh jittered_disk(int rings, int segments, double amount) {
  Mesh m = make_disk(rings, segments);
  const Topology t = topo(m);
  for (int v = 0; v < m.V.rows(); ++v) {
    if (t.is_boundary_vertex(v)) continue;
    const double angle = 2.399963 * v + 0.7, r = amount * (0.5 + 0.5 * std::sin(12.9898 * v)) / rings;
    m.V(v, 0) += r * std::cos(angle), m.V(v, 1) += r * std::sin(angle);
  }
  return m;
}

void expect_consistent(const Topology& t, const MatrixX3i& F_in, int nv, const std::string& what) {
  SCOPED_TRACE(what);
  const int nF = static_cast<int>(F_in.rows());
  ASSERT_EQ(t.num_vertices, nv);
  ASSERT_EQ(t.num_faces, nF);
  ASSERT_EQ(t.F.rows(), nF);
  ASSERT_EQ(t.edge_vertices.rows(), t.num_edges);
  ASSERT_EQ(t.edge_faces.rows(), t.num_edges);
  ASSERT_EQ(t.face_edges.rows(), nF);
  ASSERT_EQ(t.num_edges, brute_force_edges(F_in));

  // F is F_in with exactly the listed faces flipped, (a, b, c) → (a, c, b).
  std::vector<char> flipped(nF, 0);
  for (size_t i = 0; i < t.flipped_faces.size(); ++i) {
    ASSERT_TRUE(i == 0 || t.flipped_faces[i - 1] < t.flipped_faces[i]) << "flipped_faces not increasing";
    flipped[t.flipped_faces[i]] = 1;
  }
  int bad_rows = 0;
  for (int f = 0; f < nF; ++f) {
    const bool ok =
        flipped[f] ? (t.F(f, 0) == F_in(f, 0) && t.F(f, 1) == F_in(f, 2) && t.F(f, 2) == F_in(f, 1)) : (t.F.row(f) == F_in.row(f));
    bad_rows += !ok;
  }
  EXPECT_EQ(bad_rows, 0) << "rows of F that are not the input (flipped where listed)";

  // face_edges joins corners k, k+1; the half-edge i→j with i < j is in L, j→i in R.
  int bad_face_edges = 0, bad_sides = 0;
  std::vector<int> uses(t.num_edges, 0);
  for (int f = 0; f < nF; ++f)
    for (int k = 0; k < 3; ++k) {
      const int e = t.face_edges(f, k), a = t.F(f, k), b = t.F(f, (k + 1) % 3);
      if (e < 0 || e >= t.num_edges) {
        ++bad_face_edges;
        continue;
      }
      ++uses[e];
      bad_face_edges += !(t.edge_vertices(e, 0) == std::min(a, b) && t.edge_vertices(e, 1) == std::max(a, b));
      bad_sides += t.edge_faces(e, a < b ? 0 : 1) != f;
    }
  EXPECT_EQ(bad_face_edges, 0);
  EXPECT_EQ(bad_sides, 0) << "edge_faces(e, 0) must hold i→j (i < j), edge_faces(e, 1) j→i";
  int bad_edges = 0, boundary_edges = 0;
  for (int e = 0; e < t.num_edges; ++e) {
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    bad_edges += !(t.edge_vertices(e, 0) < t.edge_vertices(e, 1));
    bad_edges += !(L >= -1 && L < nF && R >= -1 && R < nF && (L >= 0 || R >= 0));
    bad_edges += uses[e] != (L >= 0) + (R >= 0);
    boundary_edges += t.is_boundary_edge(e);
  }
  EXPECT_EQ(bad_edges, 0);

  // Components: numbered by smallest face id, counts.
  ASSERT_EQ(static_cast<int>(t.face_component.size()), nF);
  std::vector<int> first(t.components.size(), -1), cf(t.components.size(), 0), cv(t.components.size(), 0), ce(t.components.size(), 0);
  for (int f = 0; f < nF; ++f) {
    const int c = t.face_component[f];
    ASSERT_TRUE(c >= 0 && c < static_cast<int>(t.components.size()));
    if (first[c] < 0) first[c] = f;
    ++cf[c];
  }
  for (size_t c = 0; c < t.components.size(); ++c) {
    EXPECT_EQ(t.components[c].first_face, first[c]) << "component " << c;
    if (c > 0) {
      EXPECT_LT(first[c - 1], first[c]) << "components must be numbered by smallest face id";
    }
  }
  for (int e = 0; e < t.num_edges; ++e) {
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    if (L >= 0 && R >= 0) {
      EXPECT_EQ(t.face_component[L], t.face_component[R]);
    }
    ++ce[t.face_component[L >= 0 ? L : R]];
  }
  ASSERT_EQ(static_cast<int>(t.vertex_component.size()), nv);
  std::vector<int> unreferenced;
  std::vector<char> referenced(nv, 0);
  for (int f = 0; f < nF; ++f)
    for (int k = 0; k < 3; ++k) {
      referenced[F_in(f, k)] = 1;
      EXPECT_EQ(t.vertex_component[F_in(f, k)], t.face_component[f]);
    }
  for (int v = 0; v < nv; ++v) {
    if (!referenced[v]) {
      unreferenced.push_back(v);
      EXPECT_EQ(t.vertex_component[v], -1);
    } else {
      ++cv[t.vertex_component[v]];
    }
  }
  EXPECT_EQ(t.unreferenced_vertices, unreferenced);
  int chi = 0;
  for (size_t c = 0; c < t.components.size(); ++c) {
    const ComponentInfo& info = t.components[c];
    EXPECT_EQ(info.faces, cf[c]);
    EXPECT_EQ(info.vertices, cv[c]);
    EXPECT_EQ(info.edges, ce[c]);
    EXPECT_EQ(info.euler_characteristic, cv[c] - ce[c] + cf[c]);
    EXPECT_EQ(2 * info.genus, 2 - info.euler_characteristic - static_cast<int>(info.boundary_loops.size()));
    EXPECT_GE(info.genus, 0);
    chi += info.euler_characteristic;
  }
  EXPECT_EQ(t.euler_characteristic(), chi);

  // Boundary loops: ordered cycles following the orientation, starting at their smallest vertex,
  // numbered by smallest vertex, covering every boundary edge once.
  std::map<std::pair<int, int>, int> boundary_half_edges;  // a→b of a boundary edge → face
  for (int e = 0; e < t.num_edges; ++e) {
    if (!t.is_boundary_edge(e)) continue;
    const int f = t.edge_faces(e, 0) >= 0 ? t.edge_faces(e, 0) : t.edge_faces(e, 1);
    for (int k = 0; k < 3; ++k)
      if (t.face_edges(f, k) == e) boundary_half_edges[{t.F(f, k), t.F(f, (k + 1) % 3)}] = f;
  }
  ASSERT_EQ(static_cast<int>(t.vertex_boundary_loop.size()), nv);
  size_t loop_edges = 0;
  std::vector<int> loops_of_component(t.components.size(), 0);
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) {
    const std::vector<int>& loop = t.boundary_loops[l];
    ASSERT_GE(loop.size(), 3u) << "loop " << l;
    EXPECT_EQ(loop[0], *std::min_element(loop.begin(), loop.end())) << "loop " << l << " must start at its smallest vertex";
    if (l > 0) {
      EXPECT_LT(t.boundary_loops[l - 1][0], loop[0]) << "loops must be numbered by smallest vertex";
    }
    int bad_steps = 0;
    for (size_t i = 0; i < loop.size(); ++i) {
      bad_steps += !boundary_half_edges.count({loop[i], loop[(i + 1) % loop.size()]});
      EXPECT_EQ(t.vertex_boundary_loop[loop[i]], static_cast<int>(l));
    }
    EXPECT_EQ(bad_steps, 0) << "loop " << l << ": consecutive vertices that are not a boundary half-edge a→b";
    loop_edges += loop.size();
    const int c = t.vertex_component[loop[0]];
    ASSERT_GE(c, 0);
    const auto& ids = t.components[c].boundary_loops;
    EXPECT_NE(std::find(ids.begin(), ids.end(), static_cast<int>(l)), ids.end()) << "loop " << l << " not listed by its component";
    ++loops_of_component[c];
  }
  EXPECT_EQ(loop_edges, boundary_half_edges.size()) << "boundary edges not on exactly one loop";
  EXPECT_EQ(static_cast<int>(loop_edges), boundary_edges);
  for (size_t c = 0; c < t.components.size(); ++c)
    EXPECT_EQ(static_cast<int>(t.components[c].boundary_loops.size()), loops_of_component[c]);
  int boundary_vertices = 0;
  for (int v = 0; v < nv; ++v) {
    boundary_vertices += t.vertex_boundary_loop[v] >= 0;
    EXPECT_EQ(t.is_interior_vertex(v), referenced[v] && t.vertex_boundary_loop[v] < 0);
  }
  EXPECT_EQ(static_cast<size_t>(boundary_vertices), loop_edges) << "a boundary vertex on two loops";

  // CSR adjacency.
  ASSERT_EQ(static_cast<int>(t.vertex_face_offsets.size()), nv + 1);
  ASSERT_EQ(static_cast<int>(t.vertex_edge_offsets.size()), nv + 1);
  std::vector<std::vector<int>> vf(nv), ve(nv);
  for (int f = 0; f < nF; ++f)
    for (int k = 0; k < 3; ++k) vf[F_in(f, k)].push_back(f);
  for (int e = 0; e < t.num_edges; ++e) {
    ve[t.edge_vertices(e, 0)].push_back(e);
    ve[t.edge_vertices(e, 1)].push_back(e);
  }
  int bad_csr = 0;
  for (int v = 0; v < nv; ++v) {
    std::vector<int> a(t.vertex_faces.begin() + t.vertex_face_offsets[v], t.vertex_faces.begin() + t.vertex_face_offsets[v + 1]);
    std::vector<int> b(t.vertex_edges.begin() + t.vertex_edge_offsets[v], t.vertex_edges.begin() + t.vertex_edge_offsets[v + 1]);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    std::sort(ve[v].begin(), ve[v].end());
    bad_csr += a != vf[v];
    bad_csr += b != ve[v];
  }
  EXPECT_EQ(bad_csr, 0) << "vertices whose vertex_faces / vertex_edges differ from brute force";
}

void expect_geometry_sane(const MatrixX3d& V, const Topology& t, const std::string& what, double gb_tol) {
  SCOPED_TRACE(what);
  const Geometry g = compute_geometry(V, t);
  auto all_finite = [](const auto& m) { return m.size() == 0 || m.array().isFinite().all(); };
  EXPECT_TRUE(all_finite(g.corner_angles));
  EXPECT_TRUE(all_finite(g.half_edge_angle));
  EXPECT_TRUE(all_finite(g.face_area));
  EXPECT_TRUE(all_finite(g.frame_x));
  EXPECT_TRUE(all_finite(g.frame_y));
  EXPECT_TRUE(all_finite(g.normal));
  EXPECT_TRUE(all_finite(g.angle_defect));
  EXPECT_TRUE(all_finite(g.rho));
  EXPECT_TRUE(all_finite(g.cotan_weight));
  ASSERT_EQ(g.corner_angles.rows(), t.num_faces);
  ASSERT_EQ(g.rho.size(), t.num_edges);
  ASSERT_EQ(g.cotan_weight.size(), t.num_edges);
  ASSERT_EQ(g.angle_defect.size(), t.num_vertices);
  int bad_sum = 0, bad_frame = 0, bad_angle = 0;
  double worst_sum = 0;
  for (int f = 0; f < t.num_faces; ++f) {
    const double s = g.corner_angles.row(f).sum();
    worst_sum = std::max(worst_sum, std::abs(s - kPi));
    bad_sum += !(std::abs(s - kPi) <= 1e-12);
    for (int k = 0; k < 3; ++k) bad_angle += !(g.corner_angles(f, k) >= 0 && g.corner_angles(f, k) <= kPi);
    const Eigen::Vector3d x = g.frame_x.row(f), y = g.frame_y.row(f), n = g.normal.row(f);
    bad_frame += !(std::abs(x.norm() - 1) < 1e-12 && std::abs(y.norm() - 1) < 1e-12 && std::abs(n.norm() - 1) < 1e-12 &&
                   std::abs(x.dot(y)) < 1e-12 && std::abs(x.dot(n)) < 1e-12 && std::abs(y.dot(n)) < 1e-12);
  }
  EXPECT_EQ(bad_sum, 0) << "faces whose corner angles do not sum to π (worst error " << worst_sum << ")";
  EXPECT_EQ(bad_angle, 0) << "corner angles outside [0, π]";
  EXPECT_EQ(bad_frame, 0) << "faces without an orthonormal frame";
  int bad_edge = 0;
  for (int e = 0; e < t.num_edges; ++e) {
    bad_edge += !(g.cotan_weight(e) >= 0);
    bad_edge += !(g.rho(e) > -kPi && g.rho(e) <= kPi);
    if (t.is_boundary_edge(e)) bad_edge += g.rho(e) != 0 || g.cotan_weight(e) != 0;
  }
  EXPECT_EQ(bad_edge, 0) << "edges with negative weight, ρ outside (−π, π], or non-zero ρ/weight on the boundary";
  std::vector<double> defect(t.components.size(), 0.0);
  for (int v = 0; v < t.num_vertices; ++v) {
    if (t.vertex_component[v] < 0) {
      EXPECT_EQ(g.angle_defect(v), 0.0) << "unreferenced vertex " << v;
      continue;
    }
    defect[t.vertex_component[v]] += g.angle_defect(v);
  }
  for (size_t c = 0; c < t.components.size(); ++c)
    EXPECT_NEAR(defect[c], 2 * kPi * t.components[c].euler_characteristic, gb_tol) << "Gauss–Bonnet on component " << c;
}

Eigen::VectorXd edge_values_on_original(const Topology& original, const Topology& renumbered, const Eigen::VectorXd& x,
                                        const std::vector<int>& vertex_perm) {
  std::map<std::pair<int, int>, double> by_pair;
  for (int e = 0; e < renumbered.num_edges; ++e) by_pair[{renumbered.edge_vertices(e, 0), renumbered.edge_vertices(e, 1)}] = x(e);
  Eigen::VectorXd out(original.num_edges);
  for (int e = 0; e < original.num_edges; ++e) {
    const int a = vertex_perm[original.edge_vertices(e, 0)], b = vertex_perm[original.edge_vertices(e, 1)];
    out(e) = (a < b ? 1 : -1) * by_pair.at({std::min(a, b), std::max(a, b)});
  }
  return out;
}

double max_field_difference(const Geometry& original, const Field& a, const Geometry& renumbered, const Field& b,
                            const std::vector<int>& face_perm) {
  double worst = 0;
  for (int f = 0; f < a.angle.size(); ++f) {
    const Eigen::Vector3d d = renumbered.direction_in_face(face_perm[f], b.angle(face_perm[f]));
    worst = std::max(worst, std::abs(reduce_angle(original.angle_in_face(f, d) - a.angle(f), a.N)));
  }
  return worst;
}

std::vector<int> vertex_ring(const Topology& t, int v, int distance) {
  std::vector<int> depth(t.num_vertices, -1), frontier{v};
  depth[v] = 0;
  for (int d = 1; d <= distance; ++d) {
    std::vector<int> next;
    for (int x : frontier)
      for (int a = t.vertex_edge_offsets[x]; a < t.vertex_edge_offsets[x + 1]; ++a) {
        const int e = t.vertex_edges[a];
        const int u = t.edge_vertices(e, 0) == x ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
        if (depth[u] < 0) depth[u] = d, next.push_back(u);
      }
    frontier.swap(next);
  }
  std::sort(frontier.begin(), frontier.end());
  return frontier;
}

std::map<int, std::string> read_singularity_texts(const std::string& path) {
  std::map<int, std::string> out;
  for (const std::string& line : lines_of(slurp(path))) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    int v = 0;
    std::string index;
    s >> v >> index;
    out[v] = index;
  }
  return out;
}

}  // namespace trivcon::test
