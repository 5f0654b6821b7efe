// SPDX-License-Identifier: MIT
// Quads for the faces of the traced graph that are not quads (src/quad/fill.cpp): around the folds a map may
// keep, the traces that fail leave larger faces (QuadMesh::other_faces, usually 6 to 14 sides).
//
// Each face is first rid of its spurs (… a, b, a …: an edge into it and back); two faces with an odd number of
// sides and an edge in common become one without it, when that one has no repeated vertex. Then a face of 2m
// sides v_0 … v_{2m−1} (counter-clockwise, each vertex once) gets one new vertex c, on the input surface at the
// point nearest the mean of its corners, and the m quads (c, v_j, v_{j+1}, v_{j+2}) for j = p, p + 2, …: c has
// valence m (4 for an octagon), and every second corner one edge more. Of the two choices of p, the one giving
// more corners their valence (4 − n at a cone of index n/4, 4 elsewhere) is taken, then the one whose worst new
// corner (the sine of its angle about the quad's normal) is larger. A hexagon is split by a diagonal instead
// (two quads, no new vertex) when that leaves fewer vertices with the wrong valence, or as many and a better
// worst corner. Faces with an odd number of sides, a repeated vertex, or no surface point found stay in
// other_faces; vertices left in no face go. The quad mesh stays closed where it was (the faces replaced are disks
// of the traced graph), with χ unchanged; the valences the fill gives are not the map's, and check_quads reports
// them.
#pragma once
#include "trivcon/design.h"
#include "trivcon/quad.h"

namespace trivcon::quad {

// Fills quads.other_faces as above, appending to V, Q, vertex_face, vertex_barycentric and vertex_cone (−1);
// returns the number of faces filled.
int fill_faces(const FieldDesigner& designer, const Parametrization& param, QuadMesh& quads);

}  // namespace trivcon::quad
