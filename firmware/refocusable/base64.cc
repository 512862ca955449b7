#include "firmware/refocusable/base64.h"

#include <md5.h>

namespace lb {
namespace {

const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// 0..63 for alphabet characters, -1 for whitespace, -2 for '=', -3 for anything else.
int Classify(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  if (c == ' ' || c == '\t' || c == '\r' || c == '\n') return -1;
  if (c == '=') return -2;
  return -3;
}

}  // namespace

void Base64Encode(const uint8_t* data, size_t size, std::string* out) {
  out->reserve(out->size() + (size + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= size; i += 3) {
    const uint32_t v = (uint32_t{data[i]} << 16) | (uint32_t{data[i + 1]} << 8) | data[i + 2];
    out->push_back(kAlphabet[v >> 18]);
    out->push_back(kAlphabet[(v >> 12) & 63]);
    out->push_back(kAlphabet[(v >> 6) & 63]);
    out->push_back(kAlphabet[v & 63]);
  }
  if (i < size) {
    const bool two = i + 1 < size;
    const uint32_t v = (uint32_t{data[i]} << 16) | (two ? uint32_t{data[i + 1]} << 8 : 0u);
    out->push_back(kAlphabet[v >> 18]);
    out->push_back(kAlphabet[(v >> 12) & 63]);
    out->push_back(two ? kAlphabet[(v >> 6) & 63] : '=');
    out->push_back('=');
  }
}

Status Base64DecodeInto(const char* text, size_t size, uint8_t* out, size_t capacity,
                        size_t* written) {
  *written = 0;
  if (Base64MaxDecoded(size) > capacity) {
    return Status(Code::kOutOfMemory, "base64: %zu characters, more than %zu bytes may hold", size,
                  capacity);
  }
  size_t n = 0;
  uint32_t quad = 0;
  int have = 0;     // sextets in `quad`
  int padding = 0;  // '=' seen; only more '=' and whitespace may follow
  for (size_t i = 0; i < size; ++i) {
    const int v = Classify(text[i]);
    if (v == -1) continue;
    if (v == -3) {
      return Status(Code::kCorruptData, "base64: byte 0x%02X at offset %zu is not base64",
                    static_cast<unsigned>(static_cast<uint8_t>(text[i])), i);
    }
    if (v == -2) {
      // '=' only as the third or fourth character of the last quad.
      if (have + padding < 2 || have + padding >= 4) {
        return Status(Code::kCorruptData, "base64: misplaced '=' at offset %zu", i);
      }
      ++padding;
      continue;
    }
    if (padding > 0) return Status(Code::kCorruptData, "base64: data after '=' at offset %zu", i);
    quad = (quad << 6) | static_cast<uint32_t>(v);
    if (++have == 4) {
      out[n++] = static_cast<uint8_t>(quad >> 16);
      out[n++] = static_cast<uint8_t>(quad >> 8);
      out[n++] = static_cast<uint8_t>(quad);
      quad = 0;
      have = 0;
    }
  }
  if (padding > 0 && have + padding != 4) {
    return Status(Code::kCorruptData, "base64: incomplete padding at the end");
  }
  if (have == 1 || (have != 0 && padding == 0)) {
    return Status(Code::kCorruptData, "base64: %zu characters are not whole quads", size);
  }
  if (have == 2) out[n++] = static_cast<uint8_t>(quad >> 4);
  if (have == 3) {
    out[n++] = static_cast<uint8_t>(quad >> 10);
    out[n++] = static_cast<uint8_t>(quad >> 2);
  }
  *written = n;
  return Status::Ok();
}

Status Base64Decode(const char* text, size_t size, std::vector<uint8_t>* out) {
  out->resize(Base64MaxDecoded(size));
  size_t written = 0;
  Status s = Base64DecodeInto(text, size, out->data(), out->size(), &written);
  out->resize(written);
  return s;
}

void Md5Hex(const uint8_t* data, size_t size, char out[33]) {
  MD5_CTX ctx;
  MD5Init(&ctx);
  MD5Update(&ctx, data, size);
  uint8_t digest[MD5_DIGEST_LENGTH];
  MD5Final(digest, &ctx);
  static const char kHex[] = "0123456789ABCDEF";
  for (int i = 0; i < MD5_DIGEST_LENGTH; ++i) {
    out[2 * i] = kHex[digest[i] >> 4];
    out[2 * i + 1] = kHex[digest[i] & 15];
  }
  out[32] = '\0';
}

}  // namespace lb
