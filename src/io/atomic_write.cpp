// SPDX-License-Identifier: MIT
// src/io/atomic_write.cpp: write_file_atomically (trivcon/io.h), through which all of trivcon's outputs are
// written: a fresh temporary file beside the target, renamed into place once it is complete.
#include "trivcon/io.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "trivcon/error.h"

namespace trivcon {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& fill) {
  const auto refuse = [&](const std::string& why) { throw Error("cannot write '" + path + "': " + why); };
  // The temporary lives beside the target so that rename() stays on one file system (atomic).
  // O_EXCL with pid + counter gives a fresh name even with several threads or processes.
  static std::atomic<unsigned> counter{0};
  std::string temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) refuse(std::strerror(errno));
  ::close(fd);

  struct RemoveUnlessKept {
    const std::string& file;
    bool keep = false;
    ~RemoveUnlessKept() {
      if (!keep) std::remove(file.c_str());
    }
  } cleanup{temporary};

  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) refuse(std::strerror(errno));
    fill(out);
    errno = 0;
    out.flush();
    const bool wrote = static_cast<bool>(out);
    out.close();
    if (!wrote || out.fail()) refuse(errno ? std::strerror(errno) : "write failed");
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) refuse(std::strerror(errno));
  cleanup.keep = true;
}

}  // namespace trivcon
