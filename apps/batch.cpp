// SPDX-License-Identifier: MIT
#include "batch.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "trivcon/error.h"
#include "trivcon/io.h"

namespace trivcon::cli {

namespace {

namespace fs = std::filesystem;

// The regular files of a directory (a dangling link is not one), sorted by name.
std::vector<fs::path> directory_files(const std::string& path) {
  std::vector<fs::path> files;
  std::error_code error;
  for (fs::directory_iterator it(path, error), end; !error && it != end; it.increment(error)) {
    std::error_code status_error;
    const fs::file_status status = it->status(status_error);
    if (status.type() == fs::file_type::none) throw Error("cannot read '" + it->path().string() + "': " + status_error.message());
    if (fs::is_regular_file(status)) files.push_back(it->path());
  }
  if (error) throw Error("cannot read '" + path + "': " + error.message());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<BatchItem> read_directory(const std::string& path, const IndexPrescription& base) {
  std::vector<BatchItem> items;
  std::map<std::string, std::size_t> item_of_name;  // outputs are named by the item: two of a name would overwrite each other
  for (const fs::path& f : directory_files(path)) {
    BatchItem item{f.stem().string(), base, f.filename().string()};
    if (const auto [it, added] = item_of_name.emplace(item.name, items.size()); !added)
      throw Error("--sing-batch " + path + ": files '" + items[it->second].source + "' and '" + f.filename().string() +
                  "' have the same name '" + item.name + "'");
    item.prescription.vertex.clear();
    read_singularities(f.string(), item.prescription);
    items.push_back(std::move(item));
  }
  if (items.empty()) throw Error("--sing-batch " + path + ": the directory has no files");
  return items;
}

}  // namespace

std::vector<BatchItem> read_batch(const std::string& path, const IndexPrescription& base) {
  std::error_code error;  // a path that cannot be examined is read as a file, whose error names it
  return fs::is_directory(path, error) ? read_directory(path, base) : read_batch_lines(read_file_bytes(path), path, base);
}

std::vector<BatchItem> read_batch_lines(const std::string& text, const std::string& path, const IndexPrescription& base) {
  std::vector<BatchItem> items;
  std::map<std::string, std::size_t> item_of_name;  // outputs are named by the item: two of a name would overwrite each other
  std::istringstream in(text);
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const std::string where = path + ":" + std::to_string(line_no);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      throw Error(where + ": not a JSON object (" + std::string(e.what()) + ")");
    }
    if (!j.is_object() || !j.contains("name") || !j["name"].is_string() || !j.contains("sing") || !j["sing"].is_object())
      throw Error(where + ": expected {\"name\": \"...\", \"sing\": {\"VERTEX\": \"INDEX\", ...}}");
    BatchItem item{j["name"].get<std::string>(), base, "line " + std::to_string(line_no)};
    if (item.name.empty() || item.name.find('/') != std::string::npos) throw Error(where + ": the name must be non-empty without '/'");
    if (const auto [it, added] = item_of_name.emplace(item.name, items.size()); !added)
      throw Error(where + ": the name '" + item.name + "' is already used on " + items[it->second].source);
    item.prescription.vertex.clear();
    auto add = [&](const char* key, void (*adder)(const std::string&, IndexPrescription&)) {
      if (!j.contains(key)) return;
      if (!j[key].is_object()) throw Error(where + ": \"" + key + "\" must be an object");
      for (const auto& [id, index] : j[key].items()) {
        // Only a string or a number is an index (dumping anything else back to text would recurse into it).
        if (!index.is_string() && !index.is_number())
          throw Error(where + ": the index of \"" + key + "\" \"" + id + "\" must be a string or a number, e.g. \"1/4\"");
        const std::string value = index.is_string() ? index.get<std::string>() : index.dump();
        try {
          adder(id + ":" + value, item.prescription);
        } catch (const Error& e) {
          throw Error(where + ": " + e.what());
        }
      }
    };
    add("sing", add_vertex_index);
    add("generator", add_generator_index);
    add("boundary", add_loop_index);
    items.push_back(std::move(item));
  }
  if (items.empty()) throw Error("--sing-batch " + path + ": no items");
  return items;
}

}  // namespace trivcon::cli
