#include "support.h"

#include <sys/wait.h>
#include <unistd.h>

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

}  // namespace trivcon::test
