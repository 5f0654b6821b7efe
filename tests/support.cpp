#include "support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace trivcon::test {

std::string shared_mesh(const std::string& name) {
  const std::filesystem::path dir = TRIVCON_SHARED_MESHES;
  if (!std::filesystem::exists(dir / "SOURCES.md")) return "";
  return (dir / name).string();
}

std::string temp_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(TRIVCON_TEST_TMP) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

CommandResult run_cli(const std::string& args) {
  static int counter = 0;
  const std::string base = temp_dir("cli-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  const std::string out = base + "/out", err = base + "/err";
  const std::string command = std::string("'") + TRIVCON_CLI + "' " + args + " > '" + out + "' 2> '" + err + "' < /dev/null";
  const int raw = std::system(command.c_str());
  CommandResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove_all(base);
  return r;
}

double max_face_optimality(const FieldDesigner& designer, const Connection& c, const std::map<int, double>& skip) {
  const Topology& t = designer.topology();
  const Eigen::VectorXd& w = designer.solver().weights();
  double worst = 0, scale = 1;
  for (int e = 0; e < t.num_edges; ++e)
    if (w(e) > 0) scale = std::max(scale, std::abs(c.x(e) / w(e)));
  for (int f = 0; f < t.num_faces; ++f) {
    if (skip.count(f)) continue;
    double sum = 0;
    bool interior = true;
    for (int k = 0; k < 3; ++k) {
      const int e = t.face_edges(f, k);
      if (t.is_boundary_edge(e) || !(w(e) > 0)) {
        interior = false;
      } else {
        sum += (t.edge_faces(e, 0) == f ? 1 : -1) * c.x(e) / w(e);
      }
    }
    if (interior) worst = std::max(worst, std::abs(sum));
  }
  return worst / scale;
}

}  // namespace trivcon::test
