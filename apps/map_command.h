// SPDX-License-Identifier: MIT
// What `param` and `quad` share: the mesh, the field request and the scale of the map, parsed once, and the run
// from the file to the seamless integer-grid map (trivcon/param.h) of a verified field.
#pragma once
#include <optional>
#include <CLI/CLI.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.h"
#include "field_options.h"
#include "trivcon/param.h"
#include "trivcon/request.h"

namespace trivcon::cli {

struct MapCommand {
  std::string mesh;
  FieldOptions field;
  double target_faces = 0, edge_length = 0;
  bool quiet = false;
  bool uniform_size = false;  // --uniform-size (as --sizing uniform)
  std::string sizing = "map";  // --sizing
  int search_maps = 0;         // --search-maps (MapSearch::max_maps)
  MeshOptions mesh_options;  // --no-repair, --weld
  CLI::Option* target = nullptr;
  CLI::Option* length = nullptr;

  // The mesh argument, the field options (N = 4), --target-faces / --edge-length (`what_unit` says what one
  // unit is: a unit square, a quad), -q, --no-repair, --weld.
  void add_to(CLI::App* cmd, const std::string& what_unit);
  // Usage errors found before any work (CLI::ValidationError): no scale, --split-large-turns.
  void check(const std::string& command) const;
};

struct MapRun {
  LoadedMesh loaded;
  double read_seconds = 0;
  double map_seconds = 0;  // map_request's wall time: every placement tried, its relaxations, maps and retries
  std::unique_ptr<FieldDesigner> designer;
  FieldRequest request;
  FieldOutcome out;
  Parametrization param;
  int placements = 1;        // MapOutcome's
  double cancel_units = 0;
  int first_problems = 0;
  double first_distortion = 0;
  int retried_maps = 0;          // MapOutcome::retried_maps
  bool relaxed = false;
  bool relaxed_periods = false;  // relaxed with the periods (MapOutcome::periods)
  double onto_units = 0;         // MapOutcome::onto_units
  bool onto_flat = false;        // MapOutcome::onto_flat
  bool onto_boundary = false;    // MapOutcome::onto_boundary
  double scale = 1;              // MapOutcome::scale
  int maps = 1;                  // MapOutcome::maps
  bool search_stopped = false;   // MapOutcome::stopped
  bool boundary_aligned_unasked = false;  // quad --auto aligned the boundary without --align-boundary
  std::optional<QuadMesh> quads;  // run_map(…, true): the kept map's quad mesh
  int refined_edges = 0;          // MapOutcome::refined_edges: the map is on out's refined mesh
  const RepairedMesh* repaired() const { return loaded.repaired(); }
  // The designer of the mesh the map is on: the refined one, else the input's (repaired).
  const FieldDesigner& map_designer() const { return out.designer(*designer); }
};

// Reads the mesh (repaired unless --no-repair), solves the request and makes the map (map_request: with --auto,
// ± pairs within one unit of the map cancel unless --auto-cancel says otherwise; a map that folds or stretches
// beyond the goal is made again, relaxed, relaxed with the periods, then with pairs cancelled within 2 or 4). Throws trivcon::Error, also
// when the field does not pass verification.
// With `quads`, the quad mesh too, and a map whose quad mesh fails a check counts as one that folds; with --auto
// the boundary is then aligned even without --align-boundary (quads end on it only so).
MapRun run_map(const MapCommand& command, bool quads = false);

// The map as `param -o` writes it: the input file's mesh (repaired or not) with one vt per corner; when the map
// refined the mesh, the refined mesh (the input's vertices first, with their ids; each face's input face in the
// report's refine.parent_face).
void write_map_obj(const std::string& path, const MapRun& run);
// --sing-out: the singularities used, by the input's vertex ids (the refined mesh's, when the map refined it).
void write_map_singularities(const std::string& path, const MapRun& run);
// What both reports hold: the mesh, the singularities (the map's cones), the field, the map (param_report), and
// repair and relax when they ran; the caller adds its own entries and "seconds".
nlohmann::ordered_json map_report(const MapCommand& command, const MapRun& run);
// The end of the time line: what the search's time covers (every step, or those before --search-maps stopped it).
std::string search_time_words(const MapRun& run);
// The map line's words for ParamQuality::small_components ("" when none).
std::string small_components_words(const ParamQuality& quality);
// What both print first: the mesh's line, the relaxation's when it ran, the field's.
std::string map_summary(const MapCommand& command, const MapRun& run);

}  // namespace trivcon::cli
