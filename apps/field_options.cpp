// SPDX-License-Identifier: MIT
#include "field_options.h"

#include <cmath>

#include "trivcon/error.h"

namespace trivcon::cli {

std::optional<double> alignment_strength(const std::string& text) {
  if (text == "curvature") return 0.0;
  const std::string prefix = "curvature:";
  if (text.compare(0, prefix.size(), prefix) != 0 || text.size() == prefix.size()) return std::nullopt;
  const std::string number = text.substr(prefix.size());
  size_t used = 0;
  double t = 0;
  try {
    t = std::stod(number, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != number.size() || !std::isfinite(t) || !(t < 1)) return std::nullopt;
  return t;
}

void FieldOptions::add_to(CLI::App* cmd, bool fixed_N) {
  prescription.add_to(cmd, true);
  if (fixed_N) prescription.N = 4, cmd->remove_option(prescription.N_option), prescription.N_option = nullptr;
  cmd->add_option("--weights", weights, "cotan (default: clamped cotangent weights) or unit")->check(CLI::IsMember({"cotan", "unit"}));
  cmd->add_option("--weight-floor", weight_floor,
                  "with cotan weights, every interior edge gets at least this fraction of the median weight (default 0: none)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--solver", solver, "cholesky (default) or qr (the paper's SuiteSparseQR route; only in a build with -DTRIVCON_WITH_SUITESPARSE=ON)")
      ->check(CLI::IsMember({"cholesky", "qr"}));
  cmd->add_option("--factorization", factorization,
                  "Cholesky route's numeric factor: own (default: trivcon's, on several threads) or cholmod (CHOLMOD's cholmod_factorize; only in a build with -DTRIVCON_WITH_SUITESPARSE=ON)")
      ->check(CLI::IsMember({"own", "cholmod"}));
  cmd->add_option("--fix", fixes,
                  "Fixed direction: F:x,y,z (world, projected to the face), F:angle=A (radians, face frame), or a file with "
                  "'FACE x y z' / 'FACE angle=A' lines; repeatable");
  cmd->add_flag("--align-boundary", align_boundary, "Fix every face with a boundary edge to that edge's direction");
  features.add_to(cmd, "every face beside one is fixed to its direction (with --auto too)");
  feature_min_option =
      cmd->add_option("--feature-min-length", feature_min_length,
                      "With --align-features: sharp edges in a chain with a loose end shorter than L (in the mesh's units, along the "
                      "chain) are not followed, again until none is left, as a scan's dashed creases (default: 0 for solve, all "
                      "followed; one unit of the map for param and quad)")
          ->check(CLI::NonNegativeNumber)
          ->needs(features.degrees_option);
  auto_flag = cmd->add_flag("--auto", auto_place,
                            "Find the singularities automatically: those of the globally smoothest field (Knoppel et al. 2013), "
                            "then solve exactly with them");
  cmd->add_option("--auto-cancel", auto_cancel,
                  "With --auto: cancel pairs of opposite singularities at most D mean edge lengths apart (geodesic, along edges), "
                  "closest first")
      ->check(CLI::NonNegativeNumber)
      ->needs(auto_flag);
  auto check_align = [](const std::string& text) -> std::string {
    return alignment_strength(text) ? "" : "expected curvature or curvature:T with a number T < 1, not '" + text + "'";
  };
  cmd->add_option("--align", align,
                  "With --auto: guidance for the smoothest field; 'curvature' or 'curvature:T' follows the principal curvature "
                  "directions (N even) with strength T < 1 (default 0; toward 1 smoother, negative closer to the curvature)")
      ->check(CLI::Validator(check_align, "curvature[:T]"))
      ->needs(auto_flag);
  from_field_option = cmd->add_option("--sing-from-field", sing_from_field,
                                      "Use the singularities of a per-face field (.txt, .ply or Directional's .rawfield, as `check` reads)");
  auto_flag->excludes(prescription.files_option)->excludes(prescription.sing_option)->excludes(from_field_option);
  from_field_option->excludes(prescription.files_option)->excludes(prescription.sing_option);
  relax_flag = cmd->add_flag("--relax", relax,
                             "Move the singularities (of -s, --sing, --auto or --sing-from-field) one edge at a time while the field's energy "
                             "goes down, each move a real solve, until no single move lowers it; indices per component kept, boundary "
                             "vertices never singular");
  cmd->add_option("--relax-pin", relax_pins, "With --relax: this vertex keeps its index, and no singularity moves onto it (repeatable)")
      ->check(CLI::NonNegativeNumber)
      ->needs(relax_flag);
  cmd->add_option("--relax-cancel", relax_cancel,
                  "With --relax: a singularity may also move onto one of opposite index at most D edges away, both vanishing, when "
                  "that lowers the energy (default 0: never)")
      ->check(CLI::NonNegativeNumber)
      ->needs(relax_flag);
  cmd->add_option("--relax-max-moves", relax_max_moves, "With --relax: accepted moves at most (default 10000)")
      ->check(CLI::NonNegativeNumber)
      ->needs(relax_flag);
  cmd->add_option("--relax-reach", relax_reach,
                  "With --relax: a singularity may move to a free vertex at most K edges away in one move (default 1: one edge), "
                  "which lets it pass a rise of the energy that single steps stop at")
      ->check(CLI::PositiveNumber)
      ->needs(relax_flag);
  cmd->add_option("--relax-periods", relax_periods,
                  "With --relax: lower the energy plus W times the squared periods of the conformal scale around the aligned "
                  "boundary loops and feature lines, so that a map of the field stretches less (docs/solver.md, \"Periods\"; "
                  "default 0: the energy alone)")
      ->check(CLI::NonNegativeNumber)
      ->needs(relax_flag);
  cmd->add_option("--root-face", root_faces, "Face where propagation starts (one per component at most; repeatable)");
  cmd->add_option("--root-angle", root_angles, "Angle (radians, in the root face's frame) of the field at the matching --root-face");
  cmd->add_flag("--split-large-turns", split_large_turns,
                "Refine the mesh where the connection turns by pi/N or more (split those edges and their faces; input ids kept, new "
                "vertices and faces appended) and solve again, until no edge does, so that any tool's own matching reads exactly the "
                "prescribed singularities; write the refined mesh with --mesh-out");
}

SolverOptions FieldOptions::solver_options() const {
  SolverOptions options;
  options.weights = weights == "unit" ? WeightKind::Unit : WeightKind::Cotan;
  options.weight_floor = weight_floor;
  options.solver = solver == "qr" ? SolverKind::QR : SolverKind::Cholesky;
  options.factorization = factorization == "cholmod" ? Factorization::Cholmod : Factorization::Parallel;
  return options;
}

FieldRequest FieldOptions::request(const FieldDesigner& designer, const RepairedMesh* repaired) const {
  FieldRequest r;
  r.prescription = prescription.build();
  if (root_angles.size() > root_faces.size()) throw Error("--root-angle given without a matching --root-face");
  for (size_t i = 0; i < root_faces.size(); ++i) r.roots.emplace_back(root_faces[i], i < root_angles.size() ? root_angles[i] : 0.0);
  FaceIdMap face_id;
  if (repaired) face_id = [repaired](int f) { return repaired_face(*repaired, f, "face"); };
  add_fix_options(fixes, designer.topology(), designer.geometry(), r.prescription.fixed, face_id);
  r.align_boundary = align_boundary;
  if (features.degrees_option->count() > 0) r.feature_degrees = features.degrees;
  if (features.file_option->count() > 0) r.feature_edges = read_feature_edges(features.file, designer.topology());
  if (feature_min_option->count() > 0) {
    if (!std::isfinite(feature_min_length)) throw Error("--feature-min-length: expected a finite length >= 0 in the mesh's units");
    r.feature_min_length = feature_min_length;
  }
  if (split_large_turns && (!r.prescription.generator.empty() || !r.prescription.loop.empty()))
    throw Error(
        "--split-large-turns makes new generators and boundary loops: leave their indices to be chosen (no --generator, --boundary)");
  if (split_large_turns && features.file_option->count() > 0)
    throw Error("--split-large-turns splits edges, which a --features file names by their vertices: use --align-features instead");
  r.auto_place = auto_place;
  r.auto_options.cancel_distance = auto_cancel;
  if (!align.empty()) r.auto_options.align_curvature = true, r.auto_options.curvature_t = *alignment_strength(align);  // checked by CLI11
  r.relax = relax;
  r.relax_options.pins = relax_pins;
  r.relax_options.cancel_distance = relax_cancel;
  r.relax_options.max_moves = relax_max_moves;
  r.relax_options.period_weight = relax_periods;
  r.relax_options.reach = relax_reach;
  r.split_large_turns = split_large_turns;
  if (repaired) move_request_to_repaired(r, designer.topology(), *repaired);
  if (!sing_from_field.empty()) {
    MatrixX3d directions =
        prescription.read_field_file(sing_from_field, repaired ? repaired->input_faces : designer.topology().num_faces, r.prescription.N);
    if (repaired) directions = rows_on_repaired(*repaired, directions);
    const Field field = field_from_directions(designer.geometry(), directions, r.prescription.N);
    const FieldIndices idx = field_indices(designer.topology(), designer.geometry(), designer.cycles(), field);
    for (int v = 0; v < designer.topology().num_vertices; ++v)
      if (idx.vertex[v] != 0) r.prescription.vertex[v] = idx.vertex[v];
  }
  return r;
}

}  // namespace trivcon::cli
