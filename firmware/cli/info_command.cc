// refocus info: what a photo carries for refocusing, as plain `key: value` lines.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/cli/commands.h"
#include "firmware/cli/options.h"
#include "firmware/codecs/image_file.h"
#include "firmware/refocusable/depth_image.h"
#include "firmware/refocusable/dynamic_depth.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "firmware/storage/input_file.h"

namespace lb::cli {
namespace {

const char kUsage[] =
    "usage: refocus info FILE.jpg\n"
    "\n"
    "Prints what a photo carries for refocusing, one `key: value` line each: the formats found\n"
    "(GDepth, GImage, GFocus: the refocusable JPEG of `refocus run` and of phones' Lens Blur;\n"
    "DynamicDepth: Dynamic Depth 1.0, as Pixel phones and `refocus run` write it), the primary\n"
    "image's size, the depth map refocusing uses (the format it comes from, its size, format,\n"
    "near, far, units, mime and colour type) and its confidence map (GDepth:Confidence or\n"
    "Dynamic Depth's confidence item), the focus (GFocus) and the all-in-focus original\n"
    "(GImage or Dynamic Depth's Original item); then Dynamic Depth's own items, depth, range,\n"
    "units, original and confidence map.\n"
    "Exit status: 0 when the file carries a depth map; 1 when it carries none (the lines then end\n"
    "with `formats: none`) or cannot be read (one line on stderr); 2 for a usage error.\n";

// As the reader's own: a refocusable JPEG holds two full-size JPEGs and the depth map.
constexpr size_t kMaxFileBytes = size_t{512} << 20;

// Room for whatever the file holds, in vectors: `info` is a host tool.
class Memory final : public RefocusableMemory {
 public:
  ExtendedXmpChunk* Chunks(size_t count) override {
    chunks_.resize(count + 1);
    return chunks_.data();
  }
  uint8_t* Bytes(Part part, size_t count) override {
    std::vector<uint8_t>& v = bytes_[static_cast<int>(part)];
    v.resize(count + 1);
    return v.data();
  }

 private:
  std::vector<ExtendedXmpChunk> chunks_;
  std::vector<uint8_t> bytes_[4];
};

std::string Text(std::string_view v) { return std::string(v.data(), v.size()); }

// An item's image size ("WxH mime, N bytes"), or why its header does not read.
std::string ItemLine(const DynamicDepthItem& item, bool jpeg_only) {
  char line[160];
  if (jpeg_only) {
    ImageFileInfo info;
    const Status s = ProbeImageMemory(item.data, item.length, "item", &info, ImageFileType::kJpeg);
    if (!s.ok()) return s.message();
    snprintf(line, sizeof(line), "%dx%d", info.width, info.height);
  } else {
    DepthImageHeader h;
    const Status s = ProbeDepthImage(item.data, item.length, item.mime, "item", &h);
    if (!s.ok()) return s.message();
    snprintf(line, sizeof(line), "%dx%d %d-bit %s", h.width, h.height, h.bits, h.colour);
  }
  return std::string(line) + " " + Text(item.mime) + ", " + std::to_string(item.length) + " bytes";
}

// Dynamic Depth's own view of the file, beside GDepth's or as the one refocusing uses.
void PrintDynamicDepth(const DynamicDepthFields& dd) {
  printf("dynamic depth items:");
  for (size_t i = 0; i < dd.item_count; ++i) {
    const DynamicDepthItem& item = dd.items[i];
    const int32_t n = static_cast<int32_t>(i);
    const char* role = n == 0               ? "primary"
                       : n == dd.depth      ? "depth"
                       : n == dd.original   ? "original"
                       : n == dd.confidence ? "confidence"
                                            : "other";
    printf("%s %s %s %zu", i == 0 ? "" : ",", role, Text(item.mime).c_str(), item.length);
  }
  printf("\n");
  printf("dynamic depth depth: %s\n", ItemLine(dd.items[dd.depth], false).c_str());
  printf("dynamic depth range: %s near %g far %g units %s\n", Text(dd.format).c_str(),
         dd.near_depth, dd.far_depth, dd.units.empty() ? "not given" : Text(dd.units).c_str());
  printf("dynamic depth original: %s\n",
         dd.original >= 0 ? ItemLine(dd.items[dd.original], true).c_str() : "none");
  printf("dynamic depth confidence: %s\n",
         dd.confidence >= 0 ? ItemLine(dd.items[dd.confidence], false).c_str() : "none");
}

}  // namespace

int InfoCommand(int argc, char** argv) {
  if (argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
    fputs(kUsage, stdout);
    return 0;
  }
  if (argc != 2) return UsageError("info", "give exactly one file");
  if (argv[1][0] == '-') return UsageError("info", std::string("unknown option '") + argv[1] + "'");
  const char* path = argv[1];
  std::vector<uint8_t> bytes;
  Status s = ReadInputFile(path, kMaxFileBytes, &bytes);
  if (!s.ok()) return Fail(s.message());
  Memory memory;
  RefocusableFields f;
  s = ReadRefocusableFields(bytes.data(), bytes.size(), path, memory, &f);
  if (s.code() == Code::kNotFound) {
    ImageFileInfo primary;
    s = ProbeImageMemory(bytes.data(), bytes.size(), path, &primary);
    if (!s.ok()) return Fail(s.message());
    printf("file: %s\nprimary: %dx%d\nformats: none\n", path, primary.width, primary.height);
    return 1;
  }
  if (!s.ok()) return Fail(s.message());

  char what[300];
  DepthPngName(path, what, sizeof(what));
  DepthImageHeader depth;
  s = ProbeDepthImage(f.depth_png, f.depth_png_size, f.depth_mime, what, &depth);
  if (!s.ok()) return Fail(s.message());
  // Dynamic Depth read on its own, whether or not GDepth is what refocusing uses.
  Memory dd_memory;
  RefocusableFields packets;
  std::string_view main, extended;
  DynamicDepthFields dd;
  Status dd_status = Status(Code::kNotFound, "none");
  if (ReadXmpPackets(bytes.data(), bytes.size(), path, dd_memory, &packets, &main, &extended)
          .ok() &&
      HasDynamicDepth(main, extended)) {
    dd_status = ReadDynamicDepthFields(bytes.data(), bytes.size(), path, main, extended,
                                       packets.width, packets.height, &dd);
  }
  ImageFileInfo original;
  if (f.image != nullptr) {
    s = ProbeImageMemory(f.image, f.image_size, "GImage", &original, ImageFileType::kJpeg);
    if (!s.ok()) return Fail(s.Prefix("%s: ", path).message());
  }

  printf("file: %s\n", path);
  printf("formats:%s%s%s%s\n", f.dynamic_depth ? "" : " GDepth",
         f.image != nullptr && !f.dynamic_depth ? " GImage" : "", f.has_focus ? " GFocus" : "",
         dd_status.code() != Code::kNotFound ? " DynamicDepth" : "");
  printf("primary: %dx%d\n", f.width, f.height);
  printf("depth from: %s\n", f.dynamic_depth ? "Dynamic Depth" : "GDepth");
  printf("depth: %dx%d\n", depth.width, depth.height);
  printf("depth format: %s\n", Text(f.depth_format).c_str());
  printf("depth near: %g\n", f.near_depth);
  printf("depth far: %g\n", f.far_depth);
  printf("depth units: %s\n", f.depth_units.empty() ? "not given" : Text(f.depth_units).c_str());
  printf("depth mime: %s\n", Text(f.depth_mime).c_str());
  printf("depth colour: %d-bit %s\n", depth.bits, depth.colour);
  if (f.confidence != nullptr) {
    printf("confidence: %dx%d %s, %zu bytes (%s)\n", f.confidence_width, f.confidence_height,
           Text(f.confidence_mime).c_str(), f.confidence_size,
           f.dynamic_depth ? "Dynamic Depth" : "GDepth");
  } else if (!f.confidence_ignored.ok()) {
    printf("confidence: ignored: %s\n", f.confidence_ignored.message());
  } else {
    printf("confidence: none\n");
  }
  if (f.has_focus) {
    printf("focus point: %.4f,%.4f\n", f.focus.focal_point_x, f.focus.focal_point_y);
    printf("focus distance: %g\n", f.focus.focal_distance);
    printf("blur at infinity: %g (%.1f px)\n", f.focus.blur_at_infinity,
           f.focus.blur_at_infinity * f.width);
  } else {
    printf("focus: none\n");
  }
  if (f.image != nullptr) {
    printf("original: %dx%d %s (%s)\n", original.width, original.height, Text(f.image_mime).c_str(),
           f.dynamic_depth ? "Dynamic Depth Original" : "GImage");
  } else {
    printf("original: none (refocusing starts from the photo, already blurred)\n");
  }
  if (dd_status.ok()) {
    PrintDynamicDepth(dd);
  } else if (dd_status.code() != Code::kNotFound) {
    printf("dynamic depth: refused: %s\n", dd_status.message());
  }
  return 0;
}

}  // namespace lb::cli
