#include "patrolmap/core/checksum.h"

#include <cstring>

namespace patrolmap {

std::uint64_t Checksum(const char* data, std::size_t size, std::uint64_t hash) {
  hash ^= size;
  std::size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, data + i, 8);
    hash = (hash ^ word) * 0xFF51AFD7ED558CCDull;
    hash ^= hash >> 29;
  }
  for (; i < size; ++i) hash = (hash ^ static_cast<unsigned char>(data[i])) * 0x100000001B3ull;
  return hash;
}

}  // namespace patrolmap
