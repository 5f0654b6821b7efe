// SPDX-License-Identifier: MIT
// Every documented option of `trivcon solve` and `trivcon check` end to end, through the real program
// (run_cli), on meshes generated here: the batch mode and its output names, boundary alignment, fixed
// directions from files, pictures, unit weights, the QR route, prescribed generator and loop indices, the
// connection file's values, Directional's .sings with N = 4, and the exact message (file and line, or byte)
// of every reader's errors. Bad input must exit with status 1 and one "trivcon: error: ..." line.
#include <iomanip>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support.h"
#include "trivcon/design.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"

namespace trivcon {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace test;  // run_cli, q, save, slurp, … (tests/support.h)
using Edge = std::pair<int, int>;

const std::string kError = "trivcon: error: ";

json read_json(const std::string& path) {
  try {
    return json::parse(slurp(path));
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << " is not JSON: " << e.what();
    return json::object();
  }
}

// Status 1 and exactly one line "trivcon: error: MESSAGE".
void expect_error(const CommandResult& r, const std::string& message, const std::string& what = "") {
  SCOPED_TRACE(what);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err, kError + message + "\n");
}
void expect_ok(const CommandResult& r, const std::string& what = "") {
  SCOPED_TRACE(what);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

// The connection file: (i, j) → x, and the N in its header.
std::map<Edge, double> read_connection_file(const std::string& path, int* N = nullptr) {
  std::map<Edge, double> x;
  for (const std::string& line : lines_of(slurp(path))) {
    if (line.rfind("# N ", 0) == 0 && N) *N = std::stoi(line.substr(4));
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    int i, j;
    double v;
    EXPECT_TRUE(s >> i >> j >> v) << line;
    EXPECT_TRUE(x.emplace(Edge{i, j}, v).second) << line;
  }
  return x;
}

// The .txt field file's directions (one row per face).
std::vector<Eigen::Vector3d> read_field_txt(const std::string& path) {
  std::vector<Eigen::Vector3d> out;
  for (const std::string& line : lines_of(slurp(path))) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Eigen::Vector3d d;
    EXPECT_TRUE(s >> d.x() >> d.y() >> d.z()) << line;
    out.push_back(d);
  }
  return out;
}

double reduce(double a, int N) {  // into (−π/N, π/N]
  const double period = 2 * kPi / N;
  a = std::fmod(a, period);
  if (a > period / 2) a -= period;
  if (a <= -period / 2) a += period;
  return a;
}

// Faces of a flat mesh (z = 0) with a boundary edge, and that edge's direction (as the face runs it).
std::map<int, Eigen::Vector3d> boundary_edges_of_faces(const Mesh& m) {
  std::map<Edge, int> count;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++count[{std::min(m.F(f, k), m.F(f, (k + 1) % 3)), std::max(m.F(f, k), m.F(f, (k + 1) % 3))}];
  std::map<int, Eigen::Vector3d> out;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
      if (count[{std::min(a, b), std::max(a, b)}] == 1) out[f] = (m.V.row(b) - m.V.row(a)).transpose();
    }
  return out;
}

// The sphere most tests use: 86 vertices (poles 0 and 85), 168 faces, χ = 2.
struct Sphere {
  std::string dir, mesh;
  explicit Sphere(const std::string& name) : dir(test::temp_dir(name)), mesh(save(dir, "sphere", make_uv_sphere(8, 12))) {}
};

// ---------------------------------------------------------------------------------------------
// --sing-batch

TEST(CliOptions, SingBatchDirectoryNamesTheOutputs) {
  const Sphere s("cli_options_batch_dir");
  fs::create_directories(s.dir + "/sings");
  fs::create_directories(s.dir + "/out.d");
  write_text(s.dir + "/sings/b.txt", "# two +1\n10 1\n60 1\n");
  write_text(s.dir + "/sings/a.txt", "0 1\n85 1\n");
  write_text(s.dir + "/sings/c.sings", "1 2\n0 1\n40 1\n");
  const CommandResult r = run_cli("solve " + q(s.mesh) + " --sing-batch " + q(s.dir + "/sings") + " --field-out " +
                                  q(s.dir + "/out.d/field.txt") + " --report " + q(s.dir + "/out.d/report.json") + " --connection-out " +
                                  q(s.dir + "/out.d/{name}-conn.txt") + " --lines-out " + q(s.dir + "/out.d/lines"));
  expect_ok(r, "batch");
  // Items in file-name order, each with its summary.
  const size_t a = r.out.find("== a\n"), b = r.out.find("== b\n"), c = r.out.find("== c\n");
  ASSERT_NE(a, std::string::npos) << r.out;
  ASSERT_NE(b, std::string::npos) << r.out;
  ASSERT_NE(c, std::string::npos) << r.out;
  EXPECT_LT(a, b);
  EXPECT_LT(b, c);
  // ".NAME" before the extension; {name} replaced; no extension (a dot only in the folder name): ".NAME" appended.
  for (const char* name : {"a", "b", "c"}) {
    SCOPED_TRACE(name);
    const std::string n = name;
    EXPECT_TRUE(fs::exists(s.dir + "/out.d/field." + n + ".txt"));
    EXPECT_TRUE(fs::exists(s.dir + "/out.d/report." + n + ".json"));
    EXPECT_TRUE(fs::exists(s.dir + "/out.d/" + n + "-conn.txt"));
    EXPECT_TRUE(fs::exists(s.dir + "/out.d/lines." + n));
    const json rep = read_json(s.dir + "/out.d/report." + n + ".json");
    EXPECT_EQ(rep["name"], n);
    EXPECT_EQ(rep["verified"], true);
  }
  for (const char* plain : {"field.txt", "report.json", "{name}-conn.txt", "lines"})
    EXPECT_FALSE(fs::exists(s.dir + "/out.d/" + plain)) << plain;
  EXPECT_EQ(std::distance(fs::directory_iterator(s.dir + "/out.d"), fs::directory_iterator()), 12);
  // Each item's singularities, and each field equal to a single solve of the same file.
  EXPECT_EQ(read_json(s.dir + "/out.d/report.a.json")["singularities"],
            json::parse(R"([{"vertex": 0, "index": "1"}, {"vertex": 85, "index": "1"}])"));
  EXPECT_EQ(read_json(s.dir + "/out.d/report.b.json")["singularities"],
            json::parse(R"([{"vertex": 10, "index": "1"}, {"vertex": 60, "index": "1"}])"));
  EXPECT_EQ(read_json(s.dir + "/out.d/report.c.json")["singularities"],
            json::parse(R"([{"vertex": 0, "index": "1"}, {"vertex": 40, "index": "1"}])"));
  for (const char* name : {"a", "b", "c"}) {
    SCOPED_TRACE(name);
    const std::string n = name, file = s.dir + "/sings/" + n + (n == "c" ? ".sings" : ".txt"), single = s.dir + "/single.txt";
    expect_ok(run_cli("solve " + q(s.mesh) + " -q -s " + q(file) + " --field-out " + q(single)));
    const std::vector<Eigen::Vector3d> one = read_field_txt(single), batch = read_field_txt(s.dir + "/out.d/field." + n + ".txt");
    ASSERT_EQ(one.size(), 168u);
    ASSERT_EQ(batch.size(), one.size());
    double worst = 0;
    for (size_t f = 0; f < one.size(); ++f) worst = std::max(worst, (one[f] - batch[f]).norm());
    EXPECT_LE(worst, 1e-12);
  }
  // The singularities of -s/--sing are replaced by each item's.
  expect_ok(run_cli("solve " + q(s.mesh) + " -q --sing 5:1 --sing-batch " + q(s.dir + "/sings") + " --report " + q(s.dir + "/r.json")));
  EXPECT_EQ(read_json(s.dir + "/r.a.json")["singularities"].size(), 2u);
}

TEST(CliOptions, SingBatchDirectoryErrors) {
  const Sphere s("cli_options_batch_dir_errors");
  fs::create_directories(s.dir + "/empty");
  expect_error(run_cli("solve " + q(s.mesh) + " --sing-batch " + q(s.dir + "/empty")),
               "--sing-batch " + s.dir + "/empty: the directory has no files");
  fs::create_directories(s.dir + "/bad");
  write_text(s.dir + "/bad/a.txt", "0 1\n85 1\n");
  write_text(s.dir + "/bad/b.txt", "# b\n\n0 1\n85 x\n");
  expect_error(run_cli("solve " + q(s.mesh) + " --sing-batch " + q(s.dir + "/bad")),
               s.dir + "/bad/b.txt:4: malformed index 'x' (expected an integer or a fraction p/q, q > 0)");
  // An item that breaks Gauss-Bonnet: every item is checked before anything is written.
  fs::create_directories(s.dir + "/gb");
  write_text(s.dir + "/gb/a.txt", "0 1\n85 1\n");
  write_text(s.dir + "/gb/b.txt", "0 1\n");
  expect_error(run_cli("solve " + q(s.mesh) + " --sing-batch " + q(s.dir + "/gb") + " --field-out " + q(s.dir + "/f.txt")),
               "batch item 'b': the indices on component 0 sum to 1, but Gauss-Bonnet needs its Euler characteristic 2");
  EXPECT_FALSE(fs::exists(s.dir + "/f.a.txt"));
  // Two files of one name (a.txt and a.sings) would write the same outputs.
  fs::create_directories(s.dir + "/twice");
  write_text(s.dir + "/twice/a.txt", "0 1\n85 1\n");
  write_text(s.dir + "/twice/a.sings", "1 2\n0 1\n85 1\n");
  expect_error(run_cli("solve " + q(s.mesh) + " --sing-batch " + q(s.dir + "/twice") + " --field-out " + q(s.dir + "/f.txt")),
               "--sing-batch " + s.dir + "/twice: files 'a.sings' and 'a.txt' have the same name 'a'");
  expect_error(run_cli("solve " + q(s.mesh) + " --sing-batch " + q(s.dir + "/none.jsonl")),
               "cannot open '" + s.dir + "/none.jsonl': No such file or directory");
}

TEST(CliOptions, SingBatchJsonLines) {
  const Sphere s("cli_options_batch_json");
  const std::string batch = s.dir + "/batch.jsonl";
  write_text(
      batch,
      "{\"name\": \"poles\", \"sing\": {\"0\": \"1\", \"85\": \"1\"}}\n\n  \n{\"name\": \"numbers\", \"sing\": {\"10\": 1, \"60\": 1}}\n");
  // {name} in a folder: the folders must exist (nothing is created; see UnwritableOutputNamesTheGivenPath).
  EXPECT_EQ(run_cli("solve " + q(s.mesh) + " -q --sing-batch " + q(batch) + " --field-out " + q(s.dir + "/{name}/field.txt")).status, 1);
  fs::create_directories(s.dir + "/poles");
  fs::create_directories(s.dir + "/numbers");
  expect_ok(run_cli("solve " + q(s.mesh) + " -q --sing-batch " + q(batch) + " --field-out " + q(s.dir + "/{name}/field.txt") +
                    " --report " + q(s.dir + "/report.json") + " --png " + q(s.dir + "/pic.png")));
  EXPECT_TRUE(fs::exists(s.dir + "/poles/field.txt"));
  EXPECT_TRUE(fs::exists(s.dir + "/numbers/field.txt"));
  EXPECT_TRUE(fs::exists(s.dir + "/pic.poles.png"));
  EXPECT_TRUE(fs::exists(s.dir + "/pic.numbers.png"));
  const json poles = read_json(s.dir + "/report.poles.json"), numbers = read_json(s.dir + "/report.numbers.json");
  EXPECT_EQ(poles["name"], "poles");
  EXPECT_EQ(numbers["name"], "numbers");
  EXPECT_EQ(poles["singularities"], json::parse(R"([{"vertex": 0, "index": "1"}, {"vertex": 85, "index": "1"}])"));
  EXPECT_EQ(numbers["singularities"], json::parse(R"([{"vertex": 10, "index": "1"}, {"vertex": 60, "index": "1"}])"));

  // Generators and loops per item (on a torus and an annulus), on top of the command line's.
  const std::string torus = save(s.dir, "torus", make_torus(12, 6)), annulus = save(s.dir, "annulus", make_annulus(3, 16));
  write_text(s.dir + "/t.jsonl", "{\"name\": \"g\", \"sing\": {}, \"generator\": {\"0\": \"1\"}}\n{\"name\": \"free\", \"sing\": {}}\n");
  expect_ok(
      run_cli("solve " + q(torus) + " -q --generator 1:0 --sing-batch " + q(s.dir + "/t.jsonl") + " --report " + q(s.dir + "/t.json")));
  const json g = read_json(s.dir + "/t.g.json"), free = read_json(s.dir + "/t.free.json");
  EXPECT_EQ(g["generators"][0]["index"], "1");
  EXPECT_EQ(g["generators"][0]["chosen"], false);
  EXPECT_EQ(g["generators"][1]["index"], "0");
  EXPECT_EQ(g["generators"][1]["chosen"], false);
  EXPECT_EQ(free["generators"][0]["chosen"], true);
  EXPECT_EQ(free["generators"][1]["index"], "0");
  EXPECT_EQ(free["generators"][1]["chosen"], false);
  write_text(s.dir + "/a.jsonl", "{\"name\": \"b\", \"sing\": {}, \"boundary\": {\"0\": \"1/2\", \"1\": \"-1/2\"}}\n");
  expect_ok(run_cli("solve " + q(annulus) + " -q -N 2 --sing-batch " + q(s.dir + "/a.jsonl") + " --report " + q(s.dir + "/a.json")));
  const json b = read_json(s.dir + "/a.b.json");
  EXPECT_EQ(b["boundary_loops"],
            json::parse(R"([{"id": 0, "index": "1/2", "chosen": false}, {"id": 1, "index": "-1/2", "chosen": false}])"));
}

// An output that cannot be written: the message should name the path the user gave.
TEST(CliOptions, UnwritableOutputNamesTheGivenPath) {
  const Sphere s("cli_options_unwritable");
  expect_error(run_cli("solve " + q(s.mesh) + " --sing 0:1 --sing 85:1 --field-out " + q(s.dir + "/no/field.txt")),
               "cannot write '" + s.dir + "/no/field.txt': No such file or directory");
  const std::string batch = s.dir + "/batch.jsonl";
  write_text(batch, "{\"name\": \"poles\", \"sing\": {\"0\": \"1\", \"85\": \"1\"}}\n");
  expect_error(run_cli("solve " + q(s.mesh) + " --sing-batch " + q(batch) + " --report " + q(s.dir + "/{name}/report.json")),
               "cannot write '" + s.dir + "/poles/report.json': No such file or directory");
}

TEST(CliOptions, SingBatchJsonLinesErrors) {
  const Sphere s("cli_options_batch_json_errors");
  const std::string path = s.dir + "/batch.jsonl";
  auto run = [&](const std::string& text) {
    write_text(path, text);
    return run_cli("solve " + q(s.mesh) + " --sing-batch " + q(path) + " --field-out " + q(s.dir + "/f.txt"));
  };
  const std::string good = "{\"name\": \"a\", \"sing\": {\"0\": \"1\", \"85\": \"1\"}}\n";
  expect_error(run(good + "{\"name\": \"x\"}\n"), path + ":2: expected {\"name\": \"...\", \"sing\": {\"VERTEX\": \"INDEX\", ...}}");
  expect_error(run(good + "\n[1, 2]\n"), path + ":3: expected {\"name\": \"...\", \"sing\": {\"VERTEX\": \"INDEX\", ...}}");
  expect_error(run("{\"name\": \"a/b\", \"sing\": {}}\n"), path + ":1: the name must be non-empty without '/'");
  expect_error(run("{\"name\": \"\", \"sing\": {}}\n"), path + ":1: the name must be non-empty without '/'");
  expect_error(run("{\"name\": \"a\", \"sing\": {\"0\": \"x\"}}\n"),
               path + ":1: --sing 0:x: malformed index 'x' (expected an integer or a fraction p/q, q > 0)");
  expect_error(run(good + "{\"name\": \"b\", \"sing\": {\"0\": \"1\"}, \"generator\": 3}\n"), path + ":2: \"generator\" must be an object");
  expect_error(run("{\"name\": \"a\", \"sing\": {\"0\": \"1\"}}\n"),
               "batch item 'a': the indices on component 0 sum to 1, but Gauss-Bonnet needs its Euler characteristic 2");
  expect_error(run("\n \n"), "--sing-batch " + path + ": no items");
  // Two items of one name would write the same files.
  expect_error(run(good + "\n" + good), path + ":3: the name 'a' is already used on line 1");
  // Not JSON: the parser's own explanation follows in parentheses.
  const CommandResult r = run(good + "nope\n");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err.rfind(kError + path + ":2: not a JSON object (", 0), 0u) << r.err;
  EXPECT_EQ(r.err.substr(r.err.size() - 2), ")\n") << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  EXPECT_FALSE(fs::exists(s.dir + "/f.a.txt"));
}

// ---------------------------------------------------------------------------------------------
// --align-boundary and --fix

TEST(CliOptions, AlignBoundaryOnAnAnnulus) {
  const std::string dir = test::temp_dir("cli_options_align");
  const Mesh m = make_annulus(4, 40);
  const std::string mesh = save(dir, "annulus", m), field = dir + "/field.txt", report = dir + "/report.json";
  const std::map<int, Eigen::Vector3d> edges = boundary_edges_of_faces(m);
  ASSERT_EQ(edges.size(), 80u);
  expect_ok(run_cli("solve " + q(mesh) + " -q -N 4 --align-boundary --field-out " + q(field) + " --report " + q(report)));
  json rep = read_json(report);
  EXPECT_EQ(rep["fixed"]["align_boundary"], true);
  EXPECT_EQ(rep["fixed"]["faces"], 80);
  EXPECT_EQ(rep["fixed"]["paths"], 79);
  EXPECT_LE(rep["fixed"]["max_error"].get<double>(), 1e-9);
  EXPECT_EQ(rep["verified"], true);
  // A tangent cross field on a flat annulus turns once with each circle: both loop indices 0.
  EXPECT_EQ(rep["boundary_loops"][0]["index"], "0");
  EXPECT_EQ(rep["boundary_loops"][1]["index"], "0");
  std::vector<Eigen::Vector3d> d = read_field_txt(field);
  ASSERT_EQ(d.size(), static_cast<size_t>(m.F.rows()));
  double worst = 0;
  for (const auto& [f, e] : edges) worst = std::max(worst, std::abs(reduce(std::atan2(d[f].y(), d[f].x()) - std::atan2(e.y(), e.x()), 4)));
  EXPECT_LE(worst, 1e-9);

  // --fix wins over --align-boundary on the same face: a world direction 0.3 rad off the boundary edge (less
  // than π/8 more than its neighbours' turn, so no singularity is needed for it: trivcon/constraints.h).
  const int f = edges.begin()->first;
  const double want = std::atan2(edges.at(f).y(), edges.at(f).x()) + 0.3;  // the annulus lies in the z = 0 plane
  std::ostringstream direction;
  direction << std::setprecision(17) << std::cos(want) << "," << std::sin(want) << ",0";
  expect_ok(run_cli("solve " + q(mesh) + " -q -N 4 --align-boundary --fix " + std::to_string(f) + ":" + direction.str() + " --field-out " +
                    q(field) + " --report " + q(report)));
  rep = read_json(report);
  EXPECT_EQ(rep["fixed"]["faces"], 80);
  d = read_field_txt(field);
  EXPECT_LE(std::abs(reduce(std::atan2(d[f].y(), d[f].x()) - want, 4)), 1e-9);
  // Without the option, nothing is fixed.
  expect_ok(run_cli("solve " + q(mesh) + " -q -N 4 --report " + q(report)));
  rep = read_json(report);
  EXPECT_EQ(rep["fixed"]["align_boundary"], false);
  EXPECT_EQ(rep["fixed"]["faces"], 0);
}

TEST(CliOptions, FixFile) {
  const std::string dir = test::temp_dir("cli_options_fix");
  const Mesh m = make_disk(4, 6);  // 96 faces, flat in z = 0
  ASSERT_EQ(m.F.rows(), 96);
  const std::string mesh = save(dir, "disk", m), file = dir + "/fix.txt", field = dir + "/field.txt", report = dir + "/report.json";
  write_text(file, "# fixed directions\n\n3 1 0 0   # along x\n50 angle=0.25\r\n  60 0.5 0.5 7\n");
  expect_ok(run_cli("solve " + q(mesh) + " -q --fix " + q(file) + " --field-out " + q(field) + " --report " + q(report)));
  const json rep = read_json(report);
  EXPECT_EQ(rep["fixed"]["faces"], 3);
  EXPECT_EQ(rep["fixed"]["paths"], 2);
  EXPECT_EQ(rep["verified"], true);
  const std::vector<Eigen::Vector3d> d = read_field_txt(field);
  ASSERT_EQ(d.size(), 96u);
  EXPECT_LE((d[3] - Eigen::Vector3d(1, 0, 0)).norm(), 1e-9);
  EXPECT_LE((d[60] - Eigen::Vector3d(1, 1, 0).normalized()).norm(), 1e-9) << "projected onto the face";
  const Eigen::Vector3d x50 = (m.V.row(m.F(50, 1)) - m.V.row(m.F(50, 0))).normalized().transpose();
  const Eigen::Vector3d want50 = Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ()) * x50;
  EXPECT_LE((d[50] - want50).norm(), 1e-9);
  // A file and a spec together.
  write_text(file, "3 1 0 0\n");
  expect_ok(run_cli("solve " + q(mesh) + " -q --fix " + q(file) + " --fix 70:0,1,0 --field-out " + q(field)));
  EXPECT_LE((read_field_txt(field)[70] - Eigen::Vector3d(0, 1, 0)).norm(), 1e-9);
}

TEST(CliOptions, FixErrorsNameTheLine) {
  const std::string dir = test::temp_dir("cli_options_fix_errors");
  const std::string mesh = save(dir, "disk", make_disk(4, 6)), file = dir + "/fix.txt";
  auto run = [&](const std::string& text) {
    write_text(file, text);
    return run_cli("solve " + q(mesh) + " --fix " + q(file));
  };
  expect_error(run("1 1 0 0\n\n# c\nx 1 0 0\n"), file + ":4: malformed face id 'x'");
  expect_error(run("1 1 0 0\n96 1 0 0\n"), file + ":2: face 96 out of range (mesh has 96 faces)");
  expect_error(run("-1 angle=0\n"), file + ":1: face -1 out of range (mesh has 96 faces)");
  expect_error(run("# c\n5 1 0\n"), file + ":2: expected 'x y z' or 'angle=A' after the face id");
  expect_error(run("5\n"), file + ":1: expected 'x y z' or 'angle=A' after the face id");
  expect_error(run("5 1 0 0 1\n"), file + ":1: expected 'x y z' or 'angle=A' after the face id");
  expect_error(run("5 1 a 0\n"), file + ":1: malformed number 'a'");
  expect_error(run("5 angle=x\n"), file + ":1: malformed number 'x'");
  expect_error(run("5 angle=inf\n"), file + ":1: number 'inf' is not finite");
  expect_error(run("\n\n5 0 0 0\n"), file + ":3: fixed direction of face 5 is zero");
  expect_error(run("5 0 0 1\n"), file + ":1: fixed direction of face 5 is perpendicular to the face: nothing is left after projection");
  expect_error(run("5 1 0 0\n# again\n5 angle=1\n"), file + ":3: face 5 is fixed twice");
  expect_error(run("5 1 0 0 # ok\r\n7 angle=1\r\n9 x\r\n"), file + ":3: expected 'x y z' or 'angle=A' after the face id");
  expect_error(run_cli("solve " + q(mesh) + " --fix " + q(dir + "/missing.txt")),
               "cannot open '" + dir + "/missing.txt': No such file or directory");
  // Specs.
  const std::string solve = "solve " + q(mesh);
  expect_error(run_cli(solve + " --fix 3:1,0"), "--fix 3:1,0: expected 'x y z' or 'angle=A' after the face id");
  expect_error(run_cli(solve + " --fix 200:angle=0"), "--fix 200:angle=0: face 200 out of range (mesh has 96 faces)");
  expect_error(run_cli(solve + " --fix 3:angle=0 --fix 3:1,0,0"), "--fix 3:1,0,0: face 3 is fixed twice");
  expect_error(run_cli(solve + " --fix 3:angle=0 --root-face 5"),
               "component 0 has fixed faces: its field starts at fixed face 3, so it takes no root face");
}

// ---------------------------------------------------------------------------------------------
// --png, --weights unit, --solver qr

TEST(CliOptions, PngHasTheDefaultSize) {
  const Sphere s("cli_options_png");
  const std::string png = s.dir + "/field.png";
  expect_ok(run_cli("solve " + q(s.mesh) + " -q --sing 0:1 --sing 85:1 --png " + q(png)));
  const std::string bytes = slurp(png);
  ASSERT_GE(bytes.size(), 33u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");
  auto be32 = [&](size_t at) {
    return (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at])) << 24) |
           (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 1])) << 16) |
           (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 2])) << 8) |
           static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 3]));
  };
  EXPECT_EQ(be32(16), 1200u) << "render's default width";
  EXPECT_EQ(be32(20), 900u) << "render's default height";
  EXPECT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND");
}

TEST(CliOptions, UnitWeightsEnergyIsTheSumOfSquares) {
  const std::string dir = test::temp_dir("cli_options_unit");
  const Mesh m = make_cube_sphere(3, true);
  const std::string mesh = save(dir, "cube", m), conn = dir + "/conn.txt", report = dir + "/report.json";
  std::string sings;
  for (int v : vertices_of_valence(m, 3)) sings += " --sing " + std::to_string(v) + ":1/4";
  expect_ok(run_cli("solve " + q(mesh) + " -q -N 4" + sings + " --weights unit --connection-out " + q(conn) + " --report " + q(report)));
  const json rep = read_json(report);
  EXPECT_EQ(rep["weights"], "unit");
  const std::map<Edge, double> x = read_connection_file(conn);
  double sum = 0;
  for (auto [e, v] : x) sum += v * v;
  EXPECT_GT(sum, 0.0);
  EXPECT_NEAR(rep["energy"].get<double>(), sum, 1e-12 * sum);
  // The same x as the library with unit weights, and not the cotan one.
  const MeshData read = read_mesh(mesh);
  SolverOptions unit;
  unit.weights = WeightKind::Unit;
  IndexPrescription p;
  p.N = 4;
  for (int v : vertices_of_valence(m, 3)) p.vertex[v] = 1;
  for (bool cotan : {false, true}) {
    const FieldDesigner designer(read.V, read.F, cotan ? SolverOptions{} : unit);
    const Design d = designer.design(p);
    double worst = 0;
    for (int e = 0; e < designer.topology().num_edges; ++e) {
      if (designer.topology().is_boundary_edge(e)) continue;
      worst = std::max(
          worst, std::abs(x.at({designer.topology().edge_vertices(e, 0), designer.topology().edge_vertices(e, 1)}) - d.connection.x(e)));
    }
    if (cotan) {
      EXPECT_GT(worst, 1e-3) << "unit and cotan weights give the same connection: the option does nothing";
    } else {
      EXPECT_LE(worst, 1e-12);
    }
  }
}

// x from the connection files of both routes. Without SuiteSparseQR in the build, --solver qr is refused with the
// reason, and the Cholesky route's solution is verified.
void expect_qr_matches_cholesky(const std::string& dir, const std::string& args, const std::string& what) {
  SCOPED_TRACE(what);
#ifndef TRIVCON_WITH_SUITESPARSE
  {
    const std::string ra = dir + "/chol.json";
    expect_ok(run_cli("solve " + args + " -q --report " + q(ra)));
    EXPECT_EQ(read_json(ra)["verified"], true);
    const CommandResult r = run_cli("solve " + args + " -q --solver qr");
    EXPECT_NE(r.status, 0);
    EXPECT_TRUE(contains(r.err, "the QR solver needs SuiteSparseQR")) << r.err;
    EXPECT_TRUE(contains(r.err, "-DTRIVCON_WITH_SUITESPARSE=ON")) << r.err;
    return;
  }
#endif
  const std::string a = dir + "/chol.txt", b = dir + "/qr.txt", ra = dir + "/chol.json", rb = dir + "/qr.json";
  expect_ok(run_cli("solve " + args + " -q --connection-out " + q(a) + " --report " + q(ra)));
  expect_ok(run_cli("solve " + args + " -q --solver qr --connection-out " + q(b) + " --report " + q(rb)));
  const json cj = read_json(ra), qj = read_json(rb);
  EXPECT_EQ(cj["solver"], "cholesky");
  EXPECT_EQ(qj["solver"], "qr");
  EXPECT_EQ(qj["ordering"], "SuiteSparseQR default");
  EXPECT_EQ(qj["symbolic_analysis"], "in set-up");
  EXPECT_EQ(qj["verified"], true);
  EXPECT_EQ(cj["generators"], qj["generators"]);
  EXPECT_EQ(cj["boundary_loops"], qj["boundary_loops"]);
  const std::map<Edge, double> x = read_connection_file(a), y = read_connection_file(b);
  ASSERT_EQ(x.size(), y.size());
  ASSERT_FALSE(x.empty());
  double worst = 0, largest = 0;
  for (auto [e, v] : x) worst = std::max(worst, std::abs(v - y.at(e))), largest = std::max(largest, std::abs(v));
  EXPECT_GT(largest, 1e-3);
  EXPECT_LE(worst, 1e-8);
  EXPECT_NEAR(cj["energy"].get<double>(), qj["energy"].get<double>(), 1e-8 * cj["energy"].get<double>());
}

TEST(CliOptions, QrSolverGivesTheSameConnection) {
  const std::string dir = test::temp_dir("cli_options_qr");
  const std::string sphere = save(dir, "sphere", make_uv_sphere(8, 12)), torus = save(dir, "torus", make_torus(12, 6)),
                    annulus = save(dir, "annulus", make_annulus(3, 24));
  expect_qr_matches_cholesky(dir, q(sphere) + " --sing 0:1 --sing 40:1", "sphere");
  expect_qr_matches_cholesky(dir, q(torus) + " -N 4 --sing 3:1 --sing 40:-1", "torus, generators chosen");
  expect_qr_matches_cholesky(dir, q(annulus) + " -N 4 --align-boundary", "annulus, aligned");
  expect_qr_matches_cholesky(dir, q(annulus) + " --weights unit --boundary 0:0", "annulus, unit weights, loop prescribed");
}

// ---------------------------------------------------------------------------------------------
// --generator, --boundary

TEST(CliOptions, PrescribedGeneratorAndLoopIndicesAreUsed) {
  const std::string dir = test::temp_dir("cli_options_cycles");
  const std::string torus = save(dir, "torus", make_torus(16, 8)), annulus = save(dir, "annulus", make_annulus(3, 24));
  const std::string report = dir + "/report.json", field = dir + "/field.txt";
  expect_ok(run_cli("solve " + q(torus) + " -q --generator 0:1 --generator 1:0 --report " + q(report) + " --field-out " + q(field)));
  json rep = read_json(report);
  EXPECT_EQ(rep["generators"], json::parse(R"([{"id": 0, "component": 0, "index": "1", "chosen": false},
                                              {"id": 1, "component": 0, "index": "0", "chosen": false}])"));
  EXPECT_LE(rep["residuals"]["max_cycle"].get<double>(), 1e-9);
  EXPECT_EQ(rep["verified"], true);
  // The field read back by check turns once along generator 0.
  CommandResult r = run_cli("check " + q(torus) + " " + q(field) + " --json");
  expect_ok(r, "check");
  EXPECT_EQ(json::parse(r.out)["generators"], json::parse(R"([{"id": 0, "index": "1"}, {"id": 1, "index": "0"}])"));
  // Fractions with N = 4, one chosen.
  expect_ok(run_cli("solve " + q(torus) + " -q -N 4 --generator 1:-1/4 --report " + q(report)));
  rep = read_json(report);
  EXPECT_EQ(rep["generators"][1]["index"], "-1/4");
  EXPECT_EQ(rep["generators"][1]["chosen"], false);
  EXPECT_EQ(rep["generators"][0]["chosen"], true);

  // Loops: both prescribed (summing to χ = 0), then one (the other follows).
  expect_ok(run_cli("solve " + q(annulus) + " -q --boundary 0:-1 --boundary 1:1 --report " + q(report) + " --field-out " + q(field)));
  rep = read_json(report);
  EXPECT_EQ(rep["boundary_loops"], json::parse(R"([{"id": 0, "index": "-1", "chosen": false}, {"id": 1, "index": "1", "chosen": false}])"));
  r = run_cli("check " + q(annulus) + " " + q(field));
  expect_ok(r, "check annulus");
  EXPECT_TRUE(contains(r.out, "  boundary loop 0 index -1\n  boundary loop 1 index 1\n")) << r.out;
  expect_ok(run_cli("solve " + q(annulus) + " -q -N 4 --boundary 0:0 --report " + q(report) + " --field-out " + q(field)));
  rep = read_json(report);
  EXPECT_EQ(rep["boundary_loops"][0]["index"], "0");
  EXPECT_EQ(rep["boundary_loops"][0]["chosen"], false);
  EXPECT_EQ(rep["boundary_loops"][1]["index"], "0");
  EXPECT_EQ(rep["verified"], true);
  r = run_cli("check " + q(annulus) + " " + q(field));
  EXPECT_TRUE(contains(r.out, "  boundary loop 0 index 0\n  boundary loop 1 index 0\n")) << r.out;
  // A loop prescription breaking Gauss-Bonnet (all loops given).
  expect_error(run_cli("solve " + q(annulus) + " --boundary 0:1 --boundary 1:1"),
               "the indices on component 0 (vertices and boundary loops) sum to 2, but Gauss-Bonnet needs its Euler characteristic 0");
}

// ---------------------------------------------------------------------------------------------
// The connection file's values, and .sings with N = 4

TEST(CliOptions, ConnectionFileHoldsTheLibrarysValues) {
  const std::string dir = test::temp_dir("cli_options_connection");
  const Mesh cube = make_cube_sphere(4, true), torus = make_torus(12, 6);
  struct Case {
    std::string name;
    const Mesh* mesh;
    IndexPrescription p;
    std::string args;
  };
  std::vector<Case> cases;
  {
    Case c{"cube", &cube, {}, " -N 4"};
    c.p.N = 4;
    for (int v : vertices_of_valence(cube, 3)) c.p.vertex[v] = 1, c.args += " --sing " + std::to_string(v) + ":1/4";
    cases.push_back(c);
  }
  {
    Case c{"torus", &torus, {}, " -N 2 --sing 5:1/2 --sing 50:-1/2 --generator 0:1"};
    c.p.N = 2;
    c.p.vertex = {{5, 1}, {50, -1}};
    c.p.generator[0] = 2;
    cases.push_back(c);
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string mesh = save(dir, c.name, *c.mesh), conn = dir + "/" + c.name + ".conn";
    expect_ok(run_cli("solve " + q(mesh) + " -q" + c.args + " --connection-out " + q(conn)));
    int N = 0;
    const std::map<Edge, double> x = read_connection_file(conn, &N);
    EXPECT_EQ(N, c.p.N);
    const MeshData read = read_mesh(mesh);
    const FieldDesigner designer(read.V, read.F);
    const Design d = designer.design(c.p);
    const Topology& t = designer.topology();
    int interior = 0;
    double worst = 0, largest = 0;
    for (int e = 0; e < t.num_edges; ++e) {
      if (t.is_boundary_edge(e)) continue;
      ++interior;
      const auto it = x.find({t.edge_vertices(e, 0), t.edge_vertices(e, 1)});
      ASSERT_NE(it, x.end()) << "edge " << t.edge_vertices(e, 0) << "-" << t.edge_vertices(e, 1) << " missing";
      worst = std::max(worst, std::abs(it->second - d.connection.x(e)));
      largest = std::max(largest, std::abs(d.connection.x(e)));
    }
    EXPECT_EQ(static_cast<int>(x.size()), interior);
    EXPECT_GT(largest, 1e-3);
    EXPECT_LE(worst, 1e-12);
  }
}

TEST(CliOptions, SingsFileWithN4) {
  const std::string dir = test::temp_dir("cli_options_sings");
  const Mesh m = make_cube_sphere(3, true);
  const std::string mesh = save(dir, "cube", m), sings = dir + "/corners.sings", report = dir + "/report.json";
  const std::vector<int> corners = vertices_of_valence(m, 3);
  ASSERT_EQ(corners.size(), 8u);
  std::string text = "4 8\n";
  for (int v : corners) text += std::to_string(v) + " 1\n";
  write_text(sings, text);
  // `vertex 1` with N = 4 in the header means +1/4.
  for (int N : {4, 8}) {
    SCOPED_TRACE("-N " + std::to_string(N));
    expect_ok(run_cli("solve " + q(mesh) + " -q -N " + std::to_string(N) + " -s " + q(sings) + " --report " + q(report)));
    const json rep = read_json(report);
    ASSERT_EQ(rep["singularities"].size(), 8u);
    for (size_t k = 0; k < 8; ++k) {
      EXPECT_EQ(rep["singularities"][k]["vertex"], corners[k]);
      EXPECT_EQ(rep["singularities"][k]["index"], "1/4");
    }
    EXPECT_EQ(rep["verified"], true);
    // (With N = 8 a corner's turn across an edge can exceed π/8 on this coarse mesh: the field cannot show it.)
    if (N == 4) {
      EXPECT_TRUE(rep["indices"]["field_mismatches"].empty());
    }
  }
  expect_error(run_cli("solve " + q(mesh) + " -N 2 -s " + q(sings)),
               sings + ":2: index 1/4 is not a multiple of 1/2 (use -N to change the symmetry)");
  expect_error(run_cli("solve " + q(mesh) + " -s " + q(sings)),
               sings + ":2: index 1/4 is not a multiple of 1/1 (use -N to change the symmetry)");
  // A .sings of N = 2 read with -N 4: `vertex 1` is 1/2, eight of them sum to 4.
  text = "2 8\n";
  for (int v : corners) text += std::to_string(v) + " 1\n";
  write_text(dir + "/halves.sings", text);
  expect_error(run_cli("solve " + q(mesh) + " -N 4 -s " + q(dir + "/halves.sings")),
               "the indices on component 0 sum to 4, but Gauss-Bonnet needs its Euler characteristic 2");
  // check reads the same file.
  expect_ok(run_cli("solve " + q(mesh) + " -q -N 4 -s " + q(sings) + " --field-out " + q(dir + "/f.rawfield")));
  const CommandResult r = run_cli("check " + q(mesh) + " " + q(dir + "/f.rawfield") + " -s " + q(sings));
  expect_ok(r, "check");
  EXPECT_TRUE(contains(r.out, "N 4: 8 singular vertices in the field\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "matches the prescription\n")) << r.out;
}

TEST(CliOptions, SingularityFileErrorsNameTheLine) {
  const Sphere s("cli_options_sing_errors");
  auto run = [&](const std::string& name, const std::string& text, const std::string& extra = "") {
    write_text(s.dir + "/" + name, text);
    return run_cli("solve " + q(s.mesh) + extra + " -s " + q(s.dir + "/" + name));
  };
  const std::string d = s.dir + "/";
  expect_error(run("h.sings", "x 8\n"), d + "h.sings:1: expected the header 'N count' of a .sings file");
  expect_error(run("h0.sings", "# c\n0 2\n0 1\n85 1\n"), d + "h0.sings:2: expected the header 'N count' of a .sings file");
  expect_error(run("e.sings", "# nothing\n\n"), d + "e.sings: empty .sings file (expected the header 'N count')");
  expect_error(run("n.sings", "1 3\n0 1\n85 1\n"), d + "n.sings: the header announces 3 singularities but the file lists 2");
  expect_error(run("f.sings", "1 2\n0 1 2\n"), d + "f.sings:2: expected two fields, got '0 1 2'");
  expect_error(run("t.sings", "1 2\n# c\n0 1\n0 1\n"), d + "t.sings:4: vertex 0 is given twice");
  expect_error(run("v.sings", "1 1\nx 1\n"), d + "v.sings:2: malformed vertex id 'x'");
  expect_error(run("i.sings", "1 2\n0 1\n85 y\n"),
               d + "i.sings:3: malformed index 'y' (a .sings file gives a whole number n for the index n/N)");
  expect_error(run("p.txt", "# c\n\n0 1\n85 1/0\n"), d + "p.txt:4: malformed index '1/0' (expected an integer or a fraction p/q, q > 0)");
  expect_error(run("m.txt", "0 1 # pole\n-3 1\n"), d + "m.txt:2: malformed vertex id '-3'");
  expect_error(run("r.txt", "0 1\n\n85 1/3\n"), d + "r.txt:3: index 1/3 is not a multiple of 1/1 (use -N to change the symmetry)");
  expect_error(run("o.txt", "0 1\n86 1\n"), "singular vertex 86 out of range (mesh has 86 vertices)");
  expect_error(run("crlf.txt", "0 1\r\n\r\n85 1 2\r\n"), d + "crlf.txt:3: expected two fields, got '85 1 2'");
}

// ---------------------------------------------------------------------------------------------
// Mesh readers: the exact message, with the line (text formats) or the byte (binary PLY).

const std::string kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

TEST(CliOptions, ObjErrorsNameTheLine) {
  const std::string dir = test::temp_dir("cli_options_obj");
  const std::string p = dir + "/m.obj";
  auto info = [&](const std::string& text) {
    write_text(p, text);
    return run_cli("info --no-repair " + q(p));  // a repeated vertex: the reader's message
  };
  expect_error(info(kTriangle + "# c\n\nf 1 2 9\n"), p + ":6: face index 9 out of range (file has 3 vertices)");
  expect_error(info(kTriangle + "f 1 2 3\nf 1 0 2\n"), p + ":5: face index 0 is invalid (OBJ indices start at 1)");
  expect_error(info("v 0 0 0\nv 1 x 0\n"), p + ":2: malformed number 'x'");
  expect_error(info("v 0 0 0\nv 1 0\n"), p + ":2: expected 3 coordinates for vertex 1");
  expect_error(info(kTriangle + "f 1 a 2\n"), p + ":4: malformed face corner 'a'");
  expect_error(info(kTriangle + "f 1 -5 2\n"), p + ":4: face index -5 out of range (3 vertices defined so far)");
  expect_error(info(kTriangle + "f 1 1 2\n"), p + ":4: face 0 has a repeated vertex (0, 0, 1)");
  expect_error(info(kTriangle + "f 1 2 3\nf 3/1 2/2/2 2//1\n"), p + ":5: face 1 has a repeated vertex (2, 1, 1)");
  expect_error(info("v nan 0 0\n"), p + ":1: non-finite coordinate in vertex 0 (nan)");
  expect_error(info(kTriangle + "f 1 2\n"), p + ":4: face 0 has 2 corners (at least 3 needed)");
  // A continued line is named by its first line; lines after it keep their numbers.
  expect_error(info(kTriangle + "f 1 2 \\\n 7\n"), p + ":4: face index 7 out of range (file has 3 vertices)");
  expect_error(info(kTriangle + "f 1 2 \\\n 3\nv 1 1 0\nf 2 x 3\n"), p + ":7: malformed face corner 'x'");
  expect_error(info(kTriangle), p + ": no faces");
}

TEST(CliOptions, OffErrorsNameTheLine) {
  const std::string dir = test::temp_dir("cli_options_off");
  const std::string p = dir + "/m.off";
  auto info = [&](const std::string& text) {
    write_text(p, text);
    return run_cli("info --no-repair " + q(p));  // a repeated vertex: the reader's message
  };
  const std::string v3 = "0 0 0\n1 0 0\n0 1 0\n";
  expect_error(info("OFF\n# c\n3 1 0\n" + v3 + "3 0 1 3\n"), p + ":7: face index 3 out of range (file has 3 vertices)");
  expect_error(info("OFF\n3 1 0\n" + v3 + "3 0 1\n"), p + ":6: face 0 announces 3 corners but lists 2");
  expect_error(info("OFF\n3 2 0\n" + v3 + "3 0 1 2\n"), p + ":6: file ends after 1 of 2 faces (truncated?)");
  expect_error(info("4OFF\n3 1 0\n" + v3 + "3 0 1 2\n"), p + ":1: unsupported OFF variant '4OFF' (only 3-D [ST][C][N]OFF is supported)");
  expect_error(info("OFF\n3 1 0\n0 0 0\n1 0 0\n0 y 0\n3 0 1 2\n"), p + ":5: malformed number 'y'");
  expect_error(info("OFF\r\n3 1\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 1\r\n"), p + ":6: face 0 has a repeated vertex (0, 1, 1)");
  expect_error(info("hello\n"), p + ":1: not an OFF file: expected 'OFF', found 'hello'");
  expect_error(info("OFF\n3 1 0\n0 0 0\n\n# c\n1 0\n0 1 0\n3 0 1 2\n"), p + ":6: expected 3 coordinates for vertex 1");
}

const std::string kPlyHeader =
    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int "
    "vertex_indices\nend_header\n";

TEST(CliOptions, AsciiPlyErrorsNameTheLine) {
  const std::string dir = test::temp_dir("cli_options_ply_ascii");
  const std::string p = dir + "/m.ply";
  auto info = [&](const std::string& text) {
    write_text(p, text);
    return run_cli("info --no-repair " + q(p));  // a repeated vertex: the reader's message
  };
  const std::string head = "ply\nformat ascii 1.0\n" + kPlyHeader;  // 9 lines
  expect_error(info(head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"), p + ":13: face index 5 out of range (file has 3 vertices) in face 0");
  expect_error(info(head + "0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n"), p + ":11: unexpected extra value '7' for vertex 1");
  expect_error(info(head + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n"), p + ":11: too few values for vertex 1 (the header lists more properties)");
  expect_error(info(head + "0 0 0\n1 0 0\n0 1 0\n"), p + ":12: file ends after 0 of 1 'face' elements (truncated?)");
  expect_error(info(head + "0 0 0\n1 0 0\n0 1 z\n3 0 1 2\n"), p + ":12: malformed number 'z'");
  expect_error(info("ply\nformat ascii 1.0\nproperty float x\n"), p + ":3: property before any element");
  expect_error(info("ply\nformat foo 1.0\n" + kPlyHeader), p + ":2: unsupported PLY format 'foo'");
  expect_error(
      info("ply\nformat ascii 1.0\ncomment c\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
           "property list uchar int vertex_index2\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
      p + ":8: face element has no list property 'vertex_indices'");
}

// Little-endian (or big-endian) bytes of a value.
template <class T>
std::string bytes_of(T value, bool big_endian = false) {
  std::string s(sizeof(T), '\0');
  std::memcpy(&s[0], &value, sizeof(T));
  if (big_endian) std::reverse(s.begin(), s.end());  // the test machine is little-endian (x86-64)
  return s;
}

TEST(CliOptions, BinaryPlyErrorsNameTheByte) {
  const std::string dir = test::temp_dir("cli_options_ply_binary");
  const std::string p = dir + "/m.ply";
  auto info = [&](const std::string& text) {
    write_text(p, text);
    return run_cli("info --no-repair " + q(p));  // a repeated vertex: the reader's message
  };
  for (bool big : {false, true}) {
    SCOPED_TRACE(big ? "big endian" : "little endian");
    auto vertices = [&](float nan_at_1) {
      std::string s;
      const float xyz[9] = {0, 0, 0, 1, nan_at_1, 0, 0, 1, 0};
      for (float v : xyz) s += bytes_of(v, big);
      return s;
    };
    auto face = [&](int a, int b, int c) {
      return std::string(1, '\3') + bytes_of<int32_t>(a, big) + bytes_of<int32_t>(b, big) + bytes_of<int32_t>(c, big);
    };
    const std::string format = big ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n";
    const std::string one = "ply\n" + format + kPlyHeader;
    std::string two = one;
    two.replace(two.find("element face 1"), 14, "element face 2");
    const size_t H = one.size();  // the data starts here; a vertex takes 12 bytes, a face 13
    expect_error(info(one + vertices(0) + face(0, 1, 5)),
                 p + ": face index 5 out of range (file has 3 vertices) in face 0 (at byte " + std::to_string(H + 36) + ")");
    expect_error(info(two + vertices(0) + face(0, 1, 2) + face(2, 1, -1)),
                 p + ": face index -1 out of range (file has 3 vertices) in face 1 (at byte " + std::to_string(H + 49) + ")");
    expect_error(info(two + vertices(0) + face(0, 1, 2) + face(2, 2, 1)),
                 p + ": face 1 has a repeated vertex (2, 2, 1) (at byte " + std::to_string(H + 49) + ")");
    // Cut inside face 1 after its count and one index: the next read starts at H + 36 + 13 + 1 + 4.
    expect_error(info(two + vertices(0) + face(0, 1, 2) + face(0, 1, 2).substr(0, 7)),
                 p + ": truncated binary data at byte " + std::to_string(H + 54) +
                     " (face 1 of 2; its 'vertex_indices' list claims 3 items of 4 bytes, but only 6 bytes follow the count)");
    expect_error(info(one + vertices(std::nanf("")) + face(0, 1, 2)),
                 p + ": non-finite coordinate in vertex 1 (nan) (at byte " + std::to_string(H + 12) + ")");
    std::string many = one;
    many.replace(many.find("element vertex 3"), 16, "element vertex 1000");
    expect_error(info(many + vertices(0) + face(0, 1, 2)),
                 p + ":3: header claims 1000 vertices, but the file has only 49 bytes after the header (a vertex needs at least 12)");
  }
}

// ---------------------------------------------------------------------------------------------
// Field files read by `check`.

TEST(CliOptions, FieldFileErrorsNameTheLine) {
  const Sphere s("cli_options_field_errors");
  const std::string txt = s.dir + "/field.txt", raw = s.dir + "/field.rawfield", ply = s.dir + "/field.ply";
  const std::string sings = " --sing 0:1 --sing 85:1";
  for (const std::string& f : {txt, raw, ply}) expect_ok(run_cli("solve " + q(s.mesh) + " -q" + sings + " --field-out " + q(f)));
  const std::vector<std::string> good = lines_of(slurp(txt));  // 3 comment lines, then 168 directions
  ASSERT_EQ(good.size(), 171u);
  ASSERT_EQ(good[1], "# N 1");
  const std::string bad = s.dir + "/bad.txt", badraw = s.dir + "/bad.rawfield";
  auto check = [&](const std::string& path, const std::vector<std::string>& lines, const std::string& extra = "") {
    std::string text;
    for (const auto& l : lines) text += l + "\n";
    write_text(path, text);
    return run_cli("check " + q(s.mesh) + " " + q(path) + extra);
  };
  auto with = [&](std::vector<std::string> lines, size_t index, const std::string& line) {
    lines[index] = line;
    return lines;
  };
  // The text format (line k + 1 is lines[k]).
  expect_error(check(bad, with(good, 4, "1 2")), bad + ":5: expected 3 numbers, got 2");
  expect_error(check(bad, with(good, 3, "1 x 0")), bad + ":4: malformed number 'x'");
  expect_error(check(bad, with(good, 5, "nan 0 0")), bad + ":6: malformed number 'nan'");
  expect_error(check(bad, with(good, 10, "1 0 0 0")), bad + ":11: expected 3 numbers, got 4");
  {
    std::vector<std::string> lines = good;
    lines.insert(lines.begin() + 5, "# a comment in the middle");
    lines.insert(lines.begin() + 6, "");
    expect_error(check(bad, with(lines, 8, "1 2")), bad + ":9: expected 3 numbers, got 2");
    lines.push_back("1 0 0");
    expect_error(check(bad, lines), bad + ":174: more lines than the mesh has faces (168)");
  }
  expect_error(check(bad, {good.begin(), good.begin() + 6}), bad + ": has 3 directions, the mesh has 168 faces");
  expect_error(check(bad, with(good, 10, "0 0 0")), "the direction of face 7 has no component in the face's plane");
  expect_error(check(bad, good, " -N 2"), "the field file " + bad + " holds an N = 1 field but -N 2 was given");
  // .rawfield.
  const std::vector<std::string> rgood = lines_of(slurp(raw));
  ASSERT_EQ(rgood.size(), 169u);
  ASSERT_EQ(rgood[0], "1 168");
  expect_error(check(badraw, {}), badraw + ": empty file (expected the header 'N F')");
  expect_error(check(badraw, with(rgood, 0, "1.5 168")), badraw + ":1: malformed N in the header");
  expect_error(check(badraw, with(rgood, 0, "1 10")), badraw + ":1: the field has 10 faces, the mesh has 168");
  expect_error(check(badraw, with(rgood, 0, "1")), badraw + ":1: expected 2 numbers, got 1");
  expect_error(check(badraw, {rgood.begin(), rgood.begin() + 4}), badraw + ": truncated after line 4 (face 3)");
  expect_error(check(badraw, with(rgood, 2, "1 2")), badraw + ":3: expected 3 numbers, got 2");
  expect_error(check(badraw, with(rgood, 0, "2 168")), badraw + ":2: expected 6 numbers, got 3");
  {
    std::vector<std::string> lines = rgood;
    lines.push_back("1 0 0");
    expect_error(check(badraw, lines), badraw + ":170: more lines than faces");
  }
  // .ply: a mesh without field properties, a cut field, a field for another mesh.
  const std::string mesh_ply = s.dir + "/mesh.ply";
  const Mesh sphere = make_uv_sphere(8, 12);
  write_ply(mesh_ply, sphere.V, sphere.F);
  expect_error(run_cli("check " + q(s.mesh) + " " + q(mesh_ply)),
               mesh_ply + ": not a field PLY written by trivcon (expected face properties fx fy fz after vertex_indices)");
  const std::string bytes = slurp(ply);
  const size_t H = bytes.find("end_header\n") + 11, face10 = H + 86 * 24 + 10 * 37;
  ASSERT_EQ(bytes.size(), H + 86 * 24 + 168 * 37);
  write_text(s.dir + "/cut.ply", bytes.substr(0, face10 + 20));
  expect_error(run_cli("check " + q(s.mesh) + " " + q(s.dir + "/cut.ply")),
               s.dir + "/cut.ply: truncated at byte " + std::to_string(face10 + 13) + " (face 10)");
  const std::string ico = save(s.dir, "ico", make_icosphere(1));
  expect_error(run_cli("check " + q(ico) + " " + q(ply)), ply + ": has 168 faces, the mesh has 80");
  expect_error(run_cli("check " + q(ico) + " " + q(txt)), txt + ":84: more lines than the mesh has faces (80)");
  expect_error(run_cli("check " + q(ico) + " " + q(raw)), raw + ":1: the field has 168 faces, the mesh has 80");
  expect_error(run_cli("check " + q(s.mesh) + " " + q(s.dir + "/none.txt")),
               "cannot open '" + s.dir + "/none.txt': No such file or directory");
}

}  // namespace
}  // namespace trivcon
