// Rewrites the checksums of a damaged map or vocabulary file, so the damage reaches the parsers behind
// them (the damage tests and the fuzzing harnesses use it).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include "patrolmap/core/checksum.h"

namespace patrolmap::testing {

// Every section checksum of a map file (graph/map_file.h), as far as its section headers can be walked.
inline void RecomputeMapChecksums(std::string* bytes) {
  std::size_t position = 16;  // magic, version, section count
  while (position + 20 <= bytes->size()) {
    std::uint64_t length = 0;
    std::memcpy(&length, bytes->data() + position + 4, 8);
    if (length > bytes->size() - position - 20) return;
    const std::uint64_t checksum = Checksum(bytes->data() + position + 20, length);
    std::memcpy(bytes->data() + position + 12, &checksum, 8);
    position += 20 + length;
  }
}

// The checksum of a vocabulary file (vocab/vocabulary_file.cc) over the layout its header describes, when
// that layout fits the file; otherwise it is left (the size check refuses such a file first).
inline void RecomputeVocabularyChecksum(std::string* bytes) {
  constexpr std::size_t kHeader = 36;  // magic, version, 5 counts, scale
  if (bytes->size() < kHeader + 8) return;
  std::uint32_t fields[6];
  std::memcpy(fields, bytes->data() + 8, sizeof(fields));
  const std::uint64_t nodes = fields[4], words = fields[5], dimension = fields[3];
  const std::uint64_t pieces[] = {4 * nodes, 2 * nodes, 4 * nodes, 4 * nodes, nodes * dimension, 4 * words, 4 * words};
  std::uint64_t total = kHeader + 8;
  for (std::uint64_t piece : pieces) total += piece;
  if (total != bytes->size()) return;
  std::uint64_t checksum = Checksum(bytes->data() + 8, kHeader - 8);
  std::size_t position = kHeader;
  for (std::uint64_t piece : pieces) {
    checksum = Checksum(bytes->data() + position, piece, checksum);
    position += piece;
  }
  std::memcpy(bytes->data() + position, &checksum, 8);
}

}  // namespace patrolmap::testing
