// SPDX-License-Identifier: MIT
// trivcon/indices.h: the text of indices: "p/q" specs, singularity files (ours and Directional's .sings).
#include "trivcon/indices.h"

#include <numeric>
#include <sstream>

#include "io/readers.h"
#include "io/text_scanner.h"
#include "trivcon/error.h"
#include "trivcon/io.h"

namespace trivcon {

namespace {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

// A whole number, one leading '+' allowed (io::parse_integer, the readers' one integer parser).
bool parse_long(const std::string& s, long long& value) { return io::parse_integer(s, value); }

int parse_id(const std::string& text, const std::string& what, const std::string& where) {
  long long id;
  if (!parse_long(trim(text), id) || id < 0 || id > 2147483647LL) throw Error(where + ": malformed " + what + " id '" + trim(text) + "'");
  return static_cast<int>(id);
}

// Splits "ID:INDEX".
std::pair<std::string, std::string> split_spec(const std::string& spec, const std::string& option) {
  const size_t colon = spec.find(':');
  if (colon == std::string::npos) throw Error(option + " '" + spec + "': expected ID:INDEX, e.g. 12:1/4");
  return {spec.substr(0, colon), spec.substr(colon + 1)};
}

void insert_once(std::map<int, int>& map, int id, int n, const std::string& what, const std::string& where) {
  if (!map.emplace(id, n).second) throw Error(where + ": " + what + " " + std::to_string(id) + " is given twice");
}

}  // namespace

int parse_index(const std::string& text_in, int N, const std::string& where) {
  const std::string text = trim(text_in);
  const size_t slash = text.find('/');
  long long p, q = 1;
  const bool ok =
      slash == std::string::npos ? parse_long(text, p) : parse_long(text.substr(0, slash), p) && parse_long(text.substr(slash + 1), q);
  if (!ok || q <= 0) throw Error(where + ": malformed index '" + text + "' (expected an integer or a fraction p/q, q > 0)");
  if (p > kMaxIndexPart || p < -kMaxIndexPart || q > kMaxIndexPart) throw Error(where + ": index '" + text + "' is too large");
  // n = p N / q must be an integer.
  if ((p * N) % q != 0)
    throw Error(where + ": index " + text + " is not a multiple of 1/" + std::to_string(N) + " (use -N to change the symmetry)");
  const long long n = p * N / q;
  if (n > kMaxIndexPart || n < -kMaxIndexPart)
    throw Error(where + ": index " + text + " is too large (|index| at most " + std::to_string(kMaxIndexPart / N) + " with N = " +
                std::to_string(N) + ")");
  return static_cast<int>(n);
}

std::string format_index(int n, int N) {
  const int g = std::gcd(std::abs(n), N);
  if (n == 0) return "0";
  if (g == N) return std::to_string(n / N);
  return std::to_string(n / g) + "/" + std::to_string(N / g);
}

void write_singularities_to(std::ostream& out, const std::map<int, int>& vertex, int N) {
  out << "# trivcon singularities\n# N " << N << "\n# " << vertex.size() << " singular vertices\n";
  for (auto [v, n] : vertex) out << v << " " << format_index(n, N) << "\n";
}

void write_singularities(const std::string& path, const std::map<int, int>& vertex, int N) {
  write_file_atomically(path, [&](std::ostream& out) { write_singularities_to(out, vertex, N); });
}

void add_vertex_index(const std::string& spec, IndexPrescription& p) {
  auto [id, index] = split_spec(spec, "--sing");
  const std::string where = "--sing " + spec;
  insert_once(p.vertex, parse_id(id, "vertex", where), parse_index(index, p.N, where), "vertex", where);
}
void add_generator_index(const std::string& spec, IndexPrescription& p) {
  auto [id, index] = split_spec(spec, "--generator");
  const std::string where = "--generator " + spec;
  insert_once(p.generator, parse_id(id, "generator", where), parse_index(index, p.N, where), "generator", where);
}
void add_loop_index(const std::string& spec, IndexPrescription& p) {
  auto [id, index] = split_spec(spec, "--boundary");
  const std::string where = "--boundary " + spec;
  insert_once(p.loop, parse_id(id, "boundary loop", where), parse_index(index, p.N, where), "boundary loop", where);
}

void read_singularities(const std::string& path, IndexPrescription& p) { io::read_singularities_from(read_file_bytes(path), path, p); }

namespace io {

void read_singularities_from(const std::string& bytes, const std::string& path, IndexPrescription& p) {
  std::istringstream in(bytes);
  const bool directional = path.size() >= 6 && path.compare(path.size() - 6, 6, ".sings") == 0;
  std::string line;
  int line_no = 0, file_N = 0;
  long long announced = -1, seen = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    const std::string content = trim(line.substr(0, line.find('#')));
    if (content.empty()) continue;
    std::istringstream fields(content);
    std::string a, b, extra;
    if (!(fields >> a >> b) || (fields >> extra)) throw Error(where + ": expected two fields, got '" + content + "'");
    if (directional && file_N == 0) {
      long long n, count;
      if (!parse_long(a, n) || !parse_long(b, count) || n < 1 || count < 0)
        throw Error(where + ": expected the header 'N count' of a .sings file");
      if (n > kMaxIndexPart)
        throw Error(where + ": N " + a + " in the header is too large (at most " + std::to_string(kMaxIndexPart) + ")");
      // The count is only compared with the lines read (at the end): nothing is allocated by it.
      file_N = static_cast<int>(n), announced = count;
      continue;
    }
    const int v = parse_id(a, "vertex", where);
    long long whole = 0;
    if (directional && !parse_long(b, whole))
      throw Error(where + ": malformed index '" + b + "' (a .sings file gives a whole number n for the index n/N)");
    const int n = directional ? parse_index(b + "/" + std::to_string(file_N), p.N, where) : parse_index(b, p.N, where);
    insert_once(p.vertex, v, n, "vertex", where);
    ++seen;
  }
  if (directional && file_N == 0) throw Error(path + ": empty .sings file (expected the header 'N count')");
  if (directional && seen != announced)
    throw Error(path + ": the header announces " + std::to_string(announced) + " singularities but the file lists " + std::to_string(seen));
}

}  // namespace io

}  // namespace trivcon
