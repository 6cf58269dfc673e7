#include "patrolmap/core/checksum.h"

#include <cstring>

namespace patrolmap {
namespace {

std::uint64_t FoldWord(std::uint64_t hash, const char* data) {
  std::uint64_t word;
  std::memcpy(&word, data, 8);
  hash = (hash ^ word) * 0xFF51AFD7ED558CCDull;
  return hash ^ (hash >> 29);
}

std::uint64_t FoldByte(std::uint64_t hash, char byte) {
  return (hash ^ static_cast<unsigned char>(byte)) * 0x100000001B3ull;
}

}  // namespace

std::uint64_t Checksum(const char* data, std::size_t size, std::uint64_t hash) {
  hash ^= size;
  std::size_t i = 0;
  for (; i + 8 <= size; i += 8) hash = FoldWord(hash, data + i);
  for (; i < size; ++i) hash = FoldByte(hash, data[i]);
  return hash;
}

ChecksumStream::ChecksumStream(std::size_t total_size, std::uint64_t hash) : hash_(hash ^ total_size) {}

void ChecksumStream::Add(const char* data, std::size_t size) {
  while (size > 0 && pending_size_ > 0) {  // complete the word split across pieces
    pending_[pending_size_++] = *data++;
    --size;
    if (pending_size_ == 8) hash_ = FoldWord(hash_, pending_), pending_size_ = 0;
  }
  for (; size >= 8; data += 8, size -= 8) hash_ = FoldWord(hash_, data);
  for (; size > 0; --size) pending_[pending_size_++] = *data++;
}

std::uint64_t ChecksumStream::Finish() const {
  std::uint64_t hash = hash_;
  for (std::size_t i = 0; i < pending_size_; ++i) hash = FoldByte(hash, pending_[i]);
  return hash;
}

}  // namespace patrolmap
