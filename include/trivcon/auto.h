// trivcon/auto.h: singularities found automatically, from the globally smoothest N-direction field.
//
// Method (Knöppel, Crane, Pinkall & Schröder 2013, "Globally Optimal Direction Fields", face-based):
// - Each face f carries one complex number u_f in its own frame (trivcon/geometry.h); the field's first
//   direction there is at angle arg(u_f)/N, so u_f = e^{iNβ_f} represents the N directions at once.
// - Energy E(u) = Σ_e w_e |u_R − e^{iNρ_e} u_L|² over interior edges e (L, R and ρ_e of
//   trivcon/geometry.h: ρ_e carries a direction from L to R, so e^{iNρ_e} carries u). Its Hermitian
//   matrix A is factored as a complex matrix (half the factor and the work of the real 2×2-block form).
// - Dual-edge weight w_e = |e|² / (m_L + m_R): the ratio of the primal edge length to the length of the
//   dual edge between the two faces, with the dual edge measured through the faces' areas
//   (≈ (m_L + m_R) / |e| up to a constant, which does not change the field). Unlike the cotan-like
//   face-Laplacian weight 2 / (cot α + cot β) it is positive and finite on every mesh (no clamping, no
//   blow-up where the circumcentres of L and R coincide).
// - Mass m_f = the face's area. On a component with slivers, zero-area faces or zero-length edges, the
//   lengths in w_e (|e| + ε) and the masses are those of the mollified intrinsic triangles of
//   trivcon/geometry.h (Geometry::component_epsilon, mollified_area): every face keeps a positive mass and
//   positive weights to its neighbours. (With the raw lengths a face whose three corners coincide has three
//   zero weights: it is cut off, an eigenvector of eigenvalue ~0 lives on it alone, and the inverse iteration
//   converges to it, leaving every other face "vanishing"; the dragon's collapsed faces did that.) A floor of
//   1e-12 × the mean face area stays as a last guard.
// - The smoothest unit field minimises E(u) / ‖u‖²_M: the eigenvector of the smallest eigenvalue of
//   A u = λ M u. It is computed per component by inverse-power iterations (x ← (A + εM)⁻¹ M x,
//   normalised per component to ‖x‖_M = 1, from a fixed pseudo-random start) on ONE supernodal
//   factorization of A + εM, ε = 1e-8 × Σ_f A_ff / Σ_f m_f (a tiny shift: A alone is singular when the
//   N-th power of the holonomy is trivial, e.g. on a flat torus). Its order: CHOLMOD's AMD, or above 50k
//   faces whichever of AMD and a nested dissection by the faces' centroids needs fewer flops (both analysed
//   at once on two threads; the dissection wins on regular, remeshed surfaces, AMD on scans); the numeric
//   factor and the solves by trivcon's own supernodal code on all threads. The result does not depend on
//   the order beyond round-off (`ordering` says which was used). At 400k faces on 2 cores: about 0.9 s in
//   all, one third of it the 8 solves (BENCHMARKS.md, "The cost of --auto").
// - Why face-based: the field lives per face like trivcon's own fields and their indices are read by
//   the same field_indices (trivcon/field.h), so the singularities are exactly those of the field that
//   was found; a vertex-based field would have to be moved to faces first (an interpolation that can
//   itself create or move singularities), and a face-based field puts singularities at vertices, which is
//   what a trivial-connection prescription needs.
//   Measured (N = 4, 8 iterations) against a vertex-based field (cotan weights, vertex frames with the
//   corner angles rescaled to 2π, the field averaged into faces, indices read the same way): on the
//   shared meshes spot, bunny_closed, armadillo, torus, kitten, rocker-arm, eight, fertility, face,
//   camelhead, circle, bun_zipper the face-based field has 52, 34, 170, 6, 43, 36, 22, 58, 32, 31, 0, 46
//   singularities (530), the vertex-based one 47, 28, 148, 6, 29, 28, 20, 56, 28, 33, 0, 41 (464); but the
//   vertex-based one puts a spurious pair on a thin round torus (r/R = 0.2) where the face-based one has
//   none, and needs that interpolation; both give the 8 corners of a cube. Face-based w_e against the
//   barycentric dual-edge weight |e| / |c_L − c_R|: the same counts within ±2 per mesh (526 in all).
// - Where the smoothest field vanishes on a face (|u_f| ≤ 1e-9 × the component's largest |u|), the face
//   takes the sum of its neighbours' values transported into it; if that vanishes too, angle 0 in its
//   frame. `vanishing_faces` counts such faces.
// - Fixed faces (AutoOptions::fixed, e.g. trivcon::boundary_alignment): their u_f = e^{iNγ_f} are
//   Dirichlet values (Knöppel Sec. 5), and on each component that has any the field is the one solve
//   (A_II + εM_II) u_I = −A_IB u_B instead of an eigenvector.
//
// Curvature alignment (AutoOptions::align_curvature; Knöppel et al. 2013, Sec. 5): the guidance q_f is the
// face's principal curvature direction as an N-field (trivcon/curvature.h: z_f^{N/2} / |z_f|^{N/2−1}, for N
// even), scaled per component so that its area-weighted mean |q| is 1, and the field solves
// (A − λ_t M) u = M q (+ the Dirichlet values of fixed faces) with λ_t = t·λ̂, λ̂ the Rayleigh quotient of the
// field the iterations above found on that component (the smallest eigenvalue's estimate). t = 0 (the default,
// geometry-central's choice) solves A u = M q with the factor already there; t → 1 approaches the smoothest
// field (q matters less and less); t < 0 follows the curvature more closely (the system is refactored for
// t ≠ 0, with the same ordering). |q| is the anisotropy |κ_max − κ_min|, so umbilic and flat regions are
// guided by the smoothness alone; a component without any curvature (flat) keeps its smoothest field.
//
// Singularities: the indices of that field at interior vertices (field_indices); being read from a
// field they satisfy Gauss–Bonnet per closed component. Boundary vertices never carry one: where the field
// beside fixed boundary faces turns by whole 2π/N steps more around a boundary vertex than the fixed
// directions need, that turning is moved to an interior neighbour (boundary_turns_moved_inside), so that
// the singularities sum to what the fixed boundary needs (check_aligned_index_sums).
//
// Coincident vertices (joined by edges of length exactly 0, as in meshes with duplicated vertices): the
// corner angles of a face with a zero-length edge are a convention (trivcon/geometry.h: π/2 at both ends),
// since the direction from one end to the other is lost, so the curvature of such a cluster is shared among
// its vertices arbitrarily, and the smoothest field answers with ± pairs on the coincident vertices, which
// no one can see. The indices of each cluster are therefore summed onto its smallest vertex id (0: removed);
// a cluster that touches the boundary keeps its vertices' own. `coincident_removed` counts what this removed.
//
// Cancellation (AutoOptions::cancel_distance > 0), for fewer singularities on noisy scans: pairs of
// singular vertices with opposite indices (+n and −n) whose geodesic distance (Dijkstra along mesh
// edges, Euclidean edge lengths) is at most the distance are removed, closest pair first (ties: smaller
// vertex ids first), each vertex in one pair at most. Removing +n and −n keeps every sum, so Gauss–Bonnet
// still holds per component. The distance is in units of the mean edge length of the mesh unless
// `cancel_absolute` (then in the mesh's units).
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/common.h"
#include "trivcon/cycles.h"
#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

class FieldDesigner;

struct AutoOptions {
  int N = 4;                     // symmetry, ≥ 1
  int iterations = 8;            // inverse-power iterations, ≥ 1
  double cancel_distance = 0;    // cancel ± pairs at most this far apart; 0: none
  bool cancel_absolute = false;  // cancel_distance in mesh units instead of mean edge lengths
  std::map<int, double> fixed;   // face → angle in its frame (radians), held as Dirichlet values
  bool align_curvature = false;  // follow the principal curvature directions (see above); N even
  double curvature_t = 0;        // its strength t < 1: 0 as geometry-central, → 1 smoother, < 0 closer to the curvature
};

struct AutoTimings {
  double assemble = 0, factor = 0, iterate = 0, align = 0, indices = 0, cancel = 0;  // seconds
};

struct AutoResult {
  Field field;                             // the smoothest field, angle = arg(u_f)/N in [0, 2π/N)
  std::map<int, int> found;                // its singularities: vertex → n (index n/N)
  int coincident_removed = 0;              // singularities of `found` that summing over coincident vertices removed
  int boundary_moved = 0;                  // 1/N steps of turning at boundary vertices beside fixed faces, moved into `found` at
                                           // an interior neighbour (boundary_turns_moved_inside, trivcon/constraints.h)
  std::map<int, int> vertex;               // after that and cancellation: the singularities to prescribe
  std::vector<std::pair<int, int>> pairs;  // cancelled pairs (vertex of index +n, vertex of −n), in order
  double energy = 0;                       // E(u) / ‖u‖²_M over the whole mesh (the Rayleigh quotient without fixed faces)
  int vanishing_faces = 0;                 // faces where |u_f| vanished (see above)
  std::string ordering;                    // the smoothest field's factor order: "AMD" or "coordinate dissection"
  AutoTimings seconds;
};

// On a prepared mesh (V gives the edge lengths for the weights and distances).
AutoResult auto_singularities(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const Cycles& cycles,
                              const AutoOptions& options);
// On a FieldDesigner's topology and geometry (fixed faces are those of options.fixed, not the designer's).
AutoResult auto_singularities(const FieldDesigner& designer, const AutoOptions& options);
// On plain (V, F): validates and prepares the mesh first (trivcon::Error as build_topology).
AutoResult auto_singularities(const MatrixX3d& V, const MatrixX3i& F, const AutoOptions& options);

// The cancellation above on its own, `distance` in the mesh's units: the singularities left, and the
// cancelled pairs (positive vertex, negative vertex) appended to `pairs` when not null.
std::map<int, int> cancel_singularity_pairs(const MatrixX3d& V, const Topology& topology, const std::map<int, int>& vertex, double distance,
                                            std::vector<std::pair<int, int>>* pairs = nullptr);

// The summing over coincident vertices above on its own.
std::map<int, int> merge_coincident_singularities(const MatrixX3d& V, const Topology& topology, const std::map<int, int>& vertex);


// The roots (face, angle) that turn each component's field to agree best with `guide`, an N-field (e.g. the
// smoothest field AutoResult::field that --auto read its singularities from: the trivial connection then
// keeps its orientation, instead of starting each component at angle 0). `field` is the field
// FieldDesigner::design made with `roots`; for each component with neither a root in `roots` nor a fixed face
// (whose directions decide its rotation), the rotation θ maximizing Σ_f A_f cos(N(α_f − β_f − θ)), i.e.
// θ = arg(Σ_f A_f e^{iN(α_f − β_f)}) / N (A_f the face areas), is returned as a root at the component's
// first face with angle β + θ (nothing where that sum vanishes). `roots` are returned first, unchanged.
std::vector<std::pair<int, double>> roots_toward(const FieldDesigner& designer, const Field& field, const Field& guide,
                                                 const std::vector<std::pair<int, double>>& roots = {},
                                                 const std::map<int, double>& fixed = {});
// The same rotation applied to `field` in place (each component's angles + θ, wrapped to [0, 2π)), without
// designing again: what an interactive front end does after every edit (a rotation by a constant per
// component changes none of the design's checks). Components with a fixed face keep their rotation.
// Components with a root in `roots` keep theirs too.
void turn_toward(const FieldDesigner& designer, Field& field, const Field& guide, const std::map<int, double>& fixed = {},
                 const std::vector<std::pair<int, double>>& roots = {});

}  // namespace trivcon
