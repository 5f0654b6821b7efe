// SPDX-License-Identifier: MIT
// trivcon/render.h: pictures of a field on its surface, rendered in software to a PNG (no display, no GPU).
//
// Typical use, after a design (this is all `trivcon solve --png` needs):
//
//   trivcon::FieldDesigner designer(V, F);
//   trivcon::Design d = designer.design(prescription);
//   trivcon::RenderOptions o;                      // 1200×900, hedgehog, view (30°, 20°), y up
//   trivcon::write_png("field.png", trivcon::render_design(designer, d, o));
//
// or, with the pieces at hand (e.g. a field read from a file):
//   trivcon::write_png(path, trivcon::render_field(V, topology, geometry, field, singularities, o));
//
// Conventions
// - Camera: perspective, looking at the mesh from azimuth/elevation (degrees). With up axis U (default +y)
//   and front axis F (+z for y up, −y for z up, +z for x up), the eye lies in direction
//   cos(el)·(cos(az)·F + sin(az)·(U × F)) + sin(el)·U from the centre of the bounding box; azimuth 0,
//   elevation 0 looks along −F. The view is then framed so that the projected mesh fills the image minus a
//   4% margin, centred. Only vertices used by faces count.
// - Pixels: (x, y) with x to the right and y down from the top-left corner; pixel (i, j) covers
//   [i, i+1) × [j, j+1). Camera::project returns continuous image coordinates in that system plus the depth
//   along the viewing direction (world units).
// - Image: 8-bit sRGB values, 3 bytes per pixel, rows top to bottom.
// - Shading: two-sided Lambert + ambient from a light above-left of the camera; smooth (area-weighted vertex
//   normals) or flat per face. Faces seen from the front (their normal, as oriented by trivcon/topology.h,
//   points at the eye) are blue-grey, faces seen from behind are orange: a closed mesh shows no orange unless
//   it is inside out. Background white.
// - Field: `hedgehog` draws, from the centroid of each face, the field's N directions as tapered segments
//   (thick at the base, so N = 1 shows its orientation), each 0.4 × the distance between neighbouring face
//   centroids (≈ 0.23 × the face's mean edge length; N = 1: 1.5 × that). When neighbouring centroids are
//   closer on screen than `glyph_spacing` pixels, glyphs go on an evenly spaced deterministic subset instead
//   (trivcon::sample_surface), each spoke 0.4 × the spacing. `streamlines` draws trivcon::trace_streamlines
//   with separation `glyph_spacing` pixels. Pixel distances are measured at the depth of the mesh's centre.
//   Field lines fade toward the surface colour where the surface is seen edge-on.
// - Lines are drawn into a supersampled image (anti-aliasing) and depth-tested against the surface with a
//   small offset toward the viewer, so lines on the visible surface show and lines behind it do not.
// - Singular vertices: discs, red for positive and blue for negative indices, radius growing with |index|
//   (radius 9 pixels for index ±1, scaled by √|index|, at least 6), drawn when the vertex is visible. A legend
//   lists N and the indices present, in the image corner where it hides the least of the surface (lower left
//   on ties). Boundary loops: green lines. Sharp (feature) edges given in RenderOptions::sharp_edges
//   (trivcon/features.h): magenta lines of the same width, with a legend row.
// - Checkerboard (corner_uv): squares with floor(u) + floor(v) odd take Palette::checker instead of the front colour.
// - Sizes in pixels scale with the image's smaller side (the values below are for 900 pixels).
// - Deterministic: identical inputs give identical pixels and bytes (single thread, no clocks, no
//   uninitialised memory).
#pragma once
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/design.h"
#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/streamlines.h"
#include "trivcon/topology.h"

namespace trivcon {

using Rgb = std::array<std::uint8_t, 3>;

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width × height × 3, rows top to bottom
  Rgb pixel(int x, int y) const {
    const size_t i = 3 * (static_cast<size_t>(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

enum class FieldStyle { Hedgehog, Streamlines };

// The colours the renderer uses (exposed so callers and tests can recognise them).
struct Palette {
  Rgb background{255, 255, 255};
  Rgb front{196, 206, 222};  // surface seen from the front, before shading
  Rgb back{240, 170, 90};    // surface seen from behind, before shading
  Rgb field{22, 28, 48};     // hedgehog glyphs and streamlines
  Rgb boundary{30, 150, 60};
  Rgb sharp{200, 40, 170};    // feature edges (RenderOptions::sharp_edges)
  Rgb polygon{35, 35, 40};    // the file's polygon edges (RenderOptions::polygon_edges), e.g. a quad mesh's
  Rgb positive{215, 35, 35};  // singularity with index > 0
  Rgb negative{30, 80, 215};  // index < 0
  Rgb text{40, 40, 40};
  Rgb checker{120, 140, 175};  // the darker squares of a (u, v) checkerboard (RenderOptions::corner_uv)
};

struct RenderOptions {
  int width = 1200, height = 900;
  double azimuth = 30, elevation = 20;  // degrees, see above
  char up = 'y';                        // 'x', 'y' or 'z': the world axis that points up in the picture
  FieldStyle style = FieldStyle::Hedgehog;
  double glyph_spacing = 11;  // pixels between glyphs or streamlines (at 900 pixels; scaled with the image)
  bool smooth_shading = true;
  bool legend = true;
  std::vector<int> sharp_edges;  // edge ids (trivcon/topology.h) drawn as feature lines; empty: none
  std::vector<int> polygon_edges;  // edge ids drawn thin and dark: the edges of the file's polygons (polygon_edges below)
  int supersampling = 3;         // samples per pixel along each axis (anti-aliasing)
  // Empty, or F × 6: (u, v) of corners 0, 1, 2 of each face of Topology::F (trivcon/param.h). The surface is then
  // a checkerboard of unit squares of (u, v), interpolated perspective-correctly: the grid of a seamless map.
  Eigen::MatrixXd corner_uv;
  bool draw_field = true;  // false: the surface (and checkerboard) only, no glyphs or streamlines
  Palette palette;
};

struct Camera {
  Eigen::Vector3d eye, right, up, forward;  // orthonormal; forward points from the eye into the scene
  double focal = 1;                         // pixels
  double cx = 0, cy = 0;                    // image position of the optical axis
  // (x, y, depth): image coordinates in pixels and the distance along `forward`.
  Eigen::Vector3d project(const Eigen::Vector3d& p) const;
  // World size of one pixel at `depth`.
  double pixel_size(double depth) const { return depth / focal; }
};

// The camera render_field uses for these options (framing the used vertices of V).
Camera fit_camera(const MatrixX3d& V, const Topology& topology, const RenderOptions& options);

// Renders the surface with the field. `singularities` are (vertex, n) pairs meaning index n/N
// (trivcon/indices.h), e.g. the prescription's vertices or singular_vertices(field_indices(...)).
Image render_field(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const Field& field,
                   const std::vector<std::pair<int, int>>& singularities, const RenderOptions& options = {});
// The same with streamlines traced by the caller (drawn whatever options.style says), e.g. to also save them.
Image render_field(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const Field& field,
                   const std::vector<std::pair<int, int>>& singularities, const std::vector<Streamline>& streamlines,
                   const RenderOptions& options);
// A design's field with the singularities read back from it (Design::indices).
Image render_design(const FieldDesigner& designer, const Design& design, const RenderOptions& options = {});

// The streamline options render_field uses for the streamline style (separation from glyph_spacing).
StreamlineOptions render_streamline_options(const MatrixX3d& V, const Topology& topology, const RenderOptions& options);

// (vertex, n) for every vertex with a nonzero index in `vertex_indices` (e.g. FieldIndices::vertex).
std::vector<std::pair<int, int>> singular_vertices(const std::vector<int>& vertex_indices);

// Writes an 8-bit RGB PNG atomically (trivcon/io.h); errors are trivcon::Error naming the path.
void write_png(const std::string& path, const Image& image);

// The edges of a fanned mesh that are edges of the file's polygons (boundary edges, and interior edges between
// triangles of two different polygons; not the diagonals the fanning added): what a quad mesh's picture draws.
// polygon_of_triangle: MeshData's (empty: every triangle its own polygon).
std::vector<int> polygon_edges(const Topology& topology, const std::vector<int>& polygon_of_triangle);

}  // namespace trivcon
