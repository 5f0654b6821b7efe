// SPDX-License-Identifier: MIT
// trivcon/design.h: the whole pipeline on plain (V, F) — validate, prepare once, then design fields.
//
//   trivcon::FieldDesigner designer(V, F);          // topology, geometry, cycles (factorization on first use)
//   designer.set_fixed_faces({});                    // optional: factor now rather than on the first design
//   trivcon::IndexPrescription p;  p.N = 4;  p.vertex[12] = 1;  ...
//   trivcon::Design d = designer.design(p);          // a re-solve: milliseconds
//   d.field.angle, d.connection.x, d.indices ...
//
// Fixed directions (trivcon/constraints.h): call set_fixed_faces() with the faces once (it refactors), then
// give their angles in each prescription's `fixed` map; each component with fixed faces starts its field
// at its smallest fixed face, with that face's angle.
//
// Set-up on two threads: after the topology, a second thread computes the cycles and the solver's
// symbolic analysis (they depend on the connectivity only, trivcon/solver.h SolverAnalysis) while this
// one computes the geometry (on one OpenMP thread fewer than the default) and the field's propagation
// plan; the factorization (on first use) waits for the analysis if it is not done yet. With fixed
// faces the solver analyses its own system and the early analysis is not used (it still runs to its
// end, on the core the first thread's single-threaded stages leave idle; the destructor waits for it);
// with SolverKind::QR there is no second thread.
//
// Every design is verified: the largest holonomy residual over all vertex, loop and generator cycles,
// the field's mismatch with the connection across every dual edge, and the indices read back from the
// field itself are compared with the prescription (see trivcon/field.h for when they can differ).
#pragma once
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/constraints.h"
#include "trivcon/cycles.h"
#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/solver.h"
#include "trivcon/topology.h"

namespace trivcon {

struct Design {
  Connection connection;
  Field field;
  FieldIndices indices;                      // read back from the field
  double transport_mismatch = 0;             // max over dual edges, radians (mod 2π/N)
  std::vector<int> index_mismatch_vertices;  // interior vertices whose field index differs from the prescription
  int large_turn_edges = 0;                  // edges with |x_e| ≥ π/N (where a field cannot show the index)
  // Mismatches at vertices none of whose edges turns by π/N or more (less 1e-9): these would be real errors.
  std::vector<int> unexplained_mismatch_vertices;
  // What a consumer of the per-face field sees: true when the field, read on its own with the closest
  // matching across every edge (field_indices), shows exactly the connection's indices at every vertex,
  // generator and boundary loop. False where the connection turns by π/N or more across some edge (then
  // split_large_turns, trivcon/split_large_turns.h, refines the mesh until it is true); design_verified does not look at it.
  bool field_exact = true;
  double max_fixed_error = 0;            // largest |field − fixed direction| modulo 2π/N over fixed faces
  std::vector<FixedConflict> conflicts;  // adjacent fixed faces the field must turn sharply between
  double solve_seconds = 0, field_seconds = 0, verify_seconds = 0;
};

// The verification `trivcon solve` applies (exit status 3 when it fails): the holonomy residuals, the transport
// mismatch and the fixed faces' deviation at most tolerance × max(1, rhs_scale) (tolerance 1e-9 unless the
// user asks for another, `solve --tolerance`), and no index mismatch that a turn of π/N or more across an
// edge does not explain (Design::unexplained_mismatch_vertices).
constexpr double kDefaultTolerance = 1e-9;
bool design_verified(const Design& design, double tolerance = kDefaultTolerance);

struct PrepareTimings {
  // Seconds of each stage; cycles and analysis ran on the second thread, concurrently with geometry and
  // plan. prepare: wall time of the constructor plus the solver's set-up (what a user waits for).
  double topology = 0, geometry = 0, cycles = 0, plan = 0, analysis = 0, setup = 0, prepare = 0;
};

class FieldDesigner {
 public:
  // Validates (finite coordinates, manifold, orientable) and prepares; throws trivcon::Error.
  FieldDesigner(const MatrixX3d& V, const MatrixX3i& F, SolverOptions options = {});
  // The solver and the second thread refer to the members: a designer stays where it was built.
  FieldDesigner(const FieldDesigner&) = delete;
  FieldDesigner& operator=(const FieldDesigner&) = delete;
  // Sets the faces whose direction prescriptions fix, and sets up (factors) the solver for them.
  void set_fixed_faces(const std::vector<int>& faces);
  // Changes the solver's options (e.g. the weights) and sets the solver up again.
  void set_solver_options(const SolverOptions& options);

  Design design(const IndexPrescription& prescription, const std::vector<std::pair<int, double>>& roots = {}) const;

  const MatrixX3d& V() const { return V_; }
  const Topology& topology() const { return topology_; }
  const Geometry& geometry() const { return geometry_; }
  const Cycles& cycles() const { return cycles_; }
  const PropagationPlan& plan() const { return plan_; }  // the field's spanning trees (trivcon/field.h)
  const ConnectionSolver& solver() const;                // set up on first use
  const PrepareTimings& timings() const { return timings_; }
  const SolverOptions& solver_options() const { return options_; }
  const std::vector<int>& fixed_faces() const { return fixed_faces_; }  // what set_fixed_faces was last given

 private:
  MatrixX3d V_;
  Topology topology_;
  Geometry geometry_;
  Cycles cycles_;
  PropagationPlan plan_;
  SolverOptions options_;
  mutable std::unique_ptr<ConnectionSolver> solver_;
  mutable PrepareTimings timings_;
  std::vector<int> fixed_faces_;
  double construct_seconds_ = 0;
  // Declared last: destroyed (joined) first, while the members its thread reads still exist.
  mutable std::future<SolverAnalysis> analysis_;
};

// Why a design failed design_verified, and what to try, in one sentence ("" when it passed); names the
// largest residual against its limit, the steps of iterative refinement taken, and what the weight
// policy did on this mesh (trivcon/geometry.h).
std::string verification_failure(const FieldDesigner& designer, const Design& design, double tolerance = kDefaultTolerance);

}  // namespace trivcon
