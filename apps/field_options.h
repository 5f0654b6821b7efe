// SPDX-License-Identifier: MIT
// The options that state a field request (trivcon/request.h), shared by `solve` and `param`: the
// prescription, fixed directions, boundary and feature alignment, automatic placement, roots, the solver's
// options and splitting of large turns. What the request means is the library's; here only the parsing.
#pragma once
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "feature_options.h"
#include "prescription_options.h"
#include "trivcon/design.h"
#include "trivcon/request.h"

namespace trivcon::cli {

struct FieldOptions {
  PrescriptionOptions prescription;
  std::string weights = "cotan", solver = "cholesky", factorization = "own";
  double weight_floor = 0;
  std::vector<int> root_faces;
  std::vector<double> root_angles;
  std::vector<std::string> fixes;
  bool align_boundary = false;
  FeatureOptions features;  // --align-features, --features
  double feature_min_length = 0;  // --feature-min-length
  CLI::Option* feature_min_option = nullptr;
  bool auto_place = false;  // --auto
  double auto_cancel = 0;   // --auto-cancel, in mean edge lengths
  std::string align;        // --align curvature[:t]
  std::string sing_from_field;
  bool relax = false;              // --relax
  std::vector<int> relax_pins;     // --relax-pin
  int relax_cancel = 0;            // --relax-cancel, in edges
  int relax_max_moves = 10000;     // --relax-max-moves
  double relax_periods = 0;        // --relax-periods
  int relax_reach = 1;             // --relax-reach
  bool split_large_turns = false;  // --split-large-turns
  CLI::Option* auto_flag = nullptr;
  CLI::Option* from_field_option = nullptr;
  CLI::Option* relax_flag = nullptr;

  // Adds the options to `cmd` (-N among them unless `fixed_N`: `param` is for N = 4 only).
  void add_to(CLI::App* cmd, bool fixed_N = false);
  SolverOptions solver_options() const;
  // The request on `designer`'s mesh: specs parsed, files read (-s, --fix, --features, --sing-from-field);
  // the vertex singularities of --sing-from-field are filled in. With `repaired` (the designer's mesh is that
  // repair of the input), every id given is the input's and is moved onto it (move_request_to_repaired).
  // Throws trivcon::Error.
  FieldRequest request(const FieldDesigner& designer, const RepairedMesh* repaired = nullptr) const;
};

// The strength T of --align curvature[:T] (0 when not given), or nothing when the text is not of that form.
std::optional<double> alignment_strength(const std::string& text);

}  // namespace trivcon::cli
