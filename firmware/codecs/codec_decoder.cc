#include "firmware/codecs/codec_decoder.h"

#include "firmware/codecs/exif.h"
#include "firmware/codecs/image_file.h"

namespace lb {
namespace {

class CodecDecoder final : public ImageDecoder {
 public:
  Status Probe(const char* path, ImageHeader* header) const override {
    ImageFileInfo info;
    LB_RETURN_IF_ERROR(ProbeImageFile(path, &info));
    header->format = info.format;
    header->width = info.width;
    header->height = info.height;
    return Status::Ok();
  }
  Status Stream(const char* path, int32_t index, FrameSink& sink) const override {
    return StreamImageFile(path, index, sink);
  }
  CameraTags Tags(const char* path, int32_t width, int32_t height) const override {
    CameraTags tags;
    tags.focal_px = ExifFocalPx(path, width, height);
    tags.orientation = ExifOrientation(path);
    return tags;
  }
};

}  // namespace

const ImageDecoder& CodecImageDecoder() {
  static const CodecDecoder decoder;
  return decoder;
}

}  // namespace lb
