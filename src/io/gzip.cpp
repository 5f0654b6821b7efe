// SPDX-License-Identifier: MIT
// src/io/gzip.cpp: gzip decompression with zlib; see src/io/gzip.h.
#include "io/gzip.h"

#include <zlib.h>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>

#include "io/file_error.h"

namespace trivcon::io {

std::string gunzip(const std::string& compressed, const std::string& path) {
  if (compressed.empty()) return {};
  z_stream stream{};
  if (inflateInit2(&stream, 16 + MAX_WBITS) != Z_OK) fail(path, "cannot initialise zlib");
  const std::unique_ptr<z_stream, int (*)(z_streamp)> end_stream(&stream, inflateEnd);

  std::string out(3 * compressed.size() + (1 << 16), '\0');  // grows when text compresses better
  std::size_t in_pos = 0;
  std::size_t out_pos = 0;
  constexpr std::size_t kMaxChunk = std::numeric_limits<uInt>::max();  // zlib counts in uInt
  for (;;) {
    if (out_pos == out.size()) out.resize(2 * out.size());
    const std::size_t in_chunk = std::min(compressed.size() - in_pos, kMaxChunk);
    const std::size_t out_chunk = std::min(out.size() - out_pos, kMaxChunk);
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + in_pos));
    stream.avail_in = static_cast<uInt>(in_chunk);
    stream.next_out = reinterpret_cast<Bytef*>(&out[out_pos]);
    stream.avail_out = static_cast<uInt>(out_chunk);
    const int status = inflate(&stream, Z_NO_FLUSH);
    in_pos += in_chunk - stream.avail_in;
    out_pos += out_chunk - stream.avail_out;
    if (status == Z_STREAM_END) {
      const bool only_padding = std::all_of(compressed.begin() + in_pos, compressed.end(), [](char c) { return c == '\0'; });
      if (only_padding) break;
      inflateReset(&stream);  // another member follows
    } else if (status == Z_BUF_ERROR || status == Z_OK) {
      // No progress with all input consumed means the stream stops in the middle.
      if (status == Z_BUF_ERROR && in_pos == compressed.size() && stream.avail_out > 0) {
        fail(path, "truncated gzip data (ends at byte " + std::to_string(compressed.size()) + ")");
      }
    } else {
      fail(path, "corrupt gzip data near byte " + std::to_string(in_pos) + " (" +
                     (stream.msg ? stream.msg : "zlib error " + std::to_string(status)) + ")");
    }
  }
  out.resize(out_pos);
  return out;
}

}  // namespace trivcon::io
