// SPDX-License-Identifier: MIT
// trivcon param MESH [field options] (--target-faces K | --edge-length H) -o P.obj: the seamless integer-grid map
// of the field (trivcon/param.h), written as the input mesh with one texture coordinate per corner.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "map_command.h"
#include "outputs.h"
#include "report.h"
#include "summary.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/param.h"
#include "trivcon/request.h"

namespace trivcon::cli {

namespace {

struct ParamCommand {
  MapCommand map;
  std::string output, sing_out, report;
};

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

void run_param(const ParamCommand& o) {
  const MapRun run = run_map(o.map);
  const double read_seconds = run.read_seconds;
  const FieldOutcome& out = run.out;
  const Parametrization& param = run.param;
  const ParamQuality& q = param.quality;

  const auto t1 = Clock::now();
  StagedOutputs staged;
  staged.write(o.output, [&](const std::string& path) { write_map_obj(path, run); });
  if (!o.sing_out.empty()) staged.write(o.sing_out, [&](const std::string& path) { write_map_singularities(path, run); });
  if (!o.report.empty()) {
    nlohmann::ordered_json report = map_report(o.map, run);
    report["seconds"] = {{"read", run.read_seconds}, {"map", run.map_seconds}, {"write", seconds_since(t1)}};
    staged.write(o.report, [&](const std::string& path) { write_file_atomically(path, [&](std::ostream& s) { s << report.dump(2) << "\n"; }); });
  }
  staged.commit();

  if (!o.map.quiet)
    std::cout << map_summary(o.map, run)
              << "map: edge length " << fmt(param.edge_length) << ", " << fmt(q.unit_squares) << " unit squares (target " << fmt(q.target_squares)
              << small_components_words(q) << "), " << q.cut_edges << " cut edges, " << q.integer_unknowns << " integers rounded in " << q.rounding_rounds << " solves\n"
              << "seamless: " << (q.seamless ? "yes" : "NO") << " (transition residual " << fmt(q.max_transition_residual) << ", cones off integer points by "
              << fmt(q.max_cone_offset) << ", cone angles off by " << fmt(q.max_cone_angle_error) << " rad"
              << (q.aligned_edges + q.unaligned_edges > 0
                      ? ", " + std::to_string(q.aligned_edges) + " aligned edges off iso-lines by " + fmt(q.max_alignment_error) +
                            (q.unaligned_edges ? ", " + std::to_string(q.unaligned_edges) + " edges the field crosses obliquely left free" : "")
                      : std::string())
              << ")\n"
              << "flipped faces " << q.flipped_faces << ", degenerate " << q.degenerate_faces << " (" << q.untangled_faces
              << " untangled, " << q.stiffening_rounds << " stiffening rounds); distortion mean " << fmt(q.mean_distortion) << ", max " << fmt(q.max_distortion) << "\n"
              << "time: read " << fmt(read_seconds) << " s, field " << fmt(out.design.solve_seconds + out.design.field_seconds) << " s, map "
              << fmt(q.seconds_total())
              << " s (cut " << fmt(q.seconds_cut) << ", setup " << fmt(q.seconds_setup) << ", rounding " << fmt(q.seconds_rounding)
              << ", untangling " << fmt(q.seconds_untangling) << ", stiffening "
              << fmt(q.seconds_stiffening) << ", check " << fmt(q.seconds_check) << "); field to map " << fmt(run.map_seconds)
              << search_time_words(run) << "\n";
  if (const std::string w = param_warning(param); !w.empty()) std::cerr << "trivcon: warning: " << w << "\n";
  if (!q.seamless) exit_code = kVerificationFailed;
}

}  // namespace

void register_param(CLI::App& app) {
  static ParamCommand o;
  auto* cmd = app.add_subcommand("param", "Seamless integer-grid parametrization of the cross field (N = 4): an OBJ with one vt per corner");
  o.map.add_to(cmd, "unit square (quad)");
  cmd->add_option("-o,--output", o.output, "OBJ of the input mesh with (u, v) per corner ('f a/ta b/tb c/tc'); the refined mesh when the map refined it (refined: ...)")->required();
  cmd->add_option("--sing-out", o.sing_out, "Singularity file of the singularities used ('VERTEX INDEX' lines, readable by -s)");
  cmd->add_option("--report", o.report, "JSON report: the field, the map's integers and quality, time per stage");
  cmd->callback([] {
    o.map.check("param");
    run_param(o);
  });
}

}  // namespace trivcon::cli
