#include "patrolmap/core/image_header.h"

namespace patrolmap {
namespace {

std::int64_t BigEndian(const unsigned char* bytes, int count) {
  std::int64_t value = 0;
  for (int k = 0; k < count; ++k) value = value << 8 | bytes[k];
  return value;
}

bool PngSize(const unsigned char* data, std::size_t size, std::int64_t* width, std::int64_t* height) {
  if (size < 24 || data[0] != 0x89 || data[1] != 'P' || data[2] != 'N' || data[3] != 'G') return false;
  *width = BigEndian(data + 16, 4), *height = BigEndian(data + 20, 4);
  return true;
}

// Walks the JPEG's segments to its frame header.
bool JpegSize(const unsigned char* data, std::size_t size, std::int64_t* width, std::int64_t* height) {
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8) return false;
  std::size_t i = 2;  // after the start-of-image marker
  while (i + 4 <= size) {
    if (data[i] != 0xFF) return false;
    const unsigned char marker = data[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // segments without a length
      i += 2;
      continue;
    }
    if (marker == 0xDA || marker == 0xD9) return false;  // the scan or the end before a frame header
    const std::size_t length = static_cast<std::size_t>(BigEndian(data + i + 2, 2));
    const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame) {
      if (i + 9 > size) return false;
      *height = BigEndian(data + i + 5, 2), *width = BigEndian(data + i + 7, 2);
      return true;
    }
    if (length < 2) return false;
    i += 2 + length;
  }
  return false;
}

}  // namespace

bool DeclaredImageSize(const unsigned char* data, std::size_t size, std::int64_t* width, std::int64_t* height) {
  return PngSize(data, size, width, height) || JpegSize(data, size, width, height);
}

}  // namespace patrolmap
