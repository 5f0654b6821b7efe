// SPDX-License-Identifier: MIT
#include "outputs.h"

#include "trivcon/matching.h"

#include <filesystem>
#include <functional>
#include <system_error>

#include "trivcon/error.h"
#include "trivcon/features.h"
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

void StagedOutputs::write(const std::string& final_path, const std::function<void(const std::string&)>& writer) {
  // Same folder (so the rename is atomic) and same ending (writers choose the format by extension).
  const std::filesystem::path p(final_path);
  const std::string temp = (p.parent_path() / (".trivcon-partial." + p.filename().string())).string();
  staged_.emplace_back(temp, final_path);
  try {
    writer(temp);
  } catch (const Error& e) {  // the user named final_path, not our temporary
    std::string message = e.what();
    for (size_t at = message.find(temp); at != std::string::npos; at = message.find(temp, at + final_path.size()))
      message.replace(at, temp.size(), final_path);
    throw Error(message);
  }
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
                          const FieldDesigner& designer, const IndexPrescription& prescription, const Design& d,
                          const std::vector<int>& sharp, const RepairedMesh* repair, const MeshData* input,
                          const std::map<int, int>& corners) {
  const Geometry& g = designer.geometry();
  if (!paths.field.empty())
    staged.write(output_path(paths.field, name), [&](const std::string& path) {
      if (repair)
        write_field(path, input->V, input->F, g, d.field, repair->face_of_input);
      else
        write_field(path, mesh.V, mesh.F, g, d.field);
    });
  if (!paths.connection.empty())
    staged.write(output_path(paths.connection, name),
                 [&](const std::string& path) { write_connection(path, designer.topology(), d.connection.x, prescription.N); });
  if (!paths.mesh.empty())
    staged.write(output_path(paths.mesh, name), [&](const std::string& path) {
      const std::string& final_path = paths.mesh;
      const bool ply = final_path.size() >= 4 && final_path.compare(final_path.size() - 4, 4, ".ply") == 0;
      if (ply)
        write_ply(path, mesh.V, mesh.F);
      else
        write_obj(path, mesh.V, mesh.F);
    });
  if (!paths.matching.empty())
    staged.write(output_path(paths.matching, name), [&](const std::string& path) {
      write_matching(path, designer.topology(), connection_matching(designer.topology(), g, d.field, d.connection.x), prescription.N);
    });
  if (!paths.lines.empty())
    staged.write(output_path(paths.lines, name), [&](const std::string& path) { write_field_lines(path, mesh.V, mesh.F, g, d.field); });
  if (!paths.singularities.empty())
    staged.write(output_path(paths.singularities, name),
                 [&](const std::string& path) {
                   write_singularities(path, input_singularities(with_corners(prescription.vertex, corners), repair), prescription.N);
                 });
  if (!paths.sharp.empty())
    staged.write(output_path(paths.sharp, name), [&](const std::string& path) {
      std::vector<char> convex;
      for (int e : sharp) convex.push_back(is_convex_edge(designer.V(), designer.topology(), g, e));
      write_sharp(path, mesh.F, designer.topology(), sharp, convex, repair ? repair->input_face : std::vector<int>{});
    });
  if (!paths.png.empty()) {  // the prescription's singularities, drawn with the default view of `trivcon render`
    std::vector<std::pair<int, int>> singular(prescription.vertex.begin(), prescription.vertex.end());
    RenderOptions ro;
    ro.sharp_edges = sharp;
    staged.write(output_path(paths.png, name),
                 [&](const std::string& path) { write_png(path, render_field(mesh.V, designer.topology(), g, d.field, singular, ro)); });
  }
}

std::map<int, int> input_singularities(const std::map<int, int>& vertex, const RepairedMesh* repair) {
  return repair ? values_on_input(*repair, vertex) : vertex;
}

}  // namespace trivcon::cli
