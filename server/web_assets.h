// SPDX-License-Identifier: MIT
// The page's files, embedded into the program at build time (web/embed.mjs writes the table from
// web/index.html and the esbuild bundle of web/src/).
#pragma once
#include <cstddef>
#include <vector>

namespace trivcon::server {

struct WebAsset {
  const char* path;  // URL path, e.g. "/app.js"
  const char* content_type;
  const unsigned char* data;
  size_t size;
};

const std::vector<WebAsset>& web_assets();

}  // namespace trivcon::server
