// The Dynamic Depth a product's photo carries beside GDepth (dynamic_depth.h). GDepth can hold its
// images only inline (base64 in the XMP) and Dynamic Depth only as items after the primary JPEG,
// neither by reference to the other, so the depth image, its confidence and the original are
// stored twice, the second time as raw bytes (three quarters of the base64), neither encoded
// again.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "firmware/refocusable/dynamic_depth.h"

namespace lb {
namespace {

constexpr char kDepthUri[] = "android/depthmap";
constexpr char kConfidenceUri[] = "android/confidencemap";
constexpr char kOriginalUri[] = "android/originalimage";
constexpr char kPrimaryUri[] = "primary_image";

void Item(const std::string& mime, size_t length, const char* uri, std::string* out) {
  char text[256];
  snprintf(text, sizeof(text),
           "     <rdf:li rdf:parseType=\"Resource\">\n"
           "      <Container:Item Item:Mime=\"%s\" Item:Length=\"%zu\" Item:DataURI=\"%s\"/>\n"
           "     </rdf:li>\n",
           mime.c_str(), length, uri);
  *out += text;
}

void Attribute(const char* name, double value, std::string* out) {
  char text[96];
  snprintf(text, sizeof(text), "\n        %s=\"%.9g\"", name, value);
  *out += text;
}

void Attribute(const char* name, const std::string& value, std::string* out) {
  *out += "\n        ";
  *out += name;
  *out += "=\"" + value + "\"";
}

bool IsPlain(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '/' || c == '-' || c == '+' || c == '.';
    if (!ok) return false;
  }
  return true;
}

}  // namespace

Status SetDynamicDepth(const DynamicDepthExtras& extras, RefocusableXmp* xmp) {
  const GDepthInfo& d = xmp->depth;
  if (d.data.empty()) return Status(Code::kInvalidArgument, "dynamic depth: no depth image");
  if (!IsPlain(d.mime) || !IsPlain(xmp->image_mime) || !IsPlain(d.confidence_mime) ||
      (extras.units != "Meters" && extras.units != "Diopters" && extras.units != "None") ||
      (d.format != "RangeInverse" && d.format != "RangeLinear")) {
    return Status(Code::kInvalidArgument, "dynamic depth: a mime, units or format out of range");
  }
  const DdImagingModel& m = extras.imaging_model;
  if (!std::isfinite(d.near_depth) || !std::isfinite(d.far_depth) ||
      !std::isfinite(m.focal_length_x) || !std::isfinite(m.focal_length_y) ||
      !std::isfinite(m.principal_point_x) || !std::isfinite(m.principal_point_y)) {
    return Status(Code::kInvalidArgument, "dynamic depth: fields must be finite");
  }
  const bool original = extras.original && !xmp->image.empty(), confidence = !d.confidence.empty();
  std::string& p = xmp->extra_description;
  p = "  <rdf:Description rdf:about=\"\"";
  const std::pair<const char*, const char*> spaces[] = {
      {"Device", kDdDeviceNs}, {"Container", kDdContainerNs},
      {"Item", kDdItemNs},     {"Profile", kDdProfileNs},
      {"Camera", kDdCameraNs}, {"DepthMap", kDdDepthMapNs},
      {"Image", kDdImageNs},   {"ImagingModel", kDdImagingModelNs}};
  for (const auto& [prefix, uri] : spaces) {
    p += std::string("\n    xmlns:") + prefix + "=\"" + uri + "\"";
  }
  p += ">\n   <Device:Container rdf:parseType=\"Resource\">\n    <Container:Directory>\n"
       "     <rdf:Seq>\n";
  Item("image/jpeg", 0, kPrimaryUri, &p);
  Item(d.mime, d.data.size(), kDepthUri, &p);
  if (confidence) Item(d.confidence_mime, d.confidence.size(), kConfidenceUri, &p);
  if (original) Item(xmp->image_mime, xmp->image.size(), kOriginalUri, &p);
  p += "     </rdf:Seq>\n    </Container:Directory>\n   </Device:Container>\n";
  p += "   <Device:Profiles>\n    <rdf:Seq>\n     <rdf:li rdf:parseType=\"Resource\">\n"
       "      <Device:Profile rdf:parseType=\"Resource\">\n"
       "       <Profile:Type>DepthPhoto</Profile:Type>\n"
       "       "
       "<Profile:CameraIndices><rdf:Seq><rdf:li>0</rdf:li></rdf:Seq></Profile:CameraIndices>\n"
       "      </Device:Profile>\n     </rdf:li>\n    </rdf:Seq>\n   </Device:Profiles>\n";
  p += "   <Device:Cameras>\n    <rdf:Seq>\n     <rdf:li rdf:parseType=\"Resource\">\n"
       "      <Device:Camera rdf:parseType=\"Resource\">\n       <Camera:DepthMap";
  Attribute("DepthMap:Format", d.format, &p);
  Attribute("DepthMap:Near", d.near_depth, &p);
  Attribute("DepthMap:Far", d.far_depth, &p);
  Attribute("DepthMap:Units", extras.units, &p);
  Attribute("DepthMap:MeasureType", std::string("OpticalAxis"), &p);
  Attribute("DepthMap:DepthURI", std::string(kDepthUri), &p);
  if (confidence) Attribute("DepthMap:ConfidenceURI", std::string(kConfidenceUri), &p);
  p += "/>\n       <Camera:Image";
  Attribute("Image:ItemSemantic", std::string(original ? "Original" : "Primary"), &p);
  Attribute("Image:ItemURI", std::string(original ? kOriginalUri : kPrimaryUri), &p);
  p += "/>\n";
  if (m.focal_length_x > 0.0) {
    p += "       <Camera:ImagingModel";
    Attribute("ImagingModel:FocalLengthX", m.focal_length_x, &p);
    Attribute("ImagingModel:FocalLengthY", m.focal_length_y, &p);
    Attribute("ImagingModel:PrincipalPointX", m.principal_point_x, &p);
    Attribute("ImagingModel:PrincipalPointY", m.principal_point_y, &p);
    Attribute("ImagingModel:ImageWidth", m.image_width, &p);
    Attribute("ImagingModel:ImageHeight", m.image_height, &p);
    p += "/>\n";
  }
  p += "      </Device:Camera>\n     </rdf:li>\n    </rdf:Seq>\n   </Device:Cameras>\n"
       "  </rdf:Description>\n";
  return Status::Ok();
}

Status AppendDynamicDepthItems(const RefocusableXmp& xmp, const DynamicDepthExtras& extras,
                               std::vector<uint8_t>* jpeg) {
  const size_t n = jpeg->size();
  if (n < 4 || (*jpeg)[n - 2] != 0xFF || (*jpeg)[n - 1] != 0xD9) {
    return Status(Code::kInvalidArgument, "dynamic depth: the primary does not end with its EOI");
  }
  jpeg->reserve(n + xmp.depth.data.size() + xmp.depth.confidence.size() +
                (extras.original ? xmp.image.size() : 0));
  // resize and memcpy rather than insert: GCC 14 takes an empty range's insert for an overflow
  // (-Wstringop-overflow) in Debian 13's Release builds.
  return WriteDynamicDepthItems(xmp, extras, [jpeg](const uint8_t* data, size_t size) {
    if (size == 0) return Status::Ok();
    const size_t at = jpeg->size();
    jpeg->resize(at + size);
    memcpy(jpeg->data() + at, data, size);
    return Status::Ok();
  });
}

}  // namespace lb
