// SPDX-License-Identifier: MIT
// src/io/file_error.h (internal): the errors of the mesh file readers, which name the file and,
// in text formats, the 1-based line ("mesh.obj:12: ..."); binary offsets go into the message.
#pragma once
#include <cstddef>
#include <string>

#include "trivcon/error.h"

namespace trivcon::io {

[[noreturn]] inline void fail(const std::string& name, const std::string& message) { throw Error(name + ": " + message); }

[[noreturn]] inline void fail_at_line(const std::string& name, std::size_t line, const std::string& message) {
  throw Error(name + ":" + std::to_string(line) + ": " + message);
}

}  // namespace trivcon::io
