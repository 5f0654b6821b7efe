// SPDX-License-Identifier: MIT
#include "prescription_options.h"

#include "trivcon/constraints.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"

namespace trivcon::cli {

void PrescriptionOptions::add_to(CLI::App* cmd, bool with_cycles) {
  N_option = cmd->add_option("-N,--symmetry", N, "Symmetry: 1 vectors, 2 lines, 4 crosses, any N >= 1")->check(CLI::Range(1, 1000));
  files_option = cmd->add_option("-s,--singularities", sing_files,
                                 "Singularity file: 'VERTEX INDEX' per line (INDEX integer or p/q), or Directional's .sings");
  sing_option = cmd->add_option("--sing", sings, "A singular vertex, V:INDEX (e.g. 12:1/4); repeatable");
  if (with_cycles) {
    cmd->add_option("--generator", generators, "Index of generator G (see info --cycles), G:INDEX; repeatable");
    cmd->add_option("--boundary", loops, "Index of boundary loop L (see info --cycles), L:INDEX; repeatable");
  }
}

IndexPrescription PrescriptionOptions::build() const {
  IndexPrescription p;
  p.N = N;
  for (const auto& f : sing_files) read_singularities(f, p);
  for (const auto& s : sings) add_vertex_index(s, p);
  for (const auto& s : generators) add_generator_index(s, p);
  for (const auto& s : loops) add_loop_index(s, p);
  return p;
}

MatrixX3d PrescriptionOptions::read_field_file(const std::string& path, int num_faces, int& N_out) const {
  int file_N = 0;
  MatrixX3d directions = read_field(path, num_faces, &file_N);
  if (N_given() && file_N > 0 && file_N != N_out)
    throw Error("the field file " + path + " holds an N = " + std::to_string(file_N) + " field but -N " + std::to_string(N_out) +
                " was given");
  if (file_N > 0) N_out = file_N;
  return directions;
}

namespace {

// --fix takes "F:x,y,z" / "F:angle=A" specs and files; a spec starts with a face id and a colon.
bool is_fix_spec(const std::string& s) {
  const size_t colon = s.find(':');
  return colon != std::string::npos && colon > 0 && s.find_first_not_of("0123456789") == colon;
}

}  // namespace

void add_fix_options(const std::vector<std::string>& fixes, const Topology& topology, const Geometry& geometry,
                     std::map<int, double>& fixed, const FaceIdMap& face_id) {
  for (const auto& f : fixes) {
    if (is_fix_spec(f))
      add_fixed_direction(f, topology, geometry, fixed, face_id);
    else
      read_fixed_directions(f, topology, geometry, fixed, face_id);
  }
}

}  // namespace trivcon::cli
