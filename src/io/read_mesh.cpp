// SPDX-License-Identifier: MIT
// src/io/read_mesh.cpp: reading a mesh file by its extension (trivcon/io.h): the whole file into memory,
// gunzipped when it ends in .gz, then the reader of its format (src/io/read_obj.cpp, read_off.cpp, read_ply.cpp, read_stl.cpp, read_gltf.cpp).
#include "trivcon/io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>
#include <system_error>

#include "io/gzip.h"
#include "trivcon/error.h"

namespace trivcon {
namespace {

bool ends_with_ignoring_case(std::string_view text, std::string_view suffix) {
  if (text.size() < suffix.size()) return false;
  return std::equal(suffix.begin(), suffix.end(), text.end() - suffix.size(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
  });
}

}  // namespace

std::string read_file_bytes(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw Error("cannot open '" + path + "': " + std::strerror(errno));
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(file, std::fclose);
  std::error_code ignored;
  const std::uintmax_t size_hint = std::filesystem::file_size(path, ignored);
  std::string bytes(ignored ? std::size_t{1} << 16 : static_cast<std::size_t>(size_hint) + 1, '\0');
  std::size_t used = 0;
  for (;;) {
    if (used == bytes.size()) bytes.resize(2 * bytes.size());
    const std::size_t wanted = bytes.size() - used;
    const std::size_t got = std::fread(&bytes[used], 1, wanted, file);
    used += got;
    if (got < wanted) break;
  }
  if (std::ferror(file)) throw Error("cannot read '" + path + "': " + std::strerror(errno));
  bytes.resize(used);
  if (ends_with_ignoring_case(path, ".gz")) return io::gunzip(bytes, path);
  return bytes;
}

MeshData read_mesh(const std::string& path, double weld_tolerance) {
  std::string_view stem = path;
  if (ends_with_ignoring_case(stem, ".gz")) stem.remove_suffix(3);
  if (weld_tolerance != 0 && !ends_with_ignoring_case(stem, ".stl"))
    throw Error("cannot read '" + path + "' with a weld tolerance: only STL files are welded (their triangles carry their own corners)");
  if (ends_with_ignoring_case(stem, ".obj")) return read_obj(read_file_bytes(path), path);
  if (ends_with_ignoring_case(stem, ".off")) return read_off(read_file_bytes(path), path);
  if (ends_with_ignoring_case(stem, ".ply")) return read_ply(read_file_bytes(path), path);
  if (ends_with_ignoring_case(stem, ".stl")) return read_stl(read_file_bytes(path), path, weld_tolerance);
  if (ends_with_ignoring_case(stem, ".gltf") || ends_with_ignoring_case(stem, ".glb")) return read_gltf(read_file_bytes(path), path);
  throw Error("cannot read '" + path +
              "': unknown mesh format (supported: .obj, .off, .ply, .stl, .gltf, .glb, each optionally followed by .gz)");
}

}  // namespace trivcon
