// SPDX-License-Identifier: MIT
#include "summary.h"

#include <iomanip>
#include <sstream>

namespace trivcon::cli {

nlohmann::ordered_json mesh_summary(const std::string& path, const MeshData& mesh, const Topology& t, const Geometry& g) {
  nlohmann::ordered_json j;
  j["file"] = path;
  j["format"] = mesh.format;
  j["vertices"] = t.num_vertices;
  j["faces"] = t.num_faces;
  j["edges"] = t.num_edges;
  j["polygons"] = mesh.polygon_count;
  j["euler_characteristic"] = t.euler_characteristic();
  j["boundary_loops"] = t.boundary_loops.size();
  j["components"] = nlohmann::ordered_json::array();
  for (size_t c = 0; c < t.components.size(); ++c) {
    const ComponentInfo& info = t.components[c];
    nlohmann::ordered_json cj;
    cj["id"] = c;
    cj["faces"] = info.faces;
    cj["vertices"] = info.vertices;
    cj["edges"] = info.edges;
    cj["euler_characteristic"] = info.euler_characteristic;
    cj["genus"] = info.genus;
    cj["boundary_loops"] = info.boundary_loops;
    cj["first_face"] = info.first_face;
    j["components"].push_back(cj);
  }
  j["unreferenced_vertices"] = t.unreferenced_vertices.size();
  j["zero_area_faces"] = g.zero_area_faces;
  j["degenerate_faces"] = g.degenerate_faces;
  j["reoriented_faces"] = t.flipped_faces.size();
  j["negative_cotan_edges"] = g.negative_cotan_edges;
  // The weight policy (docs/explanation/weights.md, trivcon/geometry.h): what it touched on this mesh.
  j["mollified_faces"] = g.mollified_faces;
  j["mollify_epsilon"] = g.mollify_epsilon;
  j["clamped_cotangents"] = g.clamped_cotangents;
  j["zero_weight_edges"] = g.zero_weight_edges;
  return j;
}

nlohmann::ordered_json cycles_summary(const Topology& t, const Geometry& g, const Cycles& cycles) {
  nlohmann::ordered_json j;
  j["generators"] = nlohmann::ordered_json::array();
  for (size_t i = 0; i < cycles.generators.size(); ++i) {
    const DualCycle& c = cycles.generators[i];
    nlohmann::ordered_json cj;
    cj["id"] = i;
    cj["component"] = c.component;
    cj["length"] = c.edges.size();
    cj["levi_civita_holonomy"] = levi_civita_holonomy(c, g);
    // The faces visited, starting with L of the first edge.
    nlohmann::ordered_json faces = nlohmann::ordered_json::array();
    for (size_t k = 0; k < c.edges.size(); ++k) faces.push_back(t.edge_faces(c.edges[k], c.signs[k] > 0 ? 0 : 1));
    cj["faces"] = faces;
    j["generators"].push_back(cj);
  }
  j["loops"] = nlohmann::ordered_json::array();
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) {
    nlohmann::ordered_json lj;
    lj["id"] = l;
    lj["component"] = t.vertex_component[t.boundary_loops[l][0]];
    lj["length"] = t.boundary_loops[l].size();
    lj["curvature"] = loop_curvature(t, g, static_cast<int>(l));
    lj["vertices"] = t.boundary_loops[l];
    j["loops"].push_back(lj);
  }
  return j;
}

nlohmann::ordered_json repair_summary_json(const RepairedMesh& r) {
  nlohmann::ordered_json copies = nlohmann::ordered_json::array();
  for (size_t v = r.input_vertices; v < r.vertex_origin.size(); ++v) copies.push_back({v, r.vertex_origin[v]});
  nlohmann::ordered_json duplicates = nlohmann::ordered_json::array(), cut = nlohmann::ordered_json::array(),
                         split = nlohmann::ordered_json::array();
  for (const auto& [f, of] : r.duplicates) duplicates.push_back({f, of});
  for (const auto& [i, j] : r.cut_edges) cut.push_back({i, j});
  for (const auto& [v, fans] : r.split_vertices) split.push_back({v, fans});
  return {{"summary", repair_summary(r)},
          {"input_vertices", r.input_vertices},
          {"input_faces", r.input_faces},
          {"degenerate_faces", r.degenerate_faces},
          {"duplicate_faces", duplicates},
          {"cut_edges", cut},
          {"unpaired_faces", r.unpaired_faces},
          {"unseparated_faces", r.unseparated_faces},
          {"split_vertices", split},
          {"appended_vertices", copies}};
}

nlohmann::ordered_json relax_summary_json(const RelaxResult& r) {
  nlohmann::ordered_json moves = nlohmann::ordered_json::array();
  int cancelled = 0;
  for (const RelaxMove& m : r.moves) {
    moves.push_back({{"from", m.from}, {"to", m.to}, {"index", m.index}, {"energy", m.energy}, {"cancelled", m.cancelled}});
    cancelled += m.cancelled;
  }
  nlohmann::ordered_json out = {{"energy_before", r.energy_before},
          {"energy_after", r.energy_after},
          {"moves", moves},
          {"cancelled_pairs", cancelled},
          {"candidates_evaluated", r.candidates_evaluated},
          {"converged", r.converged},
          {"out_of_solves", r.out_of_solves},
          {"seconds", r.seconds}};
  if (r.periods_used) out["periods_before"] = r.periods_before, out["periods_after"] = r.periods_after;
  return out;
}

std::string relax_summary_line(const RelaxResult& r) {
  int cancelled = 0;
  for (const RelaxMove& m : r.moves) cancelled += m.cancelled;
  std::ostringstream s;
  s << std::setprecision(6) << "relax: energy " << r.energy_before << " -> " << r.energy_after;
  if (r.energy_before > 0) s << std::setprecision(3) << " (" << 100 * (r.energy_after - r.energy_before) / r.energy_before << " %)";
  s << std::setprecision(3) << ", " << r.moves.size() << " moves";
  if (cancelled > 0) s << " (" << cancelled << " cancelling a pair)";
  if (r.periods_used) s << ", periods " << r.periods_before << " -> " << r.periods_after;
  s << ", " << r.candidates_evaluated << " candidate solves, " << r.seconds << " s";
  if (r.out_of_solves)
    s << " (stopped at the placement search's budget of candidate solves: a move may still lower the energy)";
  else if (r.out_of_time)
    s << " (stopped at the time limit: a move may still lower the energy)";
  else if (!r.converged)
    s << " (stopped at --relax-max-moves: a move may still lower the energy)";
  return s.str();
}

std::string loose_edges_line(size_t edges, double min_length) {
  std::ostringstream s;
  s << "features: " << edges << " sharp edges left out (faces sharp on all three edges, chains with a loose end or pieces shorter than "
    << std::setprecision(3) << min_length << "; --feature-min-length; report: features.loose_edges)\n";
  return s.str();
}

}  // namespace trivcon::cli
