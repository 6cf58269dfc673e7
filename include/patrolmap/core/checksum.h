// A fast 64-bit checksum for file sections (not cryptographic): detects
// truncation and corruption at memory speed.
#pragma once

#include <cstddef>
#include <cstdint>

namespace patrolmap {

constexpr std::uint64_t kChecksumSeed = 0x9E3779B97F4A7C15ull;

// Folds `size` bytes into `hash`; chain calls to checksum data in pieces.
std::uint64_t Checksum(const char* data, std::size_t size, std::uint64_t hash = kChecksumSeed);

}  // namespace patrolmap
