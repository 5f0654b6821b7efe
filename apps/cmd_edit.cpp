// SPDX-License-Identifier: MIT
// trivcon edit MESH [options]: the interactive editor — a local web server (server/) on one FieldDesigner,
// serving the page of web/ (embedded in the program) until SIGINT or SIGTERM.
#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <atomic>
#include <chrono>
#include <iostream>
#include <memory>
#include <thread>

#include "commands.h"
#include "editor_server.h"
#include "prescription_options.h"
#include "summary.h"
#include "trivcon/design.h"
#include "trivcon/error.h"

namespace trivcon::cli {

namespace {

struct EditOptions {
  std::string mesh;
  PrescriptionOptions prescription;
  std::vector<std::string> fixes;
  bool align_boundary = false;
  MeshOptions mesh_options;  // --no-repair, --weld
  std::optional<double> feature_degrees;  // --align-features
  std::string host = "127.0.0.1";
  int port = 8642;
  CLI::Option* port_option = nullptr;
};

// Ports tried after the default one when it is taken (an explicit --port is used as given).
constexpr int kDefaultPortTries = 20;

// How long a stop (SIGINT, SIGTERM) waits for requests still being computed before the process exits anyway.
constexpr std::chrono::milliseconds kStopGrace{1500};

// SIGINT and SIGTERM write a byte into this pipe (all a signal handler may safely do); a thread reading it
// stops the server. A handler rather than a blocked mask because the libraries' worker threads (OpenBLAS
// starts its own when it is loaded) exist before any code here runs, and a signal may land on any of them.
int stop_pipe[2] = {-1, -1};
void on_stop_signal(int) {
  const char byte = 1;
  [[maybe_unused]] const ssize_t n = write(stop_pipe[1], &byte, 1);
}

void run_edit(const EditOptions& o) {
  if (pipe(stop_pipe) != 0) throw Error("cannot create a pipe for the signal handler");
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  const auto t0 = Clock::now();
  LoadedMesh loaded = load_mesh(o.mesh, o.mesh_options, false);
  MeshData mesh = std::move(loaded.mesh);
  server::EditorOptions options;
  if (loaded.repair) {
    options.repair = std::make_shared<const RepairedMesh>(std::move(*loaded.repair));
    options.input = std::make_shared<const MeshData>(std::move(loaded.input));
  }
  options.read_seconds = seconds_since(t0);
  options.mesh_path = o.mesh;
  options.host = o.host;
  options.initial = o.prescription.build();
  if (options.repair) options.initial.vertex = singularities_on_repaired(*options.repair, options.initial.vertex);  // the file's ids
  options.align_boundary = o.align_boundary;
  options.feature_degrees = o.feature_degrees;
  auto designer = std::make_unique<FieldDesigner>(mesh.V, mesh.F);
  FaceIdMap face_id;
  if (options.repair) face_id = [&options](int f) { return repaired_face(*options.repair, f, "face"); };
  add_fix_options(o.fixes, designer->topology(), designer->geometry(), options.initial.fixed, face_id);
  const int faces = designer->topology().num_faces, vertices = designer->topology().num_vertices;
  try {
    IndexPrescription p = options.initial;
    validate_prescription(designer->topology(), static_cast<int>(designer->cycles().generators.size()), p);
  } catch (const Error& e) {
    // Starting unbalanced is normal (singularities are placed on the page); the page shows this too.
    std::cerr << "trivcon edit: note: the starting prescription does not solve yet: " << e.what() << "\n";
  }
  server::EditorServer editor(std::move(mesh), std::move(designer), options);

  const bool explicit_port = o.port_option->count() > 0;
  int port = -1;
  std::string first_error;
  for (int k = 0; k < (explicit_port || o.port == 0 ? 1 : kDefaultPortTries) && port < 0; ++k) {
    try {
      port = editor.bind(o.port + k);
    } catch (const Error& e) {
      if (first_error.empty()) first_error = e.what();
    }
  }
  if (port < 0) throw Error(first_error);

  std::cout << "trivcon edit: " << o.mesh << " (" << vertices << " vertices, " << faces << " faces)\n"
            << "open this URL in a browser (the token in it is needed by every request):\n"
            << "  " << editor.url() << "\n"
            << "press Ctrl+C to stop" << std::endl;

  std::atomic<bool> run_returned{false};
  std::thread stopper([&] {
    char byte = 0;
    while (read(stop_pipe[0], &byte, 1) < 0 && errno == EINTR) {
    }
    // A stop before the server's loop runs would be lost (Ctrl+C during the set-up): wait for it.
    while (!editor.running() && !run_returned) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    editor.stop();
    // Open connections end at once, but run() waits for the requests being computed (a solve, a re-factoring
    // of a big mesh), which cannot be interrupted. The server writes no file, so nothing is lost by not
    // waiting for them: past a short grace the process exits.
    const auto give_up = std::chrono::steady_clock::now() + kStopGrace;
    while (!run_returned && std::chrono::steady_clock::now() < give_up) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (!run_returned) {
      std::cout << "trivcon edit: stopped (a request still being computed was abandoned)" << std::endl;
      _exit(0);
    }
  });
  const bool ok = editor.run();
  run_returned = true;
  // The server may have stopped for another reason than a signal: wake the stopper itself.
  on_stop_signal(0);
  stopper.join();
  std::cout << "trivcon edit: stopped" << std::endl;
  if (!ok) throw Error("the server stopped: its listening socket failed");
}

}  // namespace

void register_edit(CLI::App& app) {
  static EditOptions o;
  auto* cmd =
      app.add_subcommand("edit", "Interactive editor: a local web page to place singularities and fixed directions, re-solved live");
  cmd->add_option("mesh", o.mesh, "Mesh file: .obj .off .ply .stl .gltf .glb, optionally .gz")->required();
  o.prescription.add_to(cmd, true);
  cmd->add_option("--fix", o.fixes,
                  "Fixed direction at start: F:x,y,z (world, projected to the face), F:angle=A (radians, face frame), or a file with "
                  "'FACE x y z' / 'FACE angle=A' lines; repeatable");
  cmd->add_flag("--align-boundary", o.align_boundary, "Start with every boundary face fixed to its boundary edge's direction");
  add_mesh_options(cmd, o.mesh_options);
  cmd->add_option("--align-features", o.feature_degrees,
                  "Start with the faces beside every sharp edge (dihedral angle above DEG degrees) fixed to its direction")
      ->check(CLI::Range(0.0, 180.0));
  o.port_option = cmd->add_option("--port", o.port, "Port to listen on (default 8642, or the next free one; 0: any free port)")
                      ->check(CLI::Range(0, 65535));
  cmd->add_option("--host", o.host,
                  "Address to listen on (default 127.0.0.1: this machine only; 0.0.0.0 opens it to the network, token still required)");
  cmd->callback([] { run_edit(o); });
}

}  // namespace trivcon::cli
