// SPDX-License-Identifier: MIT
// trivcon info MESH [--json] [--cycles]
#include <iostream>

#include "commands.h"
#include "summary.h"
#include "trivcon/cycles.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon::cli {

void register_info(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Read and validate a mesh; print its size and topology per component");
  static std::string path;
  static bool json = false, with_cycles = false;
  static MeshOptions mesh_options;
  cmd->add_option("mesh", path, "Mesh file: .obj .off .ply .stl .gltf .glb, optionally .gz")->required();
  cmd->add_flag("--json", json, "Print JSON (format documented in docs/reference/report.md)");
  cmd->add_flag("--cycles", with_cycles, "Also list the generators and boundary loops whose index solve can set");
  add_mesh_options(cmd, mesh_options);
  cmd->callback([&] {
    const LoadedMesh loaded = load_mesh(path, mesh_options, true);  // the summary says what repair did
    const MeshData& mesh = loaded.mesh;
    check_finite(mesh.V);
    const Topology t = build_topology(mesh.F, static_cast<int>(mesh.V.rows()));
    check_coordinate_range(mesh.V, t);
    const Geometry g = compute_geometry(mesh.V, t);
    nlohmann::ordered_json j = mesh_summary(path, mesh, t, g);
    if (loaded.repair) j["repair"] = repair_summary_json(*loaded.repair);
    Cycles cycles;
    if (with_cycles) {
      cycles = compute_cycles(t);
      j["cycles"] = cycles_summary(t, g, cycles);
    }
    if (json) {
      std::cout << j.dump(2) << "\n";
      return;
    }
    std::cout << "mesh " << path << " (" << mesh.format << ")\n"
              << (loaded.repair ? repair_summary(*loaded.repair) + " (counts below: the repaired mesh)\n" : "")
              << "vertices " << t.num_vertices << ", faces " << t.num_faces << ", edges " << t.num_edges << ", Euler characteristic "
              << t.euler_characteristic() << "\n"
              << "components " << t.components.size() << ", boundary loops " << t.boundary_loops.size() << "\n";
    for (size_t c = 0; c < t.components.size(); ++c) {
      const ComponentInfo& info = t.components[c];
      std::cout << "  component " << c << ": faces " << info.faces << ", vertices " << info.vertices << ", chi "
                << info.euler_characteristic << ", genus " << info.genus << ", boundary loops " << info.boundary_loops.size() << "\n";
    }
    std::cout << "unreferenced vertices " << t.unreferenced_vertices.size() << "\n"
              << "zero-area faces " << g.zero_area_faces << " (degenerate, treated specially: " << g.degenerate_faces << ")\n"
              << "re-oriented faces " << t.flipped_faces.size() << "\n"
              << "interior edges with negative cotangent weight " << g.negative_cotan_edges << "\n"
              << "weight policy: " << g.mollified_faces << " faces below the triangle-inequality margin, lengths mollified by "
              << g.mollify_epsilon << "; " << g.clamped_cotangents << " negative cotangents clamped to 0; " << g.zero_weight_edges
              << " interior edges of zero weight\n";
    if (with_cycles) {
      for (size_t i = 0; i < cycles.generators.size(); ++i)
        std::cout << "generator " << i << ": component " << cycles.generators[i].component << ", " << cycles.generators[i].edges.size()
                  << " dual edges, Levi-Civita holonomy " << levi_civita_holonomy(cycles.generators[i], g) << "\n";
      for (size_t l = 0; l < t.boundary_loops.size(); ++l)
        std::cout << "loop " << l << ": component " << t.vertex_component[t.boundary_loops[l][0]] << ", " << t.boundary_loops[l].size()
                  << " vertices starting at " << t.boundary_loops[l][0] << ", curvature " << loop_curvature(t, g, static_cast<int>(l))
                  << "\n";
    }
  });
}

}  // namespace trivcon::cli
