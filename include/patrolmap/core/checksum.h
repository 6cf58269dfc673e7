// A fast 64-bit checksum for file sections (not cryptographic): detects
// truncation and corruption at memory speed.
#pragma once

#include <cstddef>
#include <cstdint>

namespace patrolmap {

constexpr std::uint64_t kChecksumSeed = 0x9E3779B97F4A7C15ull;

// Folds `size` bytes into `hash`; chain calls to checksum data in pieces.
std::uint64_t Checksum(const char* data, std::size_t size, std::uint64_t hash = kChecksumSeed);

// Checksum(data, size) of bytes that arrive in pieces (a map section streamed to its file): the same value
// for any split, given the total size up front.
class ChecksumStream {
 public:
  explicit ChecksumStream(std::size_t total_size, std::uint64_t hash = kChecksumSeed);
  void Add(const char* data, std::size_t size);
  std::uint64_t Finish() const;  // after the last piece

 private:
  std::uint64_t hash_;
  char pending_[8] = {};  // the start of a word split across pieces
  std::size_t pending_size_ = 0;
};

}  // namespace patrolmap
