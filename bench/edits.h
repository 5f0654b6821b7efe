// SPDX-License-Identifier: MIT
// bench/edits.h: the benchmark's edits — a new set of singularities at random vertices each time.
//
// An edit moves every singularity to other random interior vertices. Per connected component:
// - the component with the most faces (the "target") gets `count` singularities (after the adjustment
//   below), the others none, except:
// - a closed component must satisfy Gauss–Bonnet: its vertex indices sum to S = N·χ (trivcon/indices.h).
//   The target then gets p indices +1 and q indices −1 (units of 1/N) with p + q = count' and p − q = S,
//   where count' is the smallest number ≥ `count` with count' ≥ |S| and count' ≡ S (mod 2):
//   a sphere with N = 4 and count = 8 gets the eight +1/4 of a cube-like cross field, a torus gets four
//   +1/4 and four −1/4. Any other closed component with S ≠ 0 gets |S| indices of sign S.
// - a component with boundary has no constraint (the loop indices are chosen by the solver), so the
//   target gets `count` indices +1.
// Vertices are drawn uniformly from the component's interior vertices, without repetition and, while
// possible (up to 100 draws per singularity), never next to another singularity of the edit: two
// singularities joined by an edge would make the connection turn by π/N or more across it, which a
// field sampled once per face cannot show (trivcon/field.h). The draws come straight from
// std::mt19937_64, so an edit is the same on every platform for a given seed. The generator keeps a
// reference to the topology.
// Header-only so that the smoke test (tests/test_bench_smoke.cpp) checks exactly what the benchmark runs.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "trivcon/indices.h"
#include "trivcon/topology.h"

namespace trivcon::bench {

class EditGenerator {
 public:
  EditGenerator(const Topology& topology, int N, int count) : topology_(topology), N_(N), interior_(topology.components.size()) {
    if (N < 1 || count < 0) throw std::invalid_argument("EditGenerator: need N >= 1 and count >= 0");
    for (int v = 0; v < topology.num_vertices; ++v)
      if (topology.is_interior_vertex(v)) interior_[topology.vertex_component[v]].push_back(v);
    for (size_t c = 0; c < topology.components.size(); ++c)
      if (target_ < 0 || topology.components[c].faces > topology.components[target_].faces) target_ = static_cast<int>(c);
    std::vector<Slot> plan;
    for (size_t c = 0; c < topology.components.size(); ++c) {
      const ComponentInfo& info = topology.components[c];
      const bool closed = info.boundary_loops.empty();
      const int S = N * info.euler_characteristic;
      Slot slot;
      slot.component = static_cast<int>(c);
      if (static_cast<int>(c) == target_) {
        if (closed) {
          int k = std::max(count, std::abs(S));
          if ((k - S) % 2 != 0) ++k;
          slot.plus = (k + S) / 2, slot.minus = (k - S) / 2;
        } else {
          slot.plus = count;
        }
      } else if (closed && S != 0) {
        (S > 0 ? slot.plus : slot.minus) = std::abs(S);
      } else {
        continue;
      }
      if (slot.plus + slot.minus > static_cast<int>(interior_[c].size()))
        throw std::invalid_argument("EditGenerator: component " + std::to_string(c) + " has only " + std::to_string(interior_[c].size()) +
                                    " interior vertices for " + std::to_string(slot.plus + slot.minus) + " singularities");
      plan.push_back(slot);
    }
    slots_ = std::move(plan);
  }

  // The next edit: every singularity at a fresh random interior vertex.
  IndexPrescription next(std::mt19937_64& rng) const {
    IndexPrescription p;
    p.N = N_;
    for (const Slot& s : slots_) {
      const std::vector<int>& pool = interior_[s.component];
      const int k = s.plus + s.minus;
      std::vector<int> chosen;
      chosen.reserve(k);
      int draws = 0;
      while (static_cast<int>(chosen.size()) < k) {
        const int v = pool[static_cast<size_t>(rng() % pool.size())];
        ++draws;
        if (std::find(chosen.begin(), chosen.end(), v) != chosen.end()) continue;
        if (draws <= 100 * k && next_to_any(v, chosen)) continue;
        chosen.push_back(v);
      }
      for (int i = 0; i < k; ++i) p.vertex[chosen[i]] = i < s.plus ? 1 : -1;
    }
    return p;
  }

  int N() const { return N_; }
  int target_component() const { return target_; }
  // Singularities per edit.
  int singularities() const {
    int k = 0;
    for (const Slot& s : slots_) k += s.plus + s.minus;
    return k;
  }

 private:
  bool next_to_any(int v, const std::vector<int>& chosen) const {
    const Topology& t = topology_;
    for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
      const int e = t.vertex_edges[a];
      const int u = t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
      if (std::find(chosen.begin(), chosen.end(), u) != chosen.end()) return true;
    }
    return false;
  }

  struct Slot {
    int component = 0, plus = 0, minus = 0;
  };
  const Topology& topology_;
  int N_;
  int target_ = -1;
  std::vector<std::vector<int>> interior_;  // interior vertices per component
  std::vector<Slot> slots_;
};

// Seed of edit `index` on mesh `name`: the same for our solver and the QR solver in one run.
inline std::uint64_t edit_seed(const std::string& name, int index) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (unsigned char ch : name) h = (h ^ ch) * 1099511628211ull;
  return h ^ (0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(index + 1));
}

}  // namespace trivcon::bench
