// What a flight id may hold. Ids name output folders (OUT/<id>/) and fill CSV, XML, HTML and JSON fields, so the
// one rule below keeps each of them well formed: valid UTF-8, no control characters, commas, double quotes or path
// separators, not "." or "..", never empty, at most kMaxFlightIdLength bytes.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace patrolmap {

// Longest flight id kept [bytes].
constexpr std::size_t kMaxFlightIdLength = 200;

// Whether `text` is valid UTF-8 (no stray continuation bytes, no overlong forms, no surrogates).
bool IsValidUtf8(std::string_view text);

// Whether `id` follows the rule above. Maps written before the rule may hold ids up to `max_length` bytes.
bool IsValidFlightId(std::string_view id, std::size_t max_length = kMaxFlightIdLength);

// `raw` made to follow the rule: each byte the rule forbids becomes '_' (a byte of a broken UTF-8 sequence too),
// "." and ".." become "_" and "__", "" becomes "flight"; an id longer than kMaxFlightIdLength keeps its start,
// cut at a character, and ends in a digest of the whole, so two long ids with one start stay two ids.
std::string CleanedFlightId(std::string_view raw);

// `raw` with each control character and each byte of a broken UTF-8 sequence made '_' (a log's path as a map
// keeps it, so every page shows it).
std::string PrintableText(std::string_view raw);

}  // namespace patrolmap
