// SPDX-License-Identifier: MIT
// trivcon check MESH FIELD [options]: the indices of a per-face field, compared with a prescription.
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "prescription_options.h"
#include "trivcon/cycles.h"
#include "trivcon/error.h"
#include "trivcon/field.h"
#include "trivcon/field_io.h"
#include "trivcon/geometry.h"
#include "trivcon/matching.h"
#include "trivcon/topology.h"

namespace trivcon::cli {

namespace {

struct CheckOptions {
  std::string mesh, field;
  PrescriptionOptions prescription;
  std::string matching;  // --matching
  bool json = false;
  MeshOptions mesh_options;  // --no-repair, --weld
};

void run_check(CheckOptions& o) {
  const LoadedMesh loaded = load_mesh(o.mesh, o.mesh_options, o.json);
  const MeshData& mesh = loaded.mesh;
  const RepairedMesh* repair = loaded.repaired();
  if (repair && !o.matching.empty())
    throw Error(o.mesh + " was repaired, and a matching file names edges by the vertices of the mesh it was written for: check on "
                "the repaired mesh (solve --mesh-out), or give --no-repair");
  check_finite(mesh.V);
  const Topology t = build_topology(mesh.F, static_cast<int>(mesh.V.rows()));
  check_coordinate_range(mesh.V, t);
  const Geometry g = compute_geometry(mesh.V, t);
  const Cycles cycles = compute_cycles(t);
  // The field file has a row per input face.
  const MatrixX3d directions =
      rows_on_mesh(loaded, o.prescription.read_field_file(o.field, loaded.input_faces(), o.prescription.N));
  // Without a prescription, check only lists the field's singularities.
  const bool compare = !o.prescription.empty();
  IndexPrescription p = o.prescription.build();
  if (repair) p.vertex = singularities_on_repaired(*repair, p.vertex);
  // Ids printed: the input's (a copy repair appended is named by the vertex it copies).
  const auto id = [repair](int v) { return repair ? repair->vertex_origin[v] : v; };
  if (compare) validate_prescription(t, static_cast<int>(cycles.generators.size()), p);
  const Field field = field_from_directions(g, directions, p.N);
  // With --matching the directions are paired as the file says; otherwise by the closest (principal) matching.
  const FieldIndices idx = o.matching.empty() ? field_indices(t, g, cycles, field)
                                              : indices_with_matching(t, g, cycles, field, read_matching(o.matching, t, p.N));
  nlohmann::ordered_json found = nlohmann::ordered_json::array(), differ = nlohmann::ordered_json::array();
  for (int v = 0; v < t.num_vertices; ++v) {
    const int want = p.vertex.count(v) ? p.vertex.at(v) : 0;
    if (idx.vertex[v] != 0) found.push_back({{"vertex", id(v)}, {"index", format_index(idx.vertex[v], p.N)}});
    if (compare && idx.vertex[v] != want)
      differ.push_back({{"vertex", id(v)}, {"found", format_index(idx.vertex[v], p.N)}, {"prescribed", format_index(want, p.N)}});
  }
  nlohmann::ordered_json j;
  j["N"] = p.N;
  j["singularities"] = found;
  if (compare) j["differences"] = differ;
  nlohmann::ordered_json loops = nlohmann::ordered_json::array(), gens = nlohmann::ordered_json::array();
  for (size_t l = 0; l < idx.loop.size(); ++l) loops.push_back({{"id", l}, {"index", format_index(idx.loop[l], p.N)}});
  for (size_t i = 0; i < idx.generator.size(); ++i) gens.push_back({{"id", i}, {"index", format_index(idx.generator[i], p.N)}});
  j["boundary_loops"] = loops;
  j["generators"] = gens;
  if (o.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "N " << p.N << ": " << found.size() << " singular vertices in the field\n";
    for (const auto& s : found) std::cout << "  vertex " << s["vertex"] << " index " << s["index"].get<std::string>() << "\n";
    for (size_t l = 0; l < idx.loop.size(); ++l)
      std::cout << "  boundary loop " << l << " index " << format_index(idx.loop[l], p.N) << "\n";
    if (compare)
      std::cout << (differ.empty() ? "matches the prescription\n"
                                   : std::to_string(differ.size()) + " vertices differ from the prescription\n");
    for (const auto& s : differ)
      std::cout << "  vertex " << s["vertex"] << ": found " << s["found"].get<std::string>() << ", prescribed "
                << s["prescribed"].get<std::string>() << "\n";
  }
  if (!differ.empty()) exit_code = kIndicesDiffer;
}

}  // namespace

void register_check(CLI::App& app) {
  static CheckOptions c;
  auto* check = app.add_subcommand(
      "check", "Compute the indices of a per-face field (any tool's); with -s/--sing, compare them with that prescription");
  check->add_option("mesh", c.mesh, "Mesh file")->required();
  check->add_option("field", c.field, "Field: trivcon's .txt or .ply, Directional's .rawfield or QuadWild's .rosy")->required();
  c.prescription.add_to(check, false);
  check->add_option("--matching", c.matching,
                    "Matching file (.matching, as solve --matching-out writes): pair the faces' directions as it says instead of by the "
                    "closest direction");
  check->add_flag("--json", c.json, "Print JSON");
  add_mesh_options(check, c.mesh_options);
  check->callback([] { run_check(c); });
}

}  // namespace trivcon::cli
