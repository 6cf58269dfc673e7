// The size an image file declares in its header, read without decoding it: a crafted header that declares a
// huge image must be refused before a decoder allocates for it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace patrolmap {

// The width and height PNG bytes (IHDR) or JPEG bytes (the first start-of-frame segment, SOF0-SOF15) declare; false
// for other kinds, or when the bytes end, or a JPEG's scan starts, before the size.
bool DeclaredImageSize(const unsigned char* data, std::size_t size, std::int64_t* width, std::int64_t* height);

}  // namespace patrolmap
