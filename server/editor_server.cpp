// SPDX-License-Identifier: MIT
#include "editor_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <functional>
#include <limits>
#include <mutex>
#include <numeric>
#include <thread>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <shared_mutex>
#include <sstream>

#include "report.h"
#include "summary.h"
#include "trivcon/auto.h"
#include "trivcon/cancel.h"
#include "trivcon/quad.h"
#include "trivcon/relax.h"
#include "trivcon/request.h"
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

// cpp-httplib compresses (brotli, gzip) any answer whose type is application/json or text/… when the client
// accepts it, brotli at its slowest level: a large field export took far longer compressed than sent as
// it is, on a connection that is almost always this machine's loopback (BENCHMARKS.md, "The editor"). No
// answer is compressed: the server drops the request's Accept-Encoding before routing
// (Http::process_and_close_socket).
constexpr const char* kJson = "application/json; charset=utf-8";

// What a chunked body may add to its payload on the wire (chunk-size lines): reads past the body limit by
// more than this fail, so that no line of a body, however long, is held in memory.
constexpr size_t kChunkFraming = 1u << 20;
// A request line and its headers: at most this many bytes (cpp-httplib reads a line of any length into
// memory before it checks its length).
constexpr size_t kMaxHeaderBytes = 64u << 10;
// Requests served on one keep-alive connection before it is closed.
constexpr int kKeepAliveRequests = 100;

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

// Whether s[i…] starts a well-formed UTF-8 sequence of 2 to 4 bytes; its length, or 0.
size_t utf8_length(const std::string& s, size_t i) {
  const auto byte = [&](size_t k) { return i + k < s.size() ? static_cast<unsigned char>(s[i + k]) : 0u; };
  const unsigned c = byte(0);
  const auto cont = [&](size_t k, unsigned lo = 0x80, unsigned hi = 0xBF) { return byte(k) >= lo && byte(k) <= hi; };
  if (c >= 0xC2 && c <= 0xDF) return cont(1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    const bool second = c == 0xE0 ? cont(1, 0xA0) : c == 0xED ? cont(1, 0x80, 0x9F) : cont(1);
    return second && cont(2) ? 3 : 0;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    const bool second = c == 0xF0 ? cont(1, 0x90) : c == 0xF4 ? cont(1, 0x80, 0x8F) : cont(1);
    return second && cont(2) && cont(3) ? 4 : 0;
  }
  return 0;
}

// Text as a message shows it: control characters (NUL too, which would end the text for anything reading it
// as a C string) as \u00XX, bytes that are not UTF-8 as \xHH, everything else as it is.
std::string printable(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    char escape[8];
    if (c < 0x20 || c == 0x7F) {
      std::snprintf(escape, sizeof escape, "\\u%04x", c);
      out += escape;
      ++i;
    } else if (c < 0x80) {
      out += static_cast<char>(c);
      ++i;
    } else if (const size_t n = utf8_length(s, i)) {
      out.append(s, i, n);
      i += n;
    } else {
      std::snprintf(escape, sizeof escape, "\\x%02X", c);
      out += escape;
      ++i;
    }
  }
  return out;
}

void set_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(json{{"error", printable(message)}}.dump() + "\n", kJson);
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

// The command line's "ID:INDEX" for one entry. A NUL in the index is refused here, in the command line's
// words: passed on, it would cut the parser's message (an exception's text is a C string) right there.
std::string index_spec(const std::string& id, const std::string& index, const char* option) {
  if (index.find('\0') != std::string::npos) {
    const std::string spec = printable(id + ":" + index);
    throw BadRequest{400, std::string(option) + " " + spec + ": malformed index '" + printable(index) +
                              "' (expected an integer or a fraction p/q, q > 0)"};
  }
  return id + ":" + index;
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

// --- connections ---------------------------------------------------------------------------------
//
// cpp-httplib 0.11.4 (Debian bookworm) serves each connection on one of a fixed pool of threads (8 here),
// and its socket stream gives each read a timeout but a request none: eight connections sending a header
// byte every half second held every thread, and every other request waited. It also reads a header or
// chunk-size line of any length into memory, and after stop() a worker writing a big answer to a client that
// does not read waits out its write timeout. So the server serves connections itself (Http below overrides
// process_and_close_socket): a thread per connection up to max_connections (WorkerPool), and this stream,
// which gives the request line and headers, then the body, a deadline and a byte budget, and fails any wait
// as soon as the server stops.

// While it lives, the library's long work on the constructing thread stops (trivcon::Cancelled) once `seconds`
// have passed or the server is stopping, whichever comes first (trivcon/cancel.h): the bound of a request's work.
class Deadline {
 public:
  Deadline(double seconds, const std::atomic<bool>& stopping) : scope_(flag_) {
    watcher_ = std::thread([this, seconds, &stopping] {
      const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
      std::unique_lock lock(mutex_);
      while (!done_) {
        if (stopping || Clock::now() >= until) {
          expired_ = !stopping;
          flag_->store(true);
          return;
        }
        wake_.wait_until(lock, std::min(until, Clock::now() + std::chrono::milliseconds(100)));  // polls `stopping`
      }
    });
  }
  ~Deadline() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    wake_.notify_all();
    watcher_.join();
  }
  Deadline(const Deadline&) = delete;
  Deadline& operator=(const Deadline&) = delete;
  bool expired() const {
    std::lock_guard lock(mutex_);
    return expired_;
  }

 private:
  CancelFlag flag_ = std::make_shared<std::atomic<bool>>(false);
  CancelScope scope_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false, expired_ = false;
  std::thread watcher_;
};

struct Limits {
  Clock::duration header, body, idle, keep_alive;
  size_t body_bytes;
};

Clock::duration seconds(double s) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }

class Connection : public httplib::Stream {
 public:
  Connection(int sock, const Limits& limits, const std::atomic<bool>& stopping) : sock_(sock), limits_(limits), stopping_(stopping) {}

  // Waits for the first byte of the next request, at most the keep-alive time.
  bool wait_for_request() {
    if (begin_ < end_) return true;
    deadline_ = Clock::now() + limits_.keep_alive;
    return wait(POLLIN, limits_.keep_alive);
  }
  // The request line and headers: header seconds, kMaxHeaderBytes.
  void start_request() {
    phase_ = Phase::Headers;
    deadline_ = Clock::now() + limits_.header;
    budget_ = kMaxHeaderBytes;
    close_ = timed_out_ = overflowed_ = false;
  }
  // The body: body seconds, the body limit plus what chunked framing may add.
  void start_body() {
    phase_ = Phase::Body;
    deadline_ = Clock::now() + limits_.body;
    budget_ = limits_.body_bytes + kChunkFraming;
  }
  // The answer: no deadline (a big download on a slow link takes what it takes), but each write must make
  // progress within the idle time.
  void start_answer() {
    phase_ = Phase::Answer;
    deadline_ = Clock::time_point::max();
  }

  // The connection is closed after this answer (its body was not read, or not to its end).
  void close_after_answer() { close_ = true; }
  bool closing() const { return close_; }
  bool timed_out() const { return timed_out_; }
  bool overflowed() const { return overflowed_; }
  bool in_headers() const { return phase_ == Phase::Headers; }

  // After an answer that left a body unread: closing at once, with unread bytes, would make the kernel reset
  // the connection, and the client could lose the answer before reading it. So reading stops, and what the
  // client still sends is read and dropped for a second at most (1 MiB at most), then the socket is closed.
  void linger() {
    ::shutdown(sock_, SHUT_WR);
    deadline_ = Clock::now() + std::chrono::seconds(1);
    char drop[16384];
    for (size_t dropped = 0; dropped < (1u << 20) && wait(POLLIN, std::chrono::seconds(1));) {
      const ssize_t n = ::recv(sock_, drop, sizeof drop, MSG_DONTWAIT);
      if (n <= 0 && !(n < 0 && (errno == EAGAIN || errno == EINTR))) break;
      if (n > 0) dropped += static_cast<size_t>(n);
    }
  }

  bool is_readable() const override { return begin_ < end_; }
  bool is_writable() const override {
    pollfd p{sock_, POLLOUT, 0};
    return ::poll(&p, 1, 0) > 0 && (p.revents & POLLOUT);
  }

  ssize_t read(char* ptr, size_t size) override {
    if (begin_ == end_) {
      if (budget_ == 0) {  // more than this part of a request may hold
        overflowed_ = true;
        return -1;
      }
      begin_ = end_ = 0;
      for (;;) {
        if (!wait(POLLIN, limits_.idle)) return -1;
        const ssize_t n = ::recv(sock_, buffer_, std::min(sizeof buffer_, budget_), MSG_DONTWAIT);
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
        if (n <= 0) return n;
        end_ = static_cast<size_t>(n);
        budget_ -= end_;
        break;
      }
    }
    const size_t n = std::min(size, end_ - begin_);
    std::memcpy(ptr, buffer_ + begin_, n);
    begin_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    for (;;) {
      if (!wait(POLLOUT, limits_.idle)) return -1;
      const ssize_t n = ::send(sock_, ptr, size, MSG_DONTWAIT | MSG_NOSIGNAL);
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
      return n;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { address(::getpeername, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address(::getsockname, ip, port); }
  socket_t socket() const override { return sock_; }

 private:
  enum class Phase { Headers, Body, Answer };

  // Waits until the socket is ready for `events`: false when the phase's deadline passes, nothing happens for
  // `idle`, or the server stops (checked every 50 ms).
  bool wait(short events, Clock::duration idle) {
    const Clock::time_point give_up = std::min(deadline_, Clock::now() + idle);
    for (;;) {
      if (stopping_) return false;
      const Clock::time_point now = Clock::now();
      if (now >= give_up) {
        timed_out_ = true;
        return false;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(give_up - now).count();
      pollfd p{sock_, events, 0};
      const int r = ::poll(&p, 1, static_cast<int>(std::clamp<long long>(left, 1, 50)));
      if (r < 0 && errno != EINTR) return false;
      if (r > 0) return true;  // ready, or an error or hang-up that the read or write reports
    }
  }

  template <class Get>
  void address(Get get, std::string& ip, int& port) const {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    ip.clear();
    port = 0;
    if (get(sock_, reinterpret_cast<sockaddr*>(&a), &len) != 0) return;
    char text[INET6_ADDRSTRLEN] = "";
    if (a.ss_family == AF_INET) {
      const auto* v4 = reinterpret_cast<const sockaddr_in*>(&a);
      ::inet_ntop(AF_INET, &v4->sin_addr, text, sizeof text);
      port = ntohs(v4->sin_port);
    } else if (a.ss_family == AF_INET6) {
      const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&a);
      ::inet_ntop(AF_INET6, &v6->sin6_addr, text, sizeof text);
      port = ntohs(v6->sin6_port);
    }
    ip = text;
  }

  int sock_;
  const Limits& limits_;
  const std::atomic<bool>& stopping_;
  Phase phase_ = Phase::Headers;
  Clock::time_point deadline_ = Clock::time_point::max();
  size_t budget_ = kMaxHeaderBytes;
  bool close_ = false, timed_out_ = false, overflowed_ = false;
  char buffer_[16384];
  size_t begin_ = 0, end_ = 0;
};

// The connection the calling thread serves (the handlers mark it to be closed after their answer).
thread_local Connection* current_connection = nullptr;

// A thread per connection, started when a connection arrives and no thread is free, up to `max`; more
// connections wait for one. shutdown() lets the queued ones run (they end at once: the server is stopping)
// and joins every thread.
class WorkerPool : public httplib::TaskQueue {
 public:
  explicit WorkerPool(size_t max) : max_(std::max<size_t>(1, max)) {}

  void enqueue(std::function<void()> fn) override {
    std::lock_guard lock(mutex_);
    jobs_.push_back(std::move(fn));
    if (jobs_.size() > idle_ && threads_.size() < max_) threads_.emplace_back([this] { work(); });
    wake_.notify_one();
  }

  void shutdown() override {
    {
      std::lock_guard lock(mutex_);
      shutdown_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

 private:
  void work() {
    std::unique_lock lock(mutex_);
    for (;;) {
      ++idle_;
      wake_.wait(lock, [&] { return shutdown_ || !jobs_.empty(); });
      --idle_;
      if (jobs_.empty()) return;
      std::function<void()> job = std::move(jobs_.front());
      jobs_.pop_front();
      lock.unlock();
      job();
      lock.lock();
    }
  }

  const size_t max_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  size_t idle_ = 0;
  bool shutdown_ = false;
};

class Http : public httplib::Server {
 public:
  Http(const Limits& limits, const std::atomic<bool>& stopping, int max_connections) : limits_(limits), stopping_(stopping) {
    new_task_queue = [max_connections] { return new WorkerPool(static_cast<size_t>(max_connections)); };
  }

 private:
  // Serves one connection: up to kKeepAliveRequests requests, each with the deadlines of Connection.
  bool process_and_close_socket(socket_t sock) override {
    // Answers go out in two writes (headers, body); without TCP_NODELAY the second waits for the ACK of the
    // first, which the client delays (about 40 ms on Linux) on every request of a keep-alive connection.
    const int one = 1;
    ::setsockopt(sock, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    Connection c(sock, limits_, stopping_);
    current_connection = &c;
    bool ok = true;
    for (int left = kKeepAliveRequests; left > 0 && !stopping_; --left) {
      if (!c.wait_for_request()) break;
      c.start_request();
      bool closed = false;
      ok = process_request(c, left == 1, closed, [&c](httplib::Request& req) {
        // The headers are in: the body's deadline starts. No answer is compressed (see kJson).
        c.start_body();
        req.headers.erase("Accept-Encoding");
      });
      if (!ok || closed || c.closing()) break;
    }
    if (c.closing() && !stopping_) c.linger();
    current_connection = nullptr;
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
    return ok;
  }

  const Limits& limits_;
  const std::atomic<bool>& stopping_;
};

}  // namespace

struct EditorServer::Impl {
  MeshData mesh;
  EditorOptions options;
  std::string token;
  std::unique_ptr<FieldDesigner> designer;
  int port = -1;
  std::atomic<bool> bound{false};
  std::atomic<bool> stopping{false};
  // Set with `stopping`: long work (a relaxation) polls it and ends at once (trivcon/cancel.h).
  CancelFlag stop_flag = std::make_shared<std::atomic<bool>>(false);
  const Limits limits{seconds(options.header_seconds), seconds(options.body_seconds), seconds(options.io_idle_seconds),
                      seconds(options.keep_alive_seconds), options.max_body_bytes};
  Http http{limits, stopping, options.max_connections};

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
    FieldRequest field;              // as asked (trivcon/request.h); field.prescription.fixed: the explicit directions of "fixed"
    IndexPrescription prescription;  // with every fixed face: the alignments' and the explicit ones (RequestConstraints::fixed)
    std::vector<int> fixed_faces;    // sorted: every face of prescription.fixed
    std::vector<int> sharp_edges;    // the feature edges followed (align_features)
  };
  // The smoothest field of the last /api/auto: later solves of its N take their rotation from it.
  std::mutex auto_guide_mutex;
  std::optional<Field> auto_guide;

  Impl(MeshData m, std::unique_ptr<FieldDesigner> d, EditorOptions o) : mesh(std::move(m)), options(std::move(o)) {
    token = options.token.empty() ? random_token() : options.token;
    designer = d ? std::move(d) : std::make_unique<FieldDesigner>(mesh.V, mesh.F);
    Request initial;
    initial.field.prescription = options.initial;
    initial.field.align_boundary = options.align_boundary;
    initial.field.feature_degrees = options.feature_degrees;
    complete_fixed(initial);
    // Not validated here: a session may well start unbalanced (a bare sphere); the page says what is missing.
    designer->set_fixed_faces(initial.fixed_faces);  // factor now: the first edit should be as fast as the others
    fixed_faces = initial.fixed_faces;
    state = {{"revision", 0},    {"initial", normalized(initial)}, {"request", normalized(initial)}, {"solved", nullptr},
             {"error", nullptr}, {"last_solved", nullptr}};
  }

  int num_generators() const { return static_cast<int>(designer->cycles().generators.size()); }

  // The complete prescription: the alignments' fixed faces under the explicit ones (trivcon/request.h).
  void complete_fixed(Request& r) const {
    RequestConstraints c = request_constraints(*designer, r.field);
    r.prescription = r.field.prescription;
    r.prescription.fixed = std::move(c.fixed);
    r.fixed_faces = std::move(c.fixed_faces);
    r.sharp_edges = std::move(c.sharp_edges);
  }

  // The request in the API's own shape, ids and index texts normalized (GET /api/state, session files).
  ojson normalized(const Request& r) const {
    const IndexPrescription& p = r.prescription;
    ojson sing = ojson::array(), gens = ojson::array(), loops = ojson::array(), fixed = ojson::array();
    for (auto [v, n] : p.vertex) sing.push_back({v, format_index(n, p.N)});
    for (auto [g, n] : p.generator) gens.push_back({g, format_index(n, p.N)});
    for (auto [l, n] : p.loop) loops.push_back({l, format_index(n, p.N)});
    for (auto [f, angle] : r.field.prescription.fixed) {
      const Eigen::Vector3d d = designer->geometry().direction_in_face(f, angle);
      fixed.push_back({f, {d.x(), d.y(), d.z()}});
    }
    return {{"N", p.N},          {"singularities", sing}, {"generators", gens},
            {"boundary", loops}, {"fixed", fixed},        {"align_boundary", r.field.align_boundary},
            {"align_features", r.field.feature_degrees ? ojson(*r.field.feature_degrees) : ojson(nullptr)}};
  }

  // `parsed`: the body's JSON too, for the keys of one endpoint.
  Request parse_request(const std::string& body_text, json* parsed = nullptr) const {
    json body;
    try {
      body = json::parse(body_text, [](int depth, json::parse_event_t, json&) {
        if (depth > kMaxDepth) throw BadRequest{400, "the request body nests deeper than " + std::to_string(kMaxDepth) + " levels"};
        return true;
      });
    } catch (const json::parse_error& e) {
      // Its text quotes the last bytes read, which may be anything (set_error shows them escaped).
      throw BadRequest{400, std::string("the request body is not valid JSON: ") + e.what()};
    } catch (const json::out_of_range& e) {
      // 406: a number beyond a double's range, such as 1e400 ("number overflow parsing '1e400'").
      std::string what = e.what();
      const size_t text = what.find("] ");
      if (text != std::string::npos) what = what.substr(text + 2);
      throw BadRequest{400, "the request body has a number out of range: " + what + " (numbers must be within ±1.8e308)"};
    } catch (const json::exception& e) {
      throw BadRequest{400, std::string("the request body is not valid JSON: ") + e.what()};
    }
    if (!body.is_object()) throw BadRequest{400, "the request body must be a JSON object, got " + std::string(body.type_name())};
    if (parsed) *parsed = body;
    Request r;
    IndexPrescription& p = r.field.prescription;
    p.N = options.initial.N;
    if (body.contains("N")) {
      const json& N = body["N"];
      if (!N.is_number_integer() || N.get<int64_t>() < 1 || N.get<int64_t>() > kMaxN)
        throw BadRequest{400, "N: expected an integer from 1 to " + std::to_string(kMaxN) + " (the symmetry), got " + brief(N)};
      p.N = N.get<int>();
    }
    try {
      // [[id, index], …] lists, each entry passed on as the CLI's "ID:INDEX" (so errors are the CLI's).
      auto index_pairs = [&](const char* key, const char* what, const char* option, void (*add)(const std::string&, IndexPrescription&)) {
        const json& list = pairs_field(body, key);
        for (size_t i = 0; i < list.size(); ++i) {
          const json& e = pair_at(list, i, key);
          const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
          add(index_spec(id_text(e[0], where, what), index_text(e[1], where), option), p);
        }
      };
      index_pairs("singularities", "vertex", "--sing", add_vertex_index);
      index_pairs("generators", "generator", "--generator", add_generator_index);
      index_pairs("boundary", "boundary loop", "--boundary", add_loop_index);
      const json& fixed = pairs_field(body, "fixed");
      for (size_t i = 0; i < fixed.size(); ++i) {
        const json& e = pair_at(fixed, i, "fixed");
        const std::string where = "fixed[" + std::to_string(i) + "]";
        std::string spec = id_text(e[0], where, "face") + ":";
        if (e[1].is_array() && e[1].size() == 3 && e[1][0].is_number() && e[1][1].is_number() && e[1][2].is_number()) {
          double d[3] = {e[1][0].get<double>(), e[1][1].get<double>(), e[1][2].get<double>()};
          // Only the direction counts: one near the ends of a double's range is scaled first, so that projecting
          // it to the face neither overflows (1e308: "perpendicular") nor underflows (1e-320: "zero").
          const double largest = std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
          if (largest > 1e100 || (largest > 0 && largest < 1e-100))
            for (double& x : d) x /= largest;
          spec += number_text(d[0]) + "," + number_text(d[1]) + "," + number_text(d[2]);
        } else if (e[1].is_object() && e[1].size() == 1 && e[1].contains("angle") && e[1]["angle"].is_number()) {
          spec += "angle=" + number_text(e[1]["angle"].get<double>());
        } else {
          throw BadRequest{400, where + ": expected a direction [x, y, z] or {\"angle\": A}, got " + brief(e[1])};
        }
        add_fixed_direction(spec, designer->topology(), designer->geometry(), p.fixed);
      }
    } catch (const Error& e) {
      throw BadRequest{400, e.what()};
    }
    if (body.contains("align_boundary")) {
      if (!body["align_boundary"].is_boolean()) throw BadRequest{400, "align_boundary: expected true or false"};
      r.field.align_boundary = body["align_boundary"].get<bool>();
    }
    if (body.contains("align_features")) {  // the sharp edges' dihedral angle in degrees, or null for none
      const json& a = body["align_features"];
      if (a.is_null()) {
        r.field.feature_degrees.reset();
      } else {
        if (!a.is_number() || !(a.get<double>() >= 0 && a.get<double>() <= 180))
          throw BadRequest{400, "align_features: expected an angle in degrees in [0, 180] (sharp edges) or null, got " + brief(a)};
        r.field.feature_degrees = a.get<double>();
      }
    }
    if (body.contains("cancel")) {
      const json& c = body["cancel"];
      if (!c.is_number() || !std::isfinite(c.get<double>()) || c.get<double>() < 0)
        throw BadRequest{400, "cancel: expected a number >= 0 (mean edge lengths), got " + brief(c)};
      r.field.auto_options.cancel_distance = c.get<double>();
    }
    try {
      complete_fixed(r);
    } catch (const Error& e) {
      throw BadRequest{400, e.what()};
    }
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
        std::optional<Field> guide;  // after Auto: the field takes each component's rotation from the smoothest field
        {
          std::lock_guard guide_lock(auto_guide_mutex);
          guide = auto_guide;
        }
        const Design design = request_design(d, r.prescription, {}, guide ? &*guide : nullptr);
        const bool ok = design_verified(design);
        const cli::ReportRun run{options.mesh_path, "", "cotan", "cholesky", r.field.align_boundary, options.read_seconds, 0, ok};
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
      const GlyphOrder& glyphs = get_glyph_order();
      ojson j = mesh_header();
      j["binary"] = {{"vertices", "float32[3 * vertices]"},
                     {"faces", "uint32[3 * faces]"},
                     {"vertex_component", "int32[vertices]"},
                     {"glyph_order", "uint32[faces]"},
                     {"glyph_times", "float32[faces]"}};
      mesh_binary = binary_container(j.dump(), {{V.data(), V.size() * 4},
                                                {F.data(), F.size() * 4},
                                                {comp.data(), comp.size() * 4},
                                                {glyphs.faces.data(), glyphs.faces.size() * 4},
                                                {glyphs.times.data(), glyphs.times.size() * 4}});
    });
    return mesh_binary;
  }

  // The order in which the page draws the field's glyphs, so that every prefix of it covers the surface in
  // proportion to area: face f's first glyph comes at "time" u_f / area_f (u_f in (0, 1), a hash of f), its
  // j-th at (u_f + j) / area_f (the page places those, web/src/glyphs.js), and a prefix up to time t holds
  // about area_f · t glyphs of every face. Faces are sorted by their first time (zero-area faces last); the
  // page receives the order and the times with the mesh, and asks for the directions of the first faces.
  struct GlyphOrder {
    std::vector<uint32_t> faces;
    std::vector<float> times;  // in the order of `faces`
  };
  std::once_flag glyph_order_once;
  GlyphOrder glyph_order;

  const GlyphOrder& get_glyph_order() {
    std::call_once(glyph_order_once, [&] {
      const Eigen::VectorXd& area = designer->geometry().face_area;
      const uint32_t nF = static_cast<uint32_t>(area.size());
      std::vector<double> time(nF);
      for (uint32_t f = 0; f < nF; ++f) {
        uint64_t z = (f + 1) * 0x9E3779B97F4A7C15ull;  // splitmix64's finalizer: a well-spread u_f per face
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        const double u = (static_cast<double>(z >> 11) + 0.5) / 9007199254740992.0;
        time[f] = area(f) > 0 ? u / area(f) : std::numeric_limits<double>::infinity();
      }
      glyph_order.faces.resize(nF);
      std::iota(glyph_order.faces.begin(), glyph_order.faces.end(), 0u);
      std::sort(glyph_order.faces.begin(), glyph_order.faces.end(),
                [&](uint32_t a, uint32_t b) { return time[a] < time[b] || (time[a] == time[b] && a < b); });
      glyph_order.times.resize(nF);
      for (uint32_t i = 0; i < nF; ++i) glyph_order.times[i] = static_cast<float>(time[glyph_order.faces[i]]);
    });
    return glyph_order;
  }

  // What `trivcon info --json --cycles` says, and the session's symmetry.
  ojson mesh_header() const {
    const Topology& t = designer->topology();
    ojson j = cli::mesh_summary(options.mesh_path, mesh, t, designer->geometry());
    j["cycles"] = cli::cycles_summary(t, designer->geometry(), designer->cycles());
    if (options.repair) j["repair"] = repair_summary(*options.repair);
    j["N"] = options.initial.N;
    return j;
  }

  // --- HTTP ---

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

  // The token comes in a header only. Not in a cookie: cookies are not limited to a port, so every other web
  // service of this host would receive it. Not in the query: URLs stay in histories and logs.
  bool token_ok(const httplib::Request& req) const {
    if (same_secret(req.get_header_value("X-Trivcon-Token"), token)) return true;
    const std::string auth = req.get_header_value("Authorization");
    return auth.rfind("token ", 0) == 0 && same_secret(auth.substr(6), token);
  }

  static bool same_text_ignoring_case(const std::string& a, const std::string& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
             return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
  }

  // Why an API call from a page is refused, or "": the page that sent it must be this editor's own (its
  // Origin, or lacking one its Referer, is the served origin). Another port of this host is another origin
  // but the same site, so SameSite rules do not separate the two. A call with neither header (a script, curl)
  // is not a page's and is judged by its token alone.
  std::string origin_problem(const httplib::Request& req) const {
    const std::string served = "http://" + req.get_header_value("Host");
    if (req.has_header("Origin")) {
      const std::string origin = req.get_header_value("Origin");
      if (same_text_ignoring_case(origin, served)) return "";
      return "refused: the request comes from another origin (Origin: " + brief_text(origin) + "); only the editor's own page (" + served +
             ") may call its API";
    }
    if (req.has_header("Referer")) {
      const std::string referer = req.get_header_value("Referer");
      const bool same = referer.size() >= served.size() && same_text_ignoring_case(referer.substr(0, served.size()), served) &&
                        (referer.size() == served.size() || std::strchr("/?#", referer[served.size()]));
      if (same) return "";
      // Its origin only: the rest of the address may hold anything.
      const size_t scheme = referer.find("://");
      const size_t path = referer.find_first_of("/?#", scheme == std::string::npos ? 0 : scheme + 3);
      return "refused: the request comes from another origin (Referer: " + brief_text(referer.substr(0, path)) +
             "); only the editor's own page (" + served + ") may call its API";
    }
    // A page may keep its Referer to itself, and a GET without CORS carries no Origin; what browsers send
    // then still says whether the page was another origin's.
    const std::string site = req.get_header_value("Sec-Fetch-Site");
    if (site == "cross-site" || site == "same-site")
      return "refused: the request comes from another origin (Sec-Fetch-Site: " + site + "); only the editor's own page (" + served +
             ") may call its API";
    return "";
  }

  static std::string brief_text(const std::string& s) { return s.size() > 200 ? s.substr(0, 200) + "…" : s; }

  static bool is_json_type(const std::string& content_type) {
    const std::string type = content_type.substr(0, content_type.find(';'));
    const size_t a = type.find_first_not_of(" \t"), b = type.find_last_not_of(" \t");
    return a != std::string::npos && same_text_ignoring_case(type.substr(a, b - a + 1), "application/json");
  }

  // A refusal before the body is read: the connection is closed after the answer (the body's bytes would
  // otherwise be read as the next request).
  static httplib::Server::HandlerResponse refuse(httplib::Response& res, int status, const std::string& message, bool body_unread) {
    set_error(res, status, message);
    if (body_unread && current_connection) {
      current_connection->close_after_answer();
      res.set_header("Connection", "close");
    }
    return httplib::Server::HandlerResponse::Handled;
  }

  // Everything checked before a request is routed (and before its body is read).
  httplib::Server::HandlerResponse screen(const httplib::Request& req, httplib::Response& res) const {
    const bool has_body = req.has_header("Content-Length") || req.has_header("Transfer-Encoding");
    const std::string host = req.get_header_value("Host");
    if (!host_allowed(host))
      return refuse(res, 403,
                    "refused: the Host header '" + host + "' is not the address this editor serves (" + options.host + ":" +
                        std::to_string(port) + "); open the URL that trivcon edit printed",
                    has_body);
    const bool api = req.path.rfind("/api/", 0) == 0;
    if (api) {
      if (const std::string why = origin_problem(req); !why.empty()) return refuse(res, 403, why, has_body);
      if (!token_ok(req))
        return refuse(res, 403,
                      "missing or wrong token: open the URL that trivcon edit printed (API calls send it as the X-Trivcon-Token header)",
                      has_body);
    }
    const bool get = req.method == "GET" || req.method == "HEAD";
    if (!get && req.method != "POST") return refuse(res, 405, "method " + req.method + " not allowed (GET and POST only)", has_body);
    if (get) {
      if (has_body && !(req.get_header_value("Content-Length") == "0" && !req.has_header("Transfer-Encoding")))
        return refuse(res, 400, "a " + req.method + " request has no body", true);
      return httplib::Server::HandlerResponse::Unhandled;
    }
    static const std::vector<std::string> posts = {"/api/solve", "/api/auto", "/api/relax", "/api/quad", "/api/export", "/api/streamlines"};
    if (std::find(posts.begin(), posts.end(), req.path) == posts.end())
      return refuse(res, 404, "no such endpoint (see docs/reference/editor-api.md)", has_body);
    // A form of any web page can POST text/plain, form data or multipart without asking; only a script of the
    // editor's own origin can send application/json.
    if (!is_json_type(req.get_header_value("Content-Type")))
      return refuse(res, 403,
                    "refused: a POST to the API must have Content-Type: application/json (got '" +
                        brief_text(req.get_header_value("Content-Type")) + "')",
                    has_body);
    // The body's framing: one Content-Length of digits, or Transfer-Encoding: chunked alone, never compressed
    // (its limit would count the compressed bytes).
    const std::string encoding = req.get_header_value("Content-Encoding");
    if (!encoding.empty() && !same_text_ignoring_case(encoding, "identity"))
      return refuse(res, 415, "request bodies must not be compressed (Content-Encoding: " + brief_text(encoding) + ")", has_body);
    const size_t lengths = req.get_header_value_count("Content-Length");
    if (req.has_header("Transfer-Encoding")) {
      if (req.get_header_value_count("Transfer-Encoding") != 1 ||
          !same_text_ignoring_case(req.get_header_value("Transfer-Encoding"), "chunked"))
        return refuse(res, 501,
                      "Transfer-Encoding '" + brief_text(req.get_header_value("Transfer-Encoding")) + "' is not supported (chunked only)",
                      true);
      if (lengths) return refuse(res, 400, "a request has Content-Length or Transfer-Encoding, not both", true);
      return httplib::Server::HandlerResponse::Unhandled;  // counted while it is read (read_body)
    }
    if (lengths == 0) return refuse(res, 411, "a POST needs a Content-Length (or Transfer-Encoding: chunked)", true);
    if (lengths > 1) return refuse(res, 400, "a request has one Content-Length, not " + std::to_string(lengths), true);
    const std::string length = req.get_header_value("Content-Length");
    unsigned long long n = 0;
    const auto [end, ec] = std::from_chars(length.data(), length.data() + length.size(), n);
    if (length.empty() || ec != std::errc() || end != length.data() + length.size())
      return refuse(res, 400, "malformed Content-Length '" + brief_text(length) + "'", true);
    if (n > options.max_body_bytes) return refuse(res, 413, too_large_message(), true);
    return httplib::Server::HandlerResponse::Unhandled;
  }

  std::string too_large_message() const {
    return "request body too large (the limit is " + std::to_string(options.max_body_bytes) + " bytes)";
  }

  // Reads a POST's body, counting it against the limit as it arrives: cpp-httplib limits a Content-Length
  // but reads a chunked body whole, however long.
  std::string read_body(const httplib::ContentReader& reader) const {
    std::string body;
    bool too_large = false;
    const bool ok = reader([&](const char* data, size_t n) {
      if (n > options.max_body_bytes - body.size()) {
        too_large = true;
        return false;
      }
      body.append(data, n);
      return true;
    });
    if (ok) return body;
    Connection* c = current_connection;
    if (c) c->close_after_answer();  // the rest of the body is still to come
    if (too_large) throw BadRequest{413, too_large_message()};
    if (stopping) throw BadRequest{503, "the editor is stopping"};
    if (c && c->timed_out())
      throw BadRequest{408, "the request body did not arrive in time (" + number_text(options.body_seconds) + " s in all, " +
                                number_text(options.io_idle_seconds) + " s without a byte)"};
    throw BadRequest{400, "the request body could not be read (cut short, or malformed chunked encoding)"};
  }

  // Wraps an API handler: answers a BadRequest, or a library error it did not expect, with {"error": …}.
  template <class Handler>
  httplib::Server::Handler api(Handler handler) {
    return [this, handler](const httplib::Request& req, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      answer_errors(res, [&] { handler(req, res); });
    };
  }

  // The same for a POST: its body is read first (read_body), then given to the handler.
  template <class Handler>
  httplib::Server::HandlerWithContentReader api_post(Handler handler) {
    return [this, handler](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader) {
      res.set_header("Cache-Control", "no-store");
      answer_errors(res, [&] {
        const std::string body = read_body(reader);
        handler(req, body, res);
      });
      if (current_connection && current_connection->closing()) res.set_header("Connection", "close");
    };
  }

  template <class Work>
  static void answer_errors(httplib::Response& res, Work work) {
    try {
      work();
    } catch (const BadRequest& e) {
      set_error(res, e.status, e.message);
    } catch (const Error& e) {
      set_error(res, 400, e.what());
    } catch (const std::bad_alloc&) {
      set_error(res, 507, "out of memory");
    }
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
    http.set_keep_alive_timeout(static_cast<time_t>(std::ceil(options.keep_alive_seconds)));
    http.set_keep_alive_max_count(kKeepAliveRequests);
    http.set_tcp_nodelay(true);
    http.set_default_headers({{"X-Content-Type-Options", "nosniff"}, {"Referrer-Policy", "no-referrer"}, {"X-Frame-Options", "DENY"}});
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) { return screen(req, res); });
    // Every answer, errors too: from here on the connection writes, with no deadline but the idle time.
    http.set_post_routing_handler([](const httplib::Request&, httplib::Response&) {
      if (current_connection) current_connection->start_answer();
    });
    http.set_error_handler([this](const httplib::Request&, httplib::Response& res) {
      Connection* c = current_connection;
      if (c && c->in_headers()) {  // a request that could not be read: what follows on the connection is not a request
        c->close_after_answer();
        res.set_header("Connection", "close");
      }
      if (!res.body.empty()) return;
      if (c && c->in_headers() && c->overflowed())
        set_error(res, 431, "the request line and headers are too large (more than " + std::to_string(kMaxHeaderBytes) + " bytes)");
      else if (c && c->in_headers() && c->timed_out())
        set_error(res, 408, "the request's headers did not arrive in time (" + number_text(options.header_seconds) + " s)");
      else if (res.status == 404)
        set_error(res, 404, "no such endpoint (see docs/reference/editor-api.md)");
      else if (res.status == 413)
        set_error(res, 413, too_large_message());
      else
        set_error(res, res.status, "request refused (HTTP " + std::to_string(res.status) + ")");
    });
    http.set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr) { set_error(res, 500, "internal error"); });

    // The page holds no secret (the API does): it is served without the token, which it takes from its
    // address (?token=, then removed from the address bar) or, on a reload, from the tab's sessionStorage.
    http.Get("/", [this](const httplib::Request&, httplib::Response& res) {
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
    http.Post("/api/solve", api_post([this](const httplib::Request& req, const std::string& body, httplib::Response& res) {
                check_format(req, {"json", "binary", "oct16"});
                const auto t0 = Clock::now();
                const Request r = parse_request(body);
                const Solved s = solve(r);
                const Geometry& g = designer->geometry();
                const int nF = static_cast<int>(s.field.angle.size());
                if (req.has_param("format") && req.get_param_value("format") == "oct16") {
                  // What the page uses: a third of the bytes of Float32 x y z (the transfer is most of an edit's time
                  // on a big mesh), at an angular error below 1e-4 radians, plenty for drawing; and with count only
                  // the faces it draws: the first `count` faces of the mesh's glyph order (order=area), or the faces
                  // i · stride mod F, i < count.
                  const bool by_area = req.has_param("order");
                  if (by_area && req.get_param_value("order") != "area")
                    throw BadRequest{400, "unknown order '" + req.get_param_value("order") + "' (known: area)"};
                  if (by_area && req.has_param("stride")) throw BadRequest{400, "order=area and stride exclude each other"};
                  const long long stride = int_param(req, "stride", 1, 1, nF > 0 ? nF : 1);
                  const long long count = int_param(req, "count", nF, 0, nF);
                  if (std::gcd(stride, static_cast<long long>(nF > 0 ? nF : 1)) != 1)
                    throw BadRequest{400, "stride " + std::to_string(stride) + " shares a factor with the face count " +
                                              std::to_string(nF) + ": the faces i * stride mod F would repeat"};
                  const std::vector<uint32_t>* order = by_area ? &get_glyph_order().faces : nullptr;
                  std::vector<int16_t> d(2 * static_cast<size_t>(count));
                  for (long long i = 0; i < count; ++i) {
                    const int f = order ? static_cast<int>((*order)[i]) : static_cast<int>((i * stride) % nF);
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
    http.Post("/api/auto", api_post([this](const httplib::Request&, const std::string& body, httplib::Response& res) {
                const Request r = parse_request(body);
                const int N = r.prescription.N;
                std::shared_lock lock(designer_mutex);  // auto_singularities reads the designer; no refactoring meanwhile
                const AutoResult a = request_auto(*designer, r.field, RequestConstraints{r.prescription.fixed, r.fixed_faces, {}, {}, {}, 0, 0});
                lock.unlock();
                {
                  std::lock_guard guide_lock(auto_guide_mutex);
                  auto_guide = a.field;
                }
                ojson sing = ojson::array();
                for (auto [v, n] : a.vertex) sing.push_back({v, format_index(n, N)});
                ojson out = {{"N", N}, {"singularities", sing}, {"found", a.found.size()}, {"cancelled_pairs", a.pairs.size()}};
                res.set_content(out.dump() + "\n", kJson);
              }));
    http.Post("/api/relax", api_post([this](const httplib::Request&, const std::string& text, httplib::Response& res) {
                json body;
                const Request r = parse_request(text, &body);
                RelaxOptions o;
                o.max_seconds = options.relax_seconds;
                if (body.contains("pins")) {
                  const json& pins = body["pins"];
                  if (!pins.is_array()) throw BadRequest{400, "pins: expected a list of vertex ids, got " + brief(pins)};
                  for (size_t i = 0; i < pins.size(); ++i) {
                    const json& v = pins[i];
                    if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() >= designer->topology().num_vertices)
                      throw BadRequest{400, "pins[" + std::to_string(i) + "]: expected a vertex id from 0 to " +
                                                std::to_string(designer->topology().num_vertices - 1) + ", got " + brief(v)};
                    o.pins.push_back(v.get<int>());
                  }
                }
                auto count = [&](const char* key, int& out, int largest) {
                  if (!body.contains(key)) return;
                  const json& c = body[key];
                  if (!c.is_number_integer() || c.get<int64_t>() < 0 || c.get<int64_t>() > largest)
                    throw BadRequest{400, std::string(key) + ": expected a whole number from 0 to " + std::to_string(largest) + ", got " +
                                              brief(c)};
                  out = c.get<int>();
                };
                count("relax_cancel", o.cancel_distance, 1000);
                count("max_moves", o.max_moves, 1000000);
                try {
                  validate_prescription(designer->topology(), num_generators(), r.prescription);
                } catch (const Error& e) {
                  throw BadRequest{400, e.what()};
                }
                RelaxResult x;
                {
                  CancelScope scope(stop_flag);  // SIGTERM ends it between two solves
                  try {
                    x = with_designer(r.fixed_faces, [&](const FieldDesigner& d) {
                      std::optional<Field> guide;  // after Auto: the fixed-face paths' turns, as request_design reads them
                      {
                        std::lock_guard guide_lock(auto_guide_mutex);
                        guide = auto_guide;
                      }
                      IndexPrescription p = r.prescription;
                      guide_paths(d, p, guide ? &*guide : nullptr);
                      return relax(d, p, o);
                    });
                  } catch (const Cancelled&) {
                    throw BadRequest{503, "the editor is stopping"};
                  }
                }
                const int N = r.prescription.N;
                ojson sing = ojson::array(), moves = ojson::array();
                for (auto [v, n] : x.prescription.vertex) sing.push_back({v, format_index(n, N)});
                for (const RelaxMove& m : x.moves) moves.push_back({{"from", m.from}, {"to", m.to}, {"index", format_index(m.index, N)},
                                                                     {"energy", m.energy}, {"cancelled", m.cancelled}});
                ojson out = {{"N", N},
                             {"singularities", sing},
                             {"moves", moves},
                             {"energy_before", x.energy_before},
                             {"energy_after", x.energy_after},
                             {"candidates_evaluated", x.candidates_evaluated},
                             {"converged", x.converged},
                             {"out_of_time", x.out_of_time},
                             {"seconds", x.seconds}};
                res.set_content(out.dump() + "\n", kJson);
              }));
    http.Post("/api/quad", api_post([this](const httplib::Request&, const std::string& text, httplib::Response& res) {
                json body;
                const Request r = parse_request(text, &body);
                if (r.prescription.N != 4)
                  throw BadRequest{400, "quads need a cross field (N = 4), not N = " + std::to_string(r.prescription.N)};
                const json* target = body.contains("target_faces") ? &body["target_faces"] : nullptr;
                if (!target || !target->is_number() || !(target->get<double>() >= 1 && target->get<double>() <= options.max_quads))
                  throw BadRequest{400, "target_faces: expected the number of quads wanted, from 1 to " + std::to_string(options.max_quads) +
                                            ", got " + (target ? brief(*target) : std::string("nothing"))};
                try {
                  validate_prescription(designer->topology(), num_generators(), r.prescription);
                } catch (const Error& e) {
                  throw BadRequest{400, e.what()};
                }
                ScaledMap made;  // at another scale when the one asked for keeps problems, as `trivcon quad` keeps it
                {
                  Deadline deadline(options.quad_seconds, stopping);
                  try {
                    with_designer(r.fixed_faces, [&](const FieldDesigner& d) {
                      std::optional<Field> guide;
                      {
                        std::lock_guard guide_lock(auto_guide_mutex);
                        guide = auto_guide;
                      }
                      const Design design = request_design(d, r.prescription, {}, guide ? &*guide : nullptr);
                      if (!design_verified(design))
                        throw Error("the field did not pass verification, so no map was made: " + verification_failure(d, design));
                      made = map_field(d, design, request_param_options(d, r.field, r.sharp_edges, 0, target->get<double>()), true);
                      return 0;
                    });
                  } catch (const Cancelled&) {
                    if (deadline.expired())
                      throw BadRequest{503, "making the quads took longer than the editor allows (" + number_text(options.quad_seconds) +
                                                " s): ask for fewer quads, or use trivcon quad"};
                    throw BadRequest{503, "the editor is stopping"};
                  }
                }
                const Parametrization& map = made.param;
                const QuadMesh& quads = *made.quads;
                std::vector<float> V(3 * static_cast<size_t>(quads.V.rows()));
                for (Eigen::Index v = 0; v < quads.V.rows(); ++v)
                  for (int k = 0; k < 3; ++k) V[3 * v + k] = static_cast<float>(quads.V(v, k));
                std::vector<uint32_t> Q(4 * static_cast<size_t>(quads.Q.rows()));
                for (Eigen::Index f = 0; f < quads.Q.rows(); ++f)
                  for (int k = 0; k < 4; ++k) Q[4 * f + k] = static_cast<uint32_t>(quads.Q(f, k));
                std::string warning = param_warning(map);
                if (const std::string w = quad_warning(quads); !w.empty()) warning += (warning.empty() ? "" : "; ") + w;
                const ojson header = {
                    {"quad", cli::quad_report(quads)}, {"param", cli::param_report(map)}, {"map_scale", made.scale}, {"warning", warning}};
                res.set_content(binary_container(header.dump(), {{V.data(), V.size() * 4}, {Q.data(), Q.size() * 4}}),
                                "application/octet-stream");
              }));
    http.Post("/api/export", api_post([this](const httplib::Request& req, const std::string& body, httplib::Response& res) {
                const std::string format = req.has_param("format") ? req.get_param_value("format") : "txt";
                check_format(req, {"txt", "rawfield", "ply", "sing"});
                const Request r = parse_request(body);
                std::ostringstream out;
                std::string name;
                if (format == "sing") {
                  try {
                    validate_prescription(designer->topology(), num_generators(), r.prescription);
                  } catch (const Error& e) {
                    throw BadRequest{400, e.what()};
                  }
                  // By the file's ids.
                  write_singularities_to(out, options.repair ? values_on_input(*options.repair, r.prescription.vertex) : r.prescription.vertex,
                                         r.prescription.N);
                  name = "singularities.txt";
                } else {
                  const Solved s = solve(r);
                  if (stopping) throw BadRequest{503, "the editor is stopping"};  // no file to write for nobody
                  name = "field." + format;
                  if (options.repair)  // a row per face of the file
                    write_field_to(out, name, options.input->V, options.input->F, designer->geometry(), s.field,
                                   options.repair->face_of_input);
                  else
                    write_field_to(out, name, mesh.V, mesh.F, designer->geometry(), s.field);
                }
                res.set_header("Content-Disposition", "attachment; filename=\"" + name + "\"");
                res.set_content(out.str(), format == "ply" ? "application/octet-stream" : "text/plain; charset=utf-8");
              }));
    http.Post("/api/streamlines", api_post([this](const httplib::Request&, const std::string& body, httplib::Response& res) {
                const Request r = parse_request(body);
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
  impl_->stopping = true;  // first: the connections' waits end at once
  impl_->stop_flag->store(true);
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
