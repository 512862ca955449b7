#include "firmware/refocusable/dynamic_depth.h"

#include <algorithm>
#include <cstdio>

#include "firmware/refocusable/xmp_lookup.h"

namespace lb {
namespace {

constexpr int32_t kMaxSide = 8192;  // the GDepth reader's limit on a depth map's side

// The item MIME types the specification lists; an item of any other is refused, whatever it is.
constexpr std::string_view kKnownMimes[] = {"image/jpeg", "image/png",  "image/tiff", "image/gif",
                                            "image/heic", "text/plain", "video/mp4"};

// A value from the file as a message shows it: at most 40 characters, each unprintable one as
// '?', so that the message stays one line.
struct Shown {
  explicit Shown(std::string_view v) {
    size_t n = 0;
    for (; n < v.size() && n < 40; ++n) text[n] = v[n] >= 0x20 && v[n] < 0x7F ? v[n] : '?';
    text[n] = '\0';
  }
  char text[41];
};

// A Length or Padding: decimal digits only, at most 19 of them (no overflow).
bool ParseCount(std::string_view v, uint64_t* out) {
  while (!v.empty() && IsXmpSpace(v.front())) v.remove_prefix(1);
  while (!v.empty() && IsXmpSpace(v.back())) v.remove_suffix(1);
  if (v.empty() || v.size() > 19) return false;
  uint64_t n = 0;
  for (char c : v) {
    if (c < '0' || c > '9') return false;
    n = n * 10 + static_cast<uint64_t>(c - '0');
  }
  *out = n;
  return true;
}

// One of the two directory namespaces, resolved in one packet.
struct Directory {
  std::string_view packet, text, item_prefix;
};

bool FindDirectory(std::string_view packet, Directory* dir) {
  const char* const spaces[2][2] = {{kDdContainerNs, kDdItemNs},
                                    {kGContainerNs, kGContainerItemNs}};
  for (const auto& ns : spaces) {
    size_t next = 0;
    if (FindXmpElement(packet, XmpPrefixOf(packet, ns[0]), "Directory", 0, &dir->text, &next)) {
      dir->packet = packet;
      dir->item_prefix = XmpPrefixOf(packet, ns[1]);
      return true;
    }
  }
  return false;
}

Status ReadItems(const Directory& dir, const uint8_t* data, size_t size, const char* name,
                 DynamicDepthFields* out) {
  // Each rdf:li of the directory's sequence is one item.
  size_t pos = 0;
  while ((pos = dir.text.find("<rdf:li", pos)) != std::string_view::npos) {
    const size_t end = std::min(dir.text.find("<rdf:li", pos + 7), dir.text.size());
    const std::string_view li = dir.text.substr(pos, end - pos);
    pos = end;
    if (out->item_count == kMaxDynamicDepthItems) {
      return Status(Code::kUnsupported, "%s: Container:Directory lists more than %zu items", name,
                    kMaxDynamicDepthItems);
    }
    const size_t index = out->item_count++;
    DynamicDepthItem& item = out->items[index];
    if (!FindXmpFieldByPrefix(li, dir.item_prefix, "Mime", &item.mime)) {
      return Status(Code::kCorruptData, "%s: Container item %zu has no Item:Mime", name, index);
    }
    if (std::find(std::begin(kKnownMimes), std::end(kKnownMimes), item.mime) ==
        std::end(kKnownMimes)) {
      return Status(Code::kUnsupported, "%s: Container item %zu: unknown Item:Mime '%s'", name,
                    index, Shown(item.mime).text);
    }
    FindXmpFieldByPrefix(li, dir.item_prefix, "Semantic", &item.semantic);
    FindXmpFieldByPrefix(li, dir.item_prefix, "DataURI", &item.uri);
    std::string_view text;
    uint64_t length = 0, padding = 0;
    const bool has_length = FindXmpFieldByPrefix(li, dir.item_prefix, "Length", &text);
    if ((index > 0 && !has_length) || (has_length && !ParseCount(text, &length))) {
      return Status(Code::kCorruptData, "%s: Container item %zu: no valid Item:Length", name,
                    index);
    }
    if (FindXmpFieldByPrefix(li, dir.item_prefix, "Padding", &text) &&
        !ParseCount(text, &padding)) {
      return Status(Code::kCorruptData, "%s: Container item %zu: Item:Padding '%s'", name, index,
                    Shown(text).text);
    }
    if (length > size || padding > size) {
      return Status(Code::kCorruptData,
                    "%s: Container item %zu: Item:Length %llu (Padding %llu) past the end of the "
                    "%zu-byte file",
                    name, index, static_cast<unsigned long long>(length),
                    static_cast<unsigned long long>(padding), size);
    }
    item.length = static_cast<size_t>(length);
    item.padding = static_cast<size_t>(padding);
  }
  if (out->item_count < 2) {
    return Status(Code::kCorruptData, "%s: Container:Directory lists no item after the primary",
                  name);
  }
  // The items after the primary end the file: sliced from its end by their lengths, and what is
  // left before them must be the primary JPEG, ending with its EOI.
  uint64_t tail = 0;
  for (size_t i = 1; i < out->item_count; ++i) tail += out->items[i].length + out->items[i].padding;
  const uint64_t primary_end = size - std::min<uint64_t>(tail, size);
  DynamicDepthItem& primary = out->items[0];
  if (tail + primary.padding + 4 > size || data[primary_end - primary.padding - 2] != 0xFF ||
      data[primary_end - primary.padding - 1] != 0xD9) {
    return Status(Code::kCorruptData,
                  "%s: the Container items' lengths (%llu bytes) do not add up: no primary image "
                  "ends where they begin",
                  name, static_cast<unsigned long long>(tail));
  }
  primary.data = data;
  primary.length = static_cast<size_t>(primary_end - primary.padding);
  size_t at = static_cast<size_t>(primary_end);
  for (size_t i = 1; i < out->item_count; ++i) {
    out->items[i].data = data + at;
    at += out->items[i].length + out->items[i].padding;
  }
  return Status::Ok();
}

// The item `uri` names; by Item:Semantic when no item has a DataURI (GContainer's directory).
int32_t ItemFor(const DynamicDepthFields& f, std::string_view uri, std::string_view semantic) {
  bool any_uri = false;
  for (size_t i = 1; i < f.item_count; ++i) {
    any_uri |= !f.items[i].uri.empty();
    if (!uri.empty() && f.items[i].uri == uri) return static_cast<int32_t>(i);
  }
  if (any_uri) return -1;
  for (size_t i = 1; i < f.item_count; ++i) {
    if (f.items[i].semantic == semantic) return static_cast<int32_t>(i);
  }
  return -1;
}

// The first element <Camera:`element`> of either packet that `accept` takes, its fields'
// prefix resolved in the packet it is in.
template <typename Accept>
bool FindCameraElement(std::string_view main, std::string_view extended, const char* element,
                       const char* ns, std::string_view* text, std::string_view* prefix,
                       Accept accept) {
  for (std::string_view packet : {main, extended}) {
    const std::string_view camera = XmpPrefixOf(packet, kDdCameraNs);
    *prefix = XmpPrefixOf(packet, ns);
    size_t from = 0;
    while (FindXmpElement(packet, camera, element, from, text, &from)) {
      if (accept(*text, *prefix)) return true;
    }
  }
  return false;
}

Status ReadDepthMap(const char* name, std::string_view main, std::string_view extended,
                    DynamicDepthFields* out) {
  std::string_view dm, prefix;
  const bool found =
      FindCameraElement(main, extended, "DepthMap", kDdDepthMapNs, &dm, &prefix,
                        [](std::string_view text, std::string_view p) {
                          std::string_view semantic;  // a segmentation mask is no depth
                          return !FindXmpFieldByPrefix(text, p, "ItemSemantic", &semantic) ||
                                 semantic != "Segmentation";
                        });
  if (!found) return Status(Code::kNotFound, "%s: Dynamic Depth without a DepthMap", name);
  std::string_view text, uri;
  if (!FindXmpFieldByPrefix(dm, prefix, "Format", &out->format) ||
      (out->format != "RangeInverse" && out->format != "RangeLinear")) {
    return Status(Code::kUnsupported, "%s: DepthMap:Format '%s' (RangeInverse or RangeLinear)",
                  name, Shown(out->format).text);
  }
  const char* names[2] = {"Near", "Far"};
  double* values[2] = {&out->near_depth, &out->far_depth};
  for (int i = 0; i < 2; ++i) {
    if (!FindXmpFieldByPrefix(dm, prefix, names[i], &text) || !ParseXmpNumber(text, values[i])) {
      return Status(Code::kCorruptData, "%s: DepthMap:%s missing or not a number", name, names[i]);
    }
  }
  const bool inverse = out->format == "RangeInverse";
  if (!(out->far_depth > out->near_depth &&
        (inverse ? out->near_depth > 0.0 : out->near_depth >= 0.0))) {
    return Status(Code::kCorruptData, "%s: DepthMap:Near %g and Far %g are not a valid range", name,
                  out->near_depth, out->far_depth);
  }
  FindXmpFieldByPrefix(dm, prefix, "Units", &out->units);
  if (!out->units.empty() && out->units != "Meters" && out->units != "Diopters" &&
      out->units != "None") {
    return Status(Code::kUnsupported, "%s: DepthMap:Units '%s' (Meters, Diopters or None)", name,
                  Shown(out->units).text);
  }
  FindXmpFieldByPrefix(dm, prefix, "MeasureType", &out->measure_type);
  FindXmpFieldByPrefix(dm, prefix, "DepthURI", &uri);
  out->depth = ItemFor(*out, uri, "Depth");
  if (out->depth < 0) {
    return Status(Code::kNotFound, "%s: DepthMap:DepthURI '%s' names no Container item", name,
                  Shown(uri).text);
  }
  if (FindXmpFieldByPrefix(dm, prefix, "ConfidenceURI", &uri) && !uri.empty()) {
    out->confidence = ItemFor(*out, uri, "Confidence");
    if (out->confidence < 0) {
      return Status(Code::kNotFound, "%s: DepthMap:ConfidenceURI '%s' names no Container item",
                    name, Shown(uri).text);
    }
  }
  return Status::Ok();
}

void FindOriginal(std::string_view main, std::string_view extended, DynamicDepthFields* out) {
  std::string_view image, prefix, uri;
  if (FindCameraElement(main, extended, "Image", kDdImageNs, &image, &prefix,
                        [](std::string_view text, std::string_view p) {
                          std::string_view semantic;
                          return FindXmpFieldByPrefix(text, p, "ItemSemantic", &semantic) &&
                                 semantic == "Original";
                        })) {
    FindXmpFieldByPrefix(image, prefix, "ItemURI", &uri);
  }
  out->original = ItemFor(*out, uri, "Original");
}

// An item to be decoded: an image of the kind its Mime says, no larger than `max_side`, by its
// header.
Status CheckImageItem(const DynamicDepthItem& item, const char* name, const char* what,
                      int32_t max_side, DepthImageHeader* header) {
  char label[320];
  snprintf(label, sizeof(label), "%s: Dynamic Depth %s item", name, what);
  LB_RETURN_IF_ERROR(ProbeDepthImage(item.data, item.length, item.mime, label, header));
  if (header->width > max_side || header->height > max_side) {
    return Status(Code::kCorruptData, "%s: a %dx%d image, larger than %d a side", label,
                  header->width, header->height, max_side);
  }
  return Status::Ok();
}

}  // namespace

bool HasDynamicDepth(std::string_view main, std::string_view extended) {
  Directory dir;
  return FindDirectory(main, &dir) || FindDirectory(extended, &dir);
}

Status ReadDynamicDepthFields(const uint8_t* data, size_t size, const char* name,
                              std::string_view main, std::string_view extended, int32_t photo_width,
                              int32_t photo_height, DynamicDepthFields* out) {
  *out = DynamicDepthFields();
  Directory dir;
  if (!FindDirectory(main, &dir) && !FindDirectory(extended, &dir)) {
    return Status(Code::kNotFound, "%s: XMP has no Container:Directory (Dynamic Depth)", name);
  }
  LB_RETURN_IF_ERROR(ReadItems(dir, data, size, name, out));
  LB_RETURN_IF_ERROR(ReadDepthMap(name, main, extended, out));
  FindOriginal(main, extended, out);
  // A depth map, its confidence and the original are never larger than the photo.
  const int32_t photo_side = std::max(photo_width, photo_height);
  out->depth_max_side = photo_side > 0 ? std::min(photo_side, kMaxSide) : kMaxSide;
  LB_RETURN_IF_ERROR(CheckImageItem(out->items[out->depth], name, "depth", out->depth_max_side,
                                    &out->depth_header));
  DepthImageHeader header;
  if (out->confidence >= 0) {
    LB_RETURN_IF_ERROR(CheckImageItem(out->items[out->confidence], name, "confidence",
                                      out->depth_max_side, &header));
  }
  if (out->original >= 0) {
    const DynamicDepthItem& original = out->items[out->original];
    if (original.mime != "image/jpeg") {
      return Status(Code::kUnsupported, "%s: Dynamic Depth original item: '%s', not a JPEG", name,
                    Shown(original.mime).text);
    }
    LB_RETURN_IF_ERROR(CheckImageItem(original, name, "original", out->depth_max_side, &header));
  }
  return Status::Ok();
}

void DynamicDepthAsRefocusable(const DynamicDepthFields& dd, RefocusableFields* out) {
  const DynamicDepthItem& depth = dd.items[dd.depth];
  out->depth_format = dd.format;
  out->depth_mime = depth.mime;
  out->depth_units = dd.units;
  out->near_depth = dd.near_depth;
  out->far_depth = dd.far_depth;
  out->depth_width = out->depth_height = 0;  // the item's own size, whatever it is
  out->depth_png = depth.data;
  out->depth_png_size = depth.length;
  out->depth_max_side = dd.depth_max_side;
  out->dynamic_depth = true;
  out->image = nullptr;
  out->image_size = 0;
  out->confidence = nullptr;
  out->confidence_size = 0;
  if (dd.confidence >= 0) {
    const DynamicDepthItem& confidence = dd.items[dd.confidence];
    out->confidence_mime = confidence.mime;
    out->confidence = confidence.data;
    out->confidence_size = confidence.length;
  }
  if (dd.original >= 0) {
    const DynamicDepthItem& original = dd.items[dd.original];
    out->image_mime = original.mime;
    out->image = original.data;
    out->image_size = original.length;
  }
}

}  // namespace lb
