// SPDX-License-Identifier: MIT
// src/io/read_gltf.cpp: glTF 2.0 (.gltf with embedded or external buffers, .glb) through tinygltf (MIT, Debian's
// libtinygltf-dev; its JSON is nlohmann's). Images are never decoded. Every triangle primitive (mode 4, and
// strips and fans, turned into triangles) of the meshes of the default scene's nodes (scene 0 without a
// default; every mesh when the file has no scene), with the nodes' transforms applied, becomes its own block of
// vertices in the order met (primitives are not welded to each other, so each is its own component unless it
// shares vertices through its own indices); points and lines are skipped. Accessors are read with every offset,
// stride and count checked against their buffers, so that a corrupt file is an error, never a crash.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io/file_error.h"
#include "io/mesh_rules.h"
#include "trivcon/io.h"

namespace trivcon {

using namespace io;

namespace {

bool ignore_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) { return true; }

// The bytes of element `i` of `accessor`, or nullptr when it lies outside its buffer.
const unsigned char* element(const tinygltf::Model& model, const tinygltf::Accessor& accessor, size_t i, size_t size,
                             const std::string& name, const std::string& what) {
  if (accessor.bufferView < 0 || accessor.bufferView >= static_cast<int>(model.bufferViews.size()))
    fail(name, what + ": an accessor without a valid buffer view");
  const tinygltf::BufferView& view = model.bufferViews[accessor.bufferView];
  if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size())) fail(name, what + ": a buffer view without a valid buffer");
  const std::vector<unsigned char>& data = model.buffers[view.buffer].data;
  const size_t stride = view.byteStride > 0 ? view.byteStride : size;
  const size_t start = view.byteOffset + accessor.byteOffset + i * stride;
  if (view.byteOffset + view.byteLength > data.size() || accessor.byteOffset + i * stride + size > view.byteLength ||
      start + size > data.size())
    fail(name, what + ": element " + std::to_string(i) + " lies outside its buffer");
  return data.data() + start;
}

Eigen::Matrix4d node_matrix(const tinygltf::Node& node) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (node.matrix.size() == 16) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m(r, c) = node.matrix[4 * c + r];  // column-major
    return m;
  }
  Eigen::Affine3d a = Eigen::Affine3d::Identity();
  if (node.translation.size() == 3) a.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4)
    a.rotate(Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]).normalized());
  if (node.scale.size() == 3) a.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
  return a.matrix();
}

struct Collector {
  const tinygltf::Model& model;
  const std::string& name;
  std::vector<Eigen::Vector3d> points;
  FaceCollector faces;
  int skipped = 0;

  void primitive(const tinygltf::Primitive& p, const Eigen::Matrix4d& transform, const std::string& where) {
    const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skipped;
      return;
    }
    const auto position = p.attributes.find("POSITION");
    if (position == p.attributes.end()) fail(name, where + ": a triangle primitive without POSITION");
    if (position->second < 0 || position->second >= static_cast<int>(model.accessors.size())) fail(name, where + ": POSITION is not an accessor");
    const tinygltf::Accessor& pa = model.accessors[position->second];
    if (pa.type != TINYGLTF_TYPE_VEC3 || pa.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail(name, where + ": POSITION must be float VEC3");
    if (pa.count > static_cast<size_t>(kMaxCount) || points.size() + pa.count > static_cast<size_t>(kMaxCount))
      fail(name, where + ": too many vertices");
    const int base = static_cast<int>(points.size());
    for (size_t i = 0; i < pa.count; ++i) {
      float c[3];
      std::memcpy(c, element(model, pa, i, 12, name, where + " POSITION"), 12);
      const Eigen::Vector4d q = transform * Eigen::Vector4d(c[0], c[1], c[2], 1.0);
      if (!q.allFinite() || q[3] == 0) fail(name, non_finite_message(base + static_cast<long long>(i), q[0]));
      points.emplace_back(q.head<3>() / q[3]);
    }
    std::vector<long long> index;
    if (p.indices >= 0) {
      if (p.indices >= static_cast<int>(model.accessors.size())) fail(name, where + ": indices is not an accessor");
      const tinygltf::Accessor& ia = model.accessors[p.indices];
      size_t size = 0;
      switch (ia.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
        default: fail(name, where + ": indices must be unsigned byte, short or int");
      }
      if (ia.type != TINYGLTF_TYPE_SCALAR) fail(name, where + ": indices must be SCALAR");
      if (ia.count > 3ull * kMaxCount) fail(name, where + ": too many indices");
      index.resize(ia.count);
      for (size_t i = 0; i < ia.count; ++i) {
        const unsigned char* b = element(model, ia, i, size, name, where + " indices");
        std::uint32_t v = 0;
        if (size == 1) v = b[0];
        if (size == 2) { std::uint16_t s; std::memcpy(&s, b, 2); v = s; }
        if (size == 4) std::memcpy(&v, b, 4);
        if (v >= pa.count) fail(name, where + ": index " + std::to_string(v) + " out of range (the primitive has " + std::to_string(pa.count) + " vertices)");
        index[i] = v;
      }
    } else {
      index.resize(pa.count);
      for (size_t i = 0; i < pa.count; ++i) index[i] = static_cast<long long>(i);
    }
    auto add = [&](long long a, long long b, long long c) {
      const std::vector<int> corners{base + static_cast<int>(a), base + static_cast<int>(b), base + static_cast<int>(c)};
      const auto failure = [&](const std::string& p) { fail(name, where + ": " + p); };
      if (const std::string problem = faces.problem(corners, failure); !problem.empty()) failure(problem);
      faces.add(corners);
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (index.size() % 3 != 0) fail(name, where + ": " + std::to_string(index.size()) + " indices are not whole triangles");
      for (size_t i = 0; i + 2 < index.size(); i += 3) add(index[i], index[i + 1], index[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < index.size(); ++i)
        i % 2 == 0 ? add(index[i], index[i + 1], index[i + 2]) : add(index[i + 1], index[i], index[i + 2]);
    } else {
      for (size_t i = 1; i + 1 < index.size(); ++i) add(index[0], index[i], index[i + 1]);
    }
  }

  void node(int id, const Eigen::Matrix4d& parent, int depth) {
    if (id < 0 || id >= static_cast<int>(model.nodes.size())) fail(name, "node " + std::to_string(id) + " does not exist");
    if (depth > 256) fail(name, "the node hierarchy is deeper than 256 levels (a cycle?)");
    const tinygltf::Node& n = model.nodes[id];
    const Eigen::Matrix4d transform = parent * node_matrix(n);
    if (n.mesh >= 0) {
      if (n.mesh >= static_cast<int>(model.meshes.size())) fail(name, "node " + std::to_string(id) + " names mesh " + std::to_string(n.mesh) + ", which does not exist");
      const tinygltf::Mesh& mesh = model.meshes[n.mesh];
      for (size_t k = 0; k < mesh.primitives.size(); ++k)
        primitive(mesh.primitives[k], transform, "mesh " + std::to_string(n.mesh) + " primitive " + std::to_string(k));
    }
    for (int child : n.children) node(child, transform, depth + 1);
  }
};

}  // namespace

MeshData read_gltf(const std::string& buffer, const std::string& name) {
  if (buffer.empty()) fail(name, "empty file");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(ignore_image, nullptr);
  tinygltf::Model model;
  std::string error, warning;
  const std::string base = std::filesystem::path(name).parent_path().string();
  const bool binary = buffer.size() >= 4 && buffer.compare(0, 4, "glTF") == 0;
  const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &error, &warning, reinterpret_cast<const unsigned char*>(buffer.data()),
                                                        static_cast<unsigned int>(buffer.size()), base)
                         : loader.LoadASCIIFromString(&model, &error, &warning, buffer.data(), static_cast<unsigned int>(buffer.size()), base);
  if (!ok) {
    while (!error.empty() && (error.back() == '\n' || error.back() == ' ')) error.pop_back();
    fail(name, "not a readable glTF 2.0 file: " + (error.empty() ? std::string("tinygltf gave no reason") : error));
  }
  Collector c{model, name, {}, {}, 0};
  if (!model.scenes.empty()) {
    const int scene = model.defaultScene >= 0 && model.defaultScene < static_cast<int>(model.scenes.size()) ? model.defaultScene : 0;
    for (int n : model.scenes[scene].nodes) c.node(n, Eigen::Matrix4d::Identity(), 0);
  } else {
    for (size_t m = 0; m < model.meshes.size(); ++m)
      for (size_t k = 0; k < model.meshes[m].primitives.size(); ++k)
        c.primitive(model.meshes[m].primitives[k], Eigen::Matrix4d::Identity(), "mesh " + std::to_string(m) + " primitive " + std::to_string(k));
  }
  if (c.faces.polygon_count() == 0)
    fail(name, c.skipped > 0 ? "no triangles (only " + std::to_string(c.skipped) + " point or line primitives)" : "no triangles");
  MeshData mesh;
  mesh.format = binary ? "glb" : "gltf";
  mesh.V.resize(static_cast<Eigen::Index>(c.points.size()), 3);
  for (size_t v = 0; v < c.points.size(); ++v) mesh.V.row(static_cast<Eigen::Index>(v)) = c.points[v].transpose();
  c.faces.move_into(mesh);
  return mesh;
}

}  // namespace trivcon
