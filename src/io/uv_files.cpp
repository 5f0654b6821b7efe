// SPDX-License-Identifier: MIT
// trivcon/io.h: the (u, v) per corner of an OBJ with texture coordinates (what `param -o` writes, or any OBJ
// whose faces are the mesh's triangles with 'v/vt' corners).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "io/text_lines.h"
#include "io/text_scanner.h"
#include "trivcon/error.h"
#include "trivcon/io.h"

namespace trivcon {

Eigen::MatrixXd read_corner_uv(const std::string& path, const MatrixX3i& F) {
  io::TextLines lines(read_file_bytes(path), path);
  std::vector<Eigen::Vector2d> vt;
  Eigen::MatrixXd out(F.rows(), 6);
  Eigen::Index face = 0;
  while (lines.next()) {
    std::istringstream s(lines.line);
    std::string key;
    s >> key;
    if (key == "vt") {
      std::string a, b;
      s >> a >> b;
      Eigen::Vector2d p;
      if (!io::parse_double(a, p.x()) || !io::parse_double(b, p.y()) || !std::isfinite(p.x()) || !std::isfinite(p.y()))
        throw Error(lines.where() + ": expected 'vt u v' with two finite numbers");
      vt.push_back(p);
    } else if (key == "f") {
      if (face >= F.rows())
        throw Error(lines.where() + ": more faces than the mesh's " + std::to_string(F.rows()) + " triangles");
      std::vector<std::string> corners;
      for (std::string c; s >> c;) corners.push_back(c);
      if (corners.size() != 3) throw Error(lines.where() + ": face " + std::to_string(face) + " is not a triangle");
      for (int k = 0; k < 3; ++k) {
        const size_t slash = corners[k].find('/');
        long long v = 0, t = 0;
        if (slash == std::string::npos || !io::parse_integer(corners[k].substr(0, slash), v))
          throw Error(lines.where() + ": corner '" + corners[k] + "' has no texture coordinate (expected v/vt)");
        const size_t end = corners[k].find('/', slash + 1);
        if (!io::parse_integer(corners[k].substr(slash + 1, end == std::string::npos ? std::string::npos : end - slash - 1), t))
          throw Error(lines.where() + ": corner '" + corners[k] + "' has no texture coordinate (expected v/vt)");
        if (v - 1 != F(face, k))
          throw Error(lines.where() + ": face " + std::to_string(face) + " is not the mesh's (corner " + std::to_string(k) + " is vertex " +
                      std::to_string(v - 1) + ", the mesh has " + std::to_string(F(face, k)) + ")");
        if (t < 1 || t > static_cast<long long>(vt.size()))
          throw Error(lines.where() + ": texture coordinate " + std::to_string(t) + " is not defined before it");
        out(face, 2 * k) = vt[t - 1].x(), out(face, 2 * k + 1) = vt[t - 1].y();
      }
      ++face;
    }
  }
  if (face != F.rows())
    throw Error(path + ": has " + std::to_string(face) + " faces, the mesh " + std::to_string(F.rows()));
  return out;
}

}  // namespace trivcon
