// SPDX-License-Identifier: MIT
// The files `solve` writes after a design. They appear together or not at all: each is written
// (atomically) beside its final path under a temporary name, and all are renamed into place once every
// one was written.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/design.h"
#include "trivcon/io.h"
#include "trivcon/repair.h"

namespace trivcon::cli {

// The output paths given on the command line; an empty one is not written.
struct OutputPaths {
  std::string field, connection, lines, report, png, singularities, matching;  // singularities: --sing-out, matching: --matching-out
  std::string mesh;                                                            // --mesh-out: the mesh the field belongs to (.ply or .obj)
  std::string sharp;                                                           // --sharp-out: QuadWild .sharp of the sharp edges
};

// Output paths for one prescription of a batch: "{name}" in a path is replaced by the item's name;
// without it, ".NAME" goes before the extension (field.txt → field.NAME.txt). Single solves keep paths.
std::string output_path(const std::string& path, const std::string& name);

class StagedOutputs {
 public:
  // Calls writer(temporary) for `final_path`; an error it throws names final_path, not the temporary.
  void write(const std::string& final_path, const std::function<void(const std::string&)>& writer);
  // Renames every staged file into place; throws trivcon::Error naming a file that cannot be.
  void commit();
  // Removes the staged files not committed.
  ~StagedOutputs();

 private:
  std::vector<std::pair<std::string, std::string>> staged_;  // (temporary, final path)
};

// Stages the field, connection, lines, sharp edges (`sharp`: edge ids, trivcon/features.h; also drawn in
// the picture) and picture of design `d` of `prescription` (item `name` of a batch, or ""); the report is
// staged by its caller.
// With `repair` (the design is on that repair of `input`), per-face and per-vertex outputs are the input's: a field
// row per input face (a duplicate's that of the face it duplicates), singularities and .sharp faces by input ids;
// --mesh-out writes the repaired mesh, and the connection and matching (edges by vertex pairs) are that mesh's.
// `corners` (FeatureAlignment::corners) are written with the singularities: -s reads a boundary vertex as a corner.
void stage_design_outputs(StagedOutputs& staged, const OutputPaths& paths, const std::string& name, const MeshData& mesh,
                          const FieldDesigner& designer, const IndexPrescription& prescription, const Design& d,
                          const std::vector<int>& sharp = {}, const RepairedMesh* repair = nullptr, const MeshData* input = nullptr,
                          const std::map<int, int>& corners = {});

// A prescription's singular vertices by the input's ids (copies made by repair named by the vertex they copy).
std::map<int, int> input_singularities(const std::map<int, int>& vertex, const RepairedMesh* repair);

}  // namespace trivcon::cli
