#include "firmware/refocusable/refocusable_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "firmware/codecs/exif.h"
#include "firmware/refocusable/base64.h"
#include "firmware/refocusable/depth_image.h"
#include "firmware/refocusable/dynamic_depth.h"
#include "firmware/refocusable/xmp_lookup.h"

namespace lb {
namespace {

constexpr int32_t kMaxDepthSide = 8192;
// Two 8192x8192 JPEGs (the photo and its original) at the highest quality, and the depth map.
constexpr size_t kMaxFileBytes = size_t{512} << 20;
constexpr size_t kExtendedHeader = sizeof(kExtendedXmpSignature) + 32 + 4 + 4;

uint32_t BigEndian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

bool StartsWith(const uint8_t* p, size_t n, const char* sig, size_t sig_size) {
  return n >= sig_size && memcmp(p, sig, sig_size) == 0;
}

// Looks a field up in the main packet, then in the extended one. `prefix` (the usual one) only
// names the field in messages; lookups go by namespace.
class Fields {
 public:
  Fields(const char* name, std::string_view main, std::string_view extended)
      : name_(name), main_(main), extended_(extended) {}

  bool Has(const char* uri, const char* /*prefix*/, const char* field) const {
    std::string_view v;
    return Lookup(uri, field, &v);
  }

  Status Text(const char* uri, const char* prefix, const char* field, std::string_view* v) const {
    if (!Lookup(uri, field, v)) {
      return Status(Code::kCorruptData, "%s: %s:%s missing", name_, prefix, field);
    }
    return Status::Ok();
  }

  Status Number(const char* uri, const char* prefix, const char* field, double* out) const {
    std::string_view v;
    LB_RETURN_IF_ERROR(Text(uri, prefix, field, &v));
    const bool ok = ParseXmpNumber(v, out);
    if (!ok) {
      return Status(Code::kCorruptData, "%s: %s:%s is not a number: '%.*s'", name_, prefix, field,
                    static_cast<int>(v.size() < 24 ? v.size() : 24), v.data());
    }
    return Status::Ok();
  }

  // Decodes into memory.Bytes(part): kOutOfMemory when the text could need more than it gives.
  Status Base64(const char* uri, const char* prefix, const char* field, RefocusableMemory& memory,
                RefocusableMemory::Part part, const uint8_t** data, size_t* size) const {
    std::string_view v;
    LB_RETURN_IF_ERROR(Text(uri, prefix, field, &v));
    const size_t most = Base64MaxDecoded(v.size());
    uint8_t* out = memory.Bytes(part, most);
    if (out == nullptr) {
      return Status(Code::kOutOfMemory, "%s: %s:%s: %zu bytes, more than the reader was given",
                    name_, prefix, field, most);
    }
    Status status = Base64DecodeInto(v.data(), v.size(), out, most, size);
    if (!status.ok()) return status.Prefix("%s: %s:%s: ", name_, prefix, field);
    *data = out;
    return status;
  }

 private:
  bool Lookup(const char* uri, const char* field, std::string_view* v) const {
    return FindXmpField(main_, uri, field, v) || FindXmpField(extended_, uri, field, v);
  }

  const char* name_;
  std::string_view main_, extended_;
};

Status ReadDepth(const char* name, const Fields& f, RefocusableMemory& memory,
                 RefocusableFields* out) {
  std::string_view text;
  LB_RETURN_IF_ERROR(f.Text(kGDepthNs, "GDepth", "Format", &text));
  if (text != "RangeInverse" && text != "RangeLinear") {
    return Status(Code::kUnsupported, "%s: GDepth:Format '%.*s' (RangeInverse or RangeLinear)",
                  name, static_cast<int>(text.size() < 32 ? text.size() : 32), text.data());
  }
  out->depth_format = text;
  LB_RETURN_IF_ERROR(f.Number(kGDepthNs, "GDepth", "Near", &out->near_depth));
  LB_RETURN_IF_ERROR(f.Number(kGDepthNs, "GDepth", "Far", &out->far_depth));
  const bool inverse = text == "RangeInverse";
  const double near_depth = out->near_depth, far_depth = out->far_depth;
  if (!(far_depth > near_depth && (inverse ? near_depth > 0.0 : near_depth >= 0.0))) {
    return Status(Code::kCorruptData, "%s: GDepth:Near %g and Far %g are not a valid range", name,
                  near_depth, far_depth);
  }
  LB_RETURN_IF_ERROR(f.Text(kGDepthNs, "GDepth", "Mime", &text));
  if (text != "image/png" && text != "image/jpeg") {
    return Status(Code::kUnsupported, "%s: GDepth:Mime '%.*s' (image/png or image/jpeg)", name,
                  static_cast<int>(text.size() < 32 ? text.size() : 32), text.data());
  }
  out->depth_mime = text;
  if (f.Has(kGDepthNs, "GDepth", "Units")) {
    LB_RETURN_IF_ERROR(f.Text(kGDepthNs, "GDepth", "Units", &out->depth_units));
  }
  LB_RETURN_IF_ERROR(f.Base64(kGDepthNs, "GDepth", "Data", memory,
                              RefocusableMemory::Part::kDepthPng, &out->depth_png,
                              &out->depth_png_size));
  const bool has_w = f.Has(kGDepthNs, "GDepth", "ImageWidth");
  const bool has_h = f.Has(kGDepthNs, "GDepth", "ImageHeight");
  if (has_w != has_h) {
    return Status(Code::kCorruptData, "%s: GDepth:ImageWidth and ImageHeight must come together",
                  name);
  }
  if (has_w) {
    double w = 0, h = 0;
    LB_RETURN_IF_ERROR(f.Number(kGDepthNs, "GDepth", "ImageWidth", &w));
    LB_RETURN_IF_ERROR(f.Number(kGDepthNs, "GDepth", "ImageHeight", &h));
    if (!(w >= 1 && w <= kMaxDepthSide && h >= 1 && h <= kMaxDepthSide) || w != std::floor(w) ||
        h != std::floor(h)) {
      return Status(Code::kCorruptData, "%s: GDepth:ImageWidth/Height %gx%g out of range", name, w,
                    h);
    }
    out->depth_width = static_cast<int32_t>(w);
    out->depth_height = static_cast<int32_t>(h);
    if (out->width > 0 && (out->depth_width > out->width || out->depth_height > out->height)) {
      return Status(Code::kCorruptData, "%s: GDepth: a %dx%d depth map in a %dx%d photo", name,
                    out->depth_width, out->depth_height, out->width, out->height);
    }
  }
  // Checked against the PNG's header before any pixel is decoded: a depth map is never larger
  // than the photo it belongs to.
  const int32_t photo_side = std::max(out->width, out->height);
  out->depth_max_side = photo_side > 0 ? std::min(photo_side, kMaxDepthSide) : kMaxDepthSide;
  return Status::Ok();
}

Status ReadImage(const char* name, const Fields& f, RefocusableMemory& memory,
                 RefocusableFields* out) {
  if (!f.Has(kGImageNs, "GImage", "Data")) return Status::Ok();  // optional
  LB_RETURN_IF_ERROR(f.Text(kGImageNs, "GImage", "Mime", &out->image_mime));
  LB_RETURN_IF_ERROR(f.Base64(kGImageNs, "GImage", "Data", memory, RefocusableMemory::Part::kImage,
                              &out->image, &out->image_size));
  if (out->image_mime == "image/jpeg" &&
      (out->image_size < 4 || out->image[0] != 0xFF || out->image[1] != 0xD8)) {
    return Status(Code::kCorruptData, "%s: GImage:Data is not a JPEG", name);
  }
  return Status::Ok();
}

// GDepth:Confidence, base64-decoded into memory; a defect only leaves it out (with why).
void ReadGDepthConfidence(const Fields& f, RefocusableMemory& memory, RefocusableFields* out) {
  if (!f.Has(kGDepthNs, "GDepth", "Confidence")) return;
  out->confidence_mime = "image/png";  // the format's usual one when ConfidenceMime is absent
  if (f.Has(kGDepthNs, "GDepth", "ConfidenceMime")) {
    (void)f.Text(kGDepthNs, "GDepth", "ConfidenceMime", &out->confidence_mime);
  }
  const uint8_t* data = nullptr;
  size_t size = 0;
  Status s = f.Base64(kGDepthNs, "GDepth", "Confidence", memory,
                      RefocusableMemory::Part::kConfidence, &data, &size);
  if (!s.ok()) {
    out->confidence_ignored = s;
    return;
  }
  out->confidence = data;
  out->confidence_size = size;
}

// The confidence map kept only when its header reads and gives the depth image's size.
void CheckConfidence(const char* name, RefocusableFields* out) {
  if (out->confidence == nullptr) return;
  const char* what = out->dynamic_depth ? "Dynamic Depth confidence item" : "GDepth:Confidence";
  char label[320];
  snprintf(label, sizeof(label), "%s: %s", name, what);
  DepthImageHeader depth, confidence;
  Status s = ProbeDepthImage(out->confidence, out->confidence_size, out->confidence_mime, label,
                             &confidence);
  if (s.ok() &&
      ProbeDepthImage(out->depth_png, out->depth_png_size, out->depth_mime, label, &depth).ok() &&
      (confidence.width != depth.width || confidence.height != depth.height)) {
    s = Status(Code::kCorruptData, "%s: a %dx%d image for a %dx%d depth map", label,
               confidence.width, confidence.height, depth.width, depth.height);
  }
  if (!s.ok()) {
    out->confidence_ignored = s;
    out->confidence = nullptr;
    out->confidence_size = 0;
    return;
  }
  out->confidence_width = confidence.width;
  out->confidence_height = confidence.height;
}

Status ReadFocus(const Fields& f, RefocusableFields* out) {
  const char* names[4] = {"BlurAtInfinity", "FocalDistance", "FocalPointX", "FocalPointY"};
  double* values[4] = {&out->focus.blur_at_infinity, &out->focus.focal_distance,
                       &out->focus.focal_point_x, &out->focus.focal_point_y};
  out->has_focus = false;
  for (const char* n : names) out->has_focus |= f.Has(kGFocusNs, "GFocus", n);
  if (!out->has_focus) return Status::Ok();
  for (int i = 0; i < 4; ++i)
    LB_RETURN_IF_ERROR(f.Number(kGFocusNs, "GFocus", names[i], values[i]));
  return Status::Ok();
}

// The main packet's chunks, in offset order, contiguous, into memory, checked against the MD5.
Status Reassemble(const char* name, std::string_view guid, ExtendedXmpChunk* all, size_t count,
                  RefocusableMemory& memory, std::string_view* extended) {
  ExtendedXmpChunk* mine = std::partition(all, all + count, [&](const ExtendedXmpChunk& c) {
    return memcmp(c.guid, guid.data(), 32) == 0;  // not another packet's chunk
  });
  if (mine == all) {
    return Status(Code::kCorruptData, "%s: extended XMP %.32s announced but absent", name,
                  guid.data());
  }
  const uint32_t full = all[0].full;
  for (const ExtendedXmpChunk* c = all; c != mine; ++c) {
    if (c->full != full) {
      return Status(Code::kCorruptData, "%s: extended XMP chunks disagree on the length", name);
    }
  }
  std::sort(all, mine, [](const ExtendedXmpChunk& a, const ExtendedXmpChunk& b) {
    return a.offset < b.offset;
  });
  uint64_t expected = 0;
  for (const ExtendedXmpChunk* c = all; c != mine; ++c) {
    if (c->offset != expected) {
      return Status(Code::kCorruptData, "%s: extended XMP has %s at offset %llu", name,
                    c->offset > expected ? "a gap" : "an overlap",
                    static_cast<unsigned long long>(expected));
    }
    expected += c->size;
  }
  if (expected != full) {
    return Status(Code::kCorruptData, "%s: extended XMP truncated: %llu of %u bytes", name,
                  static_cast<unsigned long long>(expected), static_cast<unsigned>(full));
  }
  uint8_t* text = memory.Bytes(RefocusableMemory::Part::kExtendedXmp, full);
  if (text == nullptr) {
    return Status(Code::kOutOfMemory,
                  "%s: %u bytes of extended XMP, more than the reader was given", name,
                  static_cast<unsigned>(full));
  }
  for (const ExtendedXmpChunk* c = all; c != mine; ++c) memcpy(text + c->offset, c->bytes, c->size);
  char md5[33];
  Md5Hex(text, full, md5);
  if (guid != std::string_view(md5, 32)) {
    return Status(Code::kCorruptData, "%s: extended XMP does not match its MD5 %.32s", name,
                  guid.data());
  }
  *extended = std::string_view(reinterpret_cast<const char*>(text), full);
  return Status::Ok();
}

// The segments before the image data. `chunks` null: counts the extended-XMP chunks; otherwise
// records them there too.
Status WalkSegments(const uint8_t* data, size_t size, const char* name, RefocusableFields* out,
                    std::string_view* main, ExtendedXmpChunk* chunks, size_t* count) {
  bool have_main = false, have_scan = false;
  *count = 0;
  size_t pos = 2;
  while (!have_scan) {
    if (pos >= size || data[pos] != 0xFF) {
      return Status(Code::kCorruptData, "%s: %s at offset %zu before the image data", name,
                    pos >= size ? "file ends" : "no marker", pos);
    }
    while (pos < size && data[pos] == 0xFF) ++pos;  // fill bytes
    if (pos >= size) return Status(Code::kCorruptData, "%s: file ends in a marker", name);
    const uint8_t marker = data[pos++];
    if (marker == 0xD9) return Status(Code::kCorruptData, "%s: no image data", name);
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length
    if (size - pos < 2) return Status(Code::kCorruptData, "%s: file ends in a marker", name);
    const size_t length = (size_t{data[pos]} << 8) | data[pos + 1];
    if (length < 2 || length > size - pos) {
      return Status(Code::kCorruptData, "%s: segment 0x%02X at offset %zu is truncated", name,
                    marker, pos - 2);
    }
    const uint8_t* p = data + pos + 2;
    const size_t n = length - 2;
    pos += length;
    if (marker == 0xDA) have_scan = true;
    const bool sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof && n >= 5) {
      out->height = static_cast<int32_t>((p[1] << 8) | p[2]);
      out->width = static_cast<int32_t>((p[3] << 8) | p[4]);
    }
    if (marker != 0xE1) continue;
    if (!have_main && StartsWith(p, n, kXmpSignature, sizeof(kXmpSignature))) {
      *main = std::string_view(reinterpret_cast<const char*>(p) + sizeof(kXmpSignature),
                               n - sizeof(kXmpSignature));
      have_main = true;
    } else if (StartsWith(p, n, kExtendedXmpSignature, sizeof(kExtendedXmpSignature))) {
      if (n < kExtendedHeader) {
        return Status(Code::kCorruptData, "%s: extended XMP chunk at offset %zu is truncated", name,
                      pos - length - 2);
      }
      const uint8_t* h = p + sizeof(kExtendedXmpSignature) + 32;
      const uint32_t full = BigEndian32(h), offset = BigEndian32(h + 4);
      const size_t bytes = n - kExtendedHeader;
      if (offset > full || bytes > full - offset) {
        return Status(Code::kCorruptData, "%s: extended XMP chunk at offset %zu overruns %u bytes",
                      name, pos - length - 2, static_cast<unsigned>(full));
      }
      if (chunks != nullptr) {
        chunks[*count] = {p + sizeof(kExtendedXmpSignature), full, offset, p + kExtendedHeader,
                          bytes};
      }
      ++*count;
    }
  }
  if (!have_main) {
    return Status(Code::kNotFound, "%s: no XMP metadata (not a refocusable JPEG)", name);
  }
  return Status::Ok();
}

// Host memory: the parts in vectors, the chunk descriptors in one it owns.
class VectorMemory final : public RefocusableMemory {
 public:
  explicit VectorMemory(RefocusableXmp* xmp) : xmp_(xmp) {}
  // At least one item each: data() of an empty vector may be null, which means "no room".
  ExtendedXmpChunk* Chunks(size_t count) override {
    chunks_.resize(std::max<size_t>(count, 1));
    return chunks_.data();
  }
  uint8_t* Bytes(Part part, size_t count) override {
    std::vector<uint8_t>& v = part == Part::kDepthPng     ? xmp_->depth.data
                              : part == Part::kImage      ? xmp_->image
                              : part == Part::kConfidence ? xmp_->depth.confidence
                                                          : extended_;
    v.resize(std::max<size_t>(count, 1));
    return v.data();
  }

 private:
  RefocusableXmp* xmp_;
  std::vector<ExtendedXmpChunk> chunks_;
  std::vector<uint8_t> extended_;
};

}  // namespace

ExtendedXmpChunk* RefocusableBuffers::Chunks(size_t count) {
  return count <= chunk_capacity ? chunks : nullptr;
}

uint8_t* RefocusableBuffers::Bytes(Part part, size_t count) {
  switch (part) {
    case Part::kExtendedXmp:
      return count <= extended_capacity ? extended : nullptr;
    case Part::kDepthPng:
      return count <= depth_png_capacity ? depth_png : nullptr;
    case Part::kImage:
      return count <= image_capacity ? image : nullptr;
    case Part::kConfidence:
      return count <= confidence_capacity ? confidence : nullptr;
  }
  return nullptr;
}

Status ReadXmpPackets(const uint8_t* data, size_t size, const char* name, RefocusableMemory& memory,
                      RefocusableFields* out, std::string_view* main, std::string_view* extended) {
  *main = *extended = std::string_view();
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8) {
    return Status(Code::kCorruptData, "%s: not a JPEG", name);
  }
  size_t count = 0;
  LB_RETURN_IF_ERROR(WalkSegments(data, size, name, out, main, nullptr, &count));
  std::string_view guid;
  if (FindXmpField(*main, kXmpNoteNs, "HasExtendedXMP", &guid)) {
    if (guid.size() != 32) {
      return Status(Code::kCorruptData, "%s: xmpNote:HasExtendedXMP is not an MD5", name);
    }
    ExtendedXmpChunk* chunks = memory.Chunks(count);
    if (chunks == nullptr) {
      return Status(Code::kOutOfMemory, "%s: %zu extended XMP chunks, more than the reader takes",
                    name, count);
    }
    LB_RETURN_IF_ERROR(WalkSegments(data, size, name, out, main, chunks, &count));
    LB_RETURN_IF_ERROR(Reassemble(name, guid, chunks, count, memory, extended));
  }
  return Status::Ok();
}

Status ReadRefocusableFields(const uint8_t* data, size_t size, const char* name,
                             RefocusableMemory& memory, RefocusableFields* out) {
  *out = RefocusableFields();
  std::string_view main, extended;
  LB_RETURN_IF_ERROR(ReadXmpPackets(data, size, name, memory, out, &main, &extended));
  const Fields fields(name, main, extended);
  if (fields.Has(kGDepthNs, "GDepth", "Format") || fields.Has(kGDepthNs, "GDepth", "Data")) {
    LB_RETURN_IF_ERROR(ReadDepth(name, fields, memory, out));
    LB_RETURN_IF_ERROR(ReadImage(name, fields, memory, out));
    ReadGDepthConfidence(fields, memory, out);
  } else if (HasDynamicDepth(main, extended)) {
    DynamicDepthFields dd;
    LB_RETURN_IF_ERROR(
        ReadDynamicDepthFields(data, size, name, main, extended, out->width, out->height, &dd));
    DynamicDepthAsRefocusable(dd, out);
  } else {
    return Status(Code::kNotFound, "%s: XMP has no depth map (GDepth or Dynamic Depth)", name);
  }
  CheckConfidence(name, out);
  LB_RETURN_IF_ERROR(ReadFocus(fields, out));
  // From the bytes in hand: a re-render must not open the file a second time.
  out->orientation = ExifOrientation(data, size);
  return Status::Ok();
}

void DepthPngName(const char* name, char* out, size_t out_size) {
  snprintf(out, out_size, "%s: GDepth:Data", name);
}

Status ReadRefocusable(const uint8_t* data, size_t size, const char* name, RefocusableImage* out) {
  *out = RefocusableImage();
  VectorMemory memory(&out->xmp);
  RefocusableFields f;
  Status s = ReadRefocusableFields(data, size, name, memory, &f);
  // The fields point into the file and `memory`: copied out before it goes.
  GDepthInfo& d = out->xmp.depth;
  // A Dynamic Depth file's items are in its bytes, not in `memory`.
  const auto keep = [](const uint8_t* p, size_t n, std::vector<uint8_t>* v) {
    if (p != nullptr && p != v->data()) {
      v->assign(p, p + n);
    } else {
      v->resize(n);
    }
  };
  keep(f.depth_png, f.depth_png_size, &d.data);
  keep(f.image, f.image_size, &out->xmp.image);
  keep(f.confidence, f.confidence_size, &d.confidence);
  if (!s.ok()) return s;
  out->width = f.width;
  out->height = f.height;
  out->orientation = f.orientation;
  d.format = std::string(f.depth_format);
  d.near_depth = f.near_depth;
  d.far_depth = f.far_depth;
  d.mime = std::string(f.depth_mime);
  d.units = std::string(f.depth_units);
  d.width = f.depth_width;
  d.height = f.depth_height;
  if (f.image != nullptr) out->xmp.image_mime = std::string(f.image_mime);
  out->xmp.has_focus = f.has_focus;
  out->xmp.focus = f.focus;
  char what[300];
  DepthPngName(name, what, sizeof(what));
  LB_RETURN_IF_ERROR(DecodeDepthImage(d.data.data(), d.data.size(), d.mime, what, f.depth_max_side,
                                      d.width, d.height, &out->depth));
  out->confidence_ignored = f.confidence_ignored;
  if (f.confidence != nullptr) {
    d.confidence_mime = std::string(f.confidence_mime);
    snprintf(what, sizeof(what), "%s: %s", name,
             f.dynamic_depth ? "Dynamic Depth confidence item" : "GDepth:Confidence");
    // The header promised the depth's size; the pixels may still be broken.
    Status c =
        DecodeDepthImage(d.confidence.data(), d.confidence.size(), d.confidence_mime, what,
                         f.depth_max_side, out->depth.width, out->depth.height, &out->confidence);
    if (!c.ok()) {
      out->confidence_ignored = c;
      out->confidence = GrayPng();
      d.confidence.clear();
    }
  } else {
    d.confidence.clear();
  }
  return Status::Ok();
}

Status ReadRefocusableFile(const char* path, RefocusableImage* out) {
  FILE* f = fopen(path, "rbe");
  if (f == nullptr) {
    return Status(errno == ENOENT ? Code::kNotFound : Code::kIoError, "%s: %s", path,
                  strerror(errno));
  }
  struct stat st;
  if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode) ||
      static_cast<uint64_t>(st.st_size) > kMaxFileBytes) {
    fclose(f);
    return Status(Code::kInvalidArgument, "%s: not a regular file of at most %zu MiB", path,
                  kMaxFileBytes >> 20);
  }
  std::vector<uint8_t> bytes;
  bytes.reserve(static_cast<size_t>(st.st_size));
  uint8_t buf[65536];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), f)) > 0) bytes.insert(bytes.end(), buf, buf + n);
  const bool failed = ferror(f) != 0;
  fclose(f);
  if (failed) return Status(Code::kIoError, "%s: read error", path);
  return ReadRefocusable(bytes.data(), bytes.size(), path, out);
}

Status DisparityFromDepth(const RefocusableImage& image, std::vector<uint16_t>* disp_q8,
                          DisparityRange* range) {
  return ScaledDisparityFromDepth(image, 1.0, disp_q8, range);
}

Status ScaledDisparityFromDepth(const RefocusableImage& image, double scale,
                                std::vector<uint16_t>* disp_q8, DisparityRange* range) {
  const GDepthInfo& d = image.xmp.depth;
  DepthFormat format;
  LB_RETURN_IF_ERROR(DepthFormatOf(d.format, &format));
  const GrayPng& png = image.depth;
  disp_q8->assign(png.values.size(), 0);
  return DepthValuesToDisparity(MakeView(png.values.data(), png.width, png.height), png.bits,
                                format, d.near_depth, d.far_depth, scale,
                                MakeView(disp_q8->data(), png.width, png.height), range);
}

}  // namespace lb
