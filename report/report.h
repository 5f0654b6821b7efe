// SPDX-License-Identifier: MIT
// The JSON report of one `solve` design (--report; documented in docs/reference/report.md).
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "trivcon/design.h"
#include "trivcon/io.h"
#include "trivcon/param.h"
#include "trivcon/quad.h"

namespace trivcon::cli {

// What the report says about the run beside the design itself.
struct ReportRun {
  std::string mesh_path, name;  // name: the batch item's, or "" for a single solve
  std::string weights, solver;  // as given on the command line
  bool align_boundary = false;
  double read_seconds = 0, write_seconds = 0;
  bool verified = false;
};

nlohmann::ordered_json solve_report(const ReportRun& run, const MeshData& mesh, const FieldDesigner& designer,
                                    const IndexPrescription& prescription, const Design& d);

// The "param" entry of `param`'s and `quad`'s reports: the map's size, its integers, what it promises
// checked on the result (ParamQuality) and the time per stage.
nlohmann::ordered_json param_report(const Parametrization& param);

// The "quad" entry of `quad`'s report (and of Python's QuadMesh.quality, the editor's quads view): the quad
// mesh's size, every guarantee checked on it (QuadQuality), what the extraction met, the time per stage.
nlohmann::ordered_json quad_report(const QuadMesh& quads);

}  // namespace trivcon::cli
