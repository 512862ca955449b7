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

// The MD5 of `data` as 32 upper-case hex digits and a terminating NUL (xmpNote:HasExtendedXMP).
void Md5Hex(const uint8_t* data, size_t size, char out[33]);

}  // namespace lb
