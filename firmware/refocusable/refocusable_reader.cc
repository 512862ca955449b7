#include "firmware/refocusable/refocusable_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "firmware/codecs/exif.h"
#include "firmware/refocusable/base64.h"

namespace lb {
namespace {

constexpr int32_t kMaxDepthSide = 8192;
// Two 8192x8192 JPEGs (the photo and its original) at the highest quality, and the depth map.
constexpr size_t kMaxFileBytes = size_t{512} << 20;
constexpr size_t kExtendedHeader = sizeof(kExtendedXmpSignature) + 32 + 4 + 4;

struct Chunk {
  const uint8_t* guid;  // 32 bytes
  uint32_t offset;
  const uint8_t* bytes;
  size_t size;
};

uint32_t BigEndian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

bool StartsWith(const uint8_t* p, size_t n, const char* sig, size_t sig_size) {
  return n >= sig_size && memcmp(p, sig, sig_size) == 0;
}

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// One XMP packet with the prefixes it binds to our namespaces.
class Packet {
 public:
  explicit Packet(std::string_view text) : text_(text) {}

  // The prefix bound to `uri` by an xmlns attribute; empty when none is (nothing matches then).
  std::string Prefix(const char* uri) const {
    size_t pos = 0;
    while ((pos = text_.find("xmlns:", pos)) != std::string_view::npos) {
      pos += 6;
      const size_t eq = text_.find('=', pos);
      if (eq == std::string_view::npos || eq - pos > 64) continue;
      size_t end = eq;
      while (end > pos && IsSpace(text_[end - 1])) --end;
      std::string_view value;
      if (QuotedAt(eq + 1, &value) && value == uri)
        return std::string(text_.substr(pos, end - pos));
    }
    return std::string();
  }

  // `prefix:name` as an attribute (prefix:name="value") or a simple element
  // (<prefix:name>value</prefix:name>).
  bool Find(const std::string& prefix, const char* name, std::string_view* value) const {
    if (prefix.empty()) return false;
    const std::string qname = prefix + ":" + name;
    size_t pos = 0;
    while ((pos = text_.find(qname, pos)) != std::string_view::npos) {
      const size_t start = pos, after = pos + qname.size();
      pos = after;
      if (start == 0 || after >= text_.size()) continue;
      const bool element = text_[start - 1] == '<';
      if (!element && !IsSpace(text_[start - 1])) continue;  // part of a longer name
      if (element) {
        if (text_[after] != '>') continue;
        const size_t close = text_.find("</" + qname, after + 1);
        if (close == std::string_view::npos) return false;
        *value = text_.substr(after + 1, close - after - 1);
        return true;
      }
      size_t eq = after;
      while (eq < text_.size() && IsSpace(text_[eq])) ++eq;
      if (eq >= text_.size() || text_[eq] != '=') continue;
      return QuotedAt(eq + 1, value);
    }
    return false;
  }

 private:
  bool QuotedAt(size_t pos, std::string_view* value) const {
    while (pos < text_.size() && IsSpace(text_[pos])) ++pos;
    if (pos >= text_.size() || (text_[pos] != '"' && text_[pos] != '\'')) return false;
    const size_t end = text_.find(text_[pos], pos + 1);
    if (end == std::string_view::npos) return false;
    *value = text_.substr(pos + 1, end - pos - 1);
    return true;
  }

  std::string_view text_;
};

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
    while (!v.empty() && IsSpace(v.front())) v.remove_prefix(1);
    while (!v.empty() && IsSpace(v.back())) v.remove_suffix(1);
    char text[64];
    bool ok = !v.empty() && v.size() < sizeof(text);
    if (ok) {
      memcpy(text, v.data(), v.size());
      text[v.size()] = '\0';
      char* end = nullptr;
      errno = 0;
      *out = strtod(text, &end);
      ok = end == text + v.size() && errno == 0 && std::isfinite(*out);
    }
    if (!ok) {
      return Status(Code::kCorruptData, "%s: %s:%s is not a number: '%.*s'", name_, prefix, field,
                    static_cast<int>(v.size() < 24 ? v.size() : 24), v.data());
    }
    return Status::Ok();
  }

  Status Base64(const char* uri, const char* prefix, const char* field,
                std::vector<uint8_t>* out) const {
    std::string_view v;
    LB_RETURN_IF_ERROR(Text(uri, prefix, field, &v));
    Status status = Base64Decode(v.data(), v.size(), out);
    if (!status.ok()) status.Prefix("%s: %s:%s: ", name_, prefix, field);
    return status;
  }

 private:
  bool Lookup(const char* uri, const char* field, std::string_view* v) const {
    for (std::string_view text : {main_, extended_}) {
      const Packet packet(text);
      if (packet.Find(packet.Prefix(uri), field, v)) return true;
    }
    return false;
  }

  const char* name_;
  std::string_view main_, extended_;
};

Status ReadDepth(const char* name, const Fields& f, RefocusableImage* out) {
  GDepthInfo& d = out->xmp.depth;
  std::string_view text;
  LB_RETURN_IF_ERROR(f.Text(kGDepthNs, "GDepth", "Format", &text));
  if (text != "RangeInverse" && text != "RangeLinear") {
    return Status(Code::kUnsupported, "%s: GDepth:Format '%.*s' (RangeInverse or RangeLinear)",
                  name, static_cast<int>(text.size() < 32 ? text.size() : 32), text.data());
  }
  d.format = std::string(text);
  LB_RETURN_IF_ERROR(f.Number(kGDepthNs, "GDepth", "Near", &d.near_depth));
  LB_RETURN_IF_ERROR(f.Number(kGDepthNs, "GDepth", "Far", &d.far_depth));
  const bool inverse = d.format == "RangeInverse";
  if (!(d.far_depth > d.near_depth && (inverse ? d.near_depth > 0.0 : d.near_depth >= 0.0))) {
    return Status(Code::kCorruptData, "%s: GDepth:Near %g and Far %g are not a valid range", name,
                  d.near_depth, d.far_depth);
  }
  LB_RETURN_IF_ERROR(f.Text(kGDepthNs, "GDepth", "Mime", &text));
  if (text != "image/png") {
    return Status(Code::kUnsupported, "%s: GDepth:Mime '%.*s' (only image/png)", name,
                  static_cast<int>(text.size() < 32 ? text.size() : 32), text.data());
  }
  d.mime = std::string(text);
  LB_RETURN_IF_ERROR(f.Base64(kGDepthNs, "GDepth", "Data", &d.data));
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
    d.width = static_cast<int32_t>(w);
    d.height = static_cast<int32_t>(h);
    if (out->width > 0 && (d.width > out->width || d.height > out->height)) {
      return Status(Code::kCorruptData, "%s: GDepth: a %dx%d depth map in a %dx%d photo", name,
                    d.width, d.height, out->width, out->height);
    }
  }
  char what[300];
  snprintf(what, sizeof(what), "%s: GDepth:Data", name);
  // The size is checked against the PNG's header before any pixel is decoded; a depth map is
  // never larger than the photo it belongs to.
  const int32_t photo_side = std::max(out->width, out->height);
  const int32_t max_side = photo_side > 0 ? std::min(photo_side, kMaxDepthSide) : kMaxDepthSide;
  return DecodeGrayPng(d.data.data(), d.data.size(), what, max_side, d.width, d.height,
                       &out->depth);
}

Status ReadImage(const char* name, const Fields& f, RefocusableImage* out) {
  if (!f.Has(kGImageNs, "GImage", "Data")) return Status::Ok();  // optional
  std::string_view mime;
  LB_RETURN_IF_ERROR(f.Text(kGImageNs, "GImage", "Mime", &mime));
  out->xmp.image_mime = std::string(mime);
  LB_RETURN_IF_ERROR(f.Base64(kGImageNs, "GImage", "Data", &out->xmp.image));
  if (mime == "image/jpeg" &&
      (out->xmp.image.size() < 4 || out->xmp.image[0] != 0xFF || out->xmp.image[1] != 0xD8)) {
    return Status(Code::kCorruptData, "%s: GImage:Data is not a JPEG", name);
  }
  return Status::Ok();
}

Status ReadFocus(const Fields& f, RefocusableImage* out) {
  const char* names[4] = {"BlurAtInfinity", "FocalDistance", "FocalPointX", "FocalPointY"};
  double* values[4] = {&out->xmp.focus.blur_at_infinity, &out->xmp.focus.focal_distance,
                       &out->xmp.focus.focal_point_x, &out->xmp.focus.focal_point_y};
  out->xmp.has_focus = false;
  for (const char* n : names) out->xmp.has_focus |= f.Has(kGFocusNs, "GFocus", n);
  if (!out->xmp.has_focus) return Status::Ok();
  for (int i = 0; i < 4; ++i)
    LB_RETURN_IF_ERROR(f.Number(kGFocusNs, "GFocus", names[i], values[i]));
  return Status::Ok();
}

Status Reassemble(const char* name, const std::string& guid, const std::vector<Chunk>& all,
                  const std::vector<uint32_t>& lengths, std::string* extended) {
  std::vector<Chunk> chunks;
  uint32_t full = 0;
  for (size_t i = 0; i < all.size(); ++i) {
    if (memcmp(all[i].guid, guid.data(), 32) != 0) continue;  // another packet's chunk
    if (!chunks.empty() && lengths[i] != full) {
      return Status(Code::kCorruptData, "%s: extended XMP chunks disagree on the length", name);
    }
    full = lengths[i];
    chunks.push_back(all[i]);
  }
  if (chunks.empty()) {
    return Status(Code::kCorruptData, "%s: extended XMP %s announced but absent", name,
                  guid.c_str());
  }
  std::sort(chunks.begin(), chunks.end(),
            [](const Chunk& a, const Chunk& b) { return a.offset < b.offset; });
  uint64_t expected = 0;
  for (const Chunk& c : chunks) {
    if (c.offset != expected) {
      return Status(Code::kCorruptData, "%s: extended XMP has a %s at offset %llu", name,
                    c.offset > expected ? "gap" : "overlap",
                    static_cast<unsigned long long>(expected));
    }
    expected += c.size;
  }
  if (expected != full) {
    return Status(Code::kCorruptData, "%s: extended XMP truncated: %llu of %u bytes", name,
                  static_cast<unsigned long long>(expected), static_cast<unsigned>(full));
  }
  extended->reserve(full);
  for (const Chunk& c : chunks) extended->append(reinterpret_cast<const char*>(c.bytes), c.size);
  char md5[33];
  Md5Hex(reinterpret_cast<const uint8_t*>(extended->data()), extended->size(), md5);
  if (guid != md5) {
    return Status(Code::kCorruptData, "%s: extended XMP does not match its MD5 %s", name,
                  guid.c_str());
  }
  return Status::Ok();
}

}  // namespace

Status ReadRefocusable(const uint8_t* data, size_t size, const char* name, RefocusableImage* out) {
  *out = RefocusableImage();
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8) {
    return Status(Code::kCorruptData, "%s: not a JPEG", name);
  }
  std::string_view main;
  bool have_main = false, have_scan = false;
  std::vector<Chunk> chunks;
  std::vector<uint32_t> lengths;
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
      main = std::string_view(reinterpret_cast<const char*>(p) + sizeof(kXmpSignature),
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
      chunks.push_back({p + sizeof(kExtendedXmpSignature), offset, p + kExtendedHeader, bytes});
      lengths.push_back(full);
    }
  }
  if (!have_main) {
    return Status(Code::kNotFound, "%s: no XMP metadata (not a refocusable JPEG)", name);
  }
  std::string extended;
  std::string_view guid;
  const Packet main_packet(main);
  if (main_packet.Find(main_packet.Prefix(kXmpNoteNs), "HasExtendedXMP", &guid)) {
    if (guid.size() != 32) {
      return Status(Code::kCorruptData, "%s: xmpNote:HasExtendedXMP is not an MD5", name);
    }
    LB_RETURN_IF_ERROR(Reassemble(name, std::string(guid), chunks, lengths, &extended));
  }
  const Fields fields(name, main, extended);
  if (!fields.Has(kGDepthNs, "GDepth", "Format") && !fields.Has(kGDepthNs, "GDepth", "Data")) {
    return Status(Code::kNotFound, "%s: XMP has no depth map (GDepth)", name);
  }
  LB_RETURN_IF_ERROR(ReadDepth(name, fields, out));
  LB_RETURN_IF_ERROR(ReadImage(name, fields, out));
  LB_RETURN_IF_ERROR(ReadFocus(fields, out));
  // From the bytes in hand: a re-render must not open the file a second time.
  out->orientation = ExifOrientation(data, size);
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
  const GDepthInfo& d = image.xmp.depth;
  if (d.format != "RangeInverse") {
    return Status(Code::kUnsupported, "depth map: %s (only RangeInverse maps back to disparity)",
                  d.format.c_str());
  }
  LB_RETURN_IF_ERROR(DisparityRangeFromNearFar(d.near_depth, d.far_depth, range));
  const GrayPng& png = image.depth;
  disp_q8->assign(png.values.size(), 0);
  ConstImageU16 values = MakeView(png.values.data(), png.width, png.height);
  return DecodeDepthMap(values, *range, png.bits, MakeView(disp_q8->data(), png.width, png.height));
}

}  // namespace lb
