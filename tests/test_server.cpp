// Tests of the editor's server (server/editor_server.h): every endpoint, its answers checked for what
// they mean (unit tangent directions, the prescription honoured, the CLI's error texts), and the refusals
// (token, Host, body size, malformed requests), against a server started in-process on a free port.
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "editor_server.h"
#include "support.h"
#include "trivcon/field.h"
#include "trivcon/generate.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"
// Last: its system headers (<resolv.h>) define `_res`, a name Eigen's headers use.
#include <httplib.h>

namespace trivcon {
namespace {

using json = nlohmann::json;

MeshData mesh_data(const Mesh& m) {
  MeshData d;
  d.V = m.V;
  d.F = m.F;
  d.polygon_count = static_cast<int>(m.F.rows());
  d.format = "generated";
  return d;
}

// A running server on 127.0.0.1 and a client that sends its token.
struct Running {
  std::unique_ptr<server::EditorServer> editor;
  std::thread thread;
  std::unique_ptr<httplib::Client> client;
  int port = 0;

  explicit Running(const Mesh& m, server::EditorOptions options = {}) {
    options.mesh_path = "generated.obj";
    editor = std::make_unique<server::EditorServer>(mesh_data(m), options);
    port = editor->bind(0);
    thread = std::thread([this] { editor->run(); });
    client = std::make_unique<httplib::Client>("127.0.0.1", port);
    client->set_default_headers({{"X-Trivcon-Token", editor->token()}});
    client->set_read_timeout(120, 0);
  }
  ~Running() {
    // stop() before the thread is listening would be lost: wait until it is.
    while (!editor->running()) std::this_thread::yield();
    editor->stop();
    thread.join();
  }
  httplib::Result post(const std::string& path, const json& body) { return client->Post(path.c_str(), body.dump(), "application/json"); }
  httplib::Result post_text(const std::string& path, const std::string& body) {
    return client->Post(path.c_str(), body, "application/json");
  }
};

std::string error_of(const httplib::Result& r) {
  EXPECT_TRUE(r);
  if (!r) return "";
  const json j = json::parse(r->body, nullptr, false);
  EXPECT_TRUE(j.is_object() && j.contains("error")) << r->body;
  return j.is_object() && j.contains("error") ? j["error"].get<std::string>() : "";
}

// 8 vertices of index +1/4 on a sphere: Σ = 2 = χ.
json eight_quarters(const Mesh& m) {
  json s = json::array();
  for (int k = 0; k < 8; ++k) s.push_back({k * static_cast<int>(m.V.rows()) / 8, "1/4"});
  return s;
}

// Parses the binary container: uint32 length, JSON, then the payload.
std::pair<json, std::string> unpack(const std::string& body) {
  uint32_t n = 0;
  std::memcpy(&n, body.data(), 4);
  return {json::parse(body.substr(4, n)), body.substr(4 + n)};
}

class Server : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sphere_ = new Mesh(make_icosphere(3));
    running_ = new Running(*sphere_);
  }
  static void TearDownTestSuite() {
    delete running_;
    delete sphere_;
  }
  static Mesh* sphere_;
  static Running* running_;
  Running& r() { return *running_; }
  const Mesh& sphere() { return *sphere_; }
};
Mesh* Server::sphere_ = nullptr;
Running* Server::running_ = nullptr;

TEST_F(Server, MeshJsonHasInfoVerticesFacesCycles) {
  auto res = r().client->Get("/api/mesh");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  const json j = json::parse(res->body);
  EXPECT_EQ(j["vertices"].size(), static_cast<size_t>(sphere().V.rows()));
  EXPECT_EQ(j["faces"].size(), static_cast<size_t>(sphere().F.rows()));
  EXPECT_EQ(j["faces"][5][1].get<int>(), sphere().F(5, 1));
  EXPECT_DOUBLE_EQ(j["vertices"][7][2].get<double>(), sphere().V(7, 2));
  EXPECT_EQ(j["euler_characteristic"].get<int>(), 2);
  EXPECT_EQ(j["components"].size(), 1u);
  EXPECT_TRUE(j["cycles"]["generators"].empty());
  EXPECT_EQ(j["vertex_component"].size(), static_cast<size_t>(sphere().V.rows()));
}

TEST_F(Server, MeshBinaryMatchesJson) {
  auto res = r().client->Get("/api/mesh?format=binary");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  auto [header, payload] = unpack(res->body);
  const size_t nV = sphere().V.rows(), nF = sphere().F.rows();
  ASSERT_EQ(payload.size(), nV * 12 + nF * 12 + nV * 4);
  EXPECT_EQ(header["faces"].get<size_t>(), nF);
  std::vector<float> V(3 * nV);
  std::vector<uint32_t> F(3 * nF);
  std::memcpy(V.data(), payload.data(), V.size() * 4);
  std::memcpy(F.data(), payload.data() + V.size() * 4, F.size() * 4);
  EXPECT_FLOAT_EQ(V[3 * 9 + 1], static_cast<float>(sphere().V(9, 1)));
  EXPECT_EQ(F[3 * 11 + 2], static_cast<uint32_t>(sphere().F(11, 2)));
}

TEST_F(Server, SolveGivesUnitTangentDirectionsWithThePrescribedIndices) {
  const json body = {{"N", 4}, {"singularities", eight_quarters(sphere())}};
  auto res = r().post("/api/solve", body);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json j = json::parse(res->body);
  const json& d = j["directions"];
  const Topology t = build_topology(sphere().F, static_cast<int>(sphere().V.rows()));
  const Geometry g = compute_geometry(sphere().V, t);
  ASSERT_EQ(d.size(), 3 * static_cast<size_t>(sphere().F.rows()));
  MatrixX3d directions(sphere().F.rows(), 3);
  for (int f = 0; f < sphere().F.rows(); ++f) {
    const Eigen::Vector3d v(d[3 * f].get<double>(), d[3 * f + 1].get<double>(), d[3 * f + 2].get<double>());
    EXPECT_NEAR(v.norm(), 1.0, 1e-12);
    const Eigen::Vector3d e1 = sphere().V.row(sphere().F(f, 1)) - sphere().V.row(sphere().F(f, 0));
    const Eigen::Vector3d e2 = sphere().V.row(sphere().F(f, 2)) - sphere().V.row(sphere().F(f, 0));
    EXPECT_NEAR(v.dot(e1.cross(e2).normalized()), 0.0, 1e-12);
    directions.row(f) = v;
  }
  // The indices read back from the directions alone are the prescribed ones.
  const FieldIndices idx = field_indices(t, g, compute_cycles(t), field_from_directions(g, directions, 4));
  std::set<int> singular;
  for (const auto& s : body["singularities"]) singular.insert(s[0].get<int>());
  for (int v = 0; v < t.num_vertices; ++v) EXPECT_EQ(idx.vertex[v], singular.count(v) ? 1 : 0) << "vertex " << v;
  EXPECT_TRUE(j["report"]["verified"].get<bool>());
  EXPECT_EQ(j["report"]["N"].get<int>(), 4);
  EXPECT_EQ(j["report"]["singularities"].size(), 8u);
  EXPECT_EQ(j["report"]["singularities"][1]["index"].get<std::string>(), "1/4");
  EXPECT_TRUE(res->has_header("X-Trivcon-Server-Seconds"));
}

TEST_F(Server, BinarySolveEqualsJsonSolve) {
  const json body = {{"N", 4}, {"singularities", eight_quarters(sphere())}};
  auto a = r().post("/api/solve", body);
  auto b = r().post("/api/solve?format=binary", body);
  ASSERT_TRUE(a && b);
  ASSERT_EQ(b->status, 200);
  EXPECT_EQ(b->get_header_value("Content-Type"), "application/octet-stream");
  const json ja = json::parse(a->body);
  auto [header, payload] = unpack(b->body);
  ASSERT_EQ(payload.size(), 12 * static_cast<size_t>(sphere().F.rows()));
  std::vector<float> d(payload.size() / 4);
  std::memcpy(d.data(), payload.data(), payload.size());
  for (size_t i = 0; i < d.size(); ++i) EXPECT_NEAR(d[i], ja["directions"][i].get<double>(), 1e-6);
  EXPECT_EQ(header["report"]["energy"], ja["report"]["energy"]);
  // The page's octahedral encoding: 2 × int16 per face, the same directions within 2e-4.
  auto c = r().post("/api/solve?format=oct16", body);
  ASSERT_TRUE(c);
  ASSERT_EQ(c->status, 200);
  auto [oct_header, oct_payload] = unpack(c->body);
  ASSERT_EQ(oct_payload.size(), 4 * static_cast<size_t>(sphere().F.rows()));
  std::vector<int16_t> o(oct_payload.size() / 2);
  std::memcpy(o.data(), oct_payload.data(), oct_payload.size());
  for (int f = 0; f < sphere().F.rows(); ++f) {
    double x = o[2 * f] / 32767.0, y = o[2 * f + 1] / 32767.0;
    const double z = 1 - std::abs(x) - std::abs(y);
    if (z < 0) {
      const double x0 = x;
      x = (1 - std::abs(y)) * (x0 >= 0 ? 1 : -1);
      y = (1 - std::abs(x0)) * (y >= 0 ? 1 : -1);
    }
    const Eigen::Vector3d v = Eigen::Vector3d(x, y, z).normalized();
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(v(k), ja["directions"][3 * f + k].get<double>(), 2e-4);
  }
  // Only the faces i · stride mod F for i < count, in that order.
  const int nF = static_cast<int>(sphere().F.rows()), stride = 791, count = 100;
  auto part = r().post("/api/solve?format=oct16&stride=" + std::to_string(stride) + "&count=" + std::to_string(count), body);
  ASSERT_TRUE(part);
  ASSERT_EQ(part->status, 200) << part->body;
  auto [part_header, part_payload] = unpack(part->body);
  ASSERT_EQ(part_payload.size(), 4u * count);
  std::vector<int16_t> q(2 * count);
  std::memcpy(q.data(), part_payload.data(), part_payload.size());
  for (int i = 0; i < count; ++i) {
    const int f = static_cast<int>((static_cast<long long>(i) * stride) % nF);
    EXPECT_EQ(q[2 * i], o[2 * f]) << i;
    EXPECT_EQ(q[2 * i + 1], o[2 * f + 1]) << i;
  }
  EXPECT_EQ(error_of(r().post("/api/solve?format=oct16&stride=640", body)),
            "stride 640 shares a factor with the face count 1280: the faces i * stride mod F would repeat");
  EXPECT_EQ(error_of(r().post("/api/solve?format=oct16&count=1281", body)), "count: expected a whole number from 0 to 1280, got '1281'");
  EXPECT_EQ(error_of(r().post("/api/solve?format=oct16&count=-1", body)), "count: expected a whole number from 0 to 1280, got '-1'");
}

TEST_F(Server, UnbalancedIndicesGetTheCliMessage) {
  json sing = eight_quarters(sphere());
  sing.erase(sing.size() - 1);
  auto res = r().post("/api/solve", {{"N", 4}, {"singularities", sing}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  const std::string message = error_of(res);
  EXPECT_EQ(message, "the indices on component 0 sum to 7/4, but Gauss-Bonnet needs its Euler characteristic 2");
  // The CLI says the same for the same mistake.
  const std::string path = test::temp_file("sphere.obj");
  write_obj(path, sphere().V, sphere().F);
  std::string args = "solve " + test::q(path) + " -N 4";
  for (const auto& s : sing) args += " --sing " + std::to_string(s[0].get<int>()) + ":1/4";
  const test::CommandResult cli = test::run_cli(args);
  EXPECT_EQ(cli.status, 1);
  EXPECT_TRUE(test::contains(cli.err, message)) << cli.err;
  // The state says the last request failed and keeps the last solved one.
  const json state = json::parse(r().client->Get("/api/state")->body);
  EXPECT_FALSE(state["solved"].get<bool>());
  EXPECT_EQ(state["error"].get<std::string>(), message);
}

TEST_F(Server, BadIdsAndIndicesGetTheCliMessages) {
  auto bad = [&](const json& sing) { return error_of(r().post("/api/solve", {{"N", 4}, {"singularities", sing}})); };
  EXPECT_EQ(bad({{100000, "2"}}), "singular vertex 100000 out of range (mesh has 642 vertices)");
  EXPECT_EQ(bad({{-1, "2"}}), "--sing -1:2: malformed vertex id '-1'");
  EXPECT_EQ(bad({{9007199254740993LL, "2"}}), "--sing 9007199254740993:2: malformed vertex id '9007199254740993'");
  EXPECT_EQ(bad({{3, "1/3"}}), "--sing 3:1/3: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)");
  EXPECT_EQ(bad({{3, "x"}}), "--sing 3:x: malformed index 'x' (expected an integer or a fraction p/q, q > 0)");
  EXPECT_EQ(bad({{3, "1"}, {3, "1"}}), "--sing 3:1: vertex 3 is given twice");
  // The CLI's own texts for the first two.
  const std::string path = test::temp_file("sphere.obj");
  write_obj(path, sphere().V, sphere().F);
  EXPECT_TRUE(test::contains(test::run_cli("solve " + test::q(path) + " -N 4 --sing 100000:2").err,
                             "singular vertex 100000 out of range (mesh has 642 vertices)"));
  EXPECT_TRUE(test::contains(test::run_cli("solve " + test::q(path) + " -N 4 --sing 3:1/3").err,
                             "--sing 3:1/3: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)"));
  EXPECT_TRUE(test::contains(
      test::run_cli("solve " + test::q(path) + " -N 4 --fix 99999:1,0,0").err,
      error_of(r().post("/api/solve", {{"N", 4}, {"singularities", eight_quarters(sphere())}, {"fixed", {{99999, {1, 0, 0}}}}}))));
}

TEST_F(Server, MalformedRequestsGet400AndTheServerKeepsServing) {
  const std::vector<std::string> bodies = {"",
                                           "{",
                                           "[1,2]",
                                           "\"text\"",
                                           "{\"N\": \"4\"}",
                                           "{\"N\": 0}",
                                           "{\"N\": 1e12}",
                                           "{\"N\": 4.5}",
                                           "{\"singularities\": 5}",
                                           "{\"singularities\": [5]}",
                                           "{\"singularities\": [[1.5, \"1\"]]}",
                                           "{\"singularities\": [[1, true]]}",
                                           "{\"singularities\": [[1, \"1\", 3]]}",
                                           "{\"singularities\": [[1e300, \"1\"]]}",
                                           "{\"generators\": [[0, \"0\"]]}",
                                           "{\"boundary\": [[0, \"1\"]]}",
                                           "{\"fixed\": [[0, [1, 0]]]}",
                                           "{\"fixed\": [[0, \"north\"]]}",
                                           "{\"fixed\": [[-3, [1, 0, 0]]]}",
                                           "{\"fixed\": [[0, [0, 0, 0]]]}",
                                           "{\"align_boundary\": 1}",
                                           "{\"N\": 4, \"singularities\": [[0, \"1/4\"]]}"};
  for (const std::string& body : bodies) {
    auto res = r().post_text("/api/solve", body);
    ASSERT_TRUE(res) << body;
    EXPECT_EQ(res->status, 400) << body << " → " << res->body;
    EXPECT_FALSE(error_of(res).empty()) << body;
  }
  EXPECT_EQ(error_of(r().post_text("/api/solve", "{\"N\": 0}")), "N: expected an integer from 1 to 1000 (the symmetry), got 0");
  // A body of brackets is refused while it is parsed; long values are not echoed back.
  EXPECT_EQ(error_of(r().post_text("/api/solve", "{\"N\": " + std::string(100000, '[') + std::string(100000, ']') + "}")),
            "the request body nests deeper than 8 levels");
  EXPECT_EQ(error_of(r().post_text("/api/solve", "{\"N\": \"" + std::string(5000, 'x') + "\"}")),
            "N: expected an integer from 1 to 1000 (the symmetry), got a string of 5000 bytes");
  EXPECT_EQ(error_of(r().post_text("/api/solve", "{\"generators\": [[0, \"0\"]]}")),
            "generator 0 out of range (the mesh has 0 generators)");
  EXPECT_EQ(error_of(r().post_text("/api/solve", "{\"singularities\": [[1.5, \"1\"]]}")),
            "singularities[0]: the vertex id must be an integer, got 1.5");
  auto res = r().client->Get("/api/state");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(error_of(r().post("/api/solve?format=xml", json::object())), "unknown format 'xml' (known: json, binary, oct16)");
  EXPECT_EQ(r().client->Get("/api/nothing")->status, 404);
  EXPECT_EQ(error_of(r().client->Get("/api/nothing")), "no such endpoint (see README.md, Editor)");
}

TEST_F(Server, EveryApiCallNeedsTheToken) {
  httplib::Client bare("127.0.0.1", r().port);
  for (const char* path : {"/api/mesh", "/api/state"}) {
    auto res = bare.Get(path);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 403) << path;
    EXPECT_TRUE(test::contains(error_of(res), "token"));
  }
  auto res = bare.Post("/api/solve", "{}", "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 403);
  EXPECT_EQ(bare.Get("/api/state", {{"X-Trivcon-Token", "0123456789abcdef0123456789abcdef"}})->status, 403);
  EXPECT_EQ(bare.Get("/api/state", {{"X-Trivcon-Token", ""}})->status, 403);
  const std::string token = r().editor->token();
  EXPECT_EQ(token.size(), 32u);
  EXPECT_EQ(bare.Get(("/api/state?token=" + token).c_str())->status, 200);
  EXPECT_EQ(bare.Get("/api/state", {{"Authorization", "token " + token}})->status, 200);
  EXPECT_EQ(bare.Get("/api/state", {{"Cookie", "other=1; trivcon_token_" + std::to_string(r().port) + "=" + token}})->status, 200);
  EXPECT_EQ(bare.Get("/api/state", {{"Cookie", "trivcon_token_1=" + token}})->status, 403);  // another editor's cookie name
}

TEST_F(Server, ThePageNeedsTheTokenAndSetsTheCookie) {
  httplib::Client bare("127.0.0.1", r().port);
  EXPECT_EQ(bare.Get("/")->status, 403);
  EXPECT_EQ(bare.Get("/?token=wrong")->status, 403);
  auto res = bare.Get(("/?token=" + r().editor->token()).c_str());
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_TRUE(test::contains(res->body, "/app.js"));
  EXPECT_TRUE(test::contains(res->get_header_value("Set-Cookie"), "trivcon_token_" + std::to_string(r().port) + "=" + r().editor->token()));
  EXPECT_TRUE(test::contains(res->get_header_value("Set-Cookie"), "SameSite=Strict"));
  auto js = bare.Get("/app.js");
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  EXPECT_GT(js->body.size(), 1000u);  // three.js is in it: the page needs no network
}

TEST_F(Server, RequestsForAnotherHostAreRefused) {
  httplib::Client bare("127.0.0.1", r().port);
  const std::string p = ":" + std::to_string(r().port);
  const httplib::Headers token = {{"X-Trivcon-Token", r().editor->token()}};
  for (const std::string& host :
       std::vector<std::string>{"evil.example" + p, "127.0.0.1", "127.0.0.1:1", "localhost.evil.example" + p, "10.0.0.1" + p}) {
    httplib::Headers h = token;
    h.emplace("Host", host);
    auto res = bare.Get("/api/state", h);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 403) << host;
    EXPECT_TRUE(test::contains(error_of(res), "Host header")) << host;
    h.erase("X-Trivcon-Token");
    EXPECT_EQ(bare.Get(("/?token=" + r().editor->token()).c_str(), h)->status, 403) << host;
  }
  httplib::Headers h = token;
  h.emplace("Host", "localhost" + p);
  EXPECT_EQ(bare.Get("/api/state", h)->status, 200);
}

TEST_F(Server, StateFollowsTheLastSolve) {
  json sing = eight_quarters(sphere());
  ASSERT_EQ(r().post("/api/solve", {{"N", 4}, {"singularities", sing}})->status, 200);
  const json state = json::parse(r().client->Get("/api/state")->body);
  EXPECT_TRUE(state["solved"].get<bool>());
  EXPECT_EQ(state["request"]["singularities"], sing);
  EXPECT_EQ(state["last_solved"]["singularities"], sing);
  EXPECT_EQ(state["request"]["N"].get<int>(), 4);
}

TEST_F(Server, FixedDirectionsHoldAndConcurrentRequestsAreSafe) {
  // N = 1 on a sphere: two sources of index +1; face 17 fixed to a direction of its own plane.
  const Topology t = build_topology(sphere().F, static_cast<int>(sphere().V.rows()));
  const Geometry g = compute_geometry(sphere().V, t);
  const Eigen::Vector3d want = g.direction_in_face(17, 0.7);
  const json base = {{"N", 1}, {"singularities", {{0, "1"}, {300, "1"}}}};
  json fixed = base;
  fixed["fixed"] = {{17, {want.x(), want.y(), want.z()}}};
  auto res = r().post("/api/solve", fixed);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json j = json::parse(res->body);
  const Eigen::Vector3d got(j["directions"][51].get<double>(), j["directions"][52].get<double>(), j["directions"][53].get<double>());
  EXPECT_NEAR((got - want).norm(), 0, 1e-9);
  EXPECT_EQ(j["report"]["fixed"]["faces"].get<int>(), 1);
  // Threads alternating between the two sets of fixed faces (each change refactors): every answer is whole.
  std::vector<std::thread> threads;
  std::atomic<int> good{0};
  for (int k = 0; k < 6; ++k)
    threads.emplace_back([&, k] {
      httplib::Client c("127.0.0.1", r().port);
      c.set_read_timeout(120, 0);
      for (int i = 0; i < 4; ++i) {
        const json& body = (k + i) % 2 ? fixed : base;
        auto a = c.Post("/api/solve?format=binary", {{"X-Trivcon-Token", r().editor->token()}}, body.dump(), "application/json");
        if (!a || a->status != 200) continue;
        auto [header, payload] = unpack(a->body);
        std::vector<float> d(payload.size() / 4);
        std::memcpy(d.data(), payload.data(), payload.size());
        bool unit = d.size() == 3 * static_cast<size_t>(sphere().F.rows());
        for (size_t f = 0; unit && f < d.size() / 3; ++f) unit = std::abs(std::hypot(d[3 * f], d[3 * f + 1], d[3 * f + 2]) - 1) < 1e-5;
        const bool fixed_holds =
            (k + i) % 2 == 0 || std::abs(d[51] - want.x()) + std::abs(d[52] - want.y()) + std::abs(d[53] - want.z()) < 1e-5;
        if (unit && fixed_holds && header["report"]["fixed"]["faces"].get<int>() == ((k + i) % 2 ? 1 : 0)) ++good;
      }
    });
  for (auto& th : threads) th.join();
  EXPECT_EQ(good.load(), 24);
}

TEST_F(Server, AutoPlacesSingularitiesThatBalance) {
  auto res = r().post("/api/auto", {{"N", 4}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json j = json::parse(res->body);
  int sum = 0;
  for (const auto& s : j["singularities"]) {
    const std::string idx = s[1].get<std::string>();
    sum += idx == "1/4" ? 1 : idx == "-1/4" ? -1 : idx == "1/2" ? 2 : idx == "-1/2" ? -2 : 100;
  }
  EXPECT_EQ(sum, 8);  // χ = 2, in quarters
  auto solved = r().post("/api/solve", {{"N", 4}, {"singularities", j["singularities"]}});
  ASSERT_TRUE(solved);
  EXPECT_EQ(solved->status, 200);
}

TEST_F(Server, ExportWritesTheCliFormats) {
  const json body = {{"N", 4}, {"singularities", eight_quarters(sphere())}};
  auto txt = r().post("/api/export?format=txt", body);
  ASSERT_TRUE(txt);
  ASSERT_EQ(txt->status, 200);
  const auto lines = test::lines_of(txt->body);
  EXPECT_EQ(lines[1], "# N 4");
  EXPECT_EQ(lines.size(), 3 + static_cast<size_t>(sphere().F.rows()));
  EXPECT_TRUE(test::contains(txt->get_header_value("Content-Disposition"), "field.txt"));
  auto raw = r().post("/api/export?format=rawfield", body);
  ASSERT_TRUE(raw);
  EXPECT_EQ(test::lines_of(raw->body)[0], "4 " + std::to_string(sphere().F.rows()));
  auto sing = r().post("/api/export?format=sing", body);
  ASSERT_TRUE(sing);
  EXPECT_TRUE(test::contains(sing->body, "# trivcon singularities\n# N 4\n# 8 singular vertices\n0 1/4\n"));
  EXPECT_EQ(r().post("/api/export?format=../../etc/passwd", body)->status, 400);
}

TEST_F(Server, StreamlinesAreLinesOnTheSurface) {
  auto res = r().post("/api/streamlines", {{"N", 4}, {"singularities", eight_quarters(sphere())}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  auto [header, payload] = unpack(res->body);
  size_t points = 0;
  for (const auto& c : header["counts"]) points += c.get<size_t>();
  EXPECT_GT(header["counts"].size(), 0u);
  ASSERT_EQ(payload.size(), 12 * points);
  std::vector<float> p(3 * points);
  std::memcpy(p.data(), payload.data(), payload.size());
  for (size_t i = 0; i < points; ++i) EXPECT_NEAR(std::hypot(p[3 * i], p[3 * i + 1], p[3 * i + 2]), 1.0, 0.02);  // unit sphere
}

TEST(ServerLimits, LargeBodiesAreRefusedWith413) {
  server::EditorOptions options;
  options.max_body_bytes = 1000;
  Running r(make_icosphere(1), options);
  auto res = r.post_text("/api/solve", std::string(5000, ' '));
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 413);
  EXPECT_EQ(r.client->Get("/api/state")->status, 200);
}

TEST(ServerCycles, GeneratorsAndBoundaryLoopsAreListedAndPrescribed) {
  Running torus(make_torus(24, 12));
  const json mesh = json::parse(torus.client->Get("/api/mesh")->body);
  ASSERT_EQ(mesh["cycles"]["generators"].size(), 2u);
  EXPECT_FALSE(mesh["cycles"]["generators"][0]["faces"].empty());
  auto res = torus.post("/api/solve", {{"N", 4}, {"generators", {{0, "0"}, {1, "1/4"}}}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json j = json::parse(res->body);
  EXPECT_EQ(j["report"]["generators"][1]["index"].get<std::string>(), "1/4");
  EXPECT_FALSE(j["report"]["generators"][1]["chosen"].get<bool>());
  EXPECT_EQ(error_of(torus.post("/api/solve", {{"N", 4}, {"generators", {{2, "0"}}}})),
            "generator 2 out of range (the mesh has 2 generators)");

  Running annulus(make_annulus(4, 24));
  const json am = json::parse(annulus.client->Get("/api/mesh")->body);
  ASSERT_EQ(am["cycles"]["loops"].size(), 2u);
  auto a = annulus.post("/api/solve", {{"N", 1}, {"boundary", {{0, "1"}, {1, "-1"}}}, {"align_boundary", false}});
  ASSERT_TRUE(a);
  EXPECT_EQ(a->status, 200) << a->body;
  auto b = annulus.post("/api/solve", {{"N", 4}, {"align_boundary", true}});
  ASSERT_TRUE(b);
  ASSERT_EQ(b->status, 200) << b->body;
  EXPECT_GT(json::parse(b->body)["report"]["fixed"]["faces"].get<int>(), 0);
}

}  // namespace
}  // namespace trivcon
