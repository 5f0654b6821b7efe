// SPDX-License-Identifier: MIT
// trivcon/request.h: a field request turned into a design, once for every front end.
#include "trivcon/request.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <queue>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "trivcon/error.h"
#include "trivcon/generate.h"

namespace trivcon {

namespace {

void check_face_id(const Topology& t, int f, const char* what) {
  if (f < 0 || f >= t.num_faces)
    throw Error(std::string(what) + ": face " + std::to_string(f) + " out of range (the mesh has " + std::to_string(t.num_faces) +
                " faces)");
}

// The sharp edges of a request on a mesh: those sharper than feature_degrees (when feature_min_length is set,
// without the least sharp edge of each face sharp on all three, nor the short loose ends; those go to `loose`),
// and the listed ones.
std::vector<int> request_sharp_edges(const FieldDesigner& d, const FieldRequest& r, std::vector<int>* loose = nullptr) {
  const Topology& t = d.topology();
  std::vector<int> out;
  if (r.feature_degrees) out = sharp_edges(d.V(), t, d.geometry(), *r.feature_degrees);
  if (r.feature_min_length && *r.feature_min_length > 0) {
    std::vector<int> closing;
    out = without_closed_faces(t, d.geometry(), out, loose ? &closing : nullptr);
    out = without_short_feature_ends(d.V(), t, out, *r.feature_min_length, loose);
    if (loose) {
      loose->insert(loose->end(), closing.begin(), closing.end());
      std::sort(loose->begin(), loose->end());
    }
  }
  for (int e : r.feature_edges) {
    if (e < 0 || e >= t.num_edges)
      throw Error("feature edges: edge " + std::to_string(e) + " out of range (the mesh has " + std::to_string(t.num_edges) + " edges)");
    if (t.is_boundary_edge(e))
      throw Error("feature edges: edge " + std::to_string(e) + " (" + std::to_string(t.edge_vertices(e, 0)) + ", " +
                  std::to_string(t.edge_vertices(e, 1)) + ") is a boundary edge (align the boundary instead)");
    out.push_back(e);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// The fixed faces of a request on `d` (the input mesh or a refined one): boundary, then features, then `explicit_fixed`.
std::map<int, double> fixed_on(const FieldDesigner& d, const FieldRequest& r, const std::map<int, double>& explicit_fixed,
                               RequestConstraints* report) {
  const Topology& t = d.topology();
  std::map<int, double> fixed;
  if (r.align_boundary) fixed = boundary_alignment(d.V(), t, d.geometry());
  if (r.features_given()) {
    std::vector<int> loose;
    const std::vector<int> edges = request_sharp_edges(d, r, &loose);
    FeatureAlignment a = feature_alignment(d.V(), t, d.geometry(), edges, r.prescription.N);
    int overridden = 0;
    for (auto [f, angle] : a.fixed) {
      const auto it = fixed.find(f);
      if (it != fixed.end() && std::abs(reduce_angle(it->second - angle, r.prescription.N)) > kFeatureAngleTolerance) ++overridden;
      fixed[f] = angle;
    }
    if (report) {
      for (int e : edges) report->convex_edges += is_convex_edge(d.V(), t, d.geometry(), e);
      report->sharp_edges = edges;
      report->loose_edges = std::move(loose);
      report->features = std::move(a);
      report->boundary_overridden = overridden;
    }
  }
  for (auto [f, angle] : explicit_fixed) fixed[f] = angle;
  return fixed;
}

}  // namespace

RequestConstraints request_constraints(const FieldDesigner& designer, const FieldRequest& request) {
  for (auto [f, angle] : request.prescription.fixed) {
    check_face_id(designer.topology(), f, "fixed");
    if (!std::isfinite(angle)) throw Error("fixed: face " + std::to_string(f) + " has a direction angle that is not a finite number");
  }
  RequestConstraints c;
  c.fixed = fixed_on(designer, request, request.prescription.fixed, &c);
  for (auto [f, angle] : c.fixed) c.fixed_faces.push_back(f);
  return c;
}

namespace {

bool path_guide_applies(const FieldDesigner& designer, const IndexPrescription& prescription, const Field* guide) {
  return guide && guide->N == prescription.N && prescription.path_guide.empty() && guide->angle.size() == designer.topology().num_faces &&
         designer.solver().sparse_paths();
}

}  // namespace

void guide_paths(const FieldDesigner& designer, IndexPrescription& prescription, const Field* guide) {
  if (path_guide_applies(designer, prescription, guide))
    prescription.path_guide.assign(guide->angle.data(), guide->angle.data() + guide->angle.size());
}

Design request_design(const FieldDesigner& designer, const IndexPrescription& prescription, const std::vector<std::pair<int, double>>& roots,
                      const Field* guide) {
  // The guide's copy only where it applies: an edit on the dense route designs the prescription as it is.
  IndexPrescription guided;
  const bool guiding = path_guide_applies(designer, prescription, guide);
  if (guiding) guided = prescription, guide_paths(designer, guided, guide);
  Design d = designer.design(guiding ? guided : prescription, roots);
  // A rotation by a constant per component changes none of the design's checks (trivcon/auto.h).
  if (guide && guide->N == prescription.N) turn_toward(designer, d.field, *guide, prescription.fixed, roots);
  return d;
}

namespace {

AutoOptions request_auto_options(const FieldDesigner& designer, const FieldRequest& request, const RequestConstraints& constraints) {
  AutoOptions o = request.auto_options;
  o.N = request.prescription.N;
  o.fixed = constraints.fixed;
  const Topology& t = designer.topology();
  for (int e : constraints.sharp_edges) o.held.push_back(t.edge_vertices(e, 0)), o.held.push_back(t.edge_vertices(e, 1));
  return o;
}

}  // namespace

AutoResult request_auto(const FieldDesigner& designer, const FieldRequest& request, const RequestConstraints& constraints) {
  return auto_singularities(designer, request_auto_options(designer, request, constraints));
}

void move_request_to_repaired(FieldRequest& r, const Topology& t, const RepairedMesh& repaired) {
  r.prescription.vertex = singularities_on_repaired(repaired, r.prescription.vertex);
  for (auto& [f, angle] : r.roots) f = repaired_face(repaired, f, "root face");
  std::vector<int> pins;
  for (int v : r.relax_options.pins) {
    if (v < 0 || v >= repaired.input_vertices)
      throw Error("relax: pinned vertex " + std::to_string(v) + " out of range (the mesh has " + std::to_string(repaired.input_vertices) +
                  " vertices)");
    for (int copy : vertex_copies(repaired, v)) pins.push_back(copy);
  }
  r.relax_options.pins = std::move(pins);
  std::vector<int> edges;
  for (int e : r.feature_edges) {  // given as the repaired topology's edge between the input ids' vertices
    if (e < 0 || e >= t.num_edges) {
      edges.push_back(e);  // request_sharp_edges names it
      continue;
    }
    for (int a : vertex_copies(repaired, repaired.vertex_origin[t.edge_vertices(e, 0)]))
      for (int b : vertex_copies(repaired, repaired.vertex_origin[t.edge_vertices(e, 1)]))
        if (const int copy = edge_between(t, a, b); copy >= 0) edges.push_back(copy);
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  r.feature_edges = std::move(edges);
}

FieldOutcome solve_request(FieldDesigner& designer, const MatrixX3i& F, const FieldRequest& request) {
  FieldOutcome out;
  out.constraints = request_constraints(designer, request);
  IndexPrescription& p = out.prescription;
  p = request.prescription;
  p.fixed = out.constraints.fixed;
  if (request.split_large_turns) {
    if (!p.generator.empty() || !p.loop.empty())
      throw Error("splitting large turns makes new generators and boundary loops: leave their indices to be chosen");
    if (!request.feature_edges.empty())
      throw Error("splitting large turns splits edges, which a list of feature edges names: use a feature angle instead");
  }
  out.sharp_edges = out.constraints.sharp_edges;
  if (designer.fixed_faces() != out.constraints.fixed_faces) designer.set_fixed_faces(out.constraints.fixed_faces);
  // The sectors turned anew (by moves onto the feature lines or for singularities given) are fixed faces, unless
  // a direction given by hand holds the face.
  auto take_sectors = [&](const std::vector<FeatureSnap>& turned) {
    for (const FeatureSnap& k : turned)
      for (int f : k.faces)
        if (!request.prescription.fixed.count(f)) out.constraints.fixed[f] = out.constraints.features.fixed.at(f);
    out.constraints.fixed_faces.clear();
    for (auto [f, angle] : out.constraints.fixed) out.constraints.fixed_faces.push_back(f);
    p.fixed = out.constraints.fixed;
    designer.set_fixed_faces(out.constraints.fixed_faces);
  };
  // For a map, singularities given on feature vertices get the sectors that make their index
  // (FieldRequest::sectors_for_singularities): a placement of `quad --auto` given back with -s makes the same
  // field. Not where they move (relax) or the mesh is refined (split_large_turns: its constraints are made again on
  // each refined mesh).
  if (request.sectors_for_singularities && !request.auto_place && !request.relax && !request.split_large_turns &&
      !out.constraints.sharp_edges.empty()) {
    turn_sectors_for_singularities(designer.topology(), designer.geometry(), out.constraints.sharp_edges, p.N, p.vertex, out.constraints.features);
    if (!out.constraints.features.given_sectors.empty()) take_sectors(out.constraints.features.given_sectors);
  }
  // Boundary vertices given an index are corners of the aligned boundary (turn_sectors_for_singularities with
  // `boundary`): where `quad --auto` moved singularities onto the boundary, its --sing-out lists them so, and given
  // back with -s they make the same fans. The corners leave the prescription (a boundary vertex carries no index).
  if (!request.auto_place) {
    const Topology& t = designer.topology();
    std::map<int, int> on_boundary;
    for (auto [v, n] : p.vertex)
      if (v >= 0 && v < t.num_vertices && t.is_boundary_vertex(v)) on_boundary[v] = n;
    if (!on_boundary.empty()) {
      const int v = on_boundary.begin()->first;
      const std::string where = "singular vertex " + std::to_string(v) + " is on boundary loop " + std::to_string(t.vertex_boundary_loop[v]);
      if (!request.align_boundary)
        throw Error(where + ": a boundary vertex has no dual cycle (set the loop's index with --boundary instead, or align the boundary, " +
                    "--align-boundary, to make the vertex a corner of it)");
      if (request.split_large_turns) throw Error(where + ": corners of the boundary are not made with splitting large turns");
      FeatureAlignment& a = out.constraints.features;
      turn_sectors_for_singularities(t, designer.geometry(), out.constraints.sharp_edges, p.N, on_boundary, a, true);
      for (auto [w, n] : on_boundary) {
        if (!a.corners.count(w)) {
          std::vector<int> fan;
          vertex_fan(t, w, fan);
          throw Error("singular vertex " + std::to_string(w) + " on boundary loop " + std::to_string(t.vertex_boundary_loop[w]) +
                      " cannot be a corner of index " + format_index(n, p.N) + ": its fan of " +
                      std::to_string(fan.size()) + " faces cannot turn by that much in steps the field reads unambiguously" +
                      " (or it has a corner already, or faces beside other aligned edges)");
        }
        p.vertex.erase(w);
      }
      take_sectors(a.given_sectors);
    }
  }
  if (request.auto_place) {
    const bool boundary = request.align_boundary && request.auto_options.onto_boundary;
    const bool onto = request.auto_options.onto_features > 0 && !request.split_large_turns && (!out.constraints.sharp_edges.empty() || boundary);
    AutoOptions o = request_auto_options(designer, request, out.constraints);
    // With moves onto the feature lines, they come before the split (AutoOptions::split_above) and again after
    // it: a −1/N beside a line moves onto it (a corner of the line's quads) instead of first gathering with a
    // neighbour a fraction of a unit away (two −1/N of neighbouring round holes in a plate became one −2/N in the
    // strip between them, which folds the map); those moved are held, neither gathered nor split; the ±1/N the
    // split spreads (a cap's +1 made four +1/4 a unit from its centre) may then move onto a line in turn.
    if (onto) o.split_above = 0;
    out.auto_result = auto_singularities(designer, o);
    p.vertex = out.auto_result->vertex;
    if (onto) {
      FeatureAlignment& a = out.constraints.features;
      auto move_onto = [&]() {
        const size_t before = a.snapped.size();
        move_singularities_onto_features(designer.V(), designer.topology(), designer.geometry(), out.constraints.sharp_edges, p.N,
                                         request.auto_options.onto_features, request.auto_options.onto_flat_sectors, p.vertex, a,
                                         request.auto_options.onto_separation, boundary);
        if (a.snapped.size() != before) take_sectors(a.snapped);
      };
      move_onto();
      o.split_above = request.auto_options.split_above;
      std::map<int, int> split = split_auto_singularities(designer.V(), designer.topology(), p.vertex, o, *out.auto_result);
      if (split != p.vertex) {
        p.vertex = std::move(split);
        move_onto();
      }
    }
  }
  // Where the solver reads the fixed-face paths' whole turns path by path, the relaxation and the design read them
  // from the smoothest field: --auto's, or, for singularities given, one made for this (so that --auto's
  // singularities given back with -s make the same field).
  if (!request.split_large_turns && p.path_guide.empty() && designer.solver().sparse_paths()) {
    if (out.auto_result) {
      guide_paths(designer, p, &out.auto_result->field);
    } else {
      const AutoResult smoothest = request_auto(designer, request, out.constraints);
      guide_paths(designer, p, &smoothest.field);
    }
  }
  if (request.relax) {
    out.relax_result = relax(designer, p, request.relax_options);
    p = out.relax_result->prescription;
  }
  if (!request.split_large_turns) {
    out.design = request_design(designer, p, request.roots, out.auto_result ? &out.auto_result->field : nullptr);
    out.verified = design_verified(out.design);
    return out;
  }
  // Each refined mesh: the boundary and the sharp edges found again on it, the explicit directions (as world
  // vectors) passed on to the children of their faces (they win, as on the input mesh).
  std::map<int, Eigen::Vector3d> world;
  for (auto [f, angle] : request.prescription.fixed) world[f] = designer.geometry().direction_in_face(f, angle);
  auto constraints = [&](const FieldDesigner& refined, const std::vector<int>& parent) {
    std::map<int, double> explicit_fixed;
    for (int f = 0; f < static_cast<int>(parent.size()); ++f) {
      const auto it = world.find(parent[f]);
      if (it != world.end()) explicit_fixed[f] = refined.geometry().angle_in_face(f, it->second);
    }
    RequestConstraints c;
    std::map<int, double> fixed = fixed_on(refined, request, explicit_fixed, &c);
    out.sharp_edges = std::move(c.sharp_edges);
    return fixed;
  };
  RefinedDesign r = split_large_turns(designer, F, p, designer.solver_options(), constraints, request.max_split_rounds, request.roots);
  out.rounds = std::move(r.rounds);
  out.split_converged = r.converged;
  out.parent_face = std::move(r.parent_face);
  out.prescription = std::move(r.prescription);
  out.design = std::move(r.design);
  const FieldDesigner& final_designer = r.designer ? *r.designer : designer;
  if (out.auto_result) {  // the guide on the final faces: each child lies in its parent's plane
    const Field& parent_guide = out.auto_result->field;
    Field guide{parent_guide.N, Eigen::VectorXd(static_cast<Eigen::Index>(out.parent_face.size()))};
    for (size_t f = 0; f < out.parent_face.size(); ++f) {
      const int parent = out.parent_face[f];
      guide.angle(static_cast<Eigen::Index>(f)) = final_designer.geometry().angle_in_face(
          static_cast<int>(f), designer.geometry().direction_in_face(parent, parent_guide.angle(parent)));
    }
    turn_toward(final_designer, out.design.field, guide, out.prescription.fixed, r.designer ? std::vector<std::pair<int, double>>{} : request.roots);
  }
  if (r.designer) {
    out.V = std::move(r.V);
    out.F = std::move(r.F);
    out.refined = std::move(r.designer);
  }
  out.verified = design_verified(out.design);
  return out;
}

ParamOptions request_param_options(const FieldDesigner& designer, const FieldRequest& request, const FieldOutcome& outcome,
                                   double edge_length, double target_faces) {
  return request_param_options(outcome.designer(designer), request, outcome.sharp_edges, edge_length, target_faces);
}

ParamOptions request_param_options(const FieldDesigner& designer, const FieldRequest& request, const std::vector<int>& sharp_edges,
                                   double edge_length, double target_faces) {
  const Topology& t = designer.topology();
  ParamOptions options;
  options.edge_length = edge_length;
  options.target_faces = target_faces;
  if (request.align_boundary)
    for (int e = 0; e < t.num_edges; ++e)
      if (t.is_boundary_edge(e)) options.aligned_edges.push_back(e);
  options.aligned_edges.insert(options.aligned_edges.end(), sharp_edges.begin(), sharp_edges.end());
  options.sizing = request.sizing;
  return options;
}

double map_unit(const FieldDesigner& designer, double edge_length, double target_faces) {
  if (edge_length > 0) return edge_length;
  double area = 0;
  for (int f = 0; f < designer.topology().num_faces; ++f) area += designer.geometry().face_area[f];
  return std::sqrt(area / target_faces);
}

void cancel_for_map(FieldRequest& request, const FieldDesigner& designer, double edge_length, double target_faces) {
  if (!request.auto_place) return;
  const double unit = map_unit(designer, edge_length, target_faces);
  if (request.auto_options.split_above == 0) request.auto_options.split_above = 3, request.auto_options.split_distance = unit;
  if (request.auto_options.onto_features == 0) request.auto_options.onto_features = kMapOntoFeatures * unit;
  if (request.auto_options.onto_separation == 0) request.auto_options.onto_separation = unit;
  if (request.auto_options.cancel_distance != 0) return;
  request.auto_options.cancel_distance = unit;
  request.auto_options.cancel_absolute = true;
}

namespace {

// The vertices closer than `radius` (along edges) to an end of one of `edges`: where a singularity would sit less
// than a unit from an aligned edge's iso-line, so that the rounding puts it onto that line and folds the faces
// between (a multi-source Dijkstra; src/field's edge_dijkstra is single-source and internal to that module).
std::vector<int> vertices_near_edges(const FieldDesigner& designer, const std::vector<int>& edges, double radius) {
  const Topology& t = designer.topology();
  const MatrixX3d& V = designer.V();
  std::vector<double> dist(t.num_vertices, std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (int e : edges)
    for (int end = 0; end < 2; ++end)
      if (const int v = t.edge_vertices(e, end); dist[v] > 0) dist[v] = 0, queue.emplace(0.0, v);
  std::vector<int> out;
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    out.push_back(v);
    for (int q = t.vertex_edge_offsets[v]; q < t.vertex_edge_offsets[v + 1]; ++q) {
      const int e = t.vertex_edges[q];
      const int w = t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
      const double dw = d + (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).norm();
      if (dw < radius && dw < dist[w]) dist[w] = dw, queue.emplace(dw, w);
    }
  }
  return out;
}

}  // namespace

namespace {

int map_problems(const MapOutcome& m) { return map_problems(m.param, m.quads); }

// A map's stretch beyond the goal: 0 when its mean singular-value ratio is within kMapDistortionGoal.
double map_stretch(const Parametrization& param) {
  return std::max(param.quality.mean_distortion, kMapDistortionGoal) - kMapDistortionGoal;
}

// Whether map a (with its quads) is better than map b: fewer problems, or as few and less stretch.
bool better_map(const Parametrization& a, const std::optional<QuadMesh>& a_quads, const Parametrization& b,
                const std::optional<QuadMesh>& b_quads) {
  const int pa = map_problems(a, a_quads), pb = map_problems(b, b_quads);
  return pa != pb ? pa < pb : map_stretch(a) < map_stretch(b);
}

// The maps a search has made against MapSearch::max_maps, and its progress lines. The first step's line waits:
// it is said with the second (a search that ends at its first map says nothing).
class SearchLog {
 public:
  explicit SearchLog(const MapSearch& search) : search_(search) {}
  bool room() const { return search_.max_maps <= 0 || made_ < search_.max_maps; }
  // Whether a step may start; when not, the search stops (said once).
  bool may_start() {
    if (room()) return true;
    stop();
    return false;
  }
  int maps() const { return made_; }
  bool stopped() const { return stopped_; }
  // A step that made `count` maps: what it tried, and the map it ended with (the best of its own). The search keeps
  // the best of all the steps' maps (better_map), so that is the best so far.
  void made(int count, const std::string& what, const Parametrization& param, const std::optional<QuadMesh>& quads) {
    made_ += count;
    const int problems = map_problems(param, quads);
    if (made_ == count || problems < best_problems_ || (problems == best_problems_ && map_stretch(param) < best_stretch_))
      best_problems_ = problems, best_stretch_ = map_stretch(param), best_ratio_ = param.quality.mean_distortion;
    if (!search_.progress) return;
    std::ostringstream line;
    line << std::setprecision(3) << "search: ";
    if (count == 1) line << "map " << made_;
    else line << "maps " << made_ - count + 1 << "-" << made_;
    line << " (" << what << "): " << problems << " problems, mean ratio " << param.quality.mean_distortion << "; best so far " << best_problems_
         << ", " << best_ratio_;
    say(line.str());
  }
  // A line of its own (the search moving to a refined mesh).
  void note(const std::string& line) {
    if (search_.progress) say("search: " + line);
  }
  // The bound stops the search before a step.
  void stop() {
    if (stopped_) return;
    stopped_ = true;
    if (search_.progress)
      say("search: stopped after " + std::to_string(made_) + (made_ == 1 ? " map" : " maps") + " (the bound given); the best of them kept");
  }

 private:
  void say(const std::string& line) {
    if (steps_++ == 0) {
      first_ = line;
      return;
    }
    if (steps_ == 2) search_.progress(first_);
    search_.progress(line);
  }
  const MapSearch& search_;
  int made_ = 0, steps_ = 0;
  int best_problems_ = 0;
  double best_stretch_ = 0, best_ratio_ = 0;
  bool stopped_ = false;
  std::string first_;
};

// map_at_other_scales within a search's bound.
void scales_within(const FieldDesigner& designer, const Design& design, const ParamOptions& options, ScaledMap& map, SearchLog& log) {
  if (map_problems(map.param, map.quads) == 0 || folds_necessary(map.param)) return;
  for (double scale : kMapScales) {
    if (!log.may_start()) return;
    ParamOptions o = options;
    o.edge_length *= scale, o.target_faces /= scale * scale;
    o.retries = 0;
    if (scale != std::end(kMapScales)[-1]) o.untangle_share = kUntangleShareFollowed;  // the next scale is the cheaper remedy
    ScaledMap m{parametrize(designer, design, o), std::nullopt, scale};
    if (map.quads) m.quads = extract_quads(designer, m.param);
    const bool better = better_map(m.param, m.quads, map.param, map.quads);
    const int count = std::max(1, m.param.quality.attempts);  // with the other sizings' maps (parametrize)
    std::ostringstream what;
    what << "at " << scale << " times the edge length";
    if (better) map = std::move(m);
    log.made(count, what.str(), better ? map.param : m.param, better ? map.quads : m.quads);
    if (map_problems(map.param, map.quads) == 0) break;
  }
}

// map_request's search on one mesh (map_request adds the refinement).
MapOutcome map_search(FieldDesigner& designer, const MatrixX3i& F, FieldRequest& request, double edge_length, double target_faces,
                      bool quads, SearchLog& log) {
  const bool escalate = request.auto_place && request.auto_options.cancel_distance == 0;
  // The distance onto feature lines is map_request's own (per attempt) unless the request gave one.
  const bool own_onto = escalate && request.auto_options.onto_features == 0;
  cancel_for_map(request, designer, edge_length, target_faces);
  const double unit = request.auto_place ? map_unit(designer, edge_length, target_faces) : 0.0;
  auto stretch = [&](const MapOutcome& m) { return map_stretch(m.param); };
  auto better = [&](const MapOutcome& a, const MapOutcome& b) { return better_map(a.param, a.quads, b.param, b.quads); };
  // The attempts: the placement found; the same relaxed (trivcon/relax.h: the field's energy is lower where
  // the singularities sit as the surface's curvature and the aligned lines ask, and a map of a field with less
  // rotation stretches less); the same relaxed with the periods of the conformal scale around the aligned lines
  // in the objective (a map must stretch by e^|T| around a loop of period T; with aligned lines only); then with
  // pairs cancelled within 2 and 4 units, then those relaxed. Neither kind wins everywhere: relaxed, a plate's
  // −1/4 around round holes stop twisting the map, while a coarse scan's fold more (docs/param.md; BENCHMARKS.md).
  struct Attempt {
    double units;
    bool relax;
    bool periods;
    double onto = kMapOntoFeatures;  // singularities moved onto feature lines from this many units
    bool flat = false;               // and onto sectors whose quad corners would be flat (AutoOptions::onto_flat_sectors)
    bool boundary = false;           // and onto the aligned boundary as corners (AutoOptions::onto_boundary)
  };
  const std::vector<int> sharp = request_sharp_edges(designer, request);
  // The edges on iso-lines (the relaxation keeps singularities away from them; the periods are theirs).
  const std::vector<int> aligned = request_param_options(designer, request, sharp, edge_length, target_faces).aligned_edges;
  std::vector<Attempt> attempts{{1.0, request.relax, false}};
  if (escalate) {
    // The attempts with other moves onto feature lines: only when this search sets the distance and lines exist.
    const bool onto_attempts = own_onto && !request.split_large_turns && !sharp.empty();
    // (Without aligned edges there are no periods: that relaxation would repeat the one before.)
    if (!request.relax) attempts.push_back({1.0, true, false});
    if (!request.relax && !aligned.empty()) attempts.push_back({1.0, true, true});
    if (onto_attempts)
      attempts.push_back({1.0, request.relax, false, kMapOntoFeaturesFar});
    for (double units : {2.0, 4.0}) attempts.push_back({units, request.relax, false});
    if (!request.relax)
      for (double units : {2.0, 4.0}) attempts.push_back({units, true, false});
    // Last, with a singularity beside a straight feature line moved onto it all the same: one quad gets a flat
    // corner there, where the other placements fold the map.
    if (onto_attempts)
      for (double onto : {kMapOntoFeatures, kMapOntoFeaturesFar}) attempts.push_back({1.0, request.relax, false, onto, true});
  }
  // When those keep problems after their retries and other scales: the singularities beside the aligned boundary
  // moved onto it as corners, and those relaxed (at a coarse scale a −1/4 beside a round hole has no integer point
  // a unit from the rim's iso-line and off it). Only then: ranked with the others, a clean map with corners would
  // take the place of a placement that the retries or another scale mend with quads of better shape (a plate
  // meshed in rings around its holes).
  std::vector<Attempt> corner_attempts;
  if (escalate && own_onto && !request.split_large_turns && request.align_boundary) {
    corner_attempts.push_back({1.0, request.relax, false, kMapOntoFeatures, false, true});
    if (!request.relax) corner_attempts.push_back({1.0, true, false, kMapOntoFeatures, false, true});
  }
  MapOutcome best;
  FieldRequest kept = request;
  // The screened maps next in rank after the kept one (better first, at most kMapRetryCandidates − 1), with
  // their requests: their retries follow where the kept map's leave problems.
  std::vector<std::pair<MapOutcome, FieldRequest>> runners;
  auto rank_runner = [&](MapOutcome m, const FieldRequest& r) {
    auto at = std::find_if(runners.begin(), runners.end(), [&](const auto& x) { return better(m, x.first); });
    if (at - runners.begin() < kMapRetryCandidates - 1) runners.insert(at, {std::move(m), r});
    if (static_cast<int>(runners.size()) > kMapRetryCandidates - 1) runners.pop_back();
  };
  int tried = 0, maps = 0;
  size_t first_singularities = 0;  // the first placement's
  std::vector<std::map<int, int>> placed;  // each map's singularities
  // The placements before relaxation, by the attempt's units, distance onto the lines and flat sectors (each
  // relaxed attempt follows the same one unrelaxed), and the ones relaxed, with the periods or without.
  using PlacementKey = std::tuple<double, double, bool, bool>;
  std::map<PlacementKey, std::map<int, int>> unrelaxed;
  std::set<std::pair<std::map<int, int>, bool>> relaxed_from;
  // The maps are made without ParamOptions::retries and with a share of the untangling while other attempts may
  // follow (a retry costs up to a few maps, another placement often mends more); the kept map's retries (with the
  // whole untangling) follow if it still has problems.
  const bool screen = attempts.size() + corner_attempts.size() > 1;
  bool have_best = false;  // in this round of attempts
  std::optional<MapOutcome> unverified;  // the first attempt's field, when it failed verification
  // One attempt's placement and map, ranked against the best so far; false when the search ends (a map without
  // problems within the goal, or the first field failed verification: `unverified`).
  auto attempt_map = [&](const Attempt& attempt) -> bool {
    const PlacementKey key{attempt.units, attempt.onto, attempt.flat, attempt.boundary};
    const bool own_relax = attempt.relax && !request.relax;
    // Each accepted move ranks every singularity's candidates again: past kMapRelaxMaxSingularities (cheese,
    // genus 133: 1,412 −1/4) a relaxation takes minutes, so those placements are not relaxed here. Nor are
    // those relaxed already (the same start, the same result), nor with periods where there are none.
    const auto start = unrelaxed.find(key);
    if (own_relax && (first_singularities > kMapRelaxMaxSingularities || (attempt.periods && !periods_usable(designer)) ||
                      (start != unrelaxed.end() && relaxed_from.count({start->second, attempt.periods})))) {
      ++tried;
      return true;
    }
    if (log.maps() > 0 && !log.may_start()) return false;
    FieldRequest r = request;
    if (escalate) r.auto_options.cancel_distance = attempt.units * unit;
    if (own_onto)
      r.auto_options.onto_features = attempt.onto * unit, r.auto_options.onto_flat_sectors = attempt.flat,
      r.auto_options.onto_boundary = attempt.boundary;
    r.relax = attempt.relax;
    if (attempt.relax) {
      // The relaxation keeps singularities a unit away from the aligned lines: the energy draws a −1/4 toward a
      // round hole's boundary, where the rounding would put it on the boundary's iso-line.
      r.relax_options.avoid = vertices_near_edges(designer, aligned, unit);
      // and a unit from each other: two closer than that can be rounded onto one integer point.
      r.relax_options.separation = unit;
      if (attempt.periods) r.relax_options.period_weight = kMapPeriodWeight;
      // and a singularity may jump up to kMapRelaxReach edges: steps alone stop in a crowd along the aligned lines.
      r.relax_options.reach = std::max(r.relax_options.reach, kMapRelaxReach);
      // Its candidate solves are bounded: with hundreds of singularities on a large mesh a relaxation would take
      // minutes.
      if (own_relax && r.relax_options.max_solves == 0) {
        const double singularities = static_cast<double>(start != unrelaxed.end() ? start->second.size() : first_singularities);
        const double work = kMapRelaxWork / std::max(1, designer.topology().num_vertices);
        r.relax_options.max_solves = std::max(kMapRelaxMinSolves, static_cast<int>(std::min(kMapRelaxSolves * singularities, work)));
      }
    }
    MapOutcome m;
    m.field = solve_request(designer, F, r);
    ++tried;
    if (!m.field.verified) {
      if (tried == 1) {
        request = r;
        unverified = std::move(m);  // no map of an unverified field (the caller says why)
        return false;
      }
      return true;
    }
    if (tried == 1) first_singularities = m.field.prescription.vertex.size();
    if (!attempt.relax) unrelaxed.emplace(key, m.field.prescription.vertex);
    if (own_relax && start != unrelaxed.end()) relaxed_from.insert({start->second, attempt.periods});
    // The same singularities as an earlier attempt (nothing closer than the new distance to cancel): the same map.
    if (std::find(placed.begin(), placed.end(), m.field.prescription.vertex) != placed.end()) return true;
    placed.push_back(m.field.prescription.vertex);
    ++maps;
    ParamOptions options = request_param_options(designer, r, m.field, edge_length, target_faces);
    if (screen) options.retries = 0, options.untangle_share = kUntangleShareFollowed;
    m.param = parametrize(m.field.designer(designer), m.field.design, options);
    if (quads) m.quads = extract_quads(m.field.designer(designer), m.param);
    m.cancel_units = escalate ? attempt.units : 0.0;
    m.relaxed = attempt.relax && !request.relax;
    m.periods = attempt.periods;
    m.onto_units = own_onto ? attempt.onto : 0.0;
    m.onto_flat = own_onto && attempt.flat;
    m.onto_boundary = own_onto && attempt.boundary;
    log.made(std::max(1, m.param.quality.attempts),
             request.auto_place ? "placement " + describe_placement(m.cancel_units, m.relaxed, m.periods, m.onto_units, m.onto_flat, m.onto_boundary)
                                : std::string("the singularities given"),
             m.param, m.quads);
    if (!have_best || better(m, best)) {
      const int first = tried == 1 ? map_problems(m) : best.first_problems;
      const double first_distortion = tried == 1 ? m.param.quality.mean_distortion : best.first_distortion;
      if (have_best && screen) rank_runner(std::move(best), kept);
      have_best = true;
      best = std::move(m);
      best.first_problems = first, best.first_distortion = first_distortion;
      kept = r;
    } else if (screen) {
      rank_runner(std::move(m), r);
    }
    // A map without problems within the goal ends the search; past it every attempt is made, the least stretch
    // kept.
    return !(map_problems(best) == 0 && stretch(best) == 0);
  };
  for (const Attempt& attempt : attempts)
    if (!attempt_map(attempt)) break;
  if (unverified) return std::move(*unverified);
  // A screened map's retries, resumed from its first maps (at the edge length and at the field's unit size); the
  // designer holds that field's fixed faces.
  auto retry = [&](MapOutcome& m, const FieldRequest& r) {
    if (!log.may_start()) return;
    if (designer.fixed_faces() != m.field.constraints.fixed_faces) designer.set_fixed_faces(m.field.constraints.fixed_faces);
    ParamOptions options = request_param_options(designer, r, m.field, edge_length, target_faces);
    const int before = m.param.quality.attempts;
    Parametrization param = parametrize_retries(m.field.designer(designer), m.field.design, options, m.param);
    if (quads && param.uv != m.param.uv) m.quads = extract_quads(m.field.designer(designer), param);
    m.param = std::move(param);
    log.made(std::max(1, m.param.quality.attempts - before), "near-miss retries of a placement's map", m.param, m.quads);
  };
  int retried = 0;
  // `mend` on the kept map, then on the screened runners-up in rank until a map has no problems: ranked before it,
  // a runner-up may still be the one it mends; one made better takes the kept map's place, which becomes a runner-up.
  auto mend_kept = [&](const auto& mend) {
    mend(best, kept);
    for (auto& [m, r] : runners) {
      if (map_problems(best) == 0) break;
      mend(m, r);
      if (better(m, best)) {
        m.first_problems = best.first_problems, m.first_distortion = best.first_distortion;
        std::swap(best, m);
        std::swap(kept, r);
      }
    }
  };
  auto retry_kept = [&]() {
    if (screen && best.field.verified && map_problems(best) > 0) mend_kept([&](MapOutcome& m, const FieldRequest& r) {
      retry(m, r);
      ++retried;
    });
  };
  // Problems left after every placement and the retries: the kept field's map at other edge lengths
  // (map_at_other_scales), then the runners-up's in rank until a map has none (another scale can mend the
  // placement ranked second where it does not mend the first).
  auto rescale = [&](MapOutcome& m, const FieldRequest& r) {
    if (designer.fixed_faces() != m.field.constraints.fixed_faces) designer.set_fixed_faces(m.field.constraints.fixed_faces);
    ScaledMap scaled{std::move(m.param), std::move(m.quads), 1.0};
    scales_within(m.field.designer(designer), m.field.design, request_param_options(designer, r, m.field, edge_length, target_faces), scaled,
                  log);
    m.param = std::move(scaled.param), m.quads = std::move(scaled.quads), m.scale = scaled.scale;
  };
  auto rescale_kept = [&]() {
    if (best.field.verified && map_problems(best) > 0) mend_kept(rescale);
  };
  retry_kept();
  rescale_kept();
  // Problems left after all that: the placements with corners on the boundary, their retries and scales the same
  // way, kept if better.
  if (best.field.verified && map_problems(best) > 0 && !corner_attempts.empty()) {
    MapOutcome before = std::move(best);
    FieldRequest before_kept = kept;
    best = MapOutcome(), kept = request, runners.clear(), have_best = false;
    for (const Attempt& attempt : corner_attempts)
      if (!attempt_map(attempt)) break;
    if (have_best) retry_kept(), rescale_kept();
    if (have_best && better(best, before))
      best.first_problems = before.first_problems, best.first_distortion = before.first_distortion;
    else
      best = std::move(before), kept = std::move(before_kept);
  }
  // The designer holds the last set-up (an attempt's or a retry's: fixed faces turned for singularities moved onto
  // features): it takes the kept field's fixed faces back, so that the designer is the kept field's (its design is
  // kept as it was made; solving the kept request again would place and relax again for the same result).
  if (designer.fixed_faces() != best.field.constraints.fixed_faces) designer.set_fixed_faces(best.field.constraints.fixed_faces);
  best.placements = maps;
  best.retried_maps = retried;
  best.maps = log.maps();
  best.stopped = log.stopped();
  if (maps == 1) best.first_problems = 0, best.first_distortion = 0;
  request = kept;
  return best;
}

// The edges a map may have to split (vertex pairs): those not on an integer iso-line whose two ends both lie on
// aligned edges (the request's sharp edges, and its boundary when aligned); `on_line` gets those vertices.
std::vector<std::pair<int, int>> map_chords(const FieldDesigner& designer, const FieldRequest& request, double edge_length, double target_faces,
                                            std::vector<char>& on_line) {
  const Topology& t = designer.topology();
  const std::vector<int> aligned =
      request_param_options(designer, request, request_sharp_edges(designer, request), edge_length, target_faces).aligned_edges;
  std::vector<char> is_aligned(t.num_edges, 0);
  on_line.assign(t.num_vertices, 0);
  for (int e : aligned) is_aligned[e] = 1, on_line[t.edge_vertices(e, 0)] = on_line[t.edge_vertices(e, 1)] = 1;
  std::vector<std::pair<int, int>> chords;
  for (int e = 0; e < t.num_edges; ++e)
    if (!is_aligned[e] && on_line[t.edge_vertices(e, 0)] && on_line[t.edge_vertices(e, 1)]) chords.emplace_back(t.edge_vertices(e, 0), t.edge_vertices(e, 1));
  return chords;
}

// `asked` (on `from`) on a refinement `to` of its mesh whose faces lie in `parent` faces (vertices kept): the
// fixed directions and roots pass to every child (as world vectors: the frames differ), the listed feature edges
// go by their ends (splitting never cuts them).
FieldRequest request_on_refined(const FieldRequest& asked, const FieldDesigner& from, const FieldDesigner& to, const std::vector<int>& parent) {
  FieldRequest r = asked;
  r.prescription.fixed.clear();
  r.prescription.path_guide.clear();
  for (int f = 0; f < static_cast<int>(parent.size()); ++f)
    if (const auto it = asked.prescription.fixed.find(parent[f]); it != asked.prescription.fixed.end())
      r.prescription.fixed[f] = to.geometry().angle_in_face(f, from.geometry().direction_in_face(parent[f], it->second));
  for (auto& [face, angle] : r.roots) angle = to.geometry().angle_in_face(face, from.geometry().direction_in_face(face, angle));
  r.feature_edges.clear();
  for (int e : asked.feature_edges) r.feature_edges.push_back(edge_between(to.topology(), from.topology().edge_vertices(e, 0), from.topology().edge_vertices(e, 1)));
  return r;
}

}  // namespace

int map_problems(const Parametrization& param, const std::optional<QuadMesh>& quads) {
  const ParamQuality& q = param.quality;
  return q.flipped_faces + q.degenerate_faces + q.winding_errors + (quads ? static_cast<int>(quads->quality.problems.size()) : 0);
}

void map_at_other_scales(const FieldDesigner& designer, const Design& design, const ParamOptions& options, ScaledMap& map) {
  const MapSearch unbounded;
  SearchLog log(unbounded);
  scales_within(designer, design, options, map, log);
}

ScaledMap map_field(const FieldDesigner& designer, const Design& design, const ParamOptions& options, bool quads) {
  ScaledMap map{parametrize(designer, design, options), std::nullopt, 1.0};
  if (quads) map.quads = extract_quads(designer, map.param);
  map_at_other_scales(designer, design, options, map);
  return map;
}

std::string describe_placement(double cancel_units, bool relaxed, bool periods, double onto_units, bool onto_flat, bool onto_boundary) {
  std::ostringstream out;
  if (cancel_units > 1) out << (relaxed ? "relaxed, " : "") << "pairs cancelled within " << static_cast<int>(cancel_units) << " units";
  else if (onto_boundary) out << "the singularities found, those beside the boundary moved onto it as corners" << (relaxed ? ", relaxed" : "");
  else if (onto_flat) out << "the singularities found, moved onto the feature lines from " << onto_units << " units where a quad gets a flat corner";
  else if (onto_units > kMapOntoFeatures) out << "the singularities found, moved onto the feature lines from " << onto_units << " units";
  else out << (relaxed ? (periods ? "the singularities found, relaxed with the periods" : "the singularities found, relaxed") : "the first");
  return out.str();
}

MapOutcome map_request(FieldDesigner& designer, const MatrixX3i& F, FieldRequest& request, double edge_length, double target_faces,
                       bool quads, const MapSearch& search) {
  SearchLog log(search);
  if (request.feature_degrees && !request.feature_min_length) request.feature_min_length = map_unit(designer, edge_length, target_faces);
  request.sectors_for_singularities = true;
  const FieldRequest asked = request;
  MapOutcome m = map_search(designer, F, request, edge_length, target_faces, quads, log);
  // Where the kept map folds beside an edge whose two ends lie on aligned lines (a flat CAD face triangulated from
  // its rim alone: every triangle of its fan has its corners on the rim's iso-lines, so some are flat in (u, v)
  // whatever the map), those edges are split at their midpoints and the search runs again on the refined mesh;
  // its map is kept when it has fewer problems. Not with generator or loop indices (the refined mesh's cycles are
  // its own) nor split_large_turns (a refinement of its own).
  if (!m.field.verified || map_problems(m) == 0 || m.field.refined || !asked.prescription.generator.empty() ||
      !asked.prescription.loop.empty())
    return m;
  std::vector<char> on_line;
  const std::vector<std::pair<int, int>> chords = map_chords(designer, asked, edge_length, target_faces, on_line);
  const Topology& t = designer.topology();
  std::set<std::pair<int, int>> chord_set(chords.begin(), chords.end());
  // A face flat or turned over in (u, v) (signed area below 10⁻⁶ unit squares) with a chord among its edges and
  // its third corner on an aligned line too (a fan's face).
  const Eigen::MatrixXd& uv = m.param.uv;
  bool beside = false;
  for (int f = 0; f < t.num_faces && !beside; ++f) {
    const Eigen::RowVector2d p = uv.row(3 * f), q = uv.row(3 * f + 1) - p, w = uv.row(3 * f + 2) - p;
    if ((q(0) * w(1) - q(1) * w(0)) / 2 > 1e-6) continue;
    for (int k = 0; k < 3 && !beside; ++k) {
      const int a = t.F(f, k), b = t.F(f, (k + 1) % 3), c = t.F(f, (k + 2) % 3);
      beside = chord_set.count({std::min(a, b), std::max(a, b)}) > 0 && on_line[c];
    }
  }
  if (!beside) return m;
  if (!log.may_start()) {
    m.stopped = true;
    return m;
  }
  log.note("the map kept folds beside edges whose ends lie on aligned lines: " + std::to_string(chords.size()) +
           " such edges split at their midpoints, the search again on that mesh");
  std::vector<int> parent;
  Mesh refined = split_edges_at_midpoints(Mesh{designer.V(), F}, chords, &parent);
  auto refined_designer = std::make_unique<FieldDesigner>(refined.V, refined.F, designer.solver_options());
  FieldRequest r = request_on_refined(asked, designer, *refined_designer, parent);
  MapOutcome n = map_search(*refined_designer, refined.F, r, edge_length, target_faces, quads, log);
  m.maps = n.maps = log.maps(), m.stopped = n.stopped = log.stopped();
  if (!n.field.verified || map_problems(n) >= map_problems(m)) return m;
  n.field.refined = std::move(refined_designer);
  n.field.V = std::move(refined.V), n.field.F = std::move(refined.F), n.field.parent_face = std::move(parent);
  n.refined_edges = static_cast<int>(chords.size());
  request = std::move(r);
  return n;
}

}  // namespace trivcon
