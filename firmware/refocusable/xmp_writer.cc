#include "firmware/refocusable/xmp_writer.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "firmware/codecs/png_writer.h"
#include "firmware/refocusable/base64.h"

namespace lb {
namespace {

void AppendEscaped(const std::string& text, std::string* out) {
  for (char c : text) {
    switch (c) {
      case '&':
        *out += "&amp;";
        break;
      case '<':
        *out += "&lt;";
        break;
      case '>':
        *out += "&gt;";
        break;
      case '"':
        *out += "&quot;";
        break;
      default:
        out->push_back(c);
    }
  }
}

void AppendText(const char* name, const std::string& value, std::string* out) {
  *out += "\n   ";
  *out += name;
  *out += "=\"";
  AppendEscaped(value, out);
  *out += '"';
}

void AppendNumber(const char* name, double value, std::string* out) {
  char text[40];
  snprintf(text, sizeof(text), "%.9g", value);  // enough digits to give Near/Far back exactly
  AppendText(name, text, out);
}

void AppendBase64(const char* name, const std::vector<uint8_t>& data, std::string* out) {
  *out += "\n   ";
  *out += name;
  *out += "=\"";
  Base64Encode(data.data(), data.size(), out);
  *out += '"';
}

size_t Base64Chars(size_t bytes) { return (bytes + 2) / 3 * 4; }

// The base64 of every blob the packet carries.
size_t DataChars(const RefocusableXmp& xmp) {
  return Base64Chars(xmp.depth.data.size()) + Base64Chars(xmp.depth.confidence.size()) +
         Base64Chars(xmp.image.size());
}

// One rdf:Description with the fields; `data` puts the blobs in (the depth, its confidence, the
// original), `fields` the rest.

std::string Packet(const RefocusableXmp& xmp, bool fields, bool data, const char* extended_md5,
                   bool wrapper) {
  std::string p;
  // Reserved whole: a megabyte-long packet grown by doubling would peak at twice its size.
  p.reserve(4096 + (data ? DataChars(xmp) : 0));
  if (wrapper) p += "<?xpacket begin=\"\xEF\xBB\xBF\" id=\"W5M0MpCehiHzreSzNTczkc9d\"?>\n";
  p += "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n";
  p += " <rdf:RDF xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n";
  p += "  <rdf:Description rdf:about=\"\"";
  p += std::string("\n   xmlns:GDepth=\"") + kGDepthNs + "\"";
  if (!xmp.image.empty()) p += std::string("\n   xmlns:GImage=\"") + kGImageNs + "\"";
  if (fields && xmp.has_focus) p += std::string("\n   xmlns:GFocus=\"") + kGFocusNs + "\"";
  if (extended_md5 != nullptr) p += std::string("\n   xmlns:xmpNote=\"") + kXmpNoteNs + "\"";
  if (fields) {
    if (xmp.has_focus) {
      AppendNumber("GFocus:BlurAtInfinity", xmp.focus.blur_at_infinity, &p);
      AppendNumber("GFocus:FocalDistance", xmp.focus.focal_distance, &p);
      AppendNumber("GFocus:FocalPointX", xmp.focus.focal_point_x, &p);
      AppendNumber("GFocus:FocalPointY", xmp.focus.focal_point_y, &p);
    }
    AppendText("GDepth:Format", xmp.depth.format, &p);
    AppendNumber("GDepth:Near", xmp.depth.near_depth, &p);
    AppendNumber("GDepth:Far", xmp.depth.far_depth, &p);
    AppendText("GDepth:Mime", xmp.depth.mime, &p);
    if (!xmp.depth.confidence.empty()) {
      AppendText("GDepth:ConfidenceMime", xmp.depth.confidence_mime, &p);
    }
    if (xmp.depth.width > 0 && xmp.depth.height > 0) {
      AppendNumber("GDepth:ImageWidth", xmp.depth.width, &p);
      AppendNumber("GDepth:ImageHeight", xmp.depth.height, &p);
    }
    if (!xmp.image.empty()) AppendText("GImage:Mime", xmp.image_mime, &p);
    if (extended_md5 != nullptr) AppendText("xmpNote:HasExtendedXMP", extended_md5, &p);
  }
  if (data) {
    AppendBase64("GDepth:Data", xmp.depth.data, &p);
    if (!xmp.depth.confidence.empty()) AppendBase64("GDepth:Confidence", xmp.depth.confidence, &p);
    if (!xmp.image.empty()) AppendBase64("GImage:Data", xmp.image, &p);
  }
  p += "/>\n";
  if (fields) p += xmp.extra_description;
  p += " </rdf:RDF>\n</x:xmpmeta>";
  if (wrapper) p += "\n<?xpacket end=\"w\"?>";
  return p;
}

void PutBigEndian32(uint32_t v, std::vector<uint8_t>* out) {
  out->push_back(static_cast<uint8_t>(v >> 24));
  out->push_back(static_cast<uint8_t>(v >> 16));
  out->push_back(static_cast<uint8_t>(v >> 8));
  out->push_back(static_cast<uint8_t>(v));
}

JpegSegment MainSegment(const std::string& packet) {
  JpegSegment seg;
  seg.payload.resize(sizeof(kXmpSignature) + packet.size());
  memcpy(seg.payload.data(), kXmpSignature, sizeof(kXmpSignature));  // with its NUL
  memcpy(seg.payload.data() + sizeof(kXmpSignature), packet.data(), packet.size());
  return seg;
}

bool IsPlainValue(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7E) return false;
  }
  return true;
}

}  // namespace

Status SetDepthFromDisparity(ConstImageU16 disp_q8, const DisparityRange& range, int bits,
                             RefocusableXmp* xmp) {
  if (disp_q8.empty()) return Status(Code::kInvalidArgument, "depth xmp: empty disparity map");
  GDepthInfo& depth = xmp->depth;
  LB_RETURN_IF_ERROR(DepthNearFar(range, &depth.near_depth, &depth.far_depth));
  std::vector<uint16_t> values(static_cast<size_t>(disp_q8.width) * disp_q8.height);
  ImageU16 view = MakeView(values.data(), disp_q8.width, disp_q8.height);
  LB_RETURN_IF_ERROR(EncodeDepthMap(disp_q8, range, bits, view));
  LB_RETURN_IF_ERROR(EncodeGrayPng(view, bits, &depth.data));
  depth.format = "RangeInverse";
  depth.mime = "image/png";
  depth.width = disp_q8.width;
  depth.height = disp_q8.height;
  return Status::Ok();
}

Status SetConfidence(ConstImageU8 confidence, RefocusableXmp* xmp) {
  GDepthInfo& depth = xmp->depth;
  if (confidence.empty() || confidence.width != depth.width || confidence.height != depth.height) {
    return Status(Code::kInvalidArgument, "depth xmp: a %dx%d confidence map for a %dx%d depth map",
                  confidence.width, confidence.height, depth.width, depth.height);
  }
  // The PNG writer takes 16-bit samples whatever the depth it writes.
  std::vector<uint16_t> values(static_cast<size_t>(confidence.width) * confidence.height);
  for (int32_t y = 0; y < confidence.height; ++y) {
    const uint8_t* row = confidence.Row(y);
    uint16_t* out = values.data() + static_cast<size_t>(y) * confidence.width;
    for (int32_t x = 0; x < confidence.width; ++x) out[x] = row[x];
  }
  LB_RETURN_IF_ERROR(
      EncodeGrayPng(MakeView<const uint16_t>(values.data(), confidence.width, confidence.height), 8,
                    &depth.confidence));
  depth.confidence_mime = "image/png";
  return Status::Ok();
}

Status BuildXmpSegments(const RefocusableXmp& xmp, std::vector<JpegSegment>* segments) {
  segments->clear();
  const GDepthInfo& d = xmp.depth;
  if (d.format != "RangeInverse" && d.format != "RangeLinear") {
    return Status(Code::kInvalidArgument, "depth xmp: format '%.32s' (RangeInverse or RangeLinear)",
                  d.format.c_str());
  }
  if (!(d.near_depth > 0.0 && d.far_depth > d.near_depth && std::isfinite(d.far_depth))) {
    return Status(Code::kInvalidArgument, "depth xmp: Near %g, Far %g are not 0 < near < far",
                  d.near_depth, d.far_depth);
  }
  if (d.data.empty()) return Status(Code::kInvalidArgument, "depth xmp: no depth image");
  if (!IsPlainValue(d.mime) || (!xmp.image.empty() && !IsPlainValue(xmp.image_mime)) ||
      (!d.confidence.empty() && !IsPlainValue(d.confidence_mime))) {
    return Status(Code::kInvalidArgument, "depth xmp: bad mime type");
  }
  if (xmp.has_focus) {
    const GFocusInfo& f = xmp.focus;
    if (!std::isfinite(f.blur_at_infinity) || !std::isfinite(f.focal_distance) ||
        !std::isfinite(f.focal_point_x) || !std::isfinite(f.focal_point_y)) {
      return Status(Code::kInvalidArgument, "depth xmp: focus fields must be finite");
    }
  }
  // Everything in one packet when it fits; otherwise the blobs go to extended XMP.
  // Blobs whose base64 alone is larger cannot fit: that packet is not built (megabytes, only to
  // be measured).
  if (DataChars(xmp) <= kMaxXmpPacket) {
    const std::string single = Packet(xmp, true, true, nullptr, true);
    if (single.size() <= kMaxXmpPacket) {
      segments->push_back(MainSegment(single));
      return Status::Ok();
    }
  }
  const std::string extended = Packet(xmp, false, true, nullptr, false);
  if (extended.size() > UINT32_MAX) {
    return Status(Code::kInvalidArgument, "depth xmp: %zu bytes of extended XMP", extended.size());
  }
  char md5[33];
  Md5Hex(reinterpret_cast<const uint8_t*>(extended.data()), extended.size(), md5);
  const std::string main = Packet(xmp, true, false, md5, true);
  if (main.size() > kMaxXmpPacket) {
    return Status(Code::kInternal, "depth xmp: main packet of %zu bytes", main.size());
  }
  segments->reserve(1 + (extended.size() + kExtendedXmpChunk - 1) / kExtendedXmpChunk);
  segments->push_back(MainSegment(main));
  for (size_t offset = 0; offset < extended.size(); offset += kExtendedXmpChunk) {
    const size_t n =
        extended.size() - offset < kExtendedXmpChunk ? extended.size() - offset : kExtendedXmpChunk;
    JpegSegment seg;
    seg.payload.resize(sizeof(kExtendedXmpSignature) + 32);
    memcpy(seg.payload.data(), kExtendedXmpSignature, sizeof(kExtendedXmpSignature));  // + NUL
    memcpy(seg.payload.data() + sizeof(kExtendedXmpSignature), md5, 32);  // GUID = the MD5
    PutBigEndian32(static_cast<uint32_t>(extended.size()), &seg.payload);
    PutBigEndian32(static_cast<uint32_t>(offset), &seg.payload);
    seg.payload.insert(seg.payload.end(), extended.begin() + static_cast<ptrdiff_t>(offset),
                       extended.begin() + static_cast<ptrdiff_t>(offset + n));
    segments->push_back(std::move(seg));
  }
  return Status::Ok();
}

}  // namespace lb
