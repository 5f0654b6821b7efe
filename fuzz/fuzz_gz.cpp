// SPDX-License-Identifier: MIT
// fuzz/fuzz_gz.cpp: a gzipped mesh (read_mesh on "mesh.obj.gz" and the like): the bytes are gunzipped as
// read_file_bytes does (src/io/gzip.h), then what comes out is read as OBJ, OFF and PLY in turn.
//
// Under libFuzzer a custom mutator keeps most inputs valid gzip: it gunzips the input, mutates the
// decompressed mesh and compresses it again (as one member, or split into two, sometimes with zero padding
// after it), because a mutation of the compressed bytes almost always just fails the CRC. One mutation in
// eight is of the compressed bytes themselves (corrupt and truncated streams).
#include <zlib.h>

#include <cstring>
#include <random>

#include "io/gzip.h"
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(gz) {
  const std::string data = trivcon::io::gunzip(bytes, "fuzz.gz");
  using Reader = trivcon::MeshData (*)(const std::string&, const std::string&);
  for (const Reader read : {Reader{trivcon::read_obj}, Reader{trivcon::read_off}, Reader{trivcon::read_ply}}) {
    try {
      trivcon::fuzz::check_mesh(read(data, "fuzz.gz"));
    } catch (const trivcon::Error&) {
    }
  }
}

#ifdef TRIVCON_LIBFUZZER
namespace {

// One gzip member holding `plain` (empty when zlib fails).
std::string gzip_member(const std::string& plain) {
  z_stream stream{};
  if (deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK) return {};
  std::string out(deflateBound(&stream, static_cast<uLong>(plain.size())) + 32, '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(plain.data()));
  stream.avail_in = static_cast<uInt>(plain.size());
  stream.next_out = reinterpret_cast<Bytef*>(&out[0]);
  stream.avail_out = static_cast<uInt>(out.size());
  const int status = deflate(&stream, Z_FINISH);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return status == Z_STREAM_END ? out : std::string();
}

}  // namespace

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned int seed) {
  std::minstd_rand random(seed);
  if (random() % 8 == 0) return LLVMFuzzerMutate(data, size, max_size);
  constexpr std::size_t kMaxPlain = 16384;
  std::string plain;
  try {
    plain = trivcon::io::gunzip(std::string(reinterpret_cast<const char*>(data), size), "seed.gz");
  } catch (const trivcon::Error&) {
    return LLVMFuzzerMutate(data, size, max_size);
  }
  if (plain.size() > kMaxPlain) return LLVMFuzzerMutate(data, size, max_size);
  const std::size_t used = plain.size();
  plain.resize(kMaxPlain);
  plain.resize(LLVMFuzzerMutate(reinterpret_cast<std::uint8_t*>(&plain[0]), used, kMaxPlain));
  std::string out;
  if (random() % 4 == 0 && plain.size() > 1) {  // two members, split anywhere
    const std::size_t split = random() % plain.size();
    out = gzip_member(plain.substr(0, split)) + gzip_member(plain.substr(split));
  } else {
    out = gzip_member(plain);
  }
  if (random() % 8 == 0) out.append(random() % 16 + 1, '\0');  // padding after the last member
  if (out.empty() || out.size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
  std::memcpy(data, out.data(), out.size());
  return out.size();
}
#endif
