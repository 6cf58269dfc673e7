#include "patrolmap/core/flight_id.h"

#include <cstdint>
#include <cstdio>

#include "patrolmap/core/checksum.h"
#include "patrolmap/core/csv.h"

namespace patrolmap {
namespace {

// Bytes of the UTF-8 character that starts at `text[i]`, or 0 when none does.
std::size_t CharacterLength(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  if (lead < 0x80) return 1;
  std::size_t length = 0;
  std::uint32_t code = 0, least = 0;
  if ((lead & 0xe0) == 0xc0) {
    length = 2, code = lead & 0x1f, least = 0x80;
  } else if ((lead & 0xf0) == 0xe0) {
    length = 3, code = lead & 0x0f, least = 0x800;
  } else if ((lead & 0xf8) == 0xf0) {
    length = 4, code = lead & 0x07, least = 0x10000;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xc0) != 0x80) return 0;
    code = code << 6 | (byte(i + k) & 0x3f);
  }
  if (code < least || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return 0;
  return length;
}

bool ForbiddenByte(char c) { return BreaksCsvField(c) || c == '/' || c == '\\'; }

}  // namespace

bool IsValidUtf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t length = CharacterLength(text, i);
    if (length == 0) return false;
    i += length;
  }
  return true;
}

bool IsValidFlightId(std::string_view id, std::size_t max_length) {
  if (id.empty() || id.size() > max_length || id == "." || id == "..") return false;
  for (char c : id) {
    if (ForbiddenByte(c)) return false;
  }
  return IsValidUtf8(id);
}

// `raw` with each byte of a broken UTF-8 sequence, and each one `forbidden` says, made '_'.
template <typename Forbidden>
std::string Replaced(std::string_view raw, Forbidden forbidden) {
  std::string text;
  for (std::size_t i = 0; i < raw.size();) {
    const std::size_t length = CharacterLength(raw, i);
    if (length == 0 || (length == 1 && forbidden(raw[i]))) {
      text += '_', ++i;
      continue;
    }
    text.append(raw.substr(i, length));
    i += length;
  }
  return text;
}

std::string PrintableText(std::string_view raw) {
  return Replaced(raw, [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
}

std::string CleanedFlightId(std::string_view raw) {
  const std::string id = Replaced(raw, ForbiddenByte);
  if (id.empty()) return "flight";
  if (id == "." || id == "..") return std::string(id.size(), '_');
  if (id.size() <= kMaxFlightIdLength) return id;
  char digest[18];
  std::snprintf(digest, sizeof(digest), "-%016llx", static_cast<unsigned long long>(Checksum(raw.data(), raw.size())));
  std::size_t keep = kMaxFlightIdLength - (sizeof(digest) - 1);
  while (keep > 0 && (static_cast<unsigned char>(id[keep]) & 0xc0) == 0x80) --keep;  // not inside a character
  return id.substr(0, keep) + digest;
}

}  // namespace patrolmap
