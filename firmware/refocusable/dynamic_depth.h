// Dynamic Depth 1.0 (Android's depth photos; shared/notes/formats.md): the main XMP's
// Container:Directory lists the file's items (the primary JPEG first, then the items appended
// after its EOI, in directory order, each with its Mime and Length), and the Device's Camera
// elements say which item is the depth map (DepthMap:DepthURI, ConfidenceURI) and which the
// original photo (Image:ItemURI). Phones write the directory in either of two namespaces: the
// specification's (Device:Container, items named by Item:DataURI) and GContainer's (items named
// by Item:Semantic); both are read.
//
// The reader checks every Length against the file and the depth item's header against the size
// limits before anything is decoded; the items point into the file's bytes (no allocation). The
// writer adds the Device element to the main XMP packet (RefocusableXmp::extra_description) and
// the items after the primary's EOI: the same depth image as GDepth's, the confidence map when
// there is one, GImage's original.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "algo/core/status.h"
#include "firmware/refocusable/depth_image.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "firmware/refocusable/xmp_writer.h"

namespace lb {

inline constexpr char kDdDeviceNs[] = "http://ns.google.com/photos/dd/1.0/device/";
inline constexpr char kDdContainerNs[] = "http://ns.google.com/photos/dd/1.0/container/";
inline constexpr char kDdItemNs[] = "http://ns.google.com/photos/dd/1.0/item/";
inline constexpr char kGContainerNs[] = "http://ns.google.com/photos/1.0/container/";
inline constexpr char kGContainerItemNs[] = "http://ns.google.com/photos/1.0/container/item/";
inline constexpr char kDdProfileNs[] = "http://ns.google.com/photos/dd/1.0/profile/";
inline constexpr char kDdCameraNs[] = "http://ns.google.com/photos/dd/1.0/camera/";
inline constexpr char kDdDepthMapNs[] = "http://ns.google.com/photos/dd/1.0/depthmap/";
inline constexpr char kDdImageNs[] = "http://ns.google.com/photos/dd/1.0/image/";
inline constexpr char kDdImagingModelNs[] = "http://ns.google.com/photos/dd/1.0/imagingmodel/";

inline constexpr size_t kMaxDynamicDepthItems = 16;

struct DynamicDepthItem {
  std::string_view mime;          // Item:Mime
  std::string_view semantic;      // Item:Semantic (GContainer), "" when not given
  std::string_view uri;           // Item:DataURI, "" when not given
  const uint8_t* data = nullptr;  // into the file's bytes (the primary: the file's start)
  size_t length = 0;              // the item's bytes (the primary: up to its EOI)
  size_t padding = 0;             // Item:Padding, after the item's bytes
};

struct DynamicDepthFields {
  size_t item_count = 0;
  DynamicDepthItem items[kMaxDynamicDepthItems];
  int32_t depth = -1;             // the depth map's item (always found when the read succeeds)
  int32_t confidence = -1;        // DepthMap:ConfidenceURI's item, -1 = none
  int32_t original = -1;          // the Original image's item, -1 = none
  std::string_view format;        // DepthMap:Format: RangeInverse or RangeLinear
  std::string_view units;         // DepthMap:Units: Meters, Diopters or None ("" = not given)
  std::string_view measure_type;  // DepthMap:MeasureType, "" = not given
  double near_depth = 0.0, far_depth = 0.0;
  DepthImageHeader depth_header;  // the depth item's header, read before any pixel
  int32_t depth_max_side = 0;     // the largest side the depth image may have
};

// Whether the XMP lists a Container:Directory (in either namespace).
bool HasDynamicDepth(std::string_view main, std::string_view extended);

// Reads the Dynamic Depth fields of a file whose main and extended XMP packets are `main` and
// `extended` (ReadXmpPackets) and whose primary image is `photo_width` x `photo_height` (0: not
// known). Every defect is a one-line Status naming the file: a Length past the end, lengths that
// do not add up to the file, an unknown Mime, a missing depth item, a depth image larger than the
// photo (or than 8192 a side) by its header.
Status ReadDynamicDepthFields(const uint8_t* data, size_t size, const char* name,
                              std::string_view main, std::string_view extended, int32_t photo_width,
                              int32_t photo_height, DynamicDepthFields* out);

// The fields the GDepth reader gives (RefocusableFields), from a file's Dynamic Depth: the depth
// item as the depth image, the confidence item as its confidence, the original as the image.
void DynamicDepthAsRefocusable(const DynamicDepthFields& dd, RefocusableFields* out);

// The photo's intrinsics (Camera:ImagingModel) as the specification normalises them: the focal
// lengths by the larger side of the image_width x image_height photo, the principal point by the
// width and the height.
struct DdImagingModel {
  double focal_length_x = 0.0, focal_length_y = 0.0;  // 0: not known, not written
  double principal_point_x = 0.0, principal_point_y = 0.0;
  int32_t image_width = 0, image_height = 0;
};

// What a written file carries as Dynamic Depth besides the RefocusableXmp's depth, its confidence
// (GDepth:Confidence's bytes, the ConfidenceURI item when there are any) and original.
struct DynamicDepthExtras {
  // The specification's name for depth that is not metric (the product's: 1 / disparity in px).
  std::string units = "Diopters";
  // GImage's original as an item too: Dynamic Depth readers refocus from it, at the cost of its
  // bytes a second time.
  bool original = true;
  DdImagingModel imaging_model;
};

// Sets xmp->extra_description to the Device element that lists the items AppendDynamicDepthItems
// writes, from the xmp's depth and original: call it before BuildXmpSegments.
Status SetDynamicDepth(const DynamicDepthExtras& extras, RefocusableXmp* xmp);

// Appends the items SetDynamicDepth listed to a JPEG that ends with its EOI (`jpeg`, in memory).
Status AppendDynamicDepthItems(const RefocusableXmp& xmp, const DynamicDepthExtras& extras,
                               std::vector<uint8_t>* jpeg);

// The same items written through `write` (an AtomicFile's Write, after JpegWriter::Finish).
template <typename Write>
Status WriteDynamicDepthItems(const RefocusableXmp& xmp, const DynamicDepthExtras& extras,
                              Write&& write) {
  LB_RETURN_IF_ERROR(write(xmp.depth.data.data(), xmp.depth.data.size()));
  const std::vector<uint8_t>& confidence = xmp.depth.confidence;
  if (!confidence.empty()) LB_RETURN_IF_ERROR(write(confidence.data(), confidence.size()));
  if (extras.original && !xmp.image.empty()) {
    LB_RETURN_IF_ERROR(write(xmp.image.data(), xmp.image.size()));
  }
  return Status::Ok();
}

}  // namespace lb
