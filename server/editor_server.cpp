#include "editor_server.h"

#include <algorithm>
#include <charconv>
#include <numeric>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <shared_mutex>
#include <sstream>

#include "report.h"
#include "summary.h"
#include "trivcon/auto.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/streamlines.h"
#include "web_assets.h"
// Last: its system headers (<resolv.h>) define `_res`, a name Eigen's headers use.
#include <httplib.h>

namespace trivcon::server {

namespace {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

// The CLI's range for -N (apps/prescription_options.cpp).
constexpr int kMaxN = 1000;

// cpp-httplib compresses (brotli, gzip) any body whose type is exactly "application/json" or text/… when the
// client accepts it: seconds for a big mesh or field, on a connection that is almost always this machine's
// loopback. A type with its charset parameter is not on its list, so answers go out as they are.
constexpr const char* kJson = "application/json; charset=utf-8";

// A request the client got wrong: its status and the message of the {"error": …} body.
struct BadRequest {
  int status;
  std::string message;
};

std::string random_token() {
  std::random_device rd;  // the kernel's generator on Linux
  std::string token;
  static const char* hex = "0123456789abcdef";
  for (int i = 0; i < 32; ++i) token += hex[rd() % 16];
  return token;
}

// Compares without stopping at the first difference, so that the time taken does not tell how much of a guess was right.
bool same_secret(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::string number_text(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

void set_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(json{{"error", message}}.dump() + "\n", kJson);
}

// Little-endian container of the binary responses: a uint32 byte count, that many bytes of JSON padded
// with spaces to a multiple of 4, then the raw arrays (so a Float32Array can view them in place).
std::string binary_container(const std::string& header_json, const std::vector<std::pair<const void*, size_t>>& arrays) {
  std::string h = header_json;
  while ((4 + h.size()) % 4 != 0) h += ' ';
  size_t total = 4 + h.size();
  for (const auto& a : arrays) total += a.second;
  std::string out;
  out.reserve(total);
  const uint32_t n = static_cast<uint32_t>(h.size());
  const unsigned char len[4] = {static_cast<unsigned char>(n), static_cast<unsigned char>(n >> 8), static_cast<unsigned char>(n >> 16),
                                static_cast<unsigned char>(n >> 24)};
  out.append(reinterpret_cast<const char*>(len), 4);
  out += h;
  for (const auto& a : arrays) out.append(static_cast<const char*>(a.first), a.second);  // x86/ARM hosts: little-endian already
  return out;
}

// A value as an error message shows it: numbers, booleans and short strings as they are; nothing that could be
// long (or nested deep enough to make printing it costly) in full.
std::string brief(const json& j) {
  if (j.is_array()) return "an array of " + std::to_string(j.size());
  if (j.is_object()) return "an object";
  if (j.is_string() && j.get_ref<const std::string&>().size() > 40)
    return "a string of " + std::to_string(j.get_ref<const std::string&>().size()) + " bytes";
  return j.dump();
}

// Nesting deeper than any request needs ([[v, [x, y, z]], …] is 3 levels) is refused while parsing, before a
// body of brackets becomes millions of nested values.
constexpr int kMaxDepth = 8;

// The id text of a JSON [id, …] entry: an integer, passed on as text to the CLI's own parser (which names
// negative or huge ids the way it does on the command line).
std::string id_text(const json& j, const std::string& where, const char* what) {
  if (j.is_number_integer()) return j.is_number_unsigned() ? std::to_string(j.get<uint64_t>()) : std::to_string(j.get<int64_t>());
  throw BadRequest{400, where + ": the " + std::string(what) + " id must be an integer, got " + brief(j)};
}

std::string index_text(const json& j, const std::string& where) {
  if (j.is_string()) return j.get<std::string>();
  if (j.is_number_integer()) return id_text(j, where, "index");
  throw BadRequest{400, where + ": the index must be a string such as \"1/4\" or an integer, got " + brief(j)};
}

const json& pairs_field(const json& body, const char* key) {
  static const json empty = json::array();
  const auto it = body.find(key);
  if (it == body.end() || it->is_null()) return empty;
  if (!it->is_array()) throw BadRequest{400, std::string(key) + ": expected an array of [id, value] pairs"};
  return *it;
}

const json& pair_at(const json& list, size_t i, const char* key) {
  const json& e = list[i];
  if (!e.is_array() || e.size() != 2)
    throw BadRequest{400, std::string(key) + "[" + std::to_string(i) + "]: expected a pair [id, value], got " + brief(e)};
  return e;
}

}  // namespace

struct EditorServer::Impl {
  MeshData mesh;
  EditorOptions options;
  std::string token;
  std::unique_ptr<FieldDesigner> designer;
  int port = -1;
  httplib::Server http;
  std::atomic<bool> bound{false};

  // design() is const and shares the designer; set_fixed_faces refactors and takes it exclusively.
  // `fixed_faces` is what the designer is set up for (nullopt after a set-up that failed: set it up again).
  mutable std::shared_mutex designer_mutex;
  std::optional<std::vector<int>> fixed_faces;

  // The session as the server last saw it (GET /api/state).
  std::mutex state_mutex;
  ojson state;

  std::once_flag mesh_json_once, mesh_binary_once;
  std::string mesh_json, mesh_binary;

  // One solve request, parsed.
  struct Request {
    IndexPrescription prescription;
    bool align_boundary = false;
    std::map<int, double> explicit_fixed;  // from "fixed" (they win over align_boundary on the same face)
    std::vector<int> fixed_faces;          // sorted: every face of prescription.fixed
    double auto_cancel = 0;                // /api/auto's "cancel"
  };

  Impl(MeshData m, std::unique_ptr<FieldDesigner> d, EditorOptions o) : mesh(std::move(m)), options(std::move(o)) {
    token = options.token.empty() ? random_token() : options.token;
    designer = d ? std::move(d) : std::make_unique<FieldDesigner>(mesh.V, mesh.F);
    Request initial;
    initial.prescription = options.initial;
    initial.align_boundary = options.align_boundary;
    initial.explicit_fixed = options.initial.fixed;
    complete_fixed(initial);
    // Not validated here: a session may well start unbalanced (a bare sphere); the page says what is missing.
    designer->set_fixed_faces(initial.fixed_faces);  // factor now: the first edit should be as fast as the others
    fixed_faces = initial.fixed_faces;
    state = {{"revision", 0}, {"request", normalized(initial)}, {"solved", nullptr}, {"error", nullptr}, {"last_solved", nullptr}};
  }

  int num_generators() const { return static_cast<int>(designer->cycles().generators.size()); }

  // Adds align_boundary's faces under the explicit ones, and lists the fixed faces.
  void complete_fixed(Request& r) const {
    r.prescription.fixed.clear();
    if (r.align_boundary) r.prescription.fixed = boundary_alignment(designer->V(), designer->topology(), designer->geometry());
    for (auto [f, angle] : r.explicit_fixed) r.prescription.fixed[f] = angle;
    r.fixed_faces.clear();
    for (auto [f, angle] : r.prescription.fixed) r.fixed_faces.push_back(f);
  }

  // The request in the API's own shape, ids and index texts normalized (GET /api/state, session files).
  ojson normalized(const Request& r) const {
    const IndexPrescription& p = r.prescription;
    ojson sing = ojson::array(), gens = ojson::array(), loops = ojson::array(), fixed = ojson::array();
    for (auto [v, n] : p.vertex) sing.push_back({v, format_index(n, p.N)});
    for (auto [g, n] : p.generator) gens.push_back({g, format_index(n, p.N)});
    for (auto [l, n] : p.loop) loops.push_back({l, format_index(n, p.N)});
    for (auto [f, angle] : r.explicit_fixed) {
      const Eigen::Vector3d d = designer->geometry().direction_in_face(f, angle);
      fixed.push_back({f, {d.x(), d.y(), d.z()}});
    }
    return {{"N", p.N},          {"singularities", sing}, {"generators", gens},
            {"boundary", loops}, {"fixed", fixed},        {"align_boundary", r.align_boundary}};
  }

  Request parse_request(const std::string& body_text) const {
    json body;
    try {
      body = json::parse(body_text, [](int depth, json::parse_event_t, json&) {
        if (depth > kMaxDepth) throw BadRequest{400, "the request body nests deeper than " + std::to_string(kMaxDepth) + " levels"};
        return true;
      });
    } catch (const json::parse_error& e) {
      throw BadRequest{400, std::string("the request body is not valid JSON: ") + e.what()};
    }
    if (!body.is_object()) throw BadRequest{400, "the request body must be a JSON object, got " + std::string(body.type_name())};
    Request r;
    IndexPrescription& p = r.prescription;
    p.N = options.initial.N;
    if (body.contains("N")) {
      const json& N = body["N"];
      if (!N.is_number_integer() || N.get<int64_t>() < 1 || N.get<int64_t>() > kMaxN)
        throw BadRequest{400, "N: expected an integer from 1 to " + std::to_string(kMaxN) + " (the symmetry), got " + brief(N)};
      p.N = N.get<int>();
    }
    try {
      // [[id, index], …] lists, each entry passed on as the CLI's "ID:INDEX" (so errors are the CLI's).
      auto index_pairs = [&](const char* key, const char* what, void (*add)(const std::string&, IndexPrescription&)) {
        const json& list = pairs_field(body, key);
        for (size_t i = 0; i < list.size(); ++i) {
          const json& e = pair_at(list, i, key);
          const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
          add(id_text(e[0], where, what) + ":" + index_text(e[1], where), p);
        }
      };
      index_pairs("singularities", "vertex", add_vertex_index);
      index_pairs("generators", "generator", add_generator_index);
      index_pairs("boundary", "boundary loop", add_loop_index);
      const json& fixed = pairs_field(body, "fixed");
      for (size_t i = 0; i < fixed.size(); ++i) {
        const json& e = pair_at(fixed, i, "fixed");
        const std::string where = "fixed[" + std::to_string(i) + "]";
        std::string spec = id_text(e[0], where, "face") + ":";
        if (e[1].is_array() && e[1].size() == 3 && e[1][0].is_number() && e[1][1].is_number() && e[1][2].is_number())
          spec += number_text(e[1][0].get<double>()) + "," + number_text(e[1][1].get<double>()) + "," + number_text(e[1][2].get<double>());
        else if (e[1].is_object() && e[1].size() == 1 && e[1].contains("angle") && e[1]["angle"].is_number())
          spec += "angle=" + number_text(e[1]["angle"].get<double>());
        else
          throw BadRequest{400, where + ": expected a direction [x, y, z] or {\"angle\": A}, got " + brief(e[1])};
        add_fixed_direction(spec, designer->topology(), designer->geometry(), r.explicit_fixed);
      }
    } catch (const Error& e) {
      throw BadRequest{400, e.what()};
    }
    if (body.contains("align_boundary")) {
      if (!body["align_boundary"].is_boolean()) throw BadRequest{400, "align_boundary: expected true or false"};
      r.align_boundary = body["align_boundary"].get<bool>();
    }
    if (body.contains("cancel")) {
      const json& c = body["cancel"];
      if (!c.is_number() || !std::isfinite(c.get<double>()) || c.get<double>() < 0)
        throw BadRequest{400, "cancel: expected a number >= 0 (mean edge lengths), got " + brief(c)};
      r.auto_cancel = c.get<double>();
    }
    complete_fixed(r);
    return r;
  }

  // Runs `work` with the designer set up for the request's fixed faces, sharing it when it already is.
  template <class Work>
  auto with_designer(const std::vector<int>& faces, Work work) {
    {
      std::shared_lock lock(designer_mutex);
      if (fixed_faces && *fixed_faces == faces) return work(*designer);
    }
    std::unique_lock lock(designer_mutex);
    if (!fixed_faces || *fixed_faces != faces) {
      fixed_faces.reset();
      designer->set_fixed_faces(faces);
      fixed_faces = faces;
    }
    return work(*designer);
  }

  struct Solved {
    ojson report;
    Field field;
    IndexPrescription prescription;
  };

  Solved solve(const Request& r) {
    // The prescription's own mistakes first (the CLI's messages), before any refactoring for fixed faces.
    try {
      validate_prescription(designer->topology(), num_generators(), r.prescription);
    } catch (const Error& e) {
      record(r, false, e.what());
      throw BadRequest{400, e.what()};
    }
    Solved s;
    try {
      with_designer(r.fixed_faces, [&](const FieldDesigner& d) {
        const Design design = d.design(r.prescription);
        const bool ok = design_verified(design);
        const cli::ReportRun run{options.mesh_path, "", "cotan", "cholesky", r.align_boundary, options.read_seconds, 0, ok};
        s.report = cli::solve_report(run, mesh, d, r.prescription, design);
        s.field = design.field;
        return 0;
      });
    } catch (const Error& e) {
      record(r, false, e.what());
      throw BadRequest{400, e.what()};
    }
    s.prescription = r.prescription;
    record(r, true, "");
    return s;
  }

  void record(const Request& r, bool ok, const std::string& error) {
    const ojson request = normalized(r);
    std::lock_guard lock(state_mutex);
    state["revision"] = state["revision"].get<int>() + 1;
    state["request"] = request;
    state["solved"] = ok;
    state["error"] = ok ? ojson(nullptr) : ojson(error);
    if (ok) state["last_solved"] = request;
  }

  const std::string& get_mesh_json() {
    std::call_once(mesh_json_once, [&] {
      ojson j = mesh_header();
      ojson V = ojson::array(), F = ojson::array();
      for (int v = 0; v < mesh.V.rows(); ++v) V.push_back({mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)});
      for (int f = 0; f < mesh.F.rows(); ++f) F.push_back({mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)});
      j["vertices"] = std::move(V);
      j["faces"] = std::move(F);
      j["vertex_component"] = designer->topology().vertex_component;
      mesh_json = j.dump();
    });
    return mesh_json;
  }

  const std::string& get_mesh_binary() {
    std::call_once(mesh_binary_once, [&] {
      const int nV = static_cast<int>(mesh.V.rows()), nF = static_cast<int>(mesh.F.rows());
      std::vector<float> V(3 * static_cast<size_t>(nV));
      std::vector<uint32_t> F(3 * static_cast<size_t>(nF));
      for (int v = 0; v < nV; ++v)
        for (int k = 0; k < 3; ++k) V[3 * v + k] = static_cast<float>(mesh.V(v, k));
      for (int f = 0; f < nF; ++f)
        for (int k = 0; k < 3; ++k) F[3 * f + k] = static_cast<uint32_t>(mesh.F(f, k));
      const std::vector<int>& comp = designer->topology().vertex_component;
      ojson j = mesh_header();
      j["binary"] = {{"vertices", "float32[3 * vertices]"}, {"faces", "uint32[3 * faces]"}, {"vertex_component", "int32[vertices]"}};
      mesh_binary = binary_container(j.dump(), {{V.data(), V.size() * 4}, {F.data(), F.size() * 4}, {comp.data(), comp.size() * 4}});
    });
    return mesh_binary;
  }

  // What `trivcon info --json --cycles` says, and the session's symmetry.
  ojson mesh_header() const {
    const Topology& t = designer->topology();
    ojson j = cli::mesh_summary(options.mesh_path, mesh, t, designer->geometry());
    j["cycles"] = cli::cycles_summary(t, designer->geometry(), designer->cycles());
    j["N"] = options.initial.N;
    return j;
  }

  // --- HTTP ---

  std::string cookie_name() const { return "trivcon_token_" + std::to_string(port); }

  bool host_allowed(const std::string& host_header) const {
    const std::string p = ":" + std::to_string(port);
    std::vector<std::string> names = {"127.0.0.1", "localhost", "[::1]"};
    const std::string& h = options.host;
    names.push_back(h.find(':') != std::string::npos && h.front() != '[' ? "[" + h + "]" : h);
    for (const std::string& n : names)
      if (host_header == n + p || (port == 80 && host_header == n)) return true;
    // Listening on every interface: any address literal may reach it, but no name (a rebinding attack needs a name).
    if (h == "0.0.0.0" || h == "::") {
      if (host_header.size() <= p.size() || host_header.compare(host_header.size() - p.size(), p.size(), p) != 0) return false;
      const std::string name = host_header.substr(0, host_header.size() - p.size());
      if (name.front() == '[' && name.back() == ']') return name.find_first_not_of("[]0123456789abcdefABCDEF:.") == std::string::npos;
      return name.find_first_not_of("0123456789.") == std::string::npos && std::count(name.begin(), name.end(), '.') == 3;
    }
    return false;
  }

  std::string cookie_token(const httplib::Request& req) const {
    const std::string cookies = req.get_header_value("Cookie");
    const std::string key = cookie_name() + "=";
    for (size_t pos = 0; pos < cookies.size();) {
      while (pos < cookies.size() && (cookies[pos] == ' ' || cookies[pos] == ';')) ++pos;
      const size_t end = std::min(cookies.find(';', pos), cookies.size());
      if (cookies.compare(pos, key.size(), key) == 0) return cookies.substr(pos + key.size(), end - pos - key.size());
      pos = end;
    }
    return "";
  }

  bool token_ok(const httplib::Request& req) const {
    if (same_secret(req.get_header_value("X-Trivcon-Token"), token)) return true;
    const std::string auth = req.get_header_value("Authorization");
    if (auth.rfind("token ", 0) == 0 && same_secret(auth.substr(6), token)) return true;
    if (same_secret(cookie_token(req), token)) return true;
    return req.has_param("token") && same_secret(req.get_param_value("token"), token);
  }

  // Wraps an API handler: answers a BadRequest, or a library error it did not expect, with {"error": …}.
  template <class Handler>
  httplib::Server::Handler api(Handler handler) {
    return [this, handler](const httplib::Request& req, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      try {
        handler(req, res);
      } catch (const BadRequest& e) {
        set_error(res, e.status, e.message);
      } catch (const Error& e) {
        set_error(res, 400, e.what());
      } catch (const std::bad_alloc&) {
        set_error(res, 507, "out of memory");
      }
    };
  }

  static bool wants_binary(const httplib::Request& req) {
    if (req.has_param("format")) return req.get_param_value("format") == "binary";
    return req.get_header_value("Accept").find("application/octet-stream") != std::string::npos;
  }

  // A whole-number query parameter in [lo, hi], `fallback` when absent.
  static long long int_param(const httplib::Request& req, const char* name, long long fallback, long long lo, long long hi) {
    if (!req.has_param(name)) return fallback;
    const std::string text = req.get_param_value(name);
    long long v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v < lo || v > hi)
      throw BadRequest{400, std::string(name) + ": expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
                                ", got '" + text + "'"};
    return v;
  }

  static void check_format(const httplib::Request& req, std::initializer_list<const char*> known) {
    if (!req.has_param("format")) return;
    const std::string f = req.get_param_value("format");
    for (const char* k : known)
      if (f == k) return;
    std::string list;
    for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    throw BadRequest{400, "unknown format '" + f + "' (known: " + list + ")"};
  }

  void routes() {
    http.set_payload_max_length(options.max_body_bytes);
    http.set_default_headers({{"X-Content-Type-Options", "nosniff"}, {"Referrer-Policy", "no-referrer"}, {"X-Frame-Options", "DENY"}});
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      const std::string host = req.get_header_value("Host");
      if (!host_allowed(host)) {
        set_error(res, 403,
                  "refused: the Host header '" + host + "' is not the address this editor serves (" + options.host + ":" +
                      std::to_string(port) + "); open the URL that trivcon edit printed");
        return httplib::Server::HandlerResponse::Handled;
      }
      if (req.path.rfind("/api/", 0) == 0 && !token_ok(req)) {
        set_error(res, 403,
                  "missing or wrong token: open the URL that trivcon edit printed (API calls send it as the X-Trivcon-Token header)");
        return httplib::Server::HandlerResponse::Handled;
      }
      return httplib::Server::HandlerResponse::Unhandled;
    });
    http.set_error_handler([](const httplib::Request&, httplib::Response& res) {
      if (!res.body.empty()) return;
      if (res.status == 404)
        set_error(res, 404, "no such endpoint (see README.md, Editor)");
      else if (res.status == 413)
        set_error(res, 413, "request body too large");
      else
        set_error(res, res.status, "request refused (HTTP " + std::to_string(res.status) + ")");
    });
    http.set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr) { set_error(res, 500, "internal error"); });

    http.Get("/", [this](const httplib::Request& req, httplib::Response& res) {
      const bool by_query = req.has_param("token") && same_secret(req.get_param_value("token"), token);
      if (!by_query && !same_secret(cookie_token(req), token)) {
        res.status = 403;
        res.set_content(
            "<!doctype html><title>trivcon edit</title><p>This page needs its token: open the URL that <code>trivcon edit</code> "
            "printed.</p>",
            "text/html; charset=utf-8");
        return;
      }
      // The cookie lets a reload without ?token= work; SameSite=Strict keeps other sites' pages from sending it.
      if (by_query) res.set_header("Set-Cookie", cookie_name() + "=" + token + "; Path=/; HttpOnly; SameSite=Strict");
      serve_asset("/index.html", res);
      res.set_header("Cache-Control", "no-store");
      res.set_header(
          "Content-Security-Policy",
          "default-src 'self'; img-src 'self' data: blob:; style-src 'self' 'unsafe-inline'; connect-src 'self'; frame-ancestors 'none'");
    });
    http.Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
    http.Get("/app.js", [this](const httplib::Request&, httplib::Response& res) { serve_asset("/app.js", res); });

    http.Get("/api/mesh", api([this](const httplib::Request& req, httplib::Response& res) {
               check_format(req, {"json", "binary"});
               if (wants_binary(req))
                 res.set_content(get_mesh_binary(), "application/octet-stream");
               else
                 res.set_content(get_mesh_json(), kJson);
             }));
    http.Get("/api/state", api([this](const httplib::Request&, httplib::Response& res) {
               std::lock_guard lock(state_mutex);
               res.set_content(state.dump() + "\n", kJson);
             }));
    http.Post("/api/solve", api([this](const httplib::Request& req, httplib::Response& res) {
                check_format(req, {"json", "binary", "oct16"});
                const auto t0 = Clock::now();
                const Request r = parse_request(req.body);
                const Solved s = solve(r);
                const Geometry& g = designer->geometry();
                const int nF = static_cast<int>(s.field.angle.size());
                if (req.has_param("format") && req.get_param_value("format") == "oct16") {
                  // What the page uses: a third of the bytes of Float32 x y z (the transfer is most of an edit's time
                  // on a big mesh), at an angular error below 1e-4 radians, plenty for drawing; and with stride/count
                  // only the faces it draws (faces i · stride mod F, i < count).
                  const long long stride = int_param(req, "stride", 1, 1, nF > 0 ? nF : 1);
                  const long long count = int_param(req, "count", nF, 0, nF);
                  if (std::gcd(stride, static_cast<long long>(nF > 0 ? nF : 1)) != 1)
                    throw BadRequest{400, "stride " + std::to_string(stride) + " shares a factor with the face count " +
                                              std::to_string(nF) + ": the faces i * stride mod F would repeat"};
                  std::vector<int16_t> d(2 * static_cast<size_t>(count));
                  for (long long i = 0; i < count; ++i) {
                    const int f = static_cast<int>((i * stride) % nF);
                    const Eigen::Vector3d dir = g.direction_in_face(f, s.field.angle(f));  // only the faces asked for
                    const double x = dir.x(), y = dir.y(), z = dir.z();
                    const double l1 = std::abs(x) + std::abs(y) + std::abs(z);
                    double u = x / l1, v = y / l1;
                    if (z < 0) {
                      const double u0 = u;
                      u = (1 - std::abs(v)) * (u0 >= 0 ? 1 : -1);
                      v = (1 - std::abs(u0)) * (v >= 0 ? 1 : -1);
                    }
                    d[2 * i] = static_cast<int16_t>(std::lround(u * 32767));
                    d[2 * i + 1] = static_cast<int16_t>(std::lround(v * 32767));
                  }
                  const std::string body = binary_container(ojson{{"report", s.report}}.dump(), {{d.data(), d.size() * 2}});
                  res.set_header("X-Trivcon-Server-Seconds", number_text(std::chrono::duration<double>(Clock::now() - t0).count()));
                  res.set_content(body, "application/octet-stream");
                } else if (wants_binary(req)) {
                  const MatrixX3d directions = field_directions(g, s.field);
                  std::vector<float> d(3 * static_cast<size_t>(nF));
                  for (int f = 0; f < nF; ++f)
                    for (int k = 0; k < 3; ++k) d[3 * f + k] = static_cast<float>(directions(f, k));
                  const std::string body = binary_container(ojson{{"report", s.report}}.dump(), {{d.data(), d.size() * 4}});
                  res.set_header("X-Trivcon-Server-Seconds", number_text(std::chrono::duration<double>(Clock::now() - t0).count()));
                  res.set_content(body, "application/octet-stream");
                } else {
                  const MatrixX3d directions = field_directions(g, s.field);
                  std::vector<double> d(3 * static_cast<size_t>(nF));
                  for (int f = 0; f < nF; ++f)
                    for (int k = 0; k < 3; ++k) d[3 * f + k] = directions(f, k);
                  ojson out = {{"report", s.report}, {"directions", d}};
                  res.set_header("X-Trivcon-Server-Seconds", number_text(std::chrono::duration<double>(Clock::now() - t0).count()));
                  res.set_content(out.dump() + "\n", kJson);
                }
              }));
    http.Post("/api/auto", api([this](const httplib::Request& req, httplib::Response& res) {
                const Request r = parse_request(req.body);
                AutoOptions ao;
                ao.N = r.prescription.N;
                ao.cancel_distance = r.auto_cancel;
                ao.fixed = r.prescription.fixed;
                std::shared_lock lock(designer_mutex);  // auto_singularities reads the designer; no refactoring meanwhile
                const AutoResult a = auto_singularities(*designer, ao);
                lock.unlock();
                ojson sing = ojson::array();
                for (auto [v, n] : a.vertex) sing.push_back({v, format_index(n, ao.N)});
                ojson out = {{"N", ao.N}, {"singularities", sing}, {"found", a.found.size()}, {"cancelled_pairs", a.pairs.size()}};
                res.set_content(out.dump() + "\n", kJson);
              }));
    http.Post("/api/export", api([this](const httplib::Request& req, httplib::Response& res) {
                const std::string format = req.has_param("format") ? req.get_param_value("format") : "txt";
                check_format(req, {"txt", "rawfield", "ply", "sing"});
                const Request r = parse_request(req.body);
                std::ostringstream out;
                std::string name;
                if (format == "sing") {
                  try {
                    validate_prescription(designer->topology(), num_generators(), r.prescription);
                  } catch (const Error& e) {
                    throw BadRequest{400, e.what()};
                  }
                  write_singularities_to(out, r.prescription.vertex, r.prescription.N);
                  name = "singularities.txt";
                } else {
                  const Solved s = solve(r);
                  name = "field." + format;
                  write_field_to(out, name, mesh.V, mesh.F, designer->geometry(), s.field);
                }
                res.set_header("Content-Disposition", "attachment; filename=\"" + name + "\"");
                res.set_content(out.str(), format == "ply" ? "application/octet-stream" : "text/plain; charset=utf-8");
              }));
    http.Post("/api/streamlines", api([this](const httplib::Request& req, httplib::Response& res) {
                const Request r = parse_request(req.body);
                const Solved s = solve(r);
                std::vector<std::pair<int, int>> sing(s.prescription.vertex.begin(), s.prescription.vertex.end());
                const std::vector<Streamline> lines = trace_streamlines(mesh.V, designer->topology(), designer->geometry(), s.field, sing);
                // Float32 x y z per point; a line's points follow one another, `counts` says how many each has.
                std::vector<float> points;
                ojson counts = ojson::array();
                for (const Streamline& l : lines) {
                  counts.push_back(l.points.size());
                  for (const Eigen::Vector3d& p : l.points)
                    for (int k = 0; k < 3; ++k) points.push_back(static_cast<float>(p(k)));
                }
                res.set_content(binary_container(ojson{{"counts", counts}}.dump(), {{points.data(), points.size() * 4}}),
                                "application/octet-stream");
              }));
  }

  void serve_asset(const std::string& path, httplib::Response& res) {
    for (const WebAsset& a : web_assets())
      if (path == a.path) {
        res.set_content(reinterpret_cast<const char*>(a.data), a.size, a.content_type);
        return;
      }
    set_error(res, 404, "no such file");
  }
};

EditorServer::EditorServer(MeshData mesh, EditorOptions options) : EditorServer(std::move(mesh), nullptr, std::move(options)) {}

EditorServer::EditorServer(MeshData mesh, std::unique_ptr<FieldDesigner> designer, EditorOptions options)
    : impl_(std::make_unique<Impl>(std::move(mesh), std::move(designer), std::move(options))) {
  impl_->routes();
}

EditorServer::~EditorServer() { stop(); }

int EditorServer::bind(int port) {
  Impl& m = *impl_;
  m.port = port == 0 ? m.http.bind_to_any_port(m.options.host) : (m.http.bind_to_port(m.options.host, port) ? port : -1);
  if (m.port < 0)
    throw Error("cannot listen on " + m.options.host + ":" + std::to_string(port) +
                (port ? " (in use, or not an address of this machine? --port 0 picks a free port)" : " (not an address of this machine?)"));
  m.bound = true;
  return m.port;
}

bool EditorServer::run() { return impl_->http.listen_after_bind(); }
void EditorServer::stop() {
  if (impl_->bound) impl_->http.stop();
}
bool EditorServer::running() const { return impl_->http.is_running(); }
const std::string& EditorServer::token() const { return impl_->token; }
int EditorServer::port() const { return impl_->port; }

std::string EditorServer::url() const {
  std::string host = impl_->options.host;
  if (host == "0.0.0.0" || host == "::") host = "127.0.0.1";
  if (host.find(':') != std::string::npos && host.front() != '[') host = "[" + host + "]";
  return "http://" + host + ":" + std::to_string(impl_->port) + "/?token=" + impl_->token;
}

}  // namespace trivcon::server
