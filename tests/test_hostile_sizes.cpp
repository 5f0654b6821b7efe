// SPDX-License-Identifier: MIT
// Hostile sizes: headers and list counts that claim more than the file can hold (10^12 vertices, a face
// of 2^31 corners, ...). Each must give a trivcon::Error that names the claim and what the file has, with
// bounded memory: every read here runs in a child process (fork) whose address space may grow by at most
// 100 MB (setrlimit(RLIMIT_AS); not under AddressSanitizer, whose shadow memory needs terabytes of address
// space), so a reader that reserved memory by the header's word would fail with std::bad_alloc instead.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <new>
#include <string>

#include "batch.h"
#include "support.h"
#include "trivcon/constraints.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/indices.h"
#include "trivcon/io.h"

#if defined(__SANITIZE_ADDRESS__)
#define TRIVCON_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TRIVCON_TEST_ASAN 1
#endif
#endif

namespace trivcon {
namespace {

using test::temp_file;
using test::write_text;

constexpr std::size_t kMemoryBound = 100u << 20;  // bytes of address space a read may add

// The address space this process has mapped now (/proc/self/statm, first field, in pages).
std::size_t mapped_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
}

// Runs `read` in a child process with at most kMemoryBound more address space. Returns the message of the
// trivcon::Error it throws, or a marker: "<no error>", "<std::bad_alloc>", "<other exception: ...>",
// "<killed by signal N>".
std::string bounded_error(const std::function<void()>& read) {
  int channel[2];
  if (pipe(channel) != 0) return "<pipe failed>";
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child < 0) return "<fork failed>";
  if (child == 0) {
    close(channel[0]);
#ifndef TRIVCON_TEST_ASAN
    const rlimit limit{mapped_bytes() + kMemoryBound, mapped_bytes() + kMemoryBound};
    setrlimit(RLIMIT_AS, &limit);
#endif
    std::string message;
    try {
      read();
      message = "<no error>";
    } catch (const Error& e) {
      message = e.what();
    } catch (const std::bad_alloc&) {
      message = "<std::bad_alloc>";
    } catch (const std::exception& e) {
      message = std::string("<other exception: ") + e.what() + ">";
    }
    const ssize_t ignored = write(channel[1], message.data(), message.size());
    (void)ignored;
    _exit(0);
  }
  close(channel[1]);
  std::string message;
  char buffer[4096];
  for (ssize_t got; (got = ::read(channel[0], buffer, sizeof buffer)) > 0;) message.append(buffer, static_cast<std::size_t>(got));
  close(channel[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (WIFSIGNALED(status)) return "<killed by signal " + std::to_string(WTERMSIG(status)) + ">";
  return message;
}

// A file in a fresh directory, its name in messages replaced by FILE.
struct File {
  std::string path;
  explicit File(const std::string& name, const std::string& bytes) : path(temp_file(name)) { write_text(path, bytes); }
  std::string error(const std::function<void(const std::string&)>& read) const {
    std::string m = bounded_error([&] { read(path); });
    for (std::size_t at; (at = m.find(path)) != std::string::npos;) m.replace(at, path.size(), "FILE");
    return m;
  }
};

std::string mesh_error(const std::string& name, const std::string& bytes) {
  return File(name, bytes).error([](const std::string& path) { read_mesh(path); });
}

std::string bytes_after(const std::string& file, const std::string& header_end) {
  return std::to_string(file.size() - (file.find(header_end) + header_end.size()));
}

template <class T>
std::string raw(T value) {
  return std::string(reinterpret_cast<const char*>(&value), sizeof value);
}

// A little-endian binary PLY: 3 vertices (float x y z), then the faces given as raw bytes.
std::string binary_ply(const std::string& vertex_count, const std::string& face_count, const std::string& face_properties,
                       const std::string& faces) {
  std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " + vertex_count +
                      "\nproperty float x\nproperty float y\nproperty float z\nelement face " + face_count + "\n" + face_properties +
                      "end_header\n";
  const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  bytes.append(reinterpret_cast<const char*>(corners), sizeof corners);
  return bytes + faces;
}

volatile char sink;

TEST(HostileSizes, TheMemoryBoundCatchesAReaderThatTrustsItsHeader) {
#ifdef TRIVCON_TEST_ASAN
  GTEST_SKIP() << "no address-space limit under AddressSanitizer";
#else
  // The byte read back keeps the compiler from leaving the allocation out.
  EXPECT_EQ(bounded_error([] { sink = std::string(kMemoryBound * 2, 'x')[kMemoryBound]; }), "<std::bad_alloc>");
  EXPECT_EQ(bounded_error([] { sink = std::string(kMemoryBound / 4, 'x')[kMemoryBound / 8]; }), "<no error>");
#endif
}

TEST(HostileSizes, OffCounts) {
  const std::string cube_corner = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  std::string off = "OFF\n1000000000000 1 0\n" + cube_corner;
  EXPECT_EQ(mesh_error("m.off", off),
            "FILE:2: header claims 1000000000000 vertices, but the file has only 26 bytes after the header (a vertex needs at least 6)");
  off = "OFF\n3 1000000000000 0\n" + cube_corner;
  EXPECT_EQ(mesh_error("m.off", off),
            "FILE:2: header claims 1000000000000 faces, but the file has only 26 bytes after the header (a face needs at least 8)");
  off = "OFF 3 2147483648 0\n" + cube_corner;  // counts on the keyword's line
  EXPECT_EQ(mesh_error("m.off", off),
            "FILE:1: header claims 2147483648 faces, but the file has only 26 bytes after the header (a face needs at least 8)");
  EXPECT_EQ(mesh_error("m.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2147483648 0 1 2\n"),
            "FILE:6: face 0 announces 2147483648 corners but lists 3");
}

TEST(HostileSizes, AsciiPlyCounts) {
  const std::string tail =
      "property float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string data = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(mesh_error("m.ply", "ply\nformat ascii 1.0\nelement vertex 1000000000000\n" + tail + data),
            "FILE:3: header claims 1000000000000 vertices, but the file has only 26 bytes after the header (a vertex needs at least 6)");
  const std::string faces =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1000000000000\nproperty list uint int vertex_indices\nend_header\n";
  EXPECT_EQ(mesh_error("m.ply", faces + data),
            "FILE:7: header claims 1000000000000 faces, but the file has only 26 bytes after the header (a face needs at least 8)");
  const std::string other =
      "ply\nformat ascii 1.0\nelement material 99999999999\nproperty uchar red\nproperty uchar green\n"
      "element vertex 3\n" +
      tail;
  EXPECT_EQ(mesh_error("m.ply", other + data),
            "FILE:3: header claims 99999999999 'material' elements, but the file has only 26 bytes after the header (an element needs "
            "at least 4)");
  // A list count beyond the values on the element's line.
  EXPECT_EQ(mesh_error("m.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + tail + "0 0 0\n1 0 0\n0 1 0\n2147483648 0 1 2\n"),
            "FILE:13: face 0 announces 2147483648 'vertex_indices' but lists 3");
}

TEST(HostileSizes, BinaryPlyCounts) {
  const std::string list = "property list uchar int vertex_indices\n";
  const std::string face = std::string("\x03", 1) + raw<std::int32_t>(0) + raw<std::int32_t>(1) + raw<std::int32_t>(2);
  std::string ply = binary_ply("1000000000000", "1", list, face);
  EXPECT_EQ(mesh_error("m.ply", ply), "FILE:3: header claims 1000000000000 vertices, but the file has only " +
                                          bytes_after(ply, "end_header\n") + " bytes after the header (a vertex needs at least 12)");
  ply = binary_ply("3", "1000000000000", list, face);
  EXPECT_EQ(mesh_error("m.ply", ply), "FILE:7: header claims 1000000000000 faces, but the file has only " +
                                          bytes_after(ply, "end_header\n") + " bytes after the header (a face needs at least 13)");
  ply = binary_ply("3", "2147483648", "property list uint uint vertex_indices\nproperty double quality\n", "");
  EXPECT_EQ(mesh_error("m.ply", ply),
            "FILE:7: header claims 2147483648 faces, but the file has only 36 bytes after the header "
            "(a face needs at least 24)");

  // A face list count of 2^31 (uint count): compared with the bytes left before any index is read. The
  // face starts after the 3 vertices of 12 bytes; its indices after the count.
  const auto after_count = [](const std::string& file, std::size_t count_bytes, std::size_t items) {
    return std::to_string(file.find("end_header\n") + 11 + 36 + count_bytes + items);
  };
  ply = binary_ply("3", "1", "property list uint int vertex_indices\n", raw<std::uint32_t>(2147483648u) + face.substr(1));
  EXPECT_EQ(mesh_error("m.ply", ply), "FILE: truncated binary data at byte " + after_count(ply, 4, 12) +
                                          " (face 0 of 1; its 'vertex_indices' list claims 2147483648 items of 4 bytes, but only 12 bytes "
                                          "follow the count)");
  // The same for a list the reader skips (another property of the face).
  ply = binary_ply("3", "1", list + "property list int double weights\n", face + raw<std::int32_t>(1 << 30) + raw<double>(1));
  EXPECT_EQ(mesh_error("m.ply", ply), "FILE: truncated binary data at byte " + after_count(ply, 13 + 4, 8) +
                                          " (face 0 of 1; its 'weights' list claims 1073741824 items of 8 bytes, but only 8 bytes follow "
                                          "the count)");
  // Big endian: the count 0x80000000 read the other way round would be 128.
  ply = binary_ply("3", "1", "property list uint int vertex_indices\n", raw<std::uint32_t>(0x80u) + face.substr(1));
  ply.replace(ply.find("binary_little_endian"), 20, "binary_big_endian");
  EXPECT_NE(mesh_error("m.ply", ply).find("list claims 2147483648 items"), std::string::npos);
}

TEST(HostileSizes, GzippedMesh) {
  const std::string path = temp_file("m.off.gz");
  const std::string off = "OFF\n1000000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  gzFile file = gzopen(path.c_str(), "wb");
  ASSERT_NE(file, nullptr);
  ASSERT_EQ(gzwrite(file, off.data(), static_cast<unsigned>(off.size())), static_cast<int>(off.size()));
  ASSERT_EQ(gzclose(file), Z_OK);
  EXPECT_EQ(bounded_error([&] { read_mesh(path); }),
            path + ":2: header claims 1000000000000 vertices, but the file has only 26 bytes after the header (a vertex needs at least 6)");
}

TEST(HostileSizes, SingularityFiles) {
  const auto sings_error = [](const std::string& text) {
    return File("s.sings", text).error([](const std::string& path) {
      IndexPrescription p;
      p.N = 4;
      read_singularities(path, p);
    });
  };
  // Nothing is allocated by the count: it is compared with the lines read.
  EXPECT_EQ(sings_error("4 1000000000000\n0 1\n5 1\n"), "FILE: the header announces 1000000000000 singularities but the file lists 2");
  EXPECT_EQ(sings_error("1000000000000 2\n0 1\n5 1\n"), "FILE:1: N 1000000000000 in the header is too large (at most 1000000000)");
  EXPECT_EQ(sings_error("4 2\n0 1000000000000\n5 1\n"), "FILE:2: index '1000000000000/4' is too large");
  EXPECT_EQ(File("s.txt", "0 -9223372036854775808\n").error([](const std::string& path) {
    IndexPrescription p;
    read_singularities(path, p);
  }),
            "FILE:1: index '-9223372036854775808' is too large");
}

TEST(HostileSizes, FieldFiles) {
  const auto field_error = [](const std::string& name, const std::string& bytes) {  // against a mesh of 20 faces
    return File(name, bytes).error([](const std::string& path) {
      int N = 0;
      read_field(path, 20, &N);
    });
  };
  // .ply: counts in the header.
  const std::string header_start = "ply\nformat binary_little_endian 1.0\ncomment trivcon field, N 4\nelement vertex ";
  const std::string header_rest =
      "\nproperty double x\nproperty double y\nproperty double z\nelement face 20\nproperty list uchar int vertex_indices\n"
      "property double fx\nproperty double fy\nproperty double fz\nend_header\n";
  std::string ply = header_start + "1000000000000" + header_rest + std::string(100, '\0');
  EXPECT_EQ(field_error("f.ply", ply),
            "FILE: header claims 1000000000000 vertices, but the file has only 100 bytes after the header (a vertex needs 24)");
  ply = header_start + "12" + header_rest;
  ply.replace(ply.find("face 20"), 7, "face 1000000000000");
  EXPECT_EQ(field_error("f.ply", ply), "FILE: has 1000000000000 faces, the mesh has 20");
  ply.replace(ply.find("face 1000000000000"), 18, "face 99999999999999999999");
  EXPECT_EQ(field_error("f.ply", ply), "FILE: not a field PLY written by trivcon (expected face properties fx fy fz after vertex_indices)");
  // .rawfield: "N F" as numbers.
  EXPECT_EQ(field_error("f.rawfield", "4 1000000000000\n1 0 0\n"), "FILE:1: the field has 1000000000000 faces, the mesh has 20");
  EXPECT_EQ(field_error("f.rawfield", "4 1e300\n1 0 0\n"), "FILE:1: the field has 1e+300 faces, the mesh has 20");
  EXPECT_EQ(field_error("f.rawfield", "1e30 20\n1 0 0\n"), "FILE:1: malformed N in the header");
  EXPECT_EQ(field_error("f.rawfield", "1001 20\n1 0 0\n"), "FILE:1: malformed N in the header");
  // Text: "# N" must be a valid symmetry (rendering 10^9 directions per face would never end).
  EXPECT_EQ(field_error("f.txt", "# trivcon field\n# N 1000000000\n# faces 20\n1 0 0\n"), "FILE:2: N 1000000000 out of range (1 to 1000)");
  EXPECT_EQ(field_error("f.txt", "# trivcon field\n# N -4\n1 0 0\n"), "FILE:2: N -4 out of range (1 to 1000)");
  EXPECT_EQ(field_error("f.txt", "# trivcon field\n# N 99999999999999999999\n1 0 0\n"), "FILE: has 1 directions, the mesh has 20 faces");
}

TEST(HostileSizes, BatchFile) {
  const auto batch_error = [](const std::string& text) {
    return File("b.jsonl", text).error([](const std::string& path) {
      IndexPrescription base;
      base.N = 4;
      cli::read_batch(path, base);
    });
  };
  EXPECT_EQ(batch_error("{\"name\": \"a\", \"sing\": {\"0\": \"1000000000000\"}}\n"),
            "FILE:1: --sing 0:1000000000000: index '1000000000000' is too large");
  // An index nested 200000 levels deep is refused as it is, not turned back into text (recursively).
  const std::string deep = std::string(200000, '[') + std::string(200000, ']');
  EXPECT_EQ(batch_error("{\"name\": \"a\", \"sing\": {\"0\": " + deep + "}}\n"),
            "FILE:1: the index of \"sing\" \"0\" must be a string or a number, e.g. \"1/4\"");
  // Many items: names are looked up, not compared with every earlier item (the last one repeats the first).
  std::string many;
  for (int i = 0; i < 100000; ++i) many += "{\"name\": \"n" + std::to_string(i) + "\", \"sing\": {}}\n";
  many += "{\"name\": \"n0\", \"sing\": {}}\n";
  EXPECT_EQ(batch_error(many), "FILE:100001: the name 'n0' is already used on line 1");
}

}  // namespace
}  // namespace trivcon
