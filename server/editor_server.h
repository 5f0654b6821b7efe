// SPDX-License-Identifier: MIT
// server/editor_server.h: the HTTP server of `trivcon edit` — the page and a JSON API over one FieldDesigner.
//
// No numerics here: requests are turned into the library's prescriptions (through the same parsers as
// the command line, so that a mistake gets the CLI's message), designed by FieldDesigner, and described
// by solve_report (report/report.h). The endpoints are documented in docs/reference/editor-api.md.
//
// Safety (docs/reference/editor-api.md): it listens on the host it is given (the CLI's default is 127.0.0.1);
// every API call needs the per-run token in a header (X-Trivcon-Token, or Authorization: token T; never a
// cookie, which every other port of the same host would be sent too); an API call from another origin
// (Origin or Referer not the served one) or a POST that is not application/json is refused (a page on
// another local port could send it); a request whose Host header is not the served address is refused
// (DNS rebinding); bodies are size-limited (chunked ones too), every request has deadlines for its headers
// and body, and no answer is compressed; no endpoint reads or writes a file. Requests are served on
// several threads: designs share the designer (design() is const) and a change of the fixed faces
// (set_fixed_faces refactors) takes it exclusively.
#pragma once
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "trivcon/design.h"
#include "trivcon/indices.h"
#include "trivcon/io.h"
#include "trivcon/repair.h"

namespace trivcon::server {

struct EditorOptions {
  std::string host = "127.0.0.1";
  std::string token;                  // "" → 128 random bits, in hex
  size_t max_body_bytes = 32u << 20;  // request bodies above this get 413
  std::string mesh_path;              // as given on the command line (the report names it)
  double read_seconds = 0;            // reading the mesh (the report's seconds.read)
  IndexPrescription initial;          // the session the page starts with (-N, -s, --sing, --fix angles)
  bool align_boundary = false;        // --align-boundary at start
  std::optional<double> feature_degrees;  // --align-features DEG at start
  // When the mesh given is a repair of the file (trivcon/repair.h): the map and the file's own mesh. The page
  // works on the repaired mesh (its ids: the file's, then the copies repair appended); a downloaded field has a
  // row per face of the file, downloaded singularities name the file's vertices; the mesh's info says what
  // repair did ("repair").
  std::shared_ptr<const RepairedMesh> repair;
  std::shared_ptr<const MeshData> input;
  // Connections: each is served on a thread of its own, up to max_connections at once (more wait for one to
  // end). A request's line and headers must arrive within header_seconds of its first byte, its body within
  // body_seconds after them; a read or write that makes no progress for io_idle_seconds fails; an idle
  // keep-alive connection is closed after keep_alive_seconds.
  double relax_seconds = 20;  // POST /api/relax stops after about this long, with the moves made so far
  double quad_seconds = 60;   // POST /api/quad gives up (503) after about this long
  int max_quads = 10000000;   // the largest target_faces it takes
  int max_connections = 128;
  double header_seconds = 10;
  double body_seconds = 60;
  double io_idle_seconds = 10;
  double keep_alive_seconds = 5;
};

class EditorServer {
 public:
  // Prepares the designer (validates the mesh: throws trivcon::Error) and factors for the initial fixed faces.
  EditorServer(MeshData mesh, EditorOptions options);
  // With a designer the caller prepared for this mesh (`trivcon edit` needs it to read --fix first).
  EditorServer(MeshData mesh, std::unique_ptr<FieldDesigner> designer, EditorOptions options);
  ~EditorServer();
  EditorServer(const EditorServer&) = delete;
  EditorServer& operator=(const EditorServer&) = delete;

  // Binds host:port (port 0: a free one); returns the port. Throws trivcon::Error when it cannot (then another
  // port may be tried).
  int bind(int port);
  // Serves until stop() (from any thread). Returns false if the listening socket failed. After stop(), open
  // connections end at their next read or write, and run() returns once the requests being computed finish.
  bool run();
  void stop();
  bool running() const;

  const std::string& token() const;
  int port() const;
  // The page's address with the token, e.g. http://127.0.0.1:8642/?token=… (after bind()).
  std::string url() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace trivcon::server
