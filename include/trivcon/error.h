// SPDX-License-Identifier: MIT
// trivcon/error.h: the one exception type the library throws.
//
// Every error a user can cause (bad file, bad mesh, bad singularity, infeasible constraints) is
// reported as trivcon::Error whose message names the problem and where it is (file and line, byte
// offset, vertex, edge, face). Front ends print what() and exit with a non-zero status.
#pragma once
#include <stdexcept>
#include <string>

namespace trivcon {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace trivcon
