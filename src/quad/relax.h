// SPDX-License-Identifier: MIT
// Moves the vertices of quads that the extraction left inverted or nearly so (src/quad/relax.cpp).
//
// A quad's corner is measured by the sine of its angle about the surface's normal there (the mean of the
// normals of the input faces its four vertices lie in): negative at a reflex corner or when the quad is turned
// over against the surface. The integer points of a fold-free map give such quads where the map is very
// anisotropic (beside a cone, a thin feature) or a quad spans a sharp bend. Vertices of the quads whose worst
// corner is below `threshold` move toward the mean of their neighbours (whole step, half, quarter), each put on
// the nearest point of the input surface around it; a move is kept only when the worst corner of the quads
// around that vertex gets better. Cones, vertices on aligned input edges and on the quad mesh's boundary, and
// vertices of faces that are not quads stay. The mesh's connectivity is never changed.
#pragma once
#include "trivcon/design.h"
#include "trivcon/quad.h"

namespace trivcon::quad {

// `param`: the map the quads were extracted from (its cones and aligned edges stay where they are). Updates
// quads.V, vertex_face, vertex_barycentric and vertex_cone; returns the number of vertices moved.
int relax_quads(const FieldDesigner& designer, const Parametrization& param, QuadMesh& quads, double threshold = 0.2, int sweeps = 20);

}  // namespace trivcon::quad
