// libFuzzer target: the Dynamic Depth reader (the Container directory, the items sliced from the
// end of the file by their lengths, the DepthMap and Image elements, the items' headers, then the
// depth decoded through the refocusable reader). The first byte picks how the rest is used:
//   0: the whole input is the file;
//   1: the input up to the first NUL is the main XMP packet of a minimal primary JPEG, the rest
//      the bytes appended after its EOI (the items), so mutations reach the directory and the
//      lengths without rediscovering JPEG framing.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/refocusable/dynamic_depth.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "tests/fuzz/decode_check.h"

namespace {

#define DD_REQUIRE(cond) LB_FUZZ_REQUIRE(cond, "fuzz_dd")

void Segment(uint8_t marker, const std::string& payload, std::vector<uint8_t>* out) {
  const size_t n = payload.size() > 65533 ? 65533 : payload.size();
  const uint8_t head[4] = {0xFF, marker, static_cast<uint8_t>((n + 2) >> 8),
                           static_cast<uint8_t>(n + 2)};
  out->insert(out->end(), head, head + 4);
  out->insert(out->end(), payload.begin(), payload.begin() + static_cast<ptrdiff_t>(n));
}

void CheckFields(const std::vector<uint8_t>& file) {
  lb::RefocusableBuffers memory;  // no extended XMP here: the directory alone
  lb::RefocusableFields fields;
  std::string_view main, extended;
  if (!lb::ReadXmpPackets(file.data(), file.size(), "fuzz.jpg", memory, &fields, &main, &extended)
           .ok()) {
    return;
  }
  lb::DynamicDepthFields dd;
  const lb::Status status = lb::ReadDynamicDepthFields(file.data(), file.size(), "fuzz.jpg", main,
                                                       extended, fields.width, fields.height, &dd);
  if (!status.ok()) {
    DD_REQUIRE(strncmp(status.message(), "fuzz.jpg: ", 10) == 0);
    DD_REQUIRE(strchr(status.message(), '\n') == nullptr);
    return;
  }
  // The items tile the file: the primary from its start, each next one where the last ends.
  DD_REQUIRE(dd.item_count >= 2 && dd.item_count <= lb::kMaxDynamicDepthItems);
  DD_REQUIRE(dd.items[0].data == file.data());
  const uint8_t* at = file.data() + dd.items[0].length + dd.items[0].padding;
  for (size_t i = 1; i < dd.item_count; ++i) {
    DD_REQUIRE(dd.items[i].data == at);
    at += dd.items[i].length + dd.items[i].padding;
  }
  DD_REQUIRE(at == file.data() + file.size());
  DD_REQUIRE(dd.depth >= 1 && static_cast<size_t>(dd.depth) < dd.item_count);
  DD_REQUIRE(dd.depth_header.width >= 1 && dd.depth_header.width <= dd.depth_max_side);
  DD_REQUIRE(dd.depth_header.height >= 1 && dd.depth_header.height <= dd.depth_max_side);
  DD_REQUIRE(dd.far_depth > dd.near_depth);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::vector<uint8_t> file;
  if (data[0] % 2 == 0) {
    file.assign(data + 1, data + size);
  } else {
    const std::string rest(reinterpret_cast<const char*>(data) + 1, size - 1);
    const size_t nul = rest.find('\0');
    file = {0xFF, 0xD8};
    Segment(0xE1, std::string(lb::kXmpSignature, sizeof(lb::kXmpSignature)) + rest.substr(0, nul),
            &file);
    Segment(0xDA, std::string("\x01\x01\x00\x00\x3F\x00", 6), &file);
    file.push_back(0xFF);
    file.push_back(0xD9);
    if (nul != std::string::npos) file.insert(file.end(), rest.begin() + nul + 1, rest.end());
  }
  CheckFields(file);
  lb::RefocusableImage image;
  const lb::Status status = lb::ReadRefocusable(file.data(), file.size(), "fuzz.jpg", &image);
  if (!status.ok()) {
    DD_REQUIRE(strncmp(status.message(), "fuzz.jpg: ", 10) == 0);
    return 0;
  }
  const lb::GrayPng& depth = image.depth;
  DD_REQUIRE(depth.width >= 1 && depth.width <= 8192 && depth.height >= 1 && depth.height <= 8192);
  DD_REQUIRE(depth.values.size() == static_cast<size_t>(depth.width) * depth.height);
  return 0;
}
