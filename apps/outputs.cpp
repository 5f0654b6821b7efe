#include "outputs.h"

#include <filesystem>
#include <system_error>

#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/render.h"

namespace trivcon::cli {

std::string output_path(const std::string& path, const std::string& name) {
  if (path.empty() || name.empty()) return path;
  const size_t brace = path.find("{name}");
  if (brace != std::string::npos) return path.substr(0, brace) + name + path.substr(brace + 6);
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return path + "." + name;
  return path.substr(0, dot) + "." + name + path.substr(dot);
}

std::string StagedOutputs::path(const std::string& final_path) {
  // Same folder (so the rename is atomic) and same ending (writers choose the format by extension).
  const std::filesystem::path p(final_path);
  staged_.emplace_back((p.parent_path() / (".trivcon-partial." + p.filename().string())).string(), final_path);
  return staged_.back().first;
}

void StagedOutputs::commit() {
  for (const auto& [temp, final_path] : staged_) {
    std::error_code error;
    std::filesystem::rename(temp, final_path, error);
    if (error) throw Error("cannot write '" + final_path + "': " + error.message());
  }
  staged_.clear();
}

StagedOutputs::~StagedOutputs() {
  for (const auto& [temp, final_path] : staged_) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
  }
}

void stage_design_outputs(StagedOutputs& staged, const OutputPaths& paths, const std::string& name, const MeshData& mesh,
                          const FieldDesigner& designer, const IndexPrescription& prescription, const Design& d) {
  const Geometry& g = designer.geometry();
  if (!paths.field.empty()) write_field(staged.path(output_path(paths.field, name)), mesh.V, mesh.F, g, d.field);
  if (!paths.connection.empty())
    write_connection(staged.path(output_path(paths.connection, name)), designer.topology(), d.connection.x, prescription.N);
  if (!paths.lines.empty()) write_field_lines(staged.path(output_path(paths.lines, name)), mesh.V, mesh.F, g, d.field);
  if (!paths.png.empty()) {  // the prescription's singularities, drawn with the default view of `trivcon render`
    std::vector<std::pair<int, int>> singular(prescription.vertex.begin(), prescription.vertex.end());
    write_png(staged.path(output_path(paths.png, name)), render_field(mesh.V, designer.topology(), g, d.field, singular));
  }
}

}  // namespace trivcon::cli
