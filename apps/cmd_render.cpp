// SPDX-License-Identifier: MIT
// trivcon render MESH (--field F | --uv P.obj) -o picture.png [options]: a picture of a field and/or of a map's
// checkerboard (trivcon/render.h).
#include <iostream>
#include <tuple>

#include "commands.h"
#include "feature_options.h"
#include "trivcon/cycles.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/indices.h"
#include "trivcon/render.h"

namespace trivcon::cli {

namespace {

struct RenderCommand {
  std::string mesh, field, uv, output, size = "1200x900", view = "30,20", style = "hedgehog", up = "y", streamlines_out;
  int N = 0;  // 0: the field file's
  std::vector<std::string> sing_files, sings;
  double spacing = 11;
  bool flat = false, no_legend = false;
  MeshOptions mesh_options;  // --no-repair, --weld
  FeatureOptions features;  // sharp edges to draw
  bool polygon_edges = false;  // --polygon-edges
};

// Two numbers separated by `separator` ("1200x900", "30,20"), each parsed whole by `parse` (std::stoi,
// std::stod); anything else is `error`.
template <typename T, typename Parse>
std::pair<T, T> parse_pair(const std::string& text, char separator, Parse parse, const std::string& error) {
  const size_t at = text.find(separator);
  try {
    size_t end_a = 0, end_b = 0;
    if (at == std::string::npos) throw std::invalid_argument(text);
    const T a = parse(text.substr(0, at), &end_a), b = parse(text.substr(at + 1), &end_b);
    if (end_a != at || end_b != text.size() - at - 1) throw std::invalid_argument(text);
    return {a, b};
  } catch (const std::logic_error&) {
    throw Error(error);
  }
}

// "WxH" → (W, H).
void parse_size(const std::string& text, RenderOptions& o) {
  std::tie(o.width, o.height) = parse_pair<int>(
      text, 'x', [](const std::string& s, size_t* end) { return std::stoi(s, end); },
      "--size " + text + ": expected WIDTHxHEIGHT, e.g. 1200x900");
}

// "AZ,EL" in degrees.
void parse_view(const std::string& text, RenderOptions& o) {
  std::tie(o.azimuth, o.elevation) = parse_pair<double>(
      text, ',', [](const std::string& s, size_t* end) { return std::stod(s, end); },
      "--view " + text + ": expected AZIMUTH,ELEVATION in degrees, e.g. 30,20");
}

void run_render(const RenderCommand& c) {
  const LoadedMesh loaded = load_mesh(c.mesh, c.mesh_options, false);
  const MeshData& mesh = loaded.mesh;
  const RepairedMesh* repair = loaded.repaired();
  check_finite(mesh.V);
  const Topology t = build_topology(mesh.F, static_cast<int>(mesh.V.rows()));
  check_coordinate_range(mesh.V, t);
  const Geometry g = compute_geometry(mesh.V, t);
  int file_N = 0;
  // Without --field (a checkerboard of --uv alone): a zero field, not drawn.
  const MatrixX3d directions = c.field.empty() ? MatrixX3d(g.frame_x)
                                               : rows_on_mesh(loaded, read_field(c.field, loaded.input_faces(), &file_N));
  // N: given, else the field file's, else 4 for a map alone (a map is of a cross field: its singularity files say
  // 1/4), else 1.
  const int N = c.N > 0 ? c.N : file_N > 0 ? file_N : c.field.empty() && !c.uv.empty() ? 4 : 1;
  const Field field = field_from_directions(g, directions, N);

  std::vector<std::pair<int, int>> singularities;
  if (c.sing_files.empty() && c.sings.empty()) {
    if (c.field.empty()) {}  // nothing to mark
    else
    // Nothing given: mark where the field itself is singular.
    singularities = singular_vertices(field_indices(t, g, compute_cycles(t), field).vertex);
  } else {
    IndexPrescription p;
    p.N = N;
    for (const std::string& f : c.sing_files) read_singularities(f, p);
    for (const std::string& s : c.sings) add_vertex_index(s, p);
    for (const auto& [input_v, n] : p.vertex) {
      const int v = repair ? repaired_vertex(*repair, input_v, "singular vertex") : input_v;
      if (v < 0 || v >= t.num_vertices)
        throw Error("singular vertex " + std::to_string(v) + " out of range (mesh has " + std::to_string(t.num_vertices) + " vertices)");
      singularities.emplace_back(v, n);
    }
  }

  RenderOptions o;
  parse_size(c.size, o);
  parse_view(c.view, o);
  o.up = c.up[0];
  o.style = c.style == "streamlines" ? FieldStyle::Streamlines : FieldStyle::Hedgehog;
  o.glyph_spacing = c.spacing;
  o.smooth_shading = !c.flat;
  o.legend = !c.no_legend;
  o.sharp_edges = c.features.edges(mesh.V, t, g);
  if (c.polygon_edges) o.polygon_edges = polygon_edges(t, mesh.polygon_of_triangle);
  if (!c.uv.empty()) {  // the file's corners in the input's order, the renderer's in the topology's
    // The file has the input's faces; on a repaired mesh each face reads its input face's corners.
    const Eigen::MatrixXd input =
        repair ? corner_rows_on_repaired(*repair, read_corner_uv(c.uv, loaded.input.F)) : read_corner_uv(c.uv, mesh.F);
    o.corner_uv.resize(t.num_faces, 6);
    for (int f = 0; f < t.num_faces; ++f)
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
          if (mesh.F(f, j) == t.F(f, k)) o.corner_uv(f, 2 * k) = input(f, 2 * j), o.corner_uv(f, 2 * k + 1) = input(f, 2 * j + 1);
  }
  if (c.field.empty()) o.draw_field = false, o.legend = o.legend && !singularities.empty();
  if (o.style == FieldStyle::Streamlines || !c.streamlines_out.empty()) {
    const std::vector<Streamline> lines = trace_streamlines(mesh.V, t, g, field, singularities, render_streamline_options(mesh.V, t, o));
    if (!c.streamlines_out.empty()) write_streamlines_obj(c.streamlines_out, lines);
    if (o.style == FieldStyle::Streamlines) {
      write_png(c.output, render_field(mesh.V, t, g, field, singularities, lines, o));
      return;
    }
  }
  write_png(c.output, render_field(mesh.V, t, g, field, singularities, o));
}

}  // namespace

void register_render(CLI::App& app) {
  static RenderCommand c;
  auto* cmd = app.add_subcommand("render", "Draw a field on its surface to a PNG (hedgehog glyphs or streamlines)");
  cmd->add_option("mesh", c.mesh, "Mesh file: .obj .off .ply .stl .gltf .glb, optionally .gz")->required();
  auto* field = cmd->add_option("--field", c.field, "Field: trivcon's .txt or .ply, Directional's .rawfield or QuadWild's .rosy");
  auto* uv = cmd->add_option("--uv", c.uv,
                             "OBJ with (u, v) per corner (trivcon param -o): draw its unit squares as a checkerboard on the surface");

  cmd->add_option("-o,--output", c.output, "PNG to write")->required();
  cmd->add_option("-N,--symmetry", c.N, "Symmetry N (default: the field file's; 4 with --uv and no --field)")->check(CLI::Range(1, 1000));
  cmd->add_option("-s,--singularities", c.sing_files, "Singularity file to mark (default: the field's own singular vertices)");
  cmd->add_option("--sing", c.sings, "A singular vertex to mark, V:INDEX; repeatable");
  cmd->add_option("--size", c.size, "Image size WIDTHxHEIGHT (default 1200x900)");
  cmd->add_option("--view", c.view, "View direction AZIMUTH,ELEVATION in degrees (default 30,20)");
  cmd->add_option("--up", c.up, "World axis pointing up in the picture: x, y (default) or z")->check(CLI::IsMember({"x", "y", "z"}));
  cmd->add_option("--style", c.style, "hedgehog (default) or streamlines")->check(CLI::IsMember({"hedgehog", "streamlines"}));
  cmd->add_option("--spacing", c.spacing, "Pixels between glyphs or streamlines (default 11, for 900 pixels)")->check(CLI::PositiveNumber);
  cmd->add_option("--streamlines-out", c.streamlines_out, "Also write the streamlines as OBJ polylines");
  cmd->add_flag("--flat", c.flat, "Flat shading (one normal per face)");
  cmd->add_flag("--no-legend", c.no_legend, "Leave out the legend");
  auto* polygons = cmd->add_flag("--polygon-edges", c.polygon_edges,
                                 "Draw the edges of the file's polygons (not the diagonals of their fans): a quad mesh's quads (trivcon quad -o)");
  add_mesh_options(cmd, c.mesh_options);
  c.features.add_to(cmd, "drawn as lines");
  cmd->callback([field, uv, polygons] {
    if (field->count() == 0 && uv->count() == 0 && polygons->count() == 0) throw CLI::RequiredError("--field, --uv or --polygon-edges");
    run_render(c);
  });
}

}  // namespace trivcon::cli
