// refocus info: what a photo carries for refocusing, as plain `key: value` lines.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/cli/commands.h"
#include "firmware/cli/options.h"
#include "firmware/codecs/image_file.h"
#include "firmware/refocusable/depth_image.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "firmware/storage/input_file.h"

namespace lb::cli {
namespace {

const char kUsage[] =
    "usage: refocus info FILE.jpg\n"
    "\n"
    "Prints what a photo carries for refocusing, one `key: value` line each: the formats found\n"
    "(GDepth, GImage, GFocus: the refocusable JPEG of `refocus run` and of phones' Lens Blur),\n"
    "the primary image's size, the depth map's size, format, near, far, units, mime and colour\n"
    "type, the focus (GFocus) and the all-in-focus original (GImage).\n"
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
  std::vector<uint8_t> bytes_[3];
};

std::string Text(std::string_view v) { return std::string(v.data(), v.size()); }

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
  ImageFileInfo original;
  if (f.image != nullptr) {
    s = ProbeImageMemory(f.image, f.image_size, "GImage", &original, ImageFileType::kJpeg);
    if (!s.ok()) return Fail(s.Prefix("%s: ", path).message());
  }

  printf("file: %s\n", path);
  printf("formats: GDepth%s%s\n", f.image != nullptr ? " GImage" : "",
         f.has_focus ? " GFocus" : "");
  printf("primary: %dx%d\n", f.width, f.height);
  printf("depth: %dx%d\n", depth.width, depth.height);
  printf("depth format: %s\n", Text(f.depth_format).c_str());
  printf("depth near: %g\n", f.near_depth);
  printf("depth far: %g\n", f.far_depth);
  printf("depth units: %s\n", f.depth_units.empty() ? "not given" : Text(f.depth_units).c_str());
  printf("depth mime: %s\n", Text(f.depth_mime).c_str());
  printf("depth colour: %d-bit %s\n", depth.bits, depth.colour);
  if (f.has_focus) {
    printf("focus point: %.4f,%.4f\n", f.focus.focal_point_x, f.focus.focal_point_y);
    printf("focus distance: %g\n", f.focus.focal_distance);
    printf("blur at infinity: %g (%.1f px)\n", f.focus.blur_at_infinity,
           f.focus.blur_at_infinity * f.width);
  } else {
    printf("focus: none\n");
  }
  if (f.image != nullptr) {
    printf("original: %dx%d %s\n", original.width, original.height, Text(f.image_mime).c_str());
  } else {
    printf("original: none (refocusing starts from the photo, already blurred)\n");
  }
  return 0;
}

}  // namespace lb::cli
