// Base64 (RFC 4648, with padding) and MD5 digests in hex, for the XMP of the refocusable JPEG.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "algo/core/status.h"

namespace lb {

// Appends the base64 text of `data` to `out`.
void Base64Encode(const uint8_t* data, size_t size, std::string* out);

// Decodes base64 text, skipping XML whitespace; any other character outside the alphabet, a
// misplaced '=' or a length that is not a whole number of quads is an error.
Status Base64Decode(const char* text, size_t size, std::vector<uint8_t>* out);
// The same into the caller's `out` of `capacity` bytes (kOutOfMemory, checked before decoding,
// when the text could need more); `*written` is how many bytes it holds.
Status Base64DecodeInto(const char* text, size_t size, uint8_t* out, size_t capacity,
                        size_t* written);
// The most bytes `size` characters of base64 can decode to.
inline size_t Base64MaxDecoded(size_t size) { return size / 4 * 3; }

// The MD5 of `data` as 32 upper-case hex digits and a terminating NUL (xmpNote:HasExtendedXMP).
void Md5Hex(const uint8_t* data, size_t size, char out[33]);

}  // namespace lb
