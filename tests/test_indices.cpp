// SPDX-License-Identifier: MIT
// Tests of trivcon/indices.h: parsing indices, specs and singularity files (plain and Directional's
// .sings), formatting, and validating a prescription against a mesh, with the exact messages.
#include "trivcon/indices.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

using test::error_of;
using test::topo;
using test::write_text;

// Reads the singularity file `name` holding `text` into a prescription of symmetry N.
IndexPrescription read_text(const std::string& name, const std::string& text, int N, std::string* path = nullptr) {
  const std::string file = test::temp_file(name);
  write_text(file, text);
  if (path) *path = file;
  IndexPrescription p;
  p.N = N;
  read_singularities(file, p);
  return p;
}

// The message reading `text` as the singularity file `name` (N = 4) fails with, the file's path as "FILE".
std::string file_error(const std::string& name, const std::string& text, int N = 4) {
  const std::string file = test::temp_file(name);
  write_text(file, text);
  IndexPrescription p;
  p.N = N;
  std::string message = error_of([&] { read_singularities(file, p); });
  for (size_t at; (at = message.find(file)) != std::string::npos;) message.replace(at, file.size(), "FILE");
  return message;
}

std::string validation_error(const Topology& t, int generators, const IndexPrescription& p) {
  return error_of([&] { validate_prescription(t, generators, p); });
}

TEST(Indices, Parsing) {
  EXPECT_EQ(parse_index("1/4", 4, "x"), 1);
  EXPECT_EQ(parse_index("-1/2", 4, "x"), -2);
  EXPECT_EQ(parse_index("3", 4, "x"), 12);
  EXPECT_EQ(parse_index("+2/8", 4, "x"), 1);
  EXPECT_EQ(format_index(-2, 4), "-1/2");
  EXPECT_EQ(format_index(8, 4), "2");
  EXPECT_EQ(format_index(0, 4), "0");
  try {
    parse_index("1/3", 4, "--sing 5:1/3");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "--sing 5:1/3: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)");
  }
  EXPECT_THROW(parse_index("abc", 4, "x"), Error);
  EXPECT_THROW(parse_index("1/0", 4, "x"), Error);
  EXPECT_THROW(parse_index("", 4, "x"), Error);
}

TEST(Indices, ParseIndexEdgeCases) {
  EXPECT_EQ(parse_index(" 3/6 ", 2, "x"), 1);  // surrounding blanks, a fraction that is not reduced
  EXPECT_EQ(parse_index("-0", 4, "x"), 0);
  EXPECT_EQ(parse_index("5", 1, "x"), 5);
  const std::string malformed = " (expected an integer or a fraction p/q, q > 0)";
  EXPECT_EQ(error_of([] { parse_index("1/-2", 4, "here"); }), "here: malformed index '1/-2'" + malformed);
  EXPECT_EQ(error_of([] { parse_index("1.5", 4, "here"); }), "here: malformed index '1.5'" + malformed);
  EXPECT_EQ(error_of([] { parse_index("99999999999", 4, "here"); }), "here: index '99999999999' is too large");
  EXPECT_EQ(error_of([] { parse_index("1/2", 1, "here"); }), "here: index 1/2 is not a multiple of 1/1 (use -N to change the symmetry)");
  // Within the parts' range but not in int once multiplied by N (it used to wrap around to a negative sum).
  EXPECT_EQ(error_of([] { parse_index("1000000000", 4, "here"); }), "here: index 1000000000 is too large (|index| at most 250000000 with N = 4)");
  EXPECT_EQ(parse_index("250000000", 4, "x"), 1000000000);
}

// Indices that each fit but whose sum on a component would not: refused before any sum is formed in int.
TEST(Indices, IndicesWhoseSumWouldOverflowAreRefused) {
  const Mesh m = make_disk(4, 6);
  const Topology t = test::topo(m);
  IndexPrescription p;
  p.N = 4;
  p.vertex = {{0, 1000000000}, {1, 1000000000}, {2, 1000000000}};
  EXPECT_EQ(error_of([&] { validate_prescription(t, 0, p); }),
            "the indices on component 0 are too large: their magnitudes add up to more than 1000000000/4");
}

TEST(Indices, FormatIndexGivesReducedFractionsThatParseBack) {
  EXPECT_EQ(format_index(6, 4), "3/2");
  EXPECT_EQ(format_index(-3, 6), "-1/2");
  EXPECT_EQ(format_index(4, 4), "1");
  EXPECT_EQ(format_index(-8, 4), "-2");
  EXPECT_EQ(format_index(1, 1), "1");
  EXPECT_EQ(format_index(5, 10), "1/2");
  int bad = 0;
  for (int N = 1; N <= 8; ++N)
    for (int n = -20; n <= 20; ++n) bad += parse_index(format_index(n, N), N, "x") != n;
  EXPECT_EQ(bad, 0);
}

TEST(Indices, CommandLineSpecs) {
  IndexPrescription p;
  p.N = 4;
  add_vertex_index("12:1/4", p);
  add_vertex_index("+3:-1", p);
  add_generator_index("1:-1/2", p);
  add_loop_index("0:1", p);
  EXPECT_EQ(p.vertex, (std::map<int, int>{{3, -4}, {12, 1}}));
  EXPECT_EQ(p.generator, (std::map<int, int>{{1, -2}}));
  EXPECT_EQ(p.loop, (std::map<int, int>{{0, 4}}));
  EXPECT_EQ(error_of([&] { add_vertex_index("0", p); }), "--sing '0': expected ID:INDEX, e.g. 12:1/4");
  EXPECT_EQ(error_of([&] { add_vertex_index("12:1", p); }), "--sing 12:1: vertex 12 is given twice");
  EXPECT_EQ(error_of([&] { add_vertex_index("-1:1", p); }), "--sing -1:1: malformed vertex id '-1'");
  EXPECT_EQ(error_of([&] { add_vertex_index("5:1/3", p); }),
            "--sing 5:1/3: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)");
  EXPECT_EQ(error_of([&] { add_generator_index("1:1", p); }), "--generator 1:1: generator 1 is given twice");
  EXPECT_EQ(error_of([&] { add_generator_index("g:1", p); }), "--generator g:1: malformed generator id 'g'");
  EXPECT_EQ(error_of([&] { add_loop_index("x:1", p); }), "--boundary x:1: malformed boundary loop id 'x'");
  EXPECT_EQ(error_of([&] { add_loop_index("2", p); }), "--boundary '2': expected ID:INDEX, e.g. 12:1/4");
  EXPECT_EQ(p.vertex.size(), 2u) << "a failed spec must not add anything";
}

// One "VERTEX INDEX" per line: integers and fractions p/q in units of 1/N, '#' comments, blank lines,
// CRLF line ends; added to what the prescription already holds.
TEST(Indices, PlainSingularityFile) {
  const IndexPrescription p = read_text("poles.txt", "# singularities\n12 1/4\n  3 -1   # a saddle\n\n7 +2/8\r\n40 0\n99 3/2", 4);
  EXPECT_EQ(p.vertex, (std::map<int, int>{{3, -4}, {7, 1}, {12, 1}, {40, 0}, {99, 6}}));
  EXPECT_TRUE(p.generator.empty() && p.loop.empty());
  IndexPrescription q;
  q.N = 2;
  q.vertex[5] = 1;
  const std::string file = test::temp_file("more.txt");
  write_text(file, "6 1/2\n");
  read_singularities(file, q);
  EXPECT_EQ(q.vertex, (std::map<int, int>{{5, 1}, {6, 1}}));
  EXPECT_EQ(error_of([&] { read_singularities(file, q); }), file + ":1: vertex 6 is given twice");
}

// Directional's .sings: "N count", then "vertex n" meaning n/N. A cross field's eight corners of a cube
// are +1/4 each: as .sings with N = 4 they read as n = 1 in a prescription of N = 4, 2 with N = 8, and
// they satisfy Gauss-Bonnet on the cube; with N = 2 they are not multiples of 1/2.
TEST(Indices, DirectionalSingsFileOfTheCubeCorners) {
  const Mesh cube = make_cube_sphere(3, false);
  const std::vector<int> corners = test::vertices_of_valence(cube, 3);
  ASSERT_EQ(corners.size(), 8u);
  std::string sings = "4 8\n", plain;
  for (int v : corners) sings += std::to_string(v) + " 1\n", plain += std::to_string(v) + " 1/4\n";
  std::string path;
  const IndexPrescription p4 = read_text("cube.sings", sings, 4, &path);
  ASSERT_EQ(p4.vertex.size(), 8u);
  for (int v : corners) EXPECT_EQ(p4.vertex.at(v), 1) << "corner " << v;
  EXPECT_EQ(p4.vertex, read_text("cube.txt", plain, 4).vertex) << "the .sings file and the plain one say the same";
  EXPECT_EQ(validation_error(topo(cube), 0, p4), "<no error>");
  const IndexPrescription p8 = read_text("cube.sings", sings, 8);
  for (int v : corners) EXPECT_EQ(p8.vertex.at(v), 2) << "corner " << v;
  EXPECT_EQ(file_error("cube.sings", sings, 2), "FILE:2: index 1/4 is not a multiple of 1/2 (use -N to change the symmetry)");
  // N = 1 in the file: whole indices; negative ones; comments.
  EXPECT_EQ(read_text("poles.sings", "# two poles\n1 2\n0 1\n85 -1\n", 4).vertex, (std::map<int, int>{{0, 4}, {85, -4}}));
}

TEST(Indices, SingularityFileErrorsNameTheLine) {
  const std::string malformed = " (expected an integer or a fraction p/q, q > 0)";
  const struct {
    const char *name, *text;
    std::string message;
  } cases[] = {
      {"a.txt", "# poles\n0 1\n\n85 x\n", "FILE:4: malformed index 'x'" + malformed},
      {"a.txt", "0 1\n85 1 extra\n", "FILE:2: expected two fields, got '85 1 extra'"},
      {"a.txt", "0 1\n# comment\n85\n", "FILE:3: expected two fields, got '85'"},
      {"a.txt", "0 1\n0 1\n", "FILE:2: vertex 0 is given twice"},
      {"a.txt", "0 1\n-3 1\n", "FILE:2: malformed vertex id '-3'"},
      {"a.txt", "0 1\n5 1/3\n", "FILE:2: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)"},
      {"a.txt", "\n\n0 1/0\n", "FILE:3: malformed index '1/0'" + malformed},
      {"a.sings", "1 3\n0 1\n85 1\n", "FILE: the header announces 3 singularities but the file lists 2"},
      {"a.sings", "# nothing\n\n", "FILE: empty .sings file (expected the header 'N count')"},
      {"a.sings", "# header\nx 2\n0 1\n", "FILE:2: expected the header 'N count' of a .sings file"},
      {"a.sings", "0 2\n", "FILE:1: expected the header 'N count' of a .sings file"},
      {"a.sings", "4 2\n0 1\n0 1\n", "FILE:3: vertex 0 is given twice"},
  };
  for (const auto& c : cases) EXPECT_EQ(file_error(c.name, c.text), c.message) << c.text;
  const std::string missing = test::temp_file("none.txt");
  IndexPrescription p;
  EXPECT_EQ(error_of([&] { read_singularities(missing, p); }), "cannot open '" + missing + "': No such file or directory");
}

TEST(Indices, ValidationErrors) {
  const Mesh disk = make_disk(3, 6);  // 37 vertices; 19..36 on the boundary (loop 0)
  const Topology td = topo(disk);
  IndexPrescription p;
  p.N = 4;
  p.vertex[37] = 1;
  EXPECT_EQ(validation_error(td, 0, p), "singular vertex 37 out of range (mesh has 37 vertices)");
  p.vertex = {{-1, 1}};
  EXPECT_EQ(validation_error(td, 0, p), "singular vertex -1 out of range (mesh has 37 vertices)");
  p.vertex = {{36, 1}};
  EXPECT_EQ(validation_error(td, 0, p),
            "singular vertex 36 is on boundary loop 0: a boundary vertex has no dual cycle (set the loop's index with --boundary instead)");
  p.vertex = {{0, 1}};
  p.loop[1] = 1;
  EXPECT_EQ(validation_error(td, 0, p), "boundary loop 1 out of range (the mesh has 1 boundary loops)");
  p.loop = {{0, 1}};  // every loop prescribed: vertices and loops must sum to χ = 1, i.e. 4/4
  EXPECT_EQ(validation_error(td, 0, p),
            "the indices on component 0 (vertices and boundary loops) sum to 1/2, but Gauss-Bonnet needs its "
            "Euler characteristic 1");
  p.loop = {{0, 3}};
  EXPECT_EQ(validation_error(td, 0, p), "<no error>");
  p.loop.clear();  // the loop free: no sum to check
  p.vertex = {{0, 7}};
  EXPECT_EQ(validation_error(td, 0, p), "<no error>");
  p.N = 0;
  EXPECT_EQ(validation_error(td, 0, p), "the symmetry N must be at least 1 (got 0)");

  Mesh extra = make_icosphere(1);  // 42 vertices and one more that no face uses
  extra.V.conservativeResize(43, 3);
  extra.V.row(42).setZero();
  IndexPrescription q;
  q.N = 1;
  q.vertex = {{0, 1}, {42, 1}};
  EXPECT_EQ(validation_error(topo(extra), 0, q), "singular vertex 42 is not used by any face");
  q.vertex = {{0, 1}, {5, 1}};
  q.generator[0] = 1;
  EXPECT_EQ(validation_error(topo(extra), 0, q), "generator 0 out of range (the mesh has 0 generators)");
  q.generator = {{-1, 1}};
  EXPECT_EQ(validation_error(topo(make_torus(6, 5)), 2, q), "generator -1 out of range (the mesh has 2 generators)");

  // Closed components: the sum of the vertex indices, named as a fraction, must be χ; per component.
  const Mesh spheres = concatenate({make_icosphere(1), make_icosphere(1)});
  const Topology ts = topo(spheres);
  IndexPrescription r;
  r.N = 4;
  for (int v = 0; v < 8; ++v) r.vertex[v] = 1;
  EXPECT_EQ(validation_error(ts, 0, r), "the indices on component 1 sum to 0, but Gauss-Bonnet needs its Euler characteristic 2");
  for (int v = 42; v < 48; ++v) r.vertex[v] = 1;
  r.vertex[48] = -1;
  EXPECT_EQ(validation_error(ts, 0, r), "the indices on component 1 sum to 5/4, but Gauss-Bonnet needs its Euler characteristic 2");
  r.vertex[48] = 2;
  EXPECT_EQ(validation_error(ts, 0, r), "<no error>");
  r.vertex[0] = -5;
  EXPECT_EQ(validation_error(ts, 0, r), "the indices on component 0 sum to 1/2, but Gauss-Bonnet needs its Euler characteristic 2");

  // Several loops: only when all are prescribed is the sum checked.
  const Topology tg = topo(make_holed_grid(9, 2));  // χ = −1, three loops
  IndexPrescription s;
  s.N = 1;
  s.loop = {{0, 5}, {1, 5}};
  EXPECT_EQ(validation_error(tg, 0, s), "<no error>");
  s.loop[2] = 5;
  EXPECT_EQ(validation_error(tg, 0, s),
            "the indices on component 0 (vertices and boundary loops) sum to 15, but Gauss-Bonnet needs its "
            "Euler characteristic -1");
}

}  // namespace
}  // namespace trivcon
