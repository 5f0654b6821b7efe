// SPDX-License-Identifier: MIT
// src/io/gzip.h (internal): decompressing a whole gzip file in memory, for the mesh readers.
#pragma once
#include <string>

namespace trivcon::io {

// Decompresses a whole gzip file, including several members back to back (what `cat a.gz b.gz`
// gives, and what gzip itself accepts); zero padding after the last member is ignored like gzip does.
// Errors (corrupt or truncated data) name `path`.
std::string gunzip(const std::string& compressed, const std::string& path);

}  // namespace trivcon::io
