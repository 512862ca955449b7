// libFuzzer target: the refocusable-JPEG reader (segments, extended-XMP reassembly, XMP fields,
// base64, the depth PNG). The first byte picks how the rest is used, so mutations reach the XMP
// text without first having to rediscover JPEG framing and MD5s:
//   0: the whole input is the file;
//   1: the input is the main XMP packet of a minimal JPEG;
//   2: the input up to the first NUL is the main packet, the rest the extended packet, chunked
//      with the right GUID and offsets (and its MD5 announced unless the main packet has one).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/refocusable/base64.h"
#include "firmware/refocusable/refocusable_reader.h"

namespace {

#define XMP_REQUIRE(cond)                               \
  do {                                                  \
    if (!(cond)) {                                      \
      fprintf(stderr, "broken invariant: %s\n", #cond); \
      abort();                                          \
    }                                                   \
  } while (0)

void Segment(uint8_t marker, const std::string& payload, std::vector<uint8_t>* out) {
  const size_t n = payload.size() > 65533 ? 65533 : payload.size();
  out->push_back(0xFF);
  out->push_back(marker);
  out->push_back(static_cast<uint8_t>((n + 2) >> 8));
  out->push_back(static_cast<uint8_t>(n + 2));
  out->insert(out->end(), payload.begin(), payload.begin() + static_cast<ptrdiff_t>(n));
}

std::string BigEndian32(uint32_t v) {
  const char b[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                     static_cast<char>(v >> 8), static_cast<char>(v)};
  return std::string(b, 4);
}

std::vector<uint8_t> Wrap(const std::string& main, const std::string* extended) {
  std::vector<uint8_t> jpeg = {0xFF, 0xD8};
  std::string packet = main;
  if (extended != nullptr) {
    char md5[33];
    lb::Md5Hex(reinterpret_cast<const uint8_t*>(extended->data()), extended->size(), md5);
    if (packet.find("HasExtendedXMP") == std::string::npos) {
      packet = std::string("<x:xmpmeta xmlns:xmpNote=\"") + lb::kXmpNoteNs +
               "\" xmpNote:HasExtendedXMP=\"" + md5 + "\"/>" + packet;
    }
    for (size_t offset = 0; offset < extended->size() || offset == 0; offset += 65000) {
      std::string chunk(lb::kExtendedXmpSignature, sizeof(lb::kExtendedXmpSignature));
      chunk += std::string(md5, 32) + BigEndian32(static_cast<uint32_t>(extended->size())) +
               BigEndian32(static_cast<uint32_t>(offset)) + extended->substr(offset, 65000);
      Segment(0xE1, chunk, &jpeg);
      if (extended->empty()) break;
    }
  }
  Segment(0xE1, std::string(lb::kXmpSignature, sizeof(lb::kXmpSignature)) + packet, &jpeg);
  Segment(0xDA, std::string("\x01\x01\x00\x00\x3F\x00", 6), &jpeg);
  jpeg.push_back(0xFF);
  jpeg.push_back(0xD9);
  return jpeg;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const int mode = data[0] % 3;
  const std::string rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  std::vector<uint8_t> file;
  if (mode == 0) {
    file.assign(data + 1, data + size);
  } else if (mode == 1) {
    file = Wrap(rest, nullptr);
  } else {
    const size_t nul = rest.find('\0');
    const std::string main = rest.substr(0, nul);
    const std::string extended = nul == std::string::npos ? std::string() : rest.substr(nul + 1);
    file = Wrap(main, &extended);
  }
  lb::RefocusableImage image;
  const lb::Status status = lb::ReadRefocusable(file.data(), file.size(), "fuzz.jpg", &image);
  if (!status.ok()) {
    XMP_REQUIRE(strncmp(status.message(), "fuzz.jpg: ", 10) == 0);
    return 0;
  }
  const lb::GrayPng& depth = image.depth;
  XMP_REQUIRE(depth.width >= 1 && depth.width <= 8192 && depth.height >= 1 && depth.height <= 8192);
  XMP_REQUIRE(depth.bits == 8 || depth.bits == 16);
  XMP_REQUIRE(depth.values.size() == static_cast<size_t>(depth.width) * depth.height);
  XMP_REQUIRE(image.xmp.depth.width == 0 || image.xmp.depth.width == depth.width);
  XMP_REQUIRE(image.xmp.depth.far_depth > image.xmp.depth.near_depth);
  std::vector<uint16_t> disp;
  lb::DisparityRange range;
  if (lb::DisparityFromDepth(image, &disp, &range).ok()) {
    XMP_REQUIRE(disp.size() == depth.values.size());
    for (uint16_t d : disp) XMP_REQUIRE(d >= range.min_q8 && d <= range.max_q8);
  }
  return 0;
}
