#include "sim/files/exif_focal.h"

#include <libexif/exif-data.h>

#include "algo/motion/camera.h"

namespace lb {

double ExifFocalPx(const char* path, int32_t width, int32_t height) {
  ExifData* data = exif_data_new_from_file(path);
  if (data == nullptr) return 0;
  double focal = 0;
  ExifEntry* e =
      exif_content_get_entry(data->ifd[EXIF_IFD_EXIF], EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
  if (e != nullptr && e->format == EXIF_FORMAT_SHORT && e->components == 1) {
    const double f35 = exif_get_short(e->data, exif_data_get_byte_order(data));
    // 0 means "unknown" in EXIF; a 35 mm equivalent outside 8..2000 mm is a broken tag.
    if (f35 >= 8 && f35 <= 2000) focal = FocalPxFrom35mm(f35, width, height);
  }
  exif_data_unref(data);
  return focal;
}

int32_t ExifOrientation(const char* path) {
  ExifData* data = exif_data_new_from_file(path);
  if (data == nullptr) return 0;
  int32_t orientation = 0;
  ExifEntry* e = exif_content_get_entry(data->ifd[EXIF_IFD_0], EXIF_TAG_ORIENTATION);
  if (e != nullptr && e->format == EXIF_FORMAT_SHORT && e->components == 1) {
    const int32_t v = exif_get_short(e->data, exif_data_get_byte_order(data));
    if (v >= 1 && v <= 8) orientation = v;
  }
  exif_data_unref(data);
  return orientation;
}

}  // namespace lb
