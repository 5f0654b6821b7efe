// SPDX-License-Identifier: MIT
#include "map_command.h"

#include <iomanip>
#include <sstream>

#include "outputs.h"
#include "report.h"
#include "summary.h"
#include "trivcon/error.h"
#include "trivcon/indices.h"

namespace trivcon::cli {

void MapCommand::add_to(CLI::App* cmd, const std::string& what_unit) {
  cmd->add_option("mesh", mesh, "Mesh file: .obj .off .ply .stl .gltf .glb, optionally .gz")->required();
  field.add_to(cmd, true);
  target = cmd->add_option("--target-faces", target_faces, "About this many " + what_unit + "s over the surface")->check(CLI::PositiveNumber);
  length = cmd->add_option("--edge-length", edge_length, "The length of one unit of (u, v) (one " + what_unit + "'s side), in the mesh's units")
               ->check(CLI::PositiveNumber);
  target->excludes(length);
  auto* uniform = cmd->add_flag("--uniform-size", uniform_size,
                                "One unit of (u, v) everywhere (a texture's even density): no sizing, which lets the unit follow the map's own scale where the field turns (docs/param.md); as --sizing uniform");
  cmd->add_option("--sizing", sizing,
                  "The unit's size per face: map (follows the real-valued map's own scale; the default), connection (the conformal factor of the field's connection first), uniform (docs/param.md, \"Sizing\")")
      ->check(CLI::IsMember({"map", "connection", "uniform"}))
      ->excludes(uniform);
  cmd->add_option("--search-maps", search_maps,
                  "When the first map has problems, the search for a better one (other placements, near-miss retries, other scales; each map costs about as much as the first) starts no step once this many maps are made, and keeps the best of them (default 0: no bound). Each step is printed as it ends")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("-q,--quiet", quiet, "Print nothing on success");
  add_mesh_options(cmd, mesh_options);
}

void MapCommand::check(const std::string& command) const {
  if (target->count() == 0 && length->count() == 0)
    throw CLI::ValidationError("--target-faces / --edge-length", "give the scale of the map: one of them");
  if (field.split_large_turns)
    throw CLI::ValidationError("--split-large-turns", "not needed by " + command +
                                                          ": the map uses the connection's own matching, so large turns are no problem below pi "
                                                          "(beyond, the report's param.half_turn_edges counts them)");
}

MapRun run_map(const MapCommand& o, bool quads) {
  MapRun run;
  const auto t0 = Clock::now();
  run.loaded = load_mesh(o.mesh, o.mesh_options, o.quiet);
  run.read_seconds = seconds_since(t0);
  const MeshData& mesh = run.loaded.mesh;
  run.designer = std::make_unique<FieldDesigner>(mesh.V, mesh.F, o.field.solver_options());
  run.request = o.field.request(*run.designer, run.repaired());
  run.request.sizing = o.uniform_size ? Sizing::uniform : sizing_from_name(o.sizing);
  // Quads end on a boundary only where it lies on integer iso-lines (docs/quad.md, "Boundaries"): with --auto
  // (the placement is trivcon's, so it can count the boundary's turning) `quad` aligns the boundary unasked.
  if (quads && run.request.auto_place && !run.request.align_boundary && !run.designer->topology().boundary_loops.empty()) {
    run.request.align_boundary = true;
    run.boundary_aligned_unasked = true;
    if (!o.quiet) std::cout << "boundary: aligned (quads end on it; --auto aligns every boundary loop for quad)\n";
  }
  const auto t1 = Clock::now();
  MapSearch search;
  search.max_maps = o.search_maps;
  if (!o.quiet) search.progress = [](const std::string& line) { std::cout << line << std::endl; };
  MapOutcome made = map_request(*run.designer, mesh.F, run.request, o.edge_length, o.target_faces, quads, search);
  run.map_seconds = seconds_since(t1);
  run.out = std::move(made.field);
  if (!run.out.verified)
    throw Error("the field did not pass verification, so no map was made: " + verification_failure(*run.designer, run.out.design));
  run.param = std::move(made.param);
  run.placements = made.placements, run.cancel_units = made.cancel_units, run.first_problems = made.first_problems;
  run.first_distortion = made.first_distortion, run.relaxed = made.relaxed;
  run.relaxed_periods = made.periods;
  run.retried_maps = made.retried_maps;
  run.onto_units = made.onto_units;
  run.onto_flat = made.onto_flat;
  run.onto_boundary = made.onto_boundary;
  run.scale = made.scale;
  run.maps = made.maps, run.search_stopped = made.stopped;
  run.quads = std::move(made.quads);
  run.refined_edges = made.refined_edges;
  return run;
}

void write_map_obj(const std::string& path, const MapRun& run) {
  const MeshData& mesh = run.loaded.mesh;
  if (run.out.refined) {
    write_uv_obj(path, run.out.V, run.out.F, input_corner_uv(run.param, run.map_designer().topology(), run.out.F));
    return;
  }
  const Eigen::MatrixXd uv = input_corner_uv(run.param, run.designer->topology(), mesh.F);
  if (const RepairedMesh* repair = run.repaired())
    write_uv_obj(path, run.loaded.input.V, run.loaded.input.F, corner_rows_on_input(*repair, run.loaded.input.F, uv));
  else
    write_uv_obj(path, mesh.V, mesh.F, uv);
}

void write_map_singularities(const std::string& path, const MapRun& run) {
  const std::map<int, int> vertex = with_corners(run.out.prescription.vertex, run.out.constraints.features.corners);
  write_singularities(path, run.out.refined ? vertex : input_singularities(vertex, run.repaired()), 4);
}

nlohmann::ordered_json map_report(const MapCommand& o, const MapRun& run) {
  const Topology& t = run.designer->topology();
  const Parametrization& param = run.param;
  nlohmann::ordered_json report = {{"mesh", o.mesh},
                                   {"vertices", t.num_vertices},
                                   {"faces", t.num_faces},
                                   {"components", t.components.size()},
                                   {"euler_characteristic", t.euler_characteristic()},
                                   {"boundary_loops", t.boundary_loops.size()},
                                   {"align_boundary", run.request.align_boundary},
                                   {"N", 4},
                                   {"singularities", nlohmann::ordered_json::array()},
                                   {"field", {{"verified", run.out.verified}, {"energy", run.out.design.connection.energy}}},
                                   {"param", param_report(param)}};
  if (const RepairedMesh* repair = run.repaired()) report["repair"] = repair_summary_json(*repair);
  if (run.out.refined)
    report["refine"] = {{"split_edges", run.refined_edges},
                        {"vertices", run.out.V.rows()},
                        {"faces", run.out.F.rows()},
                        {"parent_face", run.out.parent_face}};
  if (!run.out.sharp_edges.empty()) {
    const FeatureAlignment& a = run.out.constraints.features;
    report["features"] = {{"sharp_edges", run.out.sharp_edges.size()},
                          {"conflicts", a.conflicts.size()},
                          {"narrow_corners", a.narrow.size()},
                          {"singularities_moved_onto_them", a.snapped.size()},
                          {"sectors_turned_for_singularities", a.given_sectors.size()},
                          {"loose_edges", run.out.constraints.loose_edges.size()}};
    if (run.request.feature_min_length) report["features"]["min_length"] = *run.request.feature_min_length;
  }
  if (run.out.relax_result) report["relax"] = relax_summary_json(*run.out.relax_result);
  if (run.request.auto_place)
    report["placement"] = {{"placements", run.placements},
                           {"cancel_units", run.cancel_units},
                           {"relaxed", run.relaxed},
                           {"periods", run.relaxed_periods},
                           {"onto_features_units", run.onto_units},
                           {"onto_flat_sectors", run.onto_flat},
                           {"onto_boundary", run.onto_boundary},
                           {"first_problems", run.first_problems},
                           {"first_distortion", run.first_distortion},
                           {"retried_maps", run.retried_maps}};
  report["map_scale"] = run.scale;
  report["search"] = {{"maps", run.maps}, {"max_maps", o.search_maps}, {"stopped", run.search_stopped}};
  // Boundary vertices made corners of the aligned boundary (by the placement, or given): no singularity there.
  report["corners"] = nlohmann::ordered_json::array();
  const std::map<int, int>& corners = run.out.constraints.features.corners;
  for (auto [v, n] : run.out.refined ? corners : input_singularities(corners, run.repaired()))
    report["corners"].push_back({{"vertex", v}, {"index", std::to_string(n) + "/4"}});
  for (size_t i = 0; i < param.cones.size(); ++i)
    report["singularities"].push_back({{"vertex", param.cones[i]}, {"index", std::to_string(param.cone_index[i]) + "/4"}});
  return report;
}

std::string search_time_words(const MapRun& run) {
  if (!run.search_stopped) return " s in all, with every placement, retry and scale tried";
  return " s in all, the search stopped by --search-maps after " + std::to_string(run.maps) + " maps";
}

std::string small_components_words(const ParamQuality& quality) {
  if (quality.small_components == 0) return "";
  return ", " + std::to_string(quality.small_components) + " small component(s) given squares of their own size";
}

namespace {

std::string placement_line(const MapRun& run) {
  std::ostringstream line;
  line << "placement: the singularities found gave " << run.first_problems
       << (run.quads ? " problems (map folds, wrong windings, failed quad checks)" : " problems (map folds, wrong windings)")
       << " and a mean distortion of " << std::setprecision(3) << run.first_distortion << " (goal " << kMapDistortionGoal << "); placed again "
       << run.placements - 1 << " time(s), relaxed, moved onto feature lines from further or with opposite pairs cancelled further apart; kept: "
       << describe_placement(run.cancel_units, run.relaxed, run.relaxed_periods, run.onto_units, run.onto_flat, run.onto_boundary) << "\n";
  return line.str();
}

std::string scale_line(double scale) {
  std::ostringstream line;
  line << "scale: the map at the edge length asked for kept problems; made at " << scale << " times that length (about "
       << std::setprecision(2) << 1 / (scale * scale) << " times the unit squares asked for)\n";
  return line.str();
}

// The field's singular vertices are the map's cones, but where the connection turns by π or more across an edge
// (ParamQuality::half_turn_edges) the per-face field the map follows shows more than were prescribed.
std::string field_line(const MapRun& run) {
  const std::string cones = std::to_string(run.param.cones.size());
  if (run.param.quality.half_turn_edges == 0) return "field: N 4, " + cones + " singular vertices, verified\n";
  return "field: N 4, " + std::to_string(run.out.prescription.vertex.size()) + " singular vertices prescribed, verified; the per-face field the map " +
         "follows shows " + cones + " (the connection turns by pi or more across " + std::to_string(run.param.quality.half_turn_edges) + " edges)\n";
}

}  // namespace

std::string map_summary(const MapCommand& o, const MapRun& run) {
  const Topology& t = run.designer->topology();
  return "mesh " + o.mesh + ": " + std::to_string(t.num_vertices) + " vertices, " + std::to_string(t.num_faces) + " faces, " +
         std::to_string(t.components.size()) + " component(s), chi " + std::to_string(t.euler_characteristic()) + ", " +
         std::to_string(t.boundary_loops.size()) + " boundary loop(s)\n" +
         (run.out.constraints.loose_edges.empty() ? std::string()
                                                  : loose_edges_line(run.out.constraints.loose_edges.size(), *run.request.feature_min_length)) +
         (run.out.relax_result ? relax_summary_line(*run.out.relax_result) + "\n" : std::string()) +
         (run.placements > 1 ? placement_line(run) : std::string()) +
         (run.scale != 1 ? scale_line(run.scale) : std::string()) +
         (run.out.refined ? "refined: " + std::to_string(run.refined_edges) +
                                " edges whose ends lie on aligned lines split at their midpoints (the map folded beside them): " +
                                std::to_string(run.out.V.rows()) + " vertices, " + std::to_string(run.out.F.rows()) +
                                " faces; the map's file holds the refined mesh, the report its faces' input faces (refine.parent_face)\n"
                          : std::string()) +
         field_line(run);
}

}  // namespace trivcon::cli
