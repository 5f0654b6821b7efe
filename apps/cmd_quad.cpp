// SPDX-License-Identifier: MIT
// trivcon quad MESH [field options] (--target-faces K | --edge-length H) -o Q.obj: the quad mesh of the field's
// seamless integer-grid map (trivcon/quad.h), its irregular vertices exactly the field's singularities.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "map_command.h"
#include "outputs.h"
#include "report.h"
#include "summary.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/io.h"
#include "trivcon/quad.h"

namespace trivcon::cli {

namespace {

struct QuadCommand {
  MapCommand map;
  std::string output, uv_out, sing_out, report;
};

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

void run_quad(const QuadCommand& o) {
  MapRun run = run_map(o.map, true);
  const Parametrization& param = run.param;
  const ParamQuality& p = param.quality;
  const QuadMesh quads = std::move(*run.quads);
  const QuadQuality& q = quads.quality;

  const auto t1 = Clock::now();
  StagedOutputs staged;
  // A map folded everywhere can trace no quad: a mesh without faces is no file any reader takes, so -o is not
  // written (the other outputs are) and the run fails below.
  const bool empty = quads.Q.rows() == 0;
  if (!empty) staged.write(o.output, [&](const std::string& path) { write_quad_mesh(path, quads.V, quads.Q); });
  if (!o.uv_out.empty()) staged.write(o.uv_out, [&](const std::string& path) { write_map_obj(path, run); });
  if (!o.sing_out.empty()) staged.write(o.sing_out, [&](const std::string& path) { write_map_singularities(path, run); });
  if (!o.report.empty()) {
    nlohmann::ordered_json report = map_report(o.map, run);
    report["quad"] = quad_report(quads);
    report["seconds"] = {{"read", run.read_seconds},
                         {"field", run.out.design.solve_seconds + run.out.design.field_seconds},
                         {"map", run.map_seconds},
                         {"write", seconds_since(t1)}};
    staged.write(o.report, [&](const std::string& path) { write_file_atomically(path, [&](std::ostream& s) { s << report.dump(2) << "\n"; }); });
  }
  staged.commit();

  if (!o.map.quiet) {
    std::map<int, int> valences;  // valence -> cones of that valence (index n/4: valence 4 - n)
    for (size_t i = 0; i < param.cones.size(); ++i) ++valences[4 - param.cone_index[i]];
    std::ostringstream irregular;
    for (auto [valence, count] : valences) irregular << (irregular.tellp() > 0 ? ", " : "") << count << " of valence " << valence;
    std::cout << map_summary(o.map, run)
              << "map: edge length " << fmt(param.edge_length) << ", seamless " << (p.seamless ? "yes" : "NO") << ", flipped faces "
              << p.flipped_faces << ", degenerate " << p.degenerate_faces << small_components_words(p) << "\n"
              << "quads: " << q.quads << " (target " << std::llround(q.target_quads) << "), " << q.vertices << " vertices, chi "
              << q.euler_characteristic << " (input " << q.input_euler_characteristic << "), " << q.boundary_loops << " boundary loop(s) (input "
              << q.input_boundary_loops << "), " << (q.manifold ? "manifold" : "NOT manifold") << ", "
              << (q.oriented ? "oriented" : "NOT oriented") << "\n"
              << "irregular vertices: " << q.irregular_vertices << " (singularities: " << (irregular.tellp() > 0 ? irregular.str() : "none")
              << "), " << (q.singular_mismatches == 0 ? "exactly at the singularities" : std::to_string(q.singular_mismatches) + " NOT at a singularity of their valence") << "\n"
              << "scaled Jacobian: min " << fmt(q.min_scaled_jacobian) << ", mean " << fmt(q.mean_scaled_jacobian) << "; inverted quads "
              << q.inverted_quads << ", with a flat or reflex corner " << q.nonconvex_quads << "; distance to the input " << fmt(100 * q.hausdorff_relative) << " % of the bounding box diagonal\n"
              << "time: read " << fmt(run.read_seconds) << " s, field " << fmt(run.out.design.solve_seconds + run.out.design.field_seconds)
              << " s, map " << fmt(p.seconds_total())
              << " s, quads " << fmt(q.seconds_extract + q.seconds_check) << " s (extract " << fmt(q.seconds_extract) << ", check "
              << fmt(q.seconds_check) << "); field to quads " << fmt(run.map_seconds) << search_time_words(run) << "\n";
  }
  if (const std::string w = param_warning(param); !w.empty()) std::cerr << "trivcon: warning: " << w << "\n";
  if (empty) {
    std::cerr << "trivcon: error: the map gave no quads (" << p.flipped_faces + p.degenerate_faces << " of " << p.faces
              << " faces folded or degenerate in (u, v), " << fmt(p.unit_squares) << " unit squares): '" << o.output
              << "' not written\n";
    exit_code = kVerificationFailed;
  } else if (const std::string w = quad_warning(quads); !w.empty()) {
    std::cerr << "trivcon: warning: " << w << "\n";
    exit_code = kVerificationFailed;
  }
}

}  // namespace

void register_quad(CLI::App& app) {
  static QuadCommand o;
  auto* cmd = app.add_subcommand("quad", "Quad mesh of the cross field (N = 4): its irregular vertices exactly the singularities");
  o.map.add_to(cmd, "quad");
  cmd->add_option("-o,--output", o.output, "The quad mesh: .ply (binary) or .obj")->required();
  cmd->add_option("--uv-out", o.uv_out, "OBJ of the input mesh with the map's (u, v) per corner (as `param -o`; the refined mesh when the map refined it)");
  cmd->add_option("--sing-out", o.sing_out, "Singularity file of the singularities used ('VERTEX INDEX' lines, readable by -s)");
  cmd->add_option("--report", o.report, "JSON report: the field, the map, the quad mesh's guarantees and quality, time per stage");
  cmd->callback([] {
    o.map.check("quad");
    run_quad(o);
  });
}

}  // namespace trivcon::cli
