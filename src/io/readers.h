// SPDX-License-Identifier: MIT
// src/io/readers.h (internal): the readers of singularity, fixed-direction and field files on a file's
// bytes in memory. The public functions (trivcon/indices.h read_singularities, trivcon/constraints.h
// read_fixed_directions, trivcon/field_io.h read_field) read the whole file with read_file_bytes (gunzipped
// when it ends in .gz) and call these; the fuzz targets (fuzz/) call them directly. `path` names the file in
// messages and, where the format depends on the extension (.sings; .rawfield, .ply), decides the format.
#pragma once
#include <map>
#include <string>

#include "trivcon/common.h"
#include "trivcon/constraints.h"
#include "trivcon/geometry.h"
#include "trivcon/indices.h"
#include "trivcon/topology.h"

namespace trivcon::io {

void read_singularities_from(const std::string& bytes, const std::string& path, IndexPrescription& prescription);

void read_fixed_directions_from(const std::string& bytes, const std::string& path, const Topology& topology, const Geometry& geometry,
                                std::map<int, double>& fixed, const FaceIdMap& face_id = nullptr);

MatrixX3d read_field_from(const std::string& bytes, const std::string& path, int num_faces, int* N_in_file);

}  // namespace trivcon::io
