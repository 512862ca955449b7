// The refocusable-JPEG XMP (Google depth-map format, shared/notes/formats.md): GDepth (the depth
// map as a base64 PNG, and its confidence map the same way), GImage (the all-in-focus original as a
// base64 JPEG) and GFocus (the focus the picture was rendered with), laid out as APP1 segments for
// JpegMetadata::extra_segments: one main XMP packet and, when the data do not fit 64 KB,
// extended-XMP chunks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "algo/core/image.h"
#include "algo/core/status.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/refocusable/depth_encoding.h"

namespace lb {

// Namespaces and segment signatures.
inline constexpr char kXmpSignature[] = "http://ns.adobe.com/xap/1.0/";                // + NUL
inline constexpr char kExtendedXmpSignature[] = "http://ns.adobe.com/xmp/extension/";  // + NUL
inline constexpr char kGDepthNs[] = "http://ns.google.com/photos/1.0/depthmap/";
inline constexpr char kGImageNs[] = "http://ns.google.com/photos/1.0/image/";
inline constexpr char kGFocusNs[] = "http://ns.google.com/photos/1.0/focus/";
inline constexpr char kXmpNoteNs[] = "http://ns.adobe.com/xmp/note/";
inline constexpr size_t kMaxXmpPacket = 65502;      // main packet per APP1 segment
inline constexpr size_t kExtendedXmpChunk = 65400;  // extended-XMP bytes per APP1 segment

struct GDepthInfo {
  std::string format = "RangeInverse";  // or RangeLinear
  double near_depth = 0.0;
  double far_depth = 0.0;
  std::string mime = "image/png";
  std::string units;          // GDepth:Units as read ("" = not given); not written
  std::vector<uint8_t> data;  // the encoded depth image (PNG or JPEG bytes)
  int32_t width = 0;          // GDepth:ImageWidth / ImageHeight, 0 = not written
  int32_t height = 0;
  // GDepth:Confidence: how sure each depth pixel is, an 8-bit grey image the depth's size (255:
  // sure; RangeLinear over 0..1), encoded as confidence_mime says; empty = none. Dynamic Depth's
  // ConfidenceURI item is the same bytes.
  std::vector<uint8_t> confidence;
  std::string confidence_mime = "image/png";
};

struct GFocusInfo {
  double blur_at_infinity = 0.0;  // blur radius for a point at infinity / image width
  double focal_distance = 0.0;    // depth of the focal plane, in the units of Near and Far
  double focal_point_x = 0.5;     // the focus point, as a fraction of width and height
  double focal_point_y = 0.5;
};

struct RefocusableXmp {
  GDepthInfo depth;
  std::string image_mime = "image/jpeg";
  std::vector<uint8_t> image;  // the all-in-focus JPEG; empty = no GImage
  bool has_focus = false;
  GFocusInfo focus;
  // More of the main packet: whole rdf:Description elements (Dynamic Depth's Device), "" = none.
  std::string extra_description;
};

// Fills `xmp->depth` from a working-resolution disparity map: RangeInverse, `bits` (8 or 16) bit
// grey PNG, Near and Far from `range` (see depth_encoding.h). Allocates.
Status SetDepthFromDisparity(ConstImageU16 disp_q8, const DisparityRange& range, int bits,
                             RefocusableXmp* xmp);

// Fills `xmp->depth.confidence` from the depth map's confidence (0..255, 255: sure): an 8-bit
// grey PNG, which must be the size of the depth image already set. Allocates.
Status SetConfidence(ConstImageU8 confidence, RefocusableXmp* xmp);

// The APP1 segments (main packet first, then extended chunks in offset order).
Status BuildXmpSegments(const RefocusableXmp& xmp, std::vector<JpegSegment>* segments);

}  // namespace lb
