// SPDX-License-Identifier: MIT
// Tests of the editor's server (server/editor_server.h): every endpoint, its answers checked for what
// they mean (unit tangent directions, the prescription honoured, the CLI's error texts), and the refusals
// (token, origin, content type, Host, body size, malformed requests), against a server started in-process
// on a free port; connections that cpp-httplib's client does not make (slow, chunked past the limit, a
// client that does not read) over raw sockets; and `trivcon edit` itself stopped by SIGTERM mid-export.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "editor_server.h"
#include "support.h"
#include "trivcon/auto.h"
#include "trivcon/request.h"
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

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A raw TCP connection to 127.0.0.1:port, for what cpp-httplib's client does not do: send slowly, send a
// chunked body past the limit, leave an answer unread.
struct Raw {
  int fd = -1;
  explicit Raw(int port, int receive_buffer = 0) {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    if (receive_buffer > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  }
  ~Raw() { ::close(fd); }
  Raw(const Raw&) = delete;
  Raw& operator=(const Raw&) = delete;
  bool send_all(const std::string& s) const {
    for (size_t done = 0; done < s.size();) {
      const ssize_t n = ::send(fd, s.data() + done, s.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return false;
      done += static_cast<size_t>(n);
    }
    return true;
  }
  // Whether something (an answer, or the end) arrives within `seconds`.
  bool readable(double seconds) const {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, static_cast<int>(seconds * 1000)) > 0;
  }
  // What arrives until the server closes the connection, or `seconds` pass.
  std::string read_until_closed(double seconds) const {
    std::string out;
    const auto t0 = Clock::now();
    char buffer[65536];
    while (seconds_since(t0) < seconds) {
      if (!readable(0.1)) continue;
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      out.append(buffer, static_cast<size_t>(n));
    }
    return out;
  }
};

// The status of a raw answer, and the "error" of its JSON body.
int status_of(const std::string& answer) { return answer.rfind("HTTP/1.1 ", 0) == 0 ? std::atoi(answer.c_str() + 9) : -1; }
std::string raw_error(const std::string& answer) {
  const size_t body = answer.find("\r\n\r\n");
  if (body == std::string::npos) return "";
  const json j = json::parse(answer.substr(body + 4), nullptr, false);
  return j.is_object() && j.contains("error") ? j["error"].get<std::string>() : "";
}
std::string raw_head(const std::string& method, const std::string& path, int port, const std::string& token) {
  return method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\nX-Trivcon-Token: " + token +
         "\r\nContent-Type: application/json\r\n";
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
  ASSERT_EQ(payload.size(), nV * 12 + nF * 12 + nV * 4 + nF * 8);
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
  EXPECT_EQ(error_of(r().client->Get("/api/nothing")), "no such endpoint (see docs/reference/editor-api.md)");
}

// The glyph order: every face once, first times ascending, and format=oct16&order=area sends the
// directions of the first faces of it.
TEST_F(Server, TheGlyphOrderCoversEveryFaceAndSolvesFollowIt) {
  auto res = r().client->Get("/api/mesh?format=binary");
  ASSERT_TRUE(res);
  auto [header, payload] = unpack(res->body);
  const size_t nV = sphere().V.rows(), nF = sphere().F.rows();
  EXPECT_EQ(header["binary"]["glyph_order"].get<std::string>(), "uint32[faces]");
  std::vector<uint32_t> order(nF);
  std::vector<float> times(nF);
  std::memcpy(order.data(), payload.data() + 16 * nV + 12 * nF, 4 * nF);
  std::memcpy(times.data(), payload.data() + 16 * nV + 16 * nF, 4 * nF);
  EXPECT_EQ(std::set<uint32_t>(order.begin(), order.end()).size(), nF);
  EXPECT_LT(*std::max_element(order.begin(), order.end()), nF);
  EXPECT_TRUE(std::is_sorted(times.begin(), times.end()));
  EXPECT_GT(times[0], 0.0f);
  const json body = {{"N", 4}, {"singularities", eight_quarters(sphere())}};
  auto all = r().post("/api/solve?format=oct16", body);
  auto part = r().post("/api/solve?format=oct16&order=area&count=100", body);
  ASSERT_TRUE(all && part);
  ASSERT_EQ(part->status, 200) << part->body;
  auto [all_header, all_payload] = unpack(all->body);
  auto [part_header, part_payload] = unpack(part->body);
  ASSERT_EQ(part_payload.size(), 400u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(part_payload.substr(4 * i, 4), all_payload.substr(4 * order[i], 4)) << i;
  EXPECT_EQ(error_of(r().post("/api/solve?format=oct16&order=id", body)), "unknown order 'id' (known: area)");
  EXPECT_EQ(error_of(r().post("/api/solve?format=oct16&order=area&stride=7", body)), "order=area and stride exclude each other");
}

// Numbers beyond a double, text that is not UTF-8, a NUL in an index: 400 with a message that says so (the
// bytes shown escaped, nothing cut), never a 500.
TEST_F(Server, OutOfRangeNumbersAndBadTextGet400WithTheirMessage) {
  const std::string overflow =
      "the request body has a number out of range: number overflow parsing '1e400' (numbers must be within ±1.8e308)";
  const std::string sing = eight_quarters(sphere()).dump();
  auto check = [&](const std::string& body, const std::string& message) {
    auto res = r().post_text("/api/solve", body);
    ASSERT_TRUE(res) << body;
    EXPECT_EQ(res->status, 400) << body;
    EXPECT_EQ(error_of(res), message) << body;
  };
  check("{\"N\": 1e400}", overflow);
  check("{\"N\": 4, \"singularities\": " + sing + ", \"fixed\": [[0, [1e400, 0, 0]]]}", overflow);
  check("{\"N\": 4, \"cancel\": -1e400}",
        "the request body has a number out of range: number overflow parsing '-1e400' (numbers must be within ±1.8e308)");
  check("{\"N\": 4, \"singularities\": [[3, \"1/4\xff\"]]}",
        "the request body is not valid JSON: [json.exception.parse_error.101] parse error at line 1, column 36: syntax error while "
        R"(parsing value - invalid string: ill-formed UTF-8 byte; last read: '"1/4\xFF')");
  check("{\"N\": 4, \"singularities\": [[3, \"1/4\\u0000\"]]}",
        R"(--sing 3:1/4\u0000: malformed index '1/4\u0000' (expected an integer or a fraction p/q, q > 0))");
  check("{\"N\": 4, \"boundary\": [[0, \"\\u0000\"]]}",
        R"(--boundary 0:\u0000: malformed index '\u0000' (expected an integer or a fraction p/q, q > 0))");
  auto res = r().post("/api/solve?format=x%00y", json::object());
  EXPECT_EQ(error_of(res), R"(unknown format 'x\u0000y' (known: json, binary, oct16))");
  // Directions at the ends of a double's range are directions all the same.
  const json unit =
      json::parse(r().post_text("/api/solve", "{\"N\": 4, \"singularities\": " + sing + ", \"fixed\": [[0, [1, 1, 1]]]}")->body);
  for (const std::string d : {"[1e308, 1e308, 1e308]", "[1e-320, 1e-320, 1e-320]"}) {
    auto big = r().post_text("/api/solve", "{\"N\": 4, \"singularities\": " + sing + ", \"fixed\": [[0, " + d + "]]}");
    ASSERT_TRUE(big);
    ASSERT_EQ(big->status, 200) << d << ": " << big->body;
    EXPECT_EQ(json::parse(big->body)["directions"], unit["directions"]) << d;
  }
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
  EXPECT_EQ(bare.Get("/api/state", {{"X-Trivcon-Token", token}})->status, 200);
  EXPECT_EQ(bare.Get("/api/state", {{"Authorization", "token " + token}})->status, 200);
  // Not in a cookie (every port of this host is sent it), not in the address (it stays in histories).
  const std::string token_message =
      "missing or wrong token: open the URL that trivcon edit printed (API calls send it as the X-Trivcon-Token header)";
  EXPECT_EQ(error_of(bare.Get("/api/state", {{"Cookie", "trivcon_token_" + std::to_string(r().port) + "=" + token}})), token_message);
  EXPECT_EQ(error_of(bare.Get("/api/state", {{"Cookie", "trivcon_token=" + token + "; token=" + token}})), token_message);
  EXPECT_EQ(error_of(bare.Get(("/api/state?token=" + token).c_str())), token_message);
  EXPECT_EQ(
      bare.Post("/api/solve", {{"Cookie", "trivcon_token_" + std::to_string(r().port) + "=" + token}}, "{}", "application/json")->status,
      403);
}

TEST_F(Server, ThePageIsServedWithoutTokenOrCookie) {
  httplib::Client bare("127.0.0.1", r().port);
  const std::string token = r().editor->token();
  for (const std::string& path : std::vector<std::string>{"/", "/?token=" + token, "/?token=wrong"}) {
    auto res = bare.Get(path.c_str());
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200) << path;
    EXPECT_TRUE(test::contains(res->body, "/app.js"));
    EXPECT_FALSE(test::contains(res->body, token));  // the page holds no secret: the API does
    EXPECT_FALSE(res->has_header("Set-Cookie")) << path;
    EXPECT_EQ(res->get_header_value("Referrer-Policy"), "no-referrer");
  }
  auto js = bare.Get("/app.js");
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  EXPECT_GT(js->body.size(), 1000u);  // three.js is in it: the page needs no network
  // No answer of the API sets a cookie either.
  for (const char* path : {"/api/mesh", "/api/state"}) EXPECT_FALSE(r().client->Get(path)->has_header("Set-Cookie")) << path;
  EXPECT_FALSE(r().post("/api/solve", {{"N", 4}, {"singularities", eight_quarters(sphere())}})->has_header("Set-Cookie"));
}

// Another port of 127.0.0.1 is another origin but the same site: its pages' requests are refused by their
// Origin (or Referer), and a form's text/plain POST by its type, before the token is even looked at.
TEST_F(Server, RequestsFromAnotherOriginOrNotJsonAreRefused) {
  const std::string served = "http://127.0.0.1:" + std::to_string(r().port);
  const json body = {{"N", 4}, {"singularities", eight_quarters(sphere())}};
  const int revision = json::parse(r().client->Get("/api/state")->body)["revision"].get<int>();
  const std::string other = "http://127.0.0.1:18777";
  const std::string from_other = "refused: the request comes from another origin (Origin: " + other + "); only the editor's own page (" +
                                 served + ") may call its API";
  auto post = [&](const httplib::Headers& h, const std::string& type) {
    return r().client->Post("/api/solve", h, body.dump(), type.c_str());
  };
  auto res = post({{"Origin", other}}, "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 403);
  EXPECT_EQ(error_of(res), from_other);
  res = r().client->Get("/api/state", {{"Origin", other}});
  EXPECT_EQ(res->status, 403);
  EXPECT_EQ(error_of(res), from_other);
  // The form of the report: text/plain from the other port, with or without the token.
  httplib::Client bare("127.0.0.1", r().port);
  res = bare.Post("/api/solve", {{"Origin", other}}, body.dump(), "text/plain");
  EXPECT_EQ(res->status, 403);
  EXPECT_EQ(error_of(res), from_other);
  res = post({{"Referer", other + "/form.html?x=1"}}, "application/json");
  EXPECT_EQ(res->status, 403);
  EXPECT_EQ(error_of(res), "refused: the request comes from another origin (Referer: " + other + "); only the editor's own page (" +
                               served + ") may call its API");
  EXPECT_EQ(post({{"Origin", "null"}}, "application/json")->status, 403);
  EXPECT_EQ(error_of(r().client->Get("/api/state", {{"Sec-Fetch-Site", "same-site"}})),
            "refused: the request comes from another origin (Sec-Fetch-Site: same-site); only the editor's own page (" + served +
                ") may call its API");
  EXPECT_EQ(r().client->Get("/api/state", {{"Sec-Fetch-Site", "same-origin"}})->status, 200);
  EXPECT_EQ(post({{"Referer", served + ".evil.example/"}}, "application/json")->status, 403);
  // Not JSON: refused whoever sends it (a form can send these types to any address without asking).
  for (const std::string type :
       {"text/plain", "text/plain;charset=UTF-8", "application/x-www-form-urlencoded", "multipart/form-data; boundary=x"}) {
    res = post({}, type);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 403) << type;
    EXPECT_EQ(error_of(res), "refused: a POST to the API must have Content-Type: application/json (got '" + type + "')");
  }
  EXPECT_EQ(json::parse(r().client->Get("/api/state")->body)["revision"].get<int>(), revision);  // nothing above reached the session
  // The page's own requests pass: its origin, any of the served names, or no Origin at all (a script).
  EXPECT_EQ(post({{"Origin", served}}, "application/json")->status, 200);
  EXPECT_EQ(post({{"Referer", served + "/"}}, "application/json; charset=utf-8")->status, 200);
  const std::string localhost = "localhost:" + std::to_string(r().port);
  EXPECT_EQ(post({{"Origin", "http://" + localhost}, {"Host", localhost}}, "application/json")->status, 200);
  EXPECT_EQ(post({{"Origin", "http://" + localhost}}, "application/json")->status, 403);  // not the Host it was sent to
  EXPECT_EQ(post({}, "application/json")->status, 200);
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
  EXPECT_EQ(error_of(res), "request body too large (the limit is 1000 bytes)");
  EXPECT_EQ(r.client->Get("/api/state")->status, 200);
  // A chunked body within the limit is read as any other.
  const std::string small = json{{"N", 4}, {"singularities", eight_quarters(make_icosphere(1))}}.dump();
  auto chunked = r.client->Post(
      "/api/export?format=sing",
      [&](size_t, httplib::DataSink& sink) {
        sink.write(small.data(), small.size());
        sink.done();
        return true;
      },
      "application/json");
  ASSERT_TRUE(chunked);
  EXPECT_EQ(chunked->status, 200) << chunked->body;
  EXPECT_TRUE(test::contains(chunked->body, "# N 4"));
}

// A chunked body counts against the same limit as it arrives: 413 once past it, and the rest is not read
// (the client here would send 200 MiB; it stops when the answer comes).
TEST(ServerLimits, ChunkedBodiesPastTheLimitGet413WithoutBeingReadWhole) {
  server::EditorOptions options;
  options.max_body_bytes = 1u << 20;
  Running r(make_icosphere(1), options);
  Raw c(r.port);
  ASSERT_TRUE(c.send_all(raw_head("POST", "/api/solve", r.port, r.editor->token()) + "Transfer-Encoding: chunked\r\n\r\n"));
  ::fcntl(c.fd, F_SETFL, ::fcntl(c.fd, F_GETFL) | O_NONBLOCK);
  const std::string chunk = "10000\r\n" + std::string(65536, ' ') + "\r\n";
  size_t sent = 0;
  const auto t0 = Clock::now();
  bool answered = false;
  while (sent < (200u << 20) && seconds_since(t0) < 60) {
    pollfd p{c.fd, POLLIN | POLLOUT, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
      answered = true;
      break;
    }
    const size_t at = sent % chunk.size();
    const ssize_t n = ::send(c.fd, chunk.data() + at, chunk.size() - at, MSG_NOSIGNAL);
    if (n > 0) sent += static_cast<size_t>(n);
  }
  ASSERT_TRUE(answered) << "no answer after " << sent << " bytes";
  EXPECT_LT(sent, 32u << 20);
  ::fcntl(c.fd, F_SETFL, ::fcntl(c.fd, F_GETFL) & ~O_NONBLOCK);
  const std::string answer = c.read_until_closed(10);
  EXPECT_EQ(status_of(answer), 413) << answer.substr(0, 200);
  EXPECT_EQ(raw_error(answer), "request body too large (the limit is 1048576 bytes)");
  EXPECT_TRUE(test::contains(answer, "Connection: close"));
  EXPECT_EQ(r.client->Get("/api/state")->status, 200);
}

// Requests whose framing the server does not take are refused before their body is read.
TEST(ServerLimits, BodiesOfUnknownFramingAreRefused) {
  Running r(make_icosphere(1));
  auto answer = [&](const std::string& request) {
    Raw c(r.port);
    EXPECT_TRUE(c.send_all(request));
    return c.read_until_closed(10);
  };
  const std::string head = raw_head("POST", "/api/solve", r.port, r.editor->token());
  std::string a = answer(head + "\r\n");
  EXPECT_EQ(status_of(a), 411);
  EXPECT_EQ(raw_error(a), "a POST needs a Content-Length (or Transfer-Encoding: chunked)");
  a = answer(head + "Content-Length: 2\r\nContent-Encoding: gzip\r\n\r\n{}");
  EXPECT_EQ(status_of(a), 415);
  EXPECT_EQ(raw_error(a), "request bodies must not be compressed (Content-Encoding: gzip)");
  a = answer(head + "Transfer-Encoding: gzip, chunked\r\n\r\n");
  EXPECT_EQ(status_of(a), 501);
  a = answer(head + "Content-Length: 2\r\nContent-Length: 3\r\n\r\n{}");
  EXPECT_EQ(status_of(a), 400);
  EXPECT_EQ(raw_error(a), "a request has one Content-Length, not 2");
  a = answer(head + "Content-Length: 2x\r\n\r\n{}");
  EXPECT_EQ(status_of(a), 400);
  EXPECT_EQ(raw_error(a), "malformed Content-Length '2x'");
  a = answer(raw_head("PUT", "/api/solve", r.port, r.editor->token()) + "Transfer-Encoding: chunked\r\n\r\n");
  EXPECT_EQ(status_of(a), 405);
  EXPECT_EQ(raw_error(a), "method PUT not allowed (GET and POST only)");
  a = answer(raw_head("POST", "/api/nothing", r.port, r.editor->token()) + "Transfer-Encoding: chunked\r\n\r\n");
  EXPECT_EQ(status_of(a), 404);
  // A header line of any length is not read into memory: 431 past 64 KiB.
  a = answer("GET /api/state HTTP/1.1\r\nX-Long: " + std::string(100000, 'x') + "\r\n\r\n");
  EXPECT_EQ(status_of(a), 431);
  EXPECT_EQ(raw_error(a), "the request line and headers are too large (more than 65536 bytes)");
  EXPECT_EQ(r.client->Get("/api/state")->status, 200);
}

// Connections that send their headers a byte at a time hold a thread each, not the server: other requests
// are answered meanwhile, and the slow ones get 408 when their header time is up.
TEST(ServerLimits, SlowConnectionsDoNotStallTheOthers) {
  server::EditorOptions options;
  options.header_seconds = 2;
  Running r(make_icosphere(1), options);
  const std::string head = "GET /api/state HTTP/1.1\r\n";
  const std::string rest = "Host: 127.0.0.1:" + std::to_string(r.port) + "\r\nX-Trivcon-Token: " + r.editor->token() + "\r\n\r\n";
  std::vector<std::unique_ptr<Raw>> slow;
  for (int i = 0; i < 12; ++i) {
    slow.push_back(std::make_unique<Raw>(r.port));
    ASSERT_TRUE(slow.back()->send_all(head));
  }
  std::atomic<bool> done{false};
  std::thread dribble([&] {
    for (size_t k = 0; k < rest.size() && !done; ++k) {
      for (auto& s : slow) ::send(s->fd, &rest[k], 1, MSG_NOSIGNAL);
      for (int t = 0; t < 50 && !done; ++t) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  for (int i = 0; i < 5; ++i) {
    httplib::Client fresh("127.0.0.1", r.port);
    const auto t0 = Clock::now();
    auto res = fresh.Get("/api/state", {{"X-Trivcon-Token", r.editor->token()}});
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200);
    EXPECT_LT(seconds_since(t0), 1.5) << "request " << i << " waited behind the slow connections";
  }
  for (auto& s : slow) {
    const std::string answer = s->read_until_closed(8);
    EXPECT_EQ(status_of(answer), 408) << answer.substr(0, 100);
    EXPECT_EQ(raw_error(answer), "the request's headers did not arrive in time (2 s)");
  }
  done = true;
  dribble.join();
}

// Requests on one keep-alive connection do not wait for delayed ACKs: an answer's headers and body go out
// in two writes, and without TCP_NODELAY the second waited about 40 ms on most requests.
TEST(ServerLimits, KeepAliveRequestsDoNotStall) {
  Running r(make_icosphere(1));
  Raw c(r.port);
  const std::string request =
      "GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(r.port) + "\r\nX-Trivcon-Token: " + r.editor->token() + "\r\n\r\n";
  const auto t0 = Clock::now();
  std::string pending;
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(c.send_all(request));
    // One whole answer: its headers, then Content-Length bytes.
    size_t end = std::string::npos, length = 0;
    while (seconds_since(t0) < 30) {
      end = pending.find("\r\n\r\n");
      if (end != std::string::npos) {
        length = std::stoul(pending.substr(pending.find("Content-Length: ") + 16));
        if (pending.size() >= end + 4 + length) break;
      }
      char buffer[65536];
      const ssize_t n = ::recv(c.fd, buffer, sizeof buffer, 0);
      ASSERT_GT(n, 0) << "request " << i;
      pending.append(buffer, static_cast<size_t>(n));
    }
    ASSERT_EQ(status_of(pending), 200) << i;
    pending.erase(0, end + 4 + length);
  }
  EXPECT_LT(seconds_since(t0), 1.0);  // 50 requests: well under a millisecond each here, ~40 ms each with the stall
}

// No answer is compressed: cpp-httplib would brotli-compress text (a field export of 400k faces took over
// a minute); the export comes as it is, whatever the client accepts.
TEST(ServerLimits, AnswersAreNotCompressed) {
  Running r(make_icosphere(5));
  const json body = {{"N", 4}, {"singularities", eight_quarters(make_icosphere(5))}};
  auto res = r.client->Post("/api/export?format=txt", {{"Accept-Encoding", "br, gzip, deflate"}}, body.dump(), "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_FALSE(res->has_header("Content-Encoding"));
  EXPECT_EQ(test::lines_of(res->body).size(), 3u + 20480u);
  for (const char* path : {"/", "/app.js", "/api/mesh", "/api/state"}) {
    auto page = r.client->Get(path, {{"Accept-Encoding", "br, gzip"}});
    ASSERT_TRUE(page);
    EXPECT_EQ(page->status, 200) << path;
    EXPECT_FALSE(page->has_header("Content-Encoding")) << path;
  }
}

// stop() during an export whose answer the client does not read, with an idle keep-alive connection open:
// run() returns at once (a write waits no timeout after the stop).
TEST(ServerStop, StopDuringAnExportReturnsPromptly) {
  const Mesh m = make_icosphere(5);
  server::EditorOptions options;
  options.mesh_path = "generated.obj";
  auto editor = std::make_unique<server::EditorServer>(mesh_data(m), options);
  const int port = editor->bind(0);
  std::thread thread([&] { editor->run(); });
  while (!editor->running()) std::this_thread::yield();
  httplib::Client idle("127.0.0.1", port);
  idle.set_keep_alive(true);
  EXPECT_EQ(idle.Get("/api/state", {{"X-Trivcon-Token", editor->token()}})->status, 200);
  Raw c(port, 4096);
  const std::string body = json{{"N", 4}, {"singularities", eight_quarters(m)}}.dump();
  ASSERT_TRUE(c.send_all(raw_head("POST", "/api/export?format=txt", port, editor->token()) +
                         "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body));
  ASSERT_TRUE(c.readable(60));  // the answer has begun; the rest waits for a reader
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto t0 = Clock::now();
  editor->stop();
  thread.join();
  EXPECT_LT(seconds_since(t0), 2.0);
}

// `trivcon edit` itself: a big export with Accept-Encoding: br comes at once and uncompressed, and SIGTERM
// during an export ends the program within 2 s with status 0.
TEST(ServerStop, SigtermDuringAnExportEndsTheProgramPromptly) {
  const Mesh m = make_icosphere(6);
  const std::string path = test::temp_file("sphere.obj");
  write_obj(path, m.V, m.F);
  int out[2];
  ASSERT_EQ(::pipe(out), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], 1);
  posix_spawn_file_actions_addclose(&actions, out[0]);
  std::vector<std::string> args = {TRIVCON_CLI, "edit", path, "--port", "0"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, TRIVCON_CLI, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  ::close(out[1]);
  auto wait_exit = [&](double seconds) {
    const auto t0 = Clock::now();
    int status = 0;
    while (seconds_since(t0) < seconds) {
      if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  };
  // The URL it prints: http://127.0.0.1:PORT/?token=T
  std::string printed;
  const auto t0 = Clock::now();
  while (printed.find("token=") == std::string::npos || printed.find('\n', printed.find("token=")) == std::string::npos) {
    pollfd p{out[0], POLLIN, 0};
    if (seconds_since(t0) > 120 || (::poll(&p, 1, 100) > 0 && [&] {
          char b[4096];
          const ssize_t n = ::read(out[0], b, sizeof b);
          if (n > 0) printed.append(b, static_cast<size_t>(n));
          return n <= 0;
        }()))
      break;
  }
  const size_t at = printed.find("http://127.0.0.1:");
  const size_t token_at = printed.find("token=");
  if (at == std::string::npos || token_at == std::string::npos) {
    ::kill(pid, SIGKILL);
    wait_exit(10);
    FAIL() << "no URL printed: " << printed;
  }
  const int port = std::atoi(printed.c_str() + at + 17);
  const std::string token = printed.substr(token_at + 6, 32);
  const std::string body = json{{"N", 4}, {"singularities", eight_quarters(m)}}.dump();
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(120, 0);
  const auto t1 = Clock::now();
  auto res = client.Post("/api/export?format=txt", {{"X-Trivcon-Token", token}, {"Accept-Encoding", "br, gzip"}}, body, "application/json");
  const double export_seconds = seconds_since(t1);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_FALSE(res->has_header("Content-Encoding"));
  EXPECT_EQ(test::lines_of(res->body).size(), 3u + static_cast<size_t>(m.F.rows()));
  EXPECT_LT(export_seconds, 30.0);  // seconds, not the minutes of brotli
  // Another export, its answer left unread; SIGTERM while it is being computed or sent.
  Raw c(port, 4096);
  ASSERT_TRUE(c.send_all(raw_head("POST", "/api/export?format=txt", port, token) + "Content-Length: " + std::to_string(body.size()) +
                         "\r\n\r\n" + body));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto t2 = Clock::now();
  ::kill(pid, SIGTERM);
  const int status = wait_exit(5);
  const double stop_seconds = seconds_since(t2);
  if (status < 0) ::kill(pid, SIGKILL), wait_exit(10);
  EXPECT_EQ(status, 0);
  EXPECT_LT(stop_seconds, 2.0);
  ::close(out[0]);
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

// The report says whether the per-face field reads exactly the prescription (the page shows it): two +1
// crosses on a coarse icosphere turn by more than π/4 across edges, so it does not; the same two as vector
// field singularities (N = 1, where the limit is π) it does.
TEST(ServerField, TheReportSaysWhetherTheFieldIsExact) {
  Running coarse(make_icosphere(1));
  auto r = coarse.post("/api/solve", {{"N", 4}, {"singularities", {{0, "1"}, {3, "1"}}}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_TRUE(j["report"]["verified"].get<bool>());
  EXPECT_FALSE(j["report"]["field_exact"].get<bool>());
  r = coarse.post("/api/solve", {{"N", 1}, {"singularities", {{0, "1"}, {3, "1"}}}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_TRUE(json::parse(r->body)["report"]["field_exact"].get<bool>());
}

// A boundary alignment that needs interior singularities and gets none: 400 with the library's message.
TEST(ServerField, AnAlignedDiskWithoutSingularitiesIsRefused) {
  Running disk(make_disk(8, 8));
  auto r = disk.post("/api/solve", {{"N", 4}, {"align_boundary", true}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400) << r->body;
  EXPECT_NE(r->body.find("need interior singularities summing to 1"), std::string::npos) << r->body;
  r = disk.post("/api/solve", {{"N", 4}, {"align_boundary", true}, {"singularities", {{0, "1"}}}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << r->body;
}

// After Auto, solves of that N take each component's rotation from the smoothest field (as solve --auto
// and Python's "auto" do): on an ellipsoid, the field the page gets for auto's singularities is within a
// few hundredths of a radian of the smoothest field on average, and was far from it before Auto.
TEST(ServerField, AfterAutoTheFieldKeepsTheSmoothestFieldsRotation) {
  Mesh m = make_icosphere(3);
  for (int v = 0; v < m.V.rows(); ++v) m.V.row(v) = Eigen::RowVector3d(2.0 * m.V(v, 0), m.V(v, 1), 0.6 * m.V(v, 2));
  Running ellipsoid(m);
  FieldDesigner designer(m.V, m.F);
  AutoOptions o;
  o.N = 4;
  const AutoResult a = auto_singularities(designer, o);
  json sing = json::array();
  for (auto [v, n] : a.vertex) sing.push_back({v, format_index(n, 4)});
  auto mean_difference = [&](const httplib::Result& res) {
    const json d = json::parse(res->body)["directions"];
    double sum = 0, area = 0;
    for (int f = 0; f < m.F.rows(); ++f) {
      const Eigen::Vector3d v(d[3 * f].get<double>(), d[3 * f + 1].get<double>(), d[3 * f + 2].get<double>());
      const double angle = designer.geometry().angle_in_face(f, v);
      sum += designer.geometry().face_area(f) * std::abs(reduce_angle(angle - a.field.angle(f), 4));
      area += designer.geometry().face_area(f);
    }
    return sum / area;
  };
  auto before = ellipsoid.post("/api/solve", {{"N", 4}, {"singularities", sing}});
  ASSERT_TRUE(before);
  ASSERT_EQ(before->status, 200) << before->body;
  EXPECT_GT(mean_difference(before), 0.2);
  auto placed = ellipsoid.post("/api/auto", {{"N", 4}});
  ASSERT_TRUE(placed);
  ASSERT_EQ(placed->status, 200) << placed->body;
  EXPECT_EQ(json::parse(placed->body)["singularities"], sing);
  auto after = ellipsoid.post("/api/solve", {{"N", 4}, {"singularities", sing}});
  ASSERT_TRUE(after);
  ASSERT_EQ(after->status, 200) << after->body;
  EXPECT_LT(mean_difference(after), 0.03);
  EXPECT_TRUE(json::parse(after->body)["report"]["verified"].get<bool>());
}

// Feature alignment through the API, as the CLI's --align-features and Python's align_features (one request
// layer, trivcon/request.h): on the flat-faced cube, Auto with align_features puts +1/4 at the 8 corners, and
// the solve fixes the faces beside the 12 n cube edges along them, the same directions as solve_request gives;
// the state remembers the angle; a bad angle is a 400.
TEST(ServerField, FeatureAlignmentAsTheCliHasIt) {
  const int n = 4;
  const Mesh m = make_cube_sphere(n, false);
  Running cube(m);
  auto placed = cube.post("/api/auto", {{"N", 4}, {"align_features", 30}});
  ASSERT_TRUE(placed);
  ASSERT_EQ(placed->status, 200) << placed->body;
  const json sing = json::parse(placed->body)["singularities"];
  ASSERT_EQ(sing.size(), 8u);
  for (const json& s : sing) {
    EXPECT_EQ(s[1], "1/4");
    for (int k = 0; k < 3; ++k) EXPECT_EQ(std::abs(m.V(s[0].get<int>(), k)), 1.0);
  }
  auto r = cube.post("/api/solve", {{"N", 4}, {"singularities", sing}, {"align_features", 30}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json j = json::parse(r->body);
  EXPECT_TRUE(j["report"]["verified"].get<bool>());
  FieldDesigner designer(m.V, m.F);
  FieldRequest q;
  q.prescription.N = 4;
  for (const json& s : sing) q.prescription.vertex[s[0].get<int>()] = 1;
  q.feature_degrees = 30;
  const FieldOutcome out = solve_request(designer, m.F, q);
  EXPECT_EQ(out.sharp_edges.size(), static_cast<size_t>(12 * n));
  EXPECT_EQ(j["report"]["fixed"]["faces"].get<int>(), static_cast<int>(out.prescription.fixed.size()));
  const json d = j["directions"];
  double worst = 0;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d v(d[3 * f].get<double>(), d[3 * f + 1].get<double>(), d[3 * f + 2].get<double>());
    worst = std::max(worst, std::abs(reduce_angle(designer.geometry().angle_in_face(f, v) - out.design.field.angle(f), 4)));
  }
  EXPECT_LT(worst, 1e-6);
  const json state = json::parse(cube.client->Get("/api/state")->body);
  EXPECT_EQ(state["request"]["align_features"], 30);
  auto bad = cube.post("/api/solve", {{"N", 4}, {"singularities", sing}, {"align_features", 200}});
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("align_features: expected an angle in degrees in [0, 180] (sharp edges) or null, got 200"), std::string::npos)
      << bad->body;
}

}  // namespace
}  // namespace trivcon
