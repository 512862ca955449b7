#include "firmware/codecs/exif.h"

#include <libexif/exif-data.h>
#include <libexif/exif-loader.h>

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "algo/motion/camera.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/storage/input_file.h"

namespace lb {
namespace {

bool IsDateTime(const std::string& t) {
  static const char kPattern[] = "dddd:dd:dd dd:dd:dd";
  if (t.size() != sizeof(kPattern) - 1) return false;
  for (size_t i = 0; i < t.size(); ++i) {
    const bool digit = t[i] >= '0' && t[i] <= '9';
    if (kPattern[i] == 'd' ? !digit : t[i] != kPattern[i]) return false;
  }
  return true;
}

// Adds one entry whose bytes are already in the file's byte order.
bool AddEntry(ExifData* data, ExifMem* mem, ExifIfd ifd, ExifTag tag, ExifFormat format,
              unsigned long components, const void* bytes) {
  ExifEntry* entry = exif_entry_new_mem(mem);
  if (entry == nullptr) return false;
  const size_t size = exif_format_get_size(format) * components;
  entry->data = static_cast<unsigned char*>(exif_mem_alloc(mem, static_cast<ExifLong>(size)));
  if (entry->data == nullptr) {
    exif_entry_unref(entry);
    return false;
  }
  memcpy(entry->data, bytes, size);
  entry->size = static_cast<unsigned int>(size);
  entry->tag = tag;
  entry->format = format;
  entry->components = components;
  exif_content_add_entry(data->ifd[ifd], entry);
  exif_entry_unref(entry);
  return true;
}

bool AddString(ExifData* data, ExifMem* mem, ExifIfd ifd, ExifTag tag, const std::string& text) {
  if (text.empty()) return true;
  return AddEntry(data, mem, ifd, tag, EXIF_FORMAT_ASCII, text.size() + 1, text.c_str());
}

bool AddShort(ExifData* data, ExifMem* mem, ExifIfd ifd, ExifTag tag, uint16_t value) {
  unsigned char bytes[2];
  exif_set_short(bytes, exif_data_get_byte_order(data), value);
  return AddEntry(data, mem, ifd, tag, EXIF_FORMAT_SHORT, 1, bytes);
}

bool AddRational(ExifData* data, ExifMem* mem, ExifIfd ifd, ExifTag tag, ExifRational value) {
  unsigned char bytes[8];
  exif_set_rational(bytes, exif_data_get_byte_order(data), value);
  return AddEntry(data, mem, ifd, tag, EXIF_FORMAT_RATIONAL, 1, bytes);
}

bool AddLong(ExifData* data, ExifMem* mem, ExifIfd ifd, ExifTag tag, uint32_t value) {
  unsigned char bytes[4];
  exif_set_long(bytes, exif_data_get_byte_order(data), value);
  return AddEntry(data, mem, ifd, tag, EXIF_FORMAT_LONG, 1, bytes);
}

// One SHORT tag of `ifd` inside lo..hi, or 0 (absent, malformed or out of range).
int32_t ShortTag(ExifData* data, ExifIfd ifd, ExifTag tag, int32_t lo, int32_t hi) {
  if (data == nullptr) return 0;
  int32_t value = 0;
  ExifEntry* e = exif_content_get_entry(data->ifd[ifd], tag);
  if (e != nullptr && e->format == EXIF_FORMAT_SHORT && e->components == 1) {
    const int32_t v = exif_get_short(e->data, exif_data_get_byte_order(data));
    if (v >= lo && v <= hi) value = v;
  }
  exif_data_unref(data);
  return value;
}

}  // namespace

bool ExifTags::has_exif() const {
  return !make.empty() || !model.empty() || !software.empty() || !datetime_original.empty() ||
         f_number > 0.0f || focal_35mm > 0 || orientation > 0;
}

Status BuildExif(const ExifTags& meta, int32_t width, int32_t height,
                 std::vector<uint8_t>* payload) {
  payload->clear();
  if (!meta.datetime_original.empty() && !IsDateTime(meta.datetime_original)) {
    return Status(Code::kInvalidArgument,
                  "exif: DateTimeOriginal '%.40s' is not YYYY:MM:DD HH:MM:SS",
                  meta.datetime_original.c_str());
  }
  if (!(meta.f_number >= 0.0f && meta.f_number < 1000.0f)) {
    return Status(Code::kInvalidArgument, "exif: f-number %g out of range",
                  static_cast<double>(meta.f_number));
  }
  ExifMem* mem = exif_mem_new_default();
  ExifData* data = mem ? exif_data_new_mem(mem) : nullptr;
  if (data == nullptr) {
    if (mem) exif_mem_unref(mem);
    return Status(Code::kOutOfMemory, "exif: cannot create the EXIF block");
  }
  exif_data_set_byte_order(data, EXIF_BYTE_ORDER_INTEL);
  exif_data_set_data_type(data, EXIF_DATA_TYPE_COMPRESSED);
  // Besides the fields asked for, the tags EXIF 2.3 requires in a JPEG (exiftool -validate):
  // 72 dpi, centred chroma siting (what libjpeg's 4:2:0 assumes), sRGB, Y Cb Cr components.
  static const unsigned char kComponents[4] = {1, 2, 3, 0};
  bool ok =
      AddString(data, mem, EXIF_IFD_0, EXIF_TAG_MAKE, meta.make) &&
      AddString(data, mem, EXIF_IFD_0, EXIF_TAG_MODEL, meta.model) &&
      AddRational(data, mem, EXIF_IFD_0, EXIF_TAG_X_RESOLUTION, {72, 1}) &&
      AddRational(data, mem, EXIF_IFD_0, EXIF_TAG_Y_RESOLUTION, {72, 1}) &&
      AddShort(data, mem, EXIF_IFD_0, EXIF_TAG_RESOLUTION_UNIT, 2) &&
      AddString(data, mem, EXIF_IFD_0, EXIF_TAG_SOFTWARE, meta.software) &&
      AddShort(data, mem, EXIF_IFD_0, EXIF_TAG_YCBCR_POSITIONING, 1) &&
      AddEntry(data, mem, EXIF_IFD_EXIF, EXIF_TAG_EXIF_VERSION, EXIF_FORMAT_UNDEFINED, 4, "0230") &&
      AddEntry(data, mem, EXIF_IFD_EXIF, EXIF_TAG_COMPONENTS_CONFIGURATION, EXIF_FORMAT_UNDEFINED,
               4, kComponents) &&
      AddEntry(data, mem, EXIF_IFD_EXIF, EXIF_TAG_FLASH_PIX_VERSION, EXIF_FORMAT_UNDEFINED, 4,
               "0100") &&
      AddShort(data, mem, EXIF_IFD_EXIF, EXIF_TAG_COLOR_SPACE, 1) &&
      AddString(data, mem, EXIF_IFD_EXIF, EXIF_TAG_DATE_TIME_ORIGINAL, meta.datetime_original) &&
      AddLong(data, mem, EXIF_IFD_EXIF, EXIF_TAG_PIXEL_X_DIMENSION, static_cast<uint32_t>(width)) &&
      AddLong(data, mem, EXIF_IFD_EXIF, EXIF_TAG_PIXEL_Y_DIMENSION, static_cast<uint32_t>(height));
  if (ok && meta.f_number > 0.0f) {
    // Hundredths are finer than any lens marking (f/1.4, f/2.8, f/5.6).
    const ExifRational f = {static_cast<ExifLong>(meta.f_number * 100.0f + 0.5f), 100};
    ok = AddRational(data, mem, EXIF_IFD_EXIF, EXIF_TAG_FNUMBER, f);
  }
  if (ok && meta.orientation >= 1 && meta.orientation <= 8) {
    ok = AddShort(data, mem, EXIF_IFD_0, EXIF_TAG_ORIENTATION,
                  static_cast<uint16_t>(meta.orientation));
  }
  if (ok && meta.focal_35mm > 0) {
    ok = AddShort(data, mem, EXIF_IFD_EXIF, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM,
                  static_cast<uint16_t>(meta.focal_35mm < 65535 ? meta.focal_35mm : 65535));
  }
  unsigned char* bytes = nullptr;
  unsigned int size = 0;
  if (ok) exif_data_save_data(data, &bytes, &size);
  Status status;
  if (!ok || bytes == nullptr) {
    status = Status(Code::kOutOfMemory, "exif: cannot build the EXIF block");
  } else if (size > JpegSegment::kMaxPayload) {
    status = Status(Code::kInvalidArgument, "exif: %u bytes do not fit one APP1 segment", size);
  } else {
    payload->assign(bytes, bytes + size);
  }
  if (bytes) exif_mem_free(mem, bytes);
  exif_data_unref(data);
  exif_mem_unref(mem);
  return status;
}

namespace {

// The loader every read goes through, so a file and its bytes in memory find the same APP1
// segment. It is fed the 1 KiB pieces libexif's own file reader hands it, so that every read
// makes the same calls; it takes a non-const buffer it only reads, and says when it has enough.
// `next` fills a piece and returns its length, 0 at the end.
template <typename Next>
ExifData* ExifFromPieces(Next&& next) {
  ExifLoader* loader = exif_loader_new();
  if (loader == nullptr) return nullptr;
  constexpr size_t kPiece = 1024;
  unsigned char piece[kPiece];
  for (size_t n = next(piece, kPiece); n > 0; n = next(piece, kPiece)) {
    if (!exif_loader_write(loader, piece, static_cast<unsigned int>(n))) break;
  }
  ExifData* exif = exif_loader_get_data(loader);
  exif_loader_unref(loader);
  return exif;
}

ExifData* ExifFromDescriptor(int fd) {
  off_t pos = 0;
  return ExifFromPieces([&](unsigned char* piece, size_t max) -> size_t {
    for (;;) {
      const ssize_t n = pread(fd, piece, max, pos);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return 0;
      pos += n;
      return static_cast<size_t>(n);
    }
  });
}

// Through the product's input open, so a FIFO is no tag rather than a wait.
ExifData* ExifFromFile(const char* path) {
  int fd = -1;
  if (!OpenInputFile(path, &fd).ok()) return nullptr;
  ExifData* exif = ExifFromDescriptor(fd);
  close(fd);
  return exif;
}

}  // namespace

double ExifFocalPx(const char* path, int32_t width, int32_t height) {
  // 0 means "unknown" in EXIF; a 35 mm equivalent outside 8..2000 mm is a broken tag.
  const int32_t f35 =
      ShortTag(ExifFromFile(path), EXIF_IFD_EXIF, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM, 8, 2000);
  return f35 > 0 ? FocalPxFrom35mm(f35, width, height) : 0;
}

int32_t ExifOrientation(const char* path) {
  return ShortTag(ExifFromFile(path), EXIF_IFD_0, EXIF_TAG_ORIENTATION, 1, 8);
}

int32_t ExifOrientation(const uint8_t* data, size_t size) {
  size_t pos = 0;
  ExifData* exif = ExifFromPieces([&](unsigned char* piece, size_t max) {
    const size_t n = size - pos < max ? size - pos : max;
    if (n == 0) return n;  // data may be null when size is 0
    memcpy(piece, data + pos, n);
    pos += n;
    return n;
  });
  return ShortTag(exif, EXIF_IFD_0, EXIF_TAG_ORIENTATION, 1, 8);
}

int32_t ExifOrientationAt(int fd) {
  return ShortTag(ExifFromDescriptor(fd), EXIF_IFD_0, EXIF_TAG_ORIENTATION, 1, 8);
}

namespace {

// Each orientation as a transpose (5..8) followed by mirroring the displayed axes: 2 mirrors x,
// 3 both, 4 y; 5 is the transpose alone, 6 (90 degrees clockwise) then mirrors x, 7 both, 8 y.
struct Turn {
  bool swap, flip_x, flip_y;
};

Turn TurnOf(int32_t o) {
  static constexpr Turn kTurns[9] = {
      {false, false, false}, {false, false, false}, {false, true, false},
      {false, true, true},   {false, false, true},  {true, false, false},
      {true, true, false},   {true, true, true},    {true, false, true}};
  return o >= 1 && o <= 8 ? kTurns[o] : kTurns[0];
}

}  // namespace

void ExifStoredToDisplayed(int32_t o, double s, double t, double* u, double* v) {
  const Turn turn = TurnOf(o);
  const double a = turn.swap ? t : s, b = turn.swap ? s : t;
  *u = turn.flip_x ? 1 - a : a;
  *v = turn.flip_y ? 1 - b : b;
}

void ExifDisplayedToStored(int32_t o, double u, double v, double* s, double* t) {
  const Turn turn = TurnOf(o);
  const double a = turn.flip_x ? 1 - u : u, b = turn.flip_y ? 1 - v : v;
  *s = turn.swap ? b : a;
  *t = turn.swap ? a : b;
}

}  // namespace lb
