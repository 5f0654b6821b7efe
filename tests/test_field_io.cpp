// SPDX-License-Identifier: MIT
// Tests of trivcon/field_io.h: every field format reads back to the field written, the connection file
// holds the library's x, the lines file draws the field, and the readers name the file and line of each
// problem.
#include "trivcon/field_io.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "support.h"
#include "trivcon/design.h"
#include "trivcon/generate.h"

namespace trivcon {
namespace {

using test::error_of;
using test::slurp;
using test::temp_file;
using test::write_text;

std::vector<std::string> data_lines(const std::string& text) {  // without '#' comments
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') out.push_back(line);
  return out;
}

// A designed field: N = 4 on a cube sphere (its eight corners), N = 2 on a torus, N = 1 on a disk.
struct Designed {
  std::string name;
  Mesh mesh;
  std::unique_ptr<FieldDesigner> designer;
  Design design;
};

std::vector<Designed> designed_fields() {
  std::vector<Designed> out;
  auto add = [&](const std::string& name, const Mesh& m, int N, const std::vector<int>& singular) {
    auto d = std::make_unique<FieldDesigner>(m.V, m.F);
    IndexPrescription p;
    p.N = N;
    for (int v : singular) p.vertex[v] = 1;
    Design design = d->design(p);
    out.push_back({name, m, std::move(d), std::move(design)});
  };
  const Mesh cube = make_cube_sphere(5, true);
  add("cube N=4", cube, 4, test::vertices_of_valence(cube, 3));
  add("torus N=2", make_torus(16, 8), 2, {});
  add("disk N=1", make_disk(4, 6), 1, {});
  return out;
}

// The message of `action`, the file's path replaced by "FILE".
std::string message_of(const std::function<void()>& action, const std::string& path) {
  std::string m = error_of(action);
  for (size_t at; (at = m.find(path)) != std::string::npos;) m.replace(at, path.size(), "FILE");
  return m;
}

TEST(FieldIo, EveryFormatReadsBackToTheField) {
  for (const Designed& c : designed_fields()) {
    SCOPED_TRACE(c.name);
    const Geometry& g = c.designer->geometry();
    const Field& field = c.design.field;
    const MatrixX3d directions = field_directions(g, field);
    const int nF = static_cast<int>(c.mesh.F.rows());
    for (const auto& [file, N_said] : std::vector<std::pair<std::string, int>>{
             {"field.txt", field.N}, {"field.dat", field.N}, {"field.rawfield", field.N}, {"field.ply", 0}}) {
      SCOPED_TRACE(file);
      const std::string path = temp_file(file);
      write_field(path, c.mesh.V, c.mesh.F, g, field);
      int N = -1;
      const MatrixX3d back = read_field(path, nF, &N);
      EXPECT_EQ(N, N_said);
      EXPECT_TRUE(back == directions) << "not the same doubles (17 significant digits, or binary)";
      const Field angles = field_from_directions(g, back, field.N);
      double worst = 0;
      for (int f = 0; f < nF; ++f) worst = std::max(worst, std::abs(wrap_angle(angles.angle(f) - field.angle(f))));
      EXPECT_LE(worst, 1e-12);
    }
  }
}

// The text header, and the N directions of a .rawfield: the first one rotated by 2πk/N about the normal.
TEST(FieldIo, TextHeaderAndTheRawfieldsNDirections) {
  for (const Designed& c : designed_fields()) {
    SCOPED_TRACE(c.name);
    const Geometry& g = c.designer->geometry();
    const int N = c.design.field.N, nF = static_cast<int>(c.mesh.F.rows());
    const std::string txt = temp_file("field.txt"), raw = temp_file("field.rawfield");
    write_field(txt, c.mesh.V, c.mesh.F, g, c.design.field);
    write_field(raw, c.mesh.V, c.mesh.F, g, c.design.field);
    std::istringstream header(slurp(txt));
    std::string l1, l2, l3;
    std::getline(header, l1), std::getline(header, l2), std::getline(header, l3);
    EXPECT_EQ(l1.rfind("# trivcon field", 0), 0u) << l1;
    EXPECT_EQ(l2, "# N " + std::to_string(N));
    EXPECT_EQ(l3, "# faces " + std::to_string(nF));
    const std::vector<std::string> lines = data_lines(slurp(raw));
    ASSERT_EQ(static_cast<int>(lines.size()), nF + 1);
    EXPECT_EQ(lines[0], std::to_string(N) + " " + std::to_string(nF));
    double worst = 0;
    for (int f = 0; f < nF; ++f) {
      std::istringstream in(lines[f + 1]);
      std::vector<Eigen::Vector3d> v(N);
      for (auto& d : v) in >> d.x() >> d.y() >> d.z();
      ASSERT_TRUE(in) << "line " << f + 2;
      std::string rest;
      EXPECT_FALSE(in >> rest) << "more than 3N numbers on line " << f + 2;
      for (int k = 0; k < N; ++k) {
        const Eigen::AngleAxisd turn(kTwoPi * k / N, g.normal.row(f).transpose());
        worst = std::max(worst, (v[k] - turn * v[0]).norm());
      }
    }
    EXPECT_LE(worst, 1e-12);
  }
}

// One "i j x" per interior edge, i < j, sorted, with exactly the library's x; read back exactly.
TEST(FieldIo, ConnectionFileHoldsTheLibrarysX) {
  for (const Designed& c : designed_fields()) {
    SCOPED_TRACE(c.name);
    const Topology& t = c.designer->topology();
    const Eigen::VectorXd& x = c.design.connection.x;
    const std::string path = temp_file("connection.txt");
    write_connection(path, t, x, c.design.field.N);
    const std::string text = slurp(path);
    EXPECT_EQ(text.rfind("# trivcon connection", 0), 0u);
    EXPECT_NE(text.find("\n# N " + std::to_string(c.design.field.N) + "\n"), std::string::npos);
    std::map<std::pair<int, int>, int> edge_of;
    int interior = 0;
    for (int e = 0; e < t.num_edges; ++e)
      if (!t.is_boundary_edge(e)) edge_of[{t.edge_vertices(e, 0), t.edge_vertices(e, 1)}] = e, ++interior;
    std::vector<std::pair<int, int>> listed;
    int wrong = 0;
    for (const std::string& line : data_lines(text)) {
      std::istringstream in(line);
      int i, j;
      std::string value;
      ASSERT_TRUE(in >> i >> j >> value) << line;
      listed.emplace_back(i, j);
      const auto it = edge_of.find({i, j});
      ASSERT_NE(it, edge_of.end()) << "not an interior edge with i < j: " << line;
      wrong += std::stod(value) != x(it->second);
    }
    EXPECT_EQ(wrong, 0) << "values that are not exactly x";
    EXPECT_EQ(static_cast<int>(listed.size()), interior);
    EXPECT_TRUE(std::adjacent_find(listed.begin(), listed.end(), std::greater_equal<>()) == listed.end()) << "not strictly increasing";
    const Eigen::VectorXd back = read_connection(path, t);
    EXPECT_TRUE(back == x);
    EXPECT_LE(max_transport_mismatch(t, c.designer->geometry(), back, c.design.field), 1e-9);
  }
}

// N segments per face from its centroid, 0.4 × its mean edge length long, along the N directions.
TEST(FieldIo, LinesFileDrawsTheField) {
  const std::vector<Designed> fields = designed_fields();
  const Designed& c = fields[1];  // torus, N = 2
  const Geometry& g = c.designer->geometry();
  const int N = c.design.field.N, nF = static_cast<int>(c.mesh.F.rows());
  const std::string path = temp_file("lines.obj");
  write_field_lines(path, c.mesh.V, c.mesh.F, g, c.design.field);
  std::vector<Eigen::Vector3d> v;
  std::vector<std::pair<long, long>> l;
  for (const std::string& line : data_lines(slurp(path))) {
    std::istringstream in(line.substr(2));
    if (line.rfind("v ", 0) == 0) {
      Eigen::Vector3d p;
      in >> p.x() >> p.y() >> p.z();
      v.push_back(p);
    } else if (line.rfind("l ", 0) == 0) {
      long a, b;
      in >> a >> b;
      l.emplace_back(a, b);
    }
  }
  ASSERT_EQ(static_cast<int>(v.size()), nF * (N + 1));
  ASSERT_EQ(static_cast<int>(l.size()), nF * N);
  double worst = 0;
  for (int f = 0; f < nF; ++f) {
    const Eigen::Vector3d p0 = c.mesh.V.row(c.mesh.F(f, 0)), p1 = c.mesh.V.row(c.mesh.F(f, 1)), p2 = c.mesh.V.row(c.mesh.F(f, 2));
    const double length = 0.4 * ((p1 - p0).norm() + (p2 - p1).norm() + (p0 - p2).norm()) / 3;
    for (int k = 0; k < N; ++k) {
      const auto [a, b] = l[f * N + k];
      ASSERT_EQ(a, 1 + f * (N + 1));
      ASSERT_EQ(b, a + 1 + k);
      const Eigen::Vector3d expected = length * g.direction_in_face(f, c.design.field.angle(f) + kTwoPi * k / N);
      worst = std::max({worst, (v[a - 1] - (p0 + p1 + p2) / 3).norm(), (v[b - 1] - v[a - 1] - expected).norm()});
    }
  }
  EXPECT_LE(worst, 1e-7);  // 9 significant digits
}

TEST(FieldIo, FieldReaderErrorsNameTheLine) {
  const Mesh m = make_icosphere(0);  // 20 faces
  auto error = [](const std::string& name, const std::string& text, int faces = 20) {
    const std::string path = temp_file(name);
    write_text(path, text);
    return message_of([&] { read_field(path, faces); }, path);
  };
  std::string rows;
  for (int f = 0; f < 19; ++f) rows += "1 0 0\n";
  const std::string head = "# trivcon field\n# N 1\n# faces 20\n";
  EXPECT_EQ(error("a.txt", head + rows), "FILE: has 19 directions, the mesh has 20 faces");
  EXPECT_EQ(error("a.txt", head + rows + "0 1 0\r\n\n# comment\n0 0 1\n"), "FILE:26: more lines than the mesh has faces (20)");
  EXPECT_EQ(error("a.txt", head + "1 0 0\n1 2\n" + rows), "FILE:5: expected 3 numbers, got 2");
  EXPECT_EQ(error("a.txt", head + "1 0 0\n\n1 x 0\n" + rows), "FILE:6: malformed number 'x'");
  EXPECT_EQ(error("a.txt", "nan 0 0\n" + rows), "FILE:1: malformed number 'nan'");
  EXPECT_EQ(error("a.txt", "1 0 0\n" + rows, 20), "<no error>");

  std::string raw_rows;
  for (int f = 0; f < 20; ++f) raw_rows += "1 0 0 -1 0 0\n";
  EXPECT_EQ(error("a.rawfield", ""), "FILE: empty file (expected the header 'N F')");
  EXPECT_EQ(error("a.rawfield", "# only a comment\n2\n"), "FILE:2: expected 2 numbers, got 1");
  EXPECT_EQ(error("a.rawfield", "0 20\n"), "FILE:1: malformed N in the header");
  EXPECT_EQ(error("a.rawfield", "1.5 20\n"), "FILE:1: malformed N in the header");
  EXPECT_EQ(error("a.rawfield", "2 19\n" + raw_rows), "FILE:1: the field has 19 faces, the mesh has 20");
  EXPECT_EQ(error("a.rawfield", "2 20\n1 0 0 -1 0 0\n1 0 0\n" + raw_rows), "FILE:3: expected 6 numbers, got 3");
  EXPECT_EQ(error("a.rawfield", "2 20\n" + raw_rows.substr(0, 5 * 13)), "FILE: truncated after line 6 (face 5)");
  EXPECT_EQ(error("a.rawfield", "2 20\n" + raw_rows + "1 0 0 -1 0 0\n"), "FILE:22: more lines than faces");
  EXPECT_EQ(error("a.rawfield", "2 20\n" + raw_rows), "<no error>");

  EXPECT_EQ(error("a.ply", "ply\nformat ascii 1.0\nend_header\n"),
            "FILE: not a field PLY written by trivcon (expected face properties fx fy fz after vertex_indices)");
  const FieldDesigner d(m.V, m.F);
  Field f;
  f.N = 1;
  f.angle = Eigen::VectorXd::Zero(20);
  const std::string ply = temp_file("ok.ply");
  write_field(ply, m.V, m.F, d.geometry(), f);
  EXPECT_EQ(message_of([&] { read_field(ply, 80); }, ply), "FILE: has 20 faces, the mesh has 80");
  // Cut inside face 7's direction: the header, 12 vertices of 24 bytes, 7 faces of 1 + 12 + 24 bytes, then 5.
  const std::string bytes = slurp(ply);
  const size_t start = bytes.find("end_header\n") + 11 + 12 * 24, cut = start + 7 * 37 + 5;
  EXPECT_EQ(error("cut.ply", bytes.substr(0, cut)), "FILE: truncated at byte " + std::to_string(start + 7 * 37 + 13) + " (face 7)");
  EXPECT_EQ(error("cut.ply", bytes.substr(0, start + 7 * 37)), "FILE: truncated at byte " + std::to_string(start + 7 * 37) + " (face 7)");
  // A direction that is not finite is refused, as in the text formats (found by fuzz_field_ply).
  std::string nan_bytes = bytes;
  const double not_a_number = std::nan("");
  std::memcpy(&nan_bytes[start + 3 * 37 + 13 + 8], &not_a_number, 8);  // fy of face 3
  EXPECT_EQ(error("nan.ply", nan_bytes), "FILE: non-finite direction in face 3 (at byte " + std::to_string(start + 3 * 37 + 13) + ")");
  const std::string missing = temp_file("none.txt");
  EXPECT_EQ(message_of([&] { read_field(missing, 20); }, missing), "cannot open 'FILE': No such file or directory");
}

TEST(FieldIo, ConnectionReaderErrorsNameTheLine) {
  const Mesh m = make_disk(2, 5);  // 16 vertices, boundary 6..15; interior edges include (0, 1) and (1, 2)
  const Topology t = test::topo(m);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(t.num_edges, 0.01, 0.5);
  const std::string good = temp_file("good.txt");
  write_connection(good, t, x, 1);
  const std::vector<std::string> lines = data_lines(slurp(good));
  std::string all;
  for (const std::string& line : lines) all += line + "\n";
  int boundary = 0;
  while (!t.is_boundary_edge(boundary)) ++boundary;
  const std::string bi = std::to_string(t.edge_vertices(boundary, 0)), bj = std::to_string(t.edge_vertices(boundary, 1));
  auto error = [&](const std::string& text) {
    const std::string path = temp_file("c.txt");
    write_text(path, text);
    return message_of([&] { read_connection(path, t); }, path);
  };
  EXPECT_EQ(error("# N 1\n" + all), "<no error>");
  EXPECT_EQ(error(all + bi + " " + bj + " 0.1\n"),
            "FILE:" + std::to_string(lines.size() + 1) + ": (" + bi + ", " + bj + ") is not an interior edge with i < j");
  EXPECT_EQ(error("1 0 0.5\n" + all), "FILE:1: (1, 0) is not an interior edge with i < j");
  EXPECT_EQ(error("# header\n\n0 99 0.5\n" + all), "FILE:3: (0, 99) is not an interior edge with i < j");
  int i3, j3;
  std::istringstream(lines[3]) >> i3 >> j3;
  EXPECT_EQ(error(all + lines[3] + "\n"),
            "FILE:" + std::to_string(lines.size() + 1) + ": edge (" + std::to_string(i3) + ", " + std::to_string(j3) + ") is listed twice");
  std::string without_first;
  for (size_t k = 1; k < lines.size(); ++k) without_first += lines[k] + "\n";
  int i0, j0;  // the edge of the first line, the only one missing
  std::istringstream(lines[0]) >> i0 >> j0;
  EXPECT_EQ(error(without_first), "FILE: interior edge (" + std::to_string(i0) + ", " + std::to_string(j0) + ") is missing");
  std::string without_two = lines[0] + "\n";
  for (size_t k = 3; k < lines.size(); ++k) without_two += lines[k] + "\n";
  int first = -1;  // of several missing, the first in edge id order is named
  for (int e = 0; e < t.num_edges && first < 0; ++e) {
    if (t.is_boundary_edge(e)) continue;
    for (size_t k : {1, 2}) {
      int i, j;
      std::istringstream(lines[k]) >> i >> j;
      if (t.edge_vertices(e, 0) == i && t.edge_vertices(e, 1) == j) first = e;
    }
  }
  ASSERT_GE(first, 0);
  EXPECT_EQ(error(without_two), "FILE: interior edge (" + std::to_string(t.edge_vertices(first, 0)) + ", " +
                                    std::to_string(t.edge_vertices(first, 1)) + ") is missing");
  EXPECT_EQ(error("0 1 x\n" + all), "FILE:1: malformed number 'x'");
  EXPECT_EQ(error("0 1\n" + all), "FILE:1: expected 3 numbers, got 2");
}

}  // namespace
}  // namespace trivcon
