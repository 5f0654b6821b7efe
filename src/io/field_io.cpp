// SPDX-License-Identifier: MIT
#include "trivcon/field_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <iterator>
#include <sstream>
#include <string_view>

#include "io/readers.h"
#include "io/text_lines.h"
#include "io/text_scanner.h"
#include "trivcon/error.h"

namespace trivcon {

namespace {

constexpr int kMaxFieldN = 1000;  // the largest N a field file may state (as -N)

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The N unit directions of face f, counter-clockwise.
Eigen::Vector3d direction_k(const Geometry& g, const Field& field, int f, int k) {
  return g.direction_in_face(f, field.angle(f) + 2 * kPi * k / field.N);
}

void put_double(std::ostream& out, double v) { out.write(reinterpret_cast<const char*>(&v), sizeof v); }

using io::TextLines;

std::vector<double> parse_numbers(const TextLines& lines, size_t expected) {
  std::istringstream fields(lines.line);
  std::vector<double> values;
  std::string token;
  while (fields >> token) {
    double v = 0;
    if (!io::parse_double(token, v) || !std::isfinite(v)) throw Error(lines.where() + ": malformed number '" + token + "'");
    values.push_back(v);
  }
  if (values.size() != expected)
    throw Error(lines.where() + ": expected " + std::to_string(expected) + " numbers, got " + std::to_string(values.size()));
  return values;
}

// The header write_field gives a field PLY, line by line ('#' stands for the vertex and face counts);
// comment lines may come anywhere after the first.
constexpr const char* kFieldPlyHeader[] = {"ply",
                                           "format binary_little_endian 1.0",
                                           "element vertex #",
                                           "property double x",
                                           "property double y",
                                           "property double z",
                                           "element face #",
                                           "property list uchar int vertex_indices",
                                           "property double fx",
                                           "property double fy",
                                           "property double fz",
                                           "end_header"};

MatrixX3d read_field_ply(const std::string& bytes, const std::string& path, int num_faces) {
  const std::string not_ours = path + ": not a field PLY written by trivcon (expected face properties fx fy fz after vertex_indices)";
  long long counts[2] = {-1, -1};  // vertices, faces
  std::size_t pos = 0, expected = 0, count_index = 0;
  while (expected < std::size(kFieldPlyHeader)) {
    const std::size_t newline = bytes.find('\n', pos);
    if (newline == std::string::npos) throw Error(not_ours);
    const std::string_view line(bytes.data() + pos, newline - pos);
    pos = newline + 1;
    if (expected > 0 && line.substr(0, 8) == "comment ") continue;
    const std::string_view want = kFieldPlyHeader[expected++];
    const std::size_t hash = want.find('#');
    if (hash == std::string_view::npos) {
      if (line != want) throw Error(not_ours);
      continue;
    }
    long long& count = counts[count_index++];
    if (line.substr(0, hash) != want.substr(0, hash) || !io::parse_integer(line.substr(hash), count) || count < 0)
      throw Error(not_ours);
  }
  const long long nv = counts[0], nf = counts[1];
  if (nf != num_faces) throw Error(path + ": has " + std::to_string(nf) + " faces, the mesh has " + std::to_string(num_faces));
  // The vertices are skipped, not read: a claim beyond the file is caught before the faces are looked at.
  const std::size_t after_header = bytes.size() - pos;
  if (static_cast<unsigned long long>(nv) > after_header / 24)
    throw Error(path + ": header claims " + std::to_string(nv) + " vertices, but the file has only " + std::to_string(after_header) +
                " bytes after the header (a vertex needs 24)");
  pos += static_cast<std::size_t>(nv) * 24;
  MatrixX3d d(num_faces, 3);
  for (int f = 0; f < num_faces; ++f) {
    if (pos >= bytes.size()) throw Error(path + ": truncated at byte " + std::to_string(pos) + " (face " + std::to_string(f) + ")");
    const size_t count = static_cast<unsigned char>(bytes[pos]);
    pos += 1 + 4 * count;
    if (pos > bytes.size() || bytes.size() - pos < 24)  // pos: where the direction would start
      throw Error(path + ": truncated at byte " + std::to_string(pos) + " (face " + std::to_string(f) + ")");
    double v[3];
    std::memcpy(v, bytes.data() + pos, 24);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))  // as the text formats
      throw Error(path + ": non-finite direction in face " + std::to_string(f) + " (at byte " + std::to_string(pos) + ")");
    pos += 24;
    d.row(f) << v[0], v[1], v[2];
  }
  return d;
}

// "# N <n>" among the leading comments of a field text file: n, 0 when there is none. Only a whole integer
// counts (other "# N ..." lines are comments); it must be a valid symmetry, 1 to 1000 like -N.
int field_text_N(const std::string& bytes, const std::string& path) {
  int N = 0;
  std::size_t pos = 0;
  for (int line_no = 1; pos < bytes.size() && bytes[pos] == '#'; ++line_no) {
    const std::size_t newline = std::min(bytes.find('\n', pos), bytes.size());
    std::string_view line(bytes.data() + pos, newline - pos);
    pos = newline + 1;
    if (line.substr(0, 4) != "# N ") continue;
    line.remove_prefix(4);
    while (!line.empty() && io::is_space(line.back())) line.remove_suffix(1);
    while (!line.empty() && io::is_space(line.front())) line.remove_prefix(1);
    long long n;
    if (!io::parse_integer(line, n)) continue;
    if (n < 1 || n > kMaxFieldN)
      throw Error(path + ":" + std::to_string(line_no) + ": N " + std::to_string(n) + " out of range (1 to " + std::to_string(kMaxFieldN) +
                  ")");
    N = static_cast<int>(n);
  }
  return N;
}

}  // namespace

void write_field_to(std::ostream& out, const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Geometry& g,
                    const Field& field, const std::vector<int>& face_of_row) {
  const int nF = static_cast<int>(F.rows());
  if (!face_of_row.empty() && face_of_row.size() != static_cast<size_t>(nF))
    throw Error("write_field: " + std::to_string(face_of_row.size()) + " face ids for " + std::to_string(nF) + " faces");
  // The k-th direction of row f.
  const auto direction_k = [&](const Geometry& g, const Field& field, int f, int k) -> Eigen::Vector3d {
    const int face = face_of_row.empty() ? f : face_of_row[f];
    return face < 0 ? Eigen::Vector3d::Zero() : trivcon::direction_k(g, field, face, k);
  };
  if (ends_with(path, ".rawfield")) {
    out << std::setprecision(17) << field.N << " " << nF << "\n";
    for (int f = 0; f < nF; ++f) {
      for (int k = 0; k < field.N; ++k) {
        const Eigen::Vector3d d = direction_k(g, field, f, k);
        out << (k ? " " : "") << d.x() << " " << d.y() << " " << d.z();
      }
      out << "\n";
    }
  } else if (ends_with(path, ".rosy")) {
    // QuadWild reads 4-RoSy fields only (vcglib's Load4ROSY): another N would be misread, not rejected.
    if (field.N != 4)
      throw Error(path + ": a .rosy file holds a 4-direction field (QuadWild's format), this field has N = " + std::to_string(field.N));
    out << nF << "\n" << field.N << "\n" << std::setprecision(17);
    for (int f = 0; f < nF; ++f) {
      const Eigen::Vector3d d = direction_k(g, field, f, 0);
      out << d.x() << " " << d.y() << " " << d.z() << "\n";
    }
  } else if (ends_with(path, ".ply")) {
    out << "ply\nformat binary_little_endian 1.0\ncomment trivcon field, N " << field.N << "\nelement vertex " << V.rows()
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << nF
        << "\nproperty list uchar int vertex_indices\nproperty double fx\nproperty double fy\nproperty double fz\nend_header\n";
    for (int v = 0; v < V.rows(); ++v)
      for (int k = 0; k < 3; ++k) put_double(out, V(v, k));
    for (int f = 0; f < nF; ++f) {
      out.put(3);
      for (int k = 0; k < 3; ++k) {
        const int32_t id = F(f, k);
        out.write(reinterpret_cast<const char*>(&id), 4);
      }
      const Eigen::Vector3d d = direction_k(g, field, f, 0);
      for (int k = 0; k < 3; ++k) put_double(out, d(k));
    }
  } else {
    out << "# trivcon field: per face, the first of N unit directions (x y z, world coordinates)\n# N " << field.N << "\n# faces " << nF
        << "\n"
        << std::setprecision(17);
    for (int f = 0; f < nF; ++f) {
      const Eigen::Vector3d d = direction_k(g, field, f, 0);
      out << d.x() << " " << d.y() << " " << d.z() << "\n";
    }
  }
}

void write_field(const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Geometry& g, const Field& field,
                 const std::vector<int>& face_of_row) {
  write_file_atomically(path, [&](std::ostream& out) { write_field_to(out, path, V, F, g, field, face_of_row); });
}

MatrixX3d read_field(const std::string& path, int num_faces, int* N_in_file) {
  return io::read_field_from(read_file_bytes(path), path, num_faces, N_in_file);
}

MatrixX3d io::read_field_from(const std::string& bytes, const std::string& path, int num_faces, int* N_in_file) {
  if (N_in_file) *N_in_file = 0;
  if (ends_with(path, ".ply")) return read_field_ply(bytes, path, num_faces);
  MatrixX3d d(num_faces, 3);
  if (ends_with(path, ".rawfield")) {
    TextLines lines(bytes, path);
    if (!lines.next()) throw Error(path + ": empty file (expected the header 'N F')");
    const std::vector<double> header = parse_numbers(lines, 2);
    // Compared as doubles: a header value need not fit an int (converting it first would be undefined).
    if (!(header[0] >= 1 && header[0] <= kMaxFieldN) || header[0] != std::floor(header[0]))
      throw Error(lines.where() + ": malformed N in the header");
    const int N = static_cast<int>(header[0]);
    if (header[1] != num_faces) {
      std::ostringstream claimed;
      claimed << std::setprecision(15) << header[1];  // integers below 10^15 print as written
      throw Error(lines.where() + ": the field has " + claimed.str() + " faces, the mesh has " + std::to_string(num_faces));
    }
    if (N_in_file) *N_in_file = N;
    for (int f = 0; f < num_faces; ++f) {
      if (!lines.next()) throw Error(path + ": truncated after line " + std::to_string(lines.number) + " (face " + std::to_string(f) + ")");
      const std::vector<double> v = parse_numbers(lines, 3 * N);
      d.row(f) << v[0], v[1], v[2];
    }
    if (lines.next()) throw Error(lines.where() + ": more lines than faces");
    return d;
  }
  if (ends_with(path, ".rosy")) {  // QuadWild: the face count, N, then "x y z" per face
    TextLines lines(bytes, path);
    if (!lines.next()) throw Error(path + ": empty file (expected the face count on the first line)");
    const double count = parse_numbers(lines, 1)[0];
    if (count != num_faces) {
      std::ostringstream claimed;
      claimed << std::setprecision(15) << count;
      throw Error(lines.where() + ": the field has " + claimed.str() + " faces, the mesh has " + std::to_string(num_faces));
    }
    if (!lines.next()) throw Error(path + ": ends after the face count (expected N on the second line)");
    const double N = parse_numbers(lines, 1)[0];
    if (!(N >= 1 && N <= kMaxFieldN) || N != std::floor(N))
      throw Error(lines.where() + ": malformed N (expected a whole number, 4 for QuadWild)");
    if (N_in_file) *N_in_file = static_cast<int>(N);
    for (int f = 0; f < num_faces; ++f) {
      if (!lines.next()) throw Error(path + ": truncated after line " + std::to_string(lines.number) + " (face " + std::to_string(f) + ")");
      const std::vector<double> v = parse_numbers(lines, 3);
      d.row(f) << v[0], v[1], v[2];
    }
    if (lines.next()) throw Error(lines.where() + ": more lines than faces");
    return d;
  }
  // Text: "# N n" among the leading comments.
  const int N = field_text_N(bytes, path);
  if (N_in_file) *N_in_file = N;
  TextLines lines(bytes, path);
  for (int f = 0; f < num_faces; ++f) {
    if (!lines.next())
      throw Error(path + ": has " + std::to_string(f) + " directions, the mesh has " + std::to_string(num_faces) + " faces");
    const std::vector<double> v = parse_numbers(lines, 3);
    d.row(f) << v[0], v[1], v[2];
  }
  if (lines.next()) throw Error(lines.where() + ": more lines than the mesh has faces (" + std::to_string(num_faces) + ")");
  return d;
}

void write_connection(const std::string& path, const Topology& t, const Eigen::VectorXd& x, int N) {
  std::vector<int> order;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e)) order.push_back(e);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::make_pair(t.edge_vertices(a, 0), t.edge_vertices(a, 1)) < std::make_pair(t.edge_vertices(b, 0), t.edge_vertices(b, 1));
  });
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# trivcon connection: per interior edge i < j, the adjustment angle x (radians); a direction at angle b in\n"
           "# the face holding half-edge i->j is carried to b + rho - x in the other face\n# N "
        << N << "\n"
        << std::setprecision(17);
    for (int e : order) out << t.edge_vertices(e, 0) << " " << t.edge_vertices(e, 1) << " " << x(e) << "\n";
  });
}

Eigen::VectorXd read_connection(const std::string& path, const Topology& t) {
  // Edge lookup by (i, j) through the CSR vertex → edges adjacency.
  auto find_edge = [&](int i, int j) { return edge_between(t, i, j); };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(t.num_edges);
  std::vector<char> seen(t.num_edges, 0);
  TextLines lines(read_file_bytes(path), path);
  const auto as_id = [](double value) {  // -1 unless a vertex id (converting a larger double to int is undefined)
    return value >= 0 && value <= 2147483647.0 && value == std::floor(value) ? static_cast<int>(value) : -1;
  };
  while (lines.next()) {
    const std::vector<double> v = parse_numbers(lines, 3);
    const int i = as_id(v[0]), j = as_id(v[1]);
    const int e = (i >= 0 && j >= 0 && i < j) ? find_edge(i, j) : -1;
    if (e < 0 || t.is_boundary_edge(e)) {
      std::ostringstream pair;
      pair << std::setprecision(17) << "(" << v[0] << ", " << v[1] << ")";
      throw Error(lines.where() + ": " + pair.str() + " is not an interior edge with i < j");
    }
    if (seen[e]) throw Error(lines.where() + ": edge (" + std::to_string(i) + ", " + std::to_string(j) + ") is listed twice");
    seen[e] = 1;
    x(e) = v[2];
  }
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e) && !seen[e])
      throw Error(path + ": interior edge (" + std::to_string(t.edge_vertices(e, 0)) + ", " + std::to_string(t.edge_vertices(e, 1)) +
                  ") is missing");
  return x;
}

namespace {
// Interior edges in increasing (i, j).
std::vector<int> edges_by_vertices(const Topology& t) {
  std::vector<int> order;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e)) order.push_back(e);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::make_pair(t.edge_vertices(a, 0), t.edge_vertices(a, 1)) < std::make_pair(t.edge_vertices(b, 0), t.edge_vertices(b, 1));
  });
  return order;
}

using io::whole_number;
}  // namespace

void write_matching(const std::string& path, const Topology& t, const Eigen::VectorXi& matching, int N) {
  if (matching.size() != t.num_edges)
    throw Error("write_matching: " + std::to_string(matching.size()) + " values for " + std::to_string(t.num_edges) + " edges");
  const std::vector<int> order = edges_by_vertices(t);
  write_file_atomically(path, [&](std::ostream& out) {
    out << N << " " << order.size() << "\n";
    for (int e : order)
      out << t.edge_faces(e, 0) << " " << t.edge_faces(e, 1) << " " << t.edge_vertices(e, 0) << " " << t.edge_vertices(e, 1) << " "
          << ((matching(e) % N) + N) % N << "\n";
  });
}

Eigen::VectorXi read_matching(const std::string& path, const Topology& t, int N) {
  TextLines lines(read_file_bytes(path), path);
  auto tokens = [&](size_t expected) {
    std::istringstream fields(lines.line);
    std::vector<std::string> out;
    std::string token;
    while (fields >> token) out.push_back(token);
    if (out.size() != expected)
      throw Error(lines.where() + ": expected " + std::to_string(expected) + " numbers, got " + std::to_string(out.size()));
    return out;
  };
  if (!lines.next()) throw Error(path + ": empty matching file (expected a first line 'N E')");
  std::vector<std::string> head = tokens(2);
  const long long file_N = whole_number(head[0], lines, 1, 1 << 20, "N");
  const long long count = whole_number(head[1], lines, 0, t.num_edges, "the edge count");
  if (file_N != N) throw Error(path + ": the matching is for N = " + std::to_string(file_N) + ", the field has N = " + std::to_string(N));
  int interior = 0;
  for (int e = 0; e < t.num_edges; ++e) interior += !t.is_boundary_edge(e);
  if (count != interior)
    throw Error(lines.where() + ": the file lists " + std::to_string(count) + " edges, the mesh has " + std::to_string(interior) +
                " interior edges");
  Eigen::VectorXi m = Eigen::VectorXi::Zero(t.num_edges);
  std::vector<char> seen(t.num_edges, 0);
  for (long long k = 0; k < count; ++k) {
    if (!lines.next()) throw Error(path + ": ends after " + std::to_string(k) + " of its " + std::to_string(count) + " edges");
    const std::vector<std::string> v = tokens(5);
    const int a = static_cast<int>(whole_number(v[0], lines, 0, t.num_faces - 1, "face"));
    const int b = static_cast<int>(whole_number(v[1], lines, 0, t.num_faces - 1, "face"));
    const int i = static_cast<int>(whole_number(v[2], lines, 0, t.num_vertices - 1, "vertex"));
    const int j = static_cast<int>(whole_number(v[3], lines, 0, t.num_vertices - 1, "vertex"));
    const long long value = whole_number(v[4], lines, -(1LL << 40), 1LL << 40, "matching");
    const int edge = edge_between(t, i, j);
    if (edge < 0 || t.is_boundary_edge(edge))
      throw Error(lines.where() + ": (" + std::to_string(i) + ", " + std::to_string(j) + ") is not an interior edge of the mesh");
    const int L = t.edge_faces(edge, 0), R = t.edge_faces(edge, 1);
    if (!((a == L && b == R) || (a == R && b == L)))
      throw Error(lines.where() + ": faces " + std::to_string(a) + " and " + std::to_string(b) + " are not the faces of edge (" +
                  std::to_string(t.edge_vertices(edge, 0)) + ", " + std::to_string(t.edge_vertices(edge, 1)) + "), which are " +
                  std::to_string(L) + " and " + std::to_string(R));
    if (seen[edge])
      throw Error(lines.where() + ": edge (" + std::to_string(t.edge_vertices(edge, 0)) + ", " + std::to_string(t.edge_vertices(edge, 1)) +
                  ") is listed twice");
    seen[edge] = 1;
    const long long signed_value = a == L ? value : -value;
    m(edge) = static_cast<int>(((signed_value % N) + N) % N);
  }
  if (lines.next()) throw Error(lines.where() + ": text after the " + std::to_string(count) + " edges the first line announced");
  return m;
}

void write_field_lines(const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Geometry& g, const Field& field) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# trivcon field: one segment per face and direction, from the face centroid\n" << std::setprecision(9);
    for (int f = 0; f < F.rows(); ++f) {
      const Eigen::Vector3d p0 = V.row(F(f, 0)), p1 = V.row(F(f, 1)), p2 = V.row(F(f, 2));
      const Eigen::Vector3d c = (p0 + p1 + p2) / 3;
      const double length = 0.4 * ((p1 - p0).norm() + (p2 - p1).norm() + (p0 - p2).norm()) / 3;
      out << "v " << c.x() << " " << c.y() << " " << c.z() << "\n";
      for (int k = 0; k < field.N; ++k) {
        const Eigen::Vector3d q = c + length * direction_k(g, field, f, k);
        out << "v " << q.x() << " " << q.y() << " " << q.z() << "\n";
      }
    }
    long long base = 1;
    for (int f = 0; f < F.rows(); ++f, base += field.N + 1)
      for (int k = 0; k < field.N; ++k) out << "l " << base << " " << base + 1 + k << "\n";
  });
}

}  // namespace trivcon
