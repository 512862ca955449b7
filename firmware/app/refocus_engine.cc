#include "firmware/app/refocus_engine.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string_view>

// clang-format off: jpeglib.h needs <cstdio> first and jerror.h after it.
#include <jerror.h>
#include <jpeglib.h>
// clang-format on
#include <png.h>

#include "algo/core/color.h"
#include "firmware/app/focus.h"
#include "firmware/app/job.h"
#include "firmware/app/rerender.h"
#include "firmware/codecs/exif.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/platform/worker_pool.h"
#include "firmware/refocusable/base64.h"
#include "firmware/refocusable/xmp_writer.h"

namespace lb {

struct RefocusEngine::Chunk {
  const uint8_t* guid;  // 32 bytes
  uint32_t offset, full;
  const uint8_t* bytes;
  size_t size;
};

void RefocusEngine::FreeDeleter::operator()(void* p) const { free(p); }

namespace {

constexpr size_t kExtendedHeader = sizeof(kExtendedXmpSignature) + 32 + 4 + 4;

uint32_t BigEndian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// XMP lookups over a packet's text without copying it (the file reader's rules: a field is an
// attribute prefix:name="v" or a simple element <prefix:name>v</prefix:name>, the prefix the one
// an xmlns attribute binds to the namespace).
bool Quoted(std::string_view text, size_t pos, std::string_view* value) {
  while (pos < text.size() && IsSpace(text[pos])) ++pos;
  if (pos >= text.size() || (text[pos] != '"' && text[pos] != '\'')) return false;
  const size_t end = text.find(text[pos], pos + 1);
  if (end == std::string_view::npos) return false;
  *value = text.substr(pos + 1, end - pos - 1);
  return true;
}

std::string_view PrefixOf(std::string_view text, std::string_view uri) {
  size_t pos = 0;
  while ((pos = text.find("xmlns:", pos)) != std::string_view::npos) {
    pos += 6;
    const size_t eq = text.find('=', pos);
    if (eq == std::string_view::npos || eq - pos > 64) continue;
    size_t end = eq;
    while (end > pos && IsSpace(text[end - 1])) --end;
    std::string_view value;
    if (Quoted(text, eq + 1, &value) && value == uri) return text.substr(pos, end - pos);
  }
  return {};
}

bool FindIn(std::string_view text, std::string_view uri, std::string_view name,
            std::string_view* value) {
  const std::string_view prefix = PrefixOf(text, uri);
  if (prefix.empty()) return false;
  const size_t qsize = prefix.size() + 1 + name.size();
  size_t pos = 0;
  while ((pos = text.find(prefix, pos)) != std::string_view::npos) {
    const size_t start = pos, after = pos + qsize;
    pos += prefix.size();
    if (start == 0 || after >= text.size() || text[start + prefix.size()] != ':' ||
        text.substr(start + prefix.size() + 1, name.size()) != name) {
      continue;
    }
    const bool element = text[start - 1] == '<';
    if (!element && !IsSpace(text[start - 1])) continue;
    if (element) {
      if (text[after] != '>') continue;
      size_t close = after + 1;
      while ((close = text.find("</", close)) != std::string_view::npos) {
        if (text.substr(close + 2, qsize) == text.substr(start, qsize)) break;
        close += 2;
      }
      if (close == std::string_view::npos) return false;
      *value = text.substr(after + 1, close - after - 1);
      return true;
    }
    size_t eq = after;
    while (eq < text.size() && IsSpace(text[eq])) ++eq;
    if (eq >= text.size() || text[eq] != '=') continue;
    return Quoted(text, eq + 1, value);
  }
  return false;
}

struct Packets {
  std::string_view main, extended;
  bool Find(const char* uri, const char* name, std::string_view* value) const {
    return FindIn(main, uri, name, value) || FindIn(extended, uri, name, value);
  }
  bool Has(const char* uri, const char* name) const {
    std::string_view v;
    return Find(uri, name, &v);
  }
};

Status Number(const Packets& p, const char* path, const char* uri, const char* name, double* out) {
  std::string_view v;
  if (!p.Find(uri, name, &v)) return Status(Code::kCorruptData, "%s: %s missing", path, name);
  while (!v.empty() && IsSpace(v.front())) v.remove_prefix(1);
  while (!v.empty() && IsSpace(v.back())) v.remove_suffix(1);
  char text[64];
  if (v.empty() || v.size() >= sizeof(text)) {
    return Status(Code::kCorruptData, "%s: %s is not a number", path, name);
  }
  memcpy(text, v.data(), v.size());
  text[v.size()] = '\0';
  char* end = nullptr;
  errno = 0;
  *out = strtod(text, &end);
  if (end != text + v.size() || errno != 0 || !std::isfinite(*out)) {
    return Status(Code::kCorruptData, "%s: %s is not a number", path, name);
  }
  return Status::Ok();
}

// Base64 into a vector whose capacity was reserved: more than that is kOutOfMemory, checked
// before decoding so the vector never grows.
Status Base64Into(const Packets& p, const char* path, const char* uri, const char* name,
                  std::vector<uint8_t>* out) {
  std::string_view v;
  if (!p.Find(uri, name, &v)) return Status(Code::kUnsupported, "%s: no %s", path, name);
  if (v.size() / 4 * 3 > out->capacity()) {
    return Status(Code::kOutOfMemory, "%s: %s of %zu bytes is larger than the engine takes", path,
                  name, v.size() / 4 * 3);
  }
  Status s = Base64Decode(v.data(), v.size(), out);
  if (!s.ok()) s.Prefix("%s: %s: ", path, name);
  return s;
}

// --- libjpeg: the all-in-focus original, row by row into YCbCr 4:2:0 (the conversion the
// pipeline applies to a sensor's reference frame, as the Rerenderer does).
struct JpegError {
  jpeg_error_mgr pub;
  jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void JpegFail(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegError*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  longjmp(e->jump, 1);
}

void JpegMessage(j_common_ptr cinfo, int level) {
  if (level >= 0) return;
  const int code = cinfo->err->msg_code;
  if (code == JWRN_JFIF_MAJOR || code == JWRN_ADOBE_XFORM || code == JWRN_BOGUS_ICC) return;
  JpegFail(cinfo);  // corrupt data: never shown as grey padding
}

struct YccOut {
  uint8_t *y, *cb, *cr;
  uint8_t* rgb;  // two rows of max_width RGB8, then one grey row
  int32_t max_width, max_height;
  int32_t width, height;
};

Status DecodeOriginal(const char* path, const uint8_t* data, size_t size, YccOut* out) {
  jpeg_decompress_struct cinfo;
  JpegError err;
  memset(&cinfo, 0, sizeof(cinfo));
  cinfo.err = jpeg_std_error(&err.pub);
  err.pub.error_exit = JpegFail;
  err.pub.emit_message = JpegMessage;
  err.message[0] = '\0';
  Code code = Code::kCorruptData;
  char why[96] = "";
  if (setjmp(err.jump) != 0) {
    jpeg_destroy_decompress(&cinfo);
    return Status(Code::kCorruptData, "%s: GImage: JPEG %s", path, err.message);
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  const int32_t w = static_cast<int32_t>(cinfo.image_width);
  const int32_t h = static_cast<int32_t>(cinfo.image_height);
  if (w > out->max_width || h > out->max_height) {
    code = Code::kOutOfMemory;
    snprintf(why, sizeof(why), "a %dx%d original, larger than the %dx%d the engine takes", w, h,
             out->max_width, out->max_height);
  } else if (w < 16 || h < 16) {
    code = Code::kUnsupported;
    snprintf(why, sizeof(why), "a %dx%d original is too small to render", w, h);
  } else if (cinfo.jpeg_color_space != JCS_GRAYSCALE && cinfo.jpeg_color_space != JCS_YCbCr &&
             cinfo.jpeg_color_space != JCS_RGB) {
    code = Code::kUnsupported;
    snprintf(why, sizeof(why), "colour space %d", static_cast<int>(cinfo.jpeg_color_space));
  }
  if (why[0] != '\0') {
    jpeg_destroy_decompress(&cinfo);
    return Status(code, "%s: GImage: %s", path, why);
  }
  const bool gray = cinfo.jpeg_color_space == JCS_GRAYSCALE;
  cinfo.out_color_space = gray ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(&cinfo);
  const int32_t cw = (w + 1) / 2;
  uint8_t* gray_row = out->rgb + static_cast<size_t>(out->max_width) * 6;
  for (int32_t y = 0; y < h; ++y) {
    uint8_t* row = out->rgb + static_cast<size_t>(y & 1) * w * 3;
    JSAMPROW target = gray ? gray_row : row;
    if (jpeg_read_scanlines(&cinfo, &target, 1) != 1) {
      jpeg_destroy_decompress(&cinfo);
      return Status(Code::kCorruptData, "%s: GImage: no row %d", path, y);
    }
    if (gray) RowToRgb8(PixelFormat::kGray8, gray_row, nullptr, w, row);
    RowRgb8ToY(row, w, out->y + static_cast<size_t>(y) * w);
    if ((y & 1) || y == h - 1) {
      const uint8_t* above = (y & 1) ? out->rgb : row;
      RowsRgb8ToCbCr420(above, row, w, out->cb + static_cast<size_t>(y / 2) * cw,
                        out->cr + static_cast<size_t>(y / 2) * cw);
    }
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  out->width = w;
  out->height = h;
  return Status::Ok();
}

// --- libpng: the grey depth image (8 or 16 bit, not interlaced) into 16-bit values.
struct PngInput {
  jmp_buf jump;
  char message[128];
  const uint8_t* data;
  size_t size, pos;
};

[[noreturn]] void PngFail(png_structp png, png_const_charp message) {
  auto* in = static_cast<PngInput*>(png_get_error_ptr(png));
  snprintf(in->message, sizeof(in->message), "%s", message);
  longjmp(in->jump, 1);
}
void PngWarn(png_structp, png_const_charp) {}
void PngRead(png_structp png, png_bytep out, png_size_t n) {
  auto* in = static_cast<PngInput*>(png_get_io_ptr(png));
  if (n > in->size - in->pos) png_error(png, "truncated");
  memcpy(out, in->data + in->pos, n);
  in->pos += n;
}

Status DecodeDepthPng(const char* path, const std::vector<uint8_t>& bytes, int32_t max_w,
                      int32_t max_h, size_t max_values, uint16_t* values, uint8_t* row8,
                      int32_t* width, int32_t* height, int* bits) {
  PngInput in;
  in.message[0] = '\0';
  in.data = bytes.data();
  in.size = bytes.size();
  in.pos = 0;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &in, PngFail, PngWarn);
  if (png == nullptr) return Status(Code::kOutOfMemory, "%s: GDepth: no PNG decoder", path);
  png_infop info = png_create_info_struct(png);
  char why[96] = "";
  if (info == nullptr || setjmp(in.jump) != 0) {
    png_destroy_read_struct(&png, &info, nullptr);
    return Status(Code::kCorruptData, "%s: GDepth: PNG %s", path, in.message);
  }
  png_set_read_fn(png, &in, PngRead);
  png_read_info(png, info);
  png_uint_32 w = 0, h = 0;
  int depth = 0, color = 0, interlace = 0;
  png_get_IHDR(png, info, &w, &h, &depth, &color, &interlace, nullptr, nullptr);
  if (color != PNG_COLOR_TYPE_GRAY || interlace != PNG_INTERLACE_NONE ||
      (depth != 8 && depth != 16)) {
    snprintf(why, sizeof(why), "not an 8 or 16 bit grey, non-interlaced image");
  } else if (w < 1 || h < 1 || w > static_cast<png_uint_32>(max_w) ||
             h > static_cast<png_uint_32>(max_h)) {
    snprintf(why, sizeof(why), "a %ux%u depth map for a %dx%d photo", static_cast<unsigned>(w),
             static_cast<unsigned>(h), max_w, max_h);
  } else if (static_cast<size_t>(w) * h > max_values) {
    snprintf(why, sizeof(why), "a %ux%u depth map, larger than the engine takes",
             static_cast<unsigned>(w), static_cast<unsigned>(h));
  }
  if (why[0] != '\0') {
    png_destroy_read_struct(&png, &info, nullptr);
    return Status(Code::kUnsupported, "%s: GDepth: %s", path, why);
  }
  const uint16_t probe = 1;
  uint8_t first = 0;
  memcpy(&first, &probe, 1);
  if (depth == 16 && first == 1) png_set_swap(png);  // PNG is big-endian
  png_read_update_info(png, info);
  for (png_uint_32 y = 0; y < h; ++y) {
    uint16_t* out = values + static_cast<size_t>(y) * w;
    if (depth == 16) {
      png_read_row(png, reinterpret_cast<png_bytep>(out), nullptr);
    } else {
      png_read_row(png, row8, nullptr);
      for (png_uint_32 x = 0; x < w; ++x) out[x] = row8[x];
    }
  }
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  *width = static_cast<int32_t>(w);
  *height = static_cast<int32_t>(h);
  *bits = depth;
  return Status::Ok();
}

// Mean of a step x step block of `src` (clamped at its edges) into each pixel of `dst`.
void BoxDown(const uint8_t* src, int32_t sw, int32_t sh, int32_t step, uint8_t* dst, int32_t dw,
             int32_t dh) {
  const uint32_t n = static_cast<uint32_t>(step * step);
  for (int32_t y = 0; y < dh; ++y) {
    for (int32_t x = 0; x < dw; ++x) {
      uint32_t sum = 0;
      for (int32_t j = 0; j < step; ++j) {
        const int32_t sy = std::min(y * step + j, sh - 1);
        const uint8_t* row = src + static_cast<size_t>(sy) * sw;
        for (int32_t i = 0; i < step; ++i) sum += row[std::min(x * step + i, sw - 1)];
      }
      dst[static_cast<size_t>(y) * dw + x] = static_cast<uint8_t>((sum + n / 2) / n);
    }
  }
}

// Waits while the camera works, between strips.
class CameraYield final : public StripObserver {
 public:
  CameraYield(const std::atomic<bool>* busy, int64_t* paused) : busy_(busy), paused_(paused) {}
  void OnStrip(const ConstPlanarU8&, int32_t, int32_t) override {
    if (busy_ == nullptr || !busy_->load(std::memory_order_acquire)) return;
    ++*paused_;
    const timespec nap = {0, 2 * 1000 * 1000};
    while (busy_->load(std::memory_order_acquire)) nanosleep(&nap, nullptr);
  }

 private:
  const std::atomic<bool>* busy_;
  int64_t* paused_;
};

}  // namespace

RefocusEngine::RefocusEngine() = default;
RefocusEngine::~RefocusEngine() = default;

Status RefocusEngine::Configure(const RefocusEngineConfig& config) {
  if (configured_) return Status(Code::kBusy, "refocus engine: configured twice");
  const int32_t W = config.max_width, H = config.max_height;
  if (W < 16 || H < 16 || W > kMaxFrameSide || H > kMaxFrameSide) {
    return Status(Code::kInvalidArgument, "refocus engine: photo size %dx%d outside 16..%d", W, H,
                  kMaxFrameSide);
  }
  if (config.preview_side < 64 || config.max_blur_radius < 1 || config.max_blur_radius > 128) {
    return Status(Code::kInvalidArgument, "refocus engine: preview side %d, blur radius %d",
                  config.preview_side, config.max_blur_radius);
  }
  config_ = config;
  const size_t pixels = static_cast<size_t>(W) * H;
  if (config_.max_file_bytes == 0) config_.max_file_bytes = pixels + (size_t{1} << 20);
  const size_t file = config_.max_file_bytes;
  const size_t cpx = static_cast<size_t>((W + 1) / 2) * ((H + 1) / 2);
  const int32_t pw = std::min(W, config.preview_side), ph = std::min(H, config.preview_side);
  const size_t ppx = static_cast<size_t>(pw) * ph;
  const size_t pcpx = static_cast<size_t>((pw + 1) / 2) * ((ph + 1) / 2);
  scratch_.reserve(file);
  extended_.resize(file);
  chunks_.reserve(file / kExtendedXmpChunk + 2);
  // Base64 in the extended XMP: at most 3/4 of the file; a 16-bit depth PNG, at most its
  // values' bytes and a little (stored rows of 64 KiB deflate blocks).
  const size_t depth_px =
      std::min(pixels, static_cast<size_t>(std::max(1, config.max_depth_pixels)));
  png_.reserve(std::min(file / 4 * 3, depth_px * 2 + depth_px / 64 + 65536));
  original_.reserve(file / 4 * 3);
  rgb_rows_.resize(static_cast<size_t>(W) * 7);
  y_.resize(pixels);
  cb_.resize(cpx);
  cr_.resize(cpx);
  depth_values_.resize(depth_px);
  disp_q8_.resize(depth_values_.size());
  py_.resize(ppx);
  pcb_.resize(pcpx);
  pcr_.resize(pcpx);
  pdisp_q8_.resize(ppx);

  // The arenas: the largest any photo up to W x H needs, whatever its depth map's scale.
  const int32_t workers = WorkerPool::CountFor(config.threads);
  for (int32_t s = 1; s <= 16; ++s) {
    RenderConfig rc;
    rc.width = W;
    rc.height = H;
    rc.working_scale = s;
    rc.working_width = std::max(1, W / s);
    rc.working_height = std::max(1, H / s);
    rc.max_radius = config.max_blur_radius;
    rc.workers = workers;
    full_bytes_ = std::max(full_bytes_, Arena::RoundUp(RenderStage::RequiredBytes(rc)));
  }
  RenderConfig prc;
  prc.width = pw;
  prc.height = ph;
  prc.working_width = pw;
  prc.working_height = ph;
  prc.max_radius = config.max_blur_radius;
  prc.workers = workers;
  LB_RETURN_IF_ERROR(RenderStage::Validate(prc));
  preview_bytes_ = Arena::RoundUp(RenderStage::RequiredBytes(prc));
  full_block_.reset(static_cast<uint8_t*>(aligned_alloc(Arena::kAlign, full_bytes_)));
  preview_block_.reset(static_cast<uint8_t*>(aligned_alloc(Arena::kAlign, preview_bytes_)));
  if (!full_block_ || !preview_block_) {
    return Status(Code::kOutOfMemory, "refocus engine: cannot allocate %zu bytes to render",
                  full_bytes_ + preview_bytes_);
  }
  full_ = std::make_unique<RenderStage>();
  preview_ = std::make_unique<RenderStage>();
  writer_ = std::make_unique<JpegWriter>();
  pool_ = std::make_unique<WorkerPool>();
  LB_RETURN_IF_ERROR(pool_->Start(workers));
  reserved_bytes_ = scratch_.capacity() + extended_.size() + png_.capacity() +
                    original_.capacity() + rgb_rows_.size() + pixels + 2 * cpx +
                    4 * depth_values_.size() + ppx * 3 + 2 * pcpx + full_bytes_ + preview_bytes_;
  configured_ = true;
  return Status::Ok();
}

Status RefocusEngine::LoadFile(const char* path) {
  const int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    return Status(errno == ENOENT ? Code::kNotFound : Code::kIoError, "%s: %s", path,
                  strerror(errno));
  }
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    return Status(Code::kInvalidArgument, "%s: not a regular file", path);
  }
  const size_t size = static_cast<size_t>(st.st_size);
  if (size > scratch_.capacity()) {
    close(fd);
    return Status(Code::kOutOfMemory, "%s: %zu bytes, more than the %zu the engine takes", path,
                  size, scratch_.capacity());
  }
  scratch_.resize(size);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = read(fd, scratch_.data() + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  close(fd);
  if (done != size) return Status(Code::kIoError, "%s: read %zu of %zu bytes", path, done, size);
  return ParseAndDecode(path, size);
}

Status RefocusEngine::Load(const char* path) {
  if (!configured_) return Status(Code::kInvalidArgument, "refocus engine: Load before Configure");
  loaded_ = false;
  output_size_ = 0;
  WaitForCamera();  // reading and decoding a 12 MP photo takes about 0.1 s of a core
  Status s = LoadFile(path);
  scratch_.clear();  // the bytes are decoded; the buffer now holds outputs
  if (!s.ok()) return s;
  LB_RETURN_IF_ERROR(MakePreviewInputs());
  loaded_ = true;
  return Status::Ok();
}

Status RefocusEngine::ParseAndDecode(const char* path, size_t size) {
  const uint8_t* data = scratch_.data();
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8) {
    return Status(Code::kUnsupported, "%s: not a JPEG", path);
  }
  // The segments before the image data: the main XMP packet and the extended-XMP chunks.
  Packets packets;
  bool have_main = false, have_scan = false;
  chunks_.clear();
  size_t pos = 2;
  while (!have_scan) {
    if (pos >= size || data[pos] != 0xFF) {
      return Status(Code::kCorruptData, "%s: no marker at offset %zu", path, pos);
    }
    while (pos < size && data[pos] == 0xFF) ++pos;
    if (pos >= size) return Status(Code::kCorruptData, "%s: ends in a marker", path);
    const uint8_t marker = data[pos++];
    if (marker == 0xD9) return Status(Code::kCorruptData, "%s: no image data", path);
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;
    if (size - pos < 2) return Status(Code::kCorruptData, "%s: ends in a marker", path);
    const size_t length = (size_t{data[pos]} << 8) | data[pos + 1];
    if (length < 2 || length > size - pos) {
      return Status(Code::kCorruptData, "%s: segment 0x%02X truncated", path, marker);
    }
    const uint8_t* p = data + pos + 2;
    const size_t n = length - 2;
    pos += length;
    if (marker == 0xDA) have_scan = true;
    if (marker != 0xE1) continue;
    if (!have_main && n >= sizeof(kXmpSignature) &&
        memcmp(p, kXmpSignature, sizeof(kXmpSignature)) == 0) {
      packets.main = std::string_view(reinterpret_cast<const char*>(p) + sizeof(kXmpSignature),
                                      n - sizeof(kXmpSignature));
      have_main = true;
    } else if (n >= kExtendedHeader &&
               memcmp(p, kExtendedXmpSignature, sizeof(kExtendedXmpSignature)) == 0) {
      const uint8_t* h = p + sizeof(kExtendedXmpSignature) + 32;
      const uint32_t full = BigEndian32(h), offset = BigEndian32(h + 4);
      const size_t bytes = n - kExtendedHeader;
      if (offset > full || bytes > full - offset) {
        return Status(Code::kCorruptData, "%s: extended XMP chunk overruns", path);
      }
      if (chunks_.size() == chunks_.capacity()) {
        return Status(Code::kOutOfMemory, "%s: more extended XMP than the engine takes", path);
      }
      chunks_.push_back(
          {p + sizeof(kExtendedXmpSignature), offset, full, p + kExtendedHeader, bytes});
    }
  }
  if (!have_main) return Status(Code::kUnsupported, "%s: no XMP (not a refocusable JPEG)", path);
  std::string_view guid;
  if (FindIn(packets.main, kXmpNoteNs, "HasExtendedXMP", &guid)) {
    if (guid.size() != 32) return Status(Code::kCorruptData, "%s: bad HasExtendedXMP", path);
    // This packet's chunks in offset order, contiguous, then checked against the MD5.
    auto mine = std::partition(chunks_.begin(), chunks_.end(), [&](const Chunk& c) {
      return memcmp(c.guid, guid.data(), 32) == 0;
    });
    std::sort(chunks_.begin(), mine,
              [](const Chunk& a, const Chunk& b) { return a.offset < b.offset; });
    size_t expected = 0;
    for (auto c = chunks_.begin(); c != mine; ++c) {
      if (c->offset != expected || c->full != chunks_.front().full) {
        return Status(Code::kCorruptData, "%s: extended XMP chunks do not fit together", path);
      }
      memcpy(extended_.data() + expected, c->bytes, c->size);
      expected += c->size;
    }
    if (chunks_.begin() == mine || expected != chunks_.front().full) {
      return Status(Code::kCorruptData, "%s: extended XMP incomplete", path);
    }
    char md5[33];
    Md5Hex(extended_.data(), expected, md5);
    if (guid != std::string_view(md5, 32)) {
      return Status(Code::kCorruptData, "%s: extended XMP does not match its MD5", path);
    }
    packets.extended = std::string_view(reinterpret_cast<const char*>(extended_.data()), expected);
  }

  // GDepth: a RangeInverse PNG, back to the disparity it was rendered from.
  std::string_view text;
  if (!packets.Find(kGDepthNs, "Format", &text)) {
    return Status(Code::kUnsupported, "%s: no depth map (GDepth)", path);
  }
  if (text != "RangeInverse") {
    return Status(Code::kUnsupported, "%s: GDepth:Format '%.*s' (only RangeInverse)", path,
                  static_cast<int>(std::min<size_t>(text.size(), 32)), text.data());
  }
  if (!packets.Find(kGImageNs, "Data", &text)) {
    return Status(Code::kUnsupported, "%s: no all-in-focus original (GImage)", path);
  }
  double near_depth = 0, far_depth = 0;
  LB_RETURN_IF_ERROR(Number(packets, path, kGDepthNs, "Near", &near_depth));
  LB_RETURN_IF_ERROR(Number(packets, path, kGDepthNs, "Far", &far_depth));
  Status s = DisparityRangeFromNearFar(near_depth, far_depth, &range_);
  if (!s.ok()) return s.Prefix("%s: ", path);
  LB_RETURN_IF_ERROR(Base64Into(packets, path, kGDepthNs, "Data", &png_));
  LB_RETURN_IF_ERROR(Base64Into(packets, path, kGImageNs, "Data", &original_));
  double fx = 0.5, fy = 0.5, blur_inf = 0, focal_distance = 0;
  const bool has_focus = packets.Has(kGFocusNs, "FocalPointX");
  if (has_focus) {
    LB_RETURN_IF_ERROR(Number(packets, path, kGFocusNs, "FocalPointX", &fx));
    LB_RETURN_IF_ERROR(Number(packets, path, kGFocusNs, "FocalPointY", &fy));
    LB_RETURN_IF_ERROR(Number(packets, path, kGFocusNs, "BlurAtInfinity", &blur_inf));
    LB_RETURN_IF_ERROR(Number(packets, path, kGFocusNs, "FocalDistance", &focal_distance));
  }
  const int32_t orientation = ExifOrientation(data, size);

  YccOut ycc = {y_.data(),         cb_.data(),         cr_.data(), rgb_rows_.data(),
                config_.max_width, config_.max_height, 0,          0};
  LB_RETURN_IF_ERROR(DecodeOriginal(path, original_.data(), original_.size(), &ycc));
  int32_t dw = 0, dh = 0;
  int bits = 0;
  LB_RETURN_IF_ERROR(DecodeDepthPng(path, png_, ycc.width, ycc.height, depth_values_.size(),
                                    depth_values_.data(), rgb_rows_.data(), &dw, &dh, &bits));
  const int32_t scale = ycc.width / dw;
  if (scale < 1 || dw * scale > ycc.width || dh * scale > ycc.height || ycc.height / scale != dh) {
    return Status(Code::kUnsupported,
                  "%s: depth map %dx%d is not a whole-number fraction of the %dx%d original", path,
                  dw, dh, ycc.width, ycc.height);
  }
  LB_RETURN_IF_ERROR(DecodeDepthMap(MakeView<const uint16_t>(depth_values_.data(), dw, dh), range_,
                                    bits, MakeView(disp_q8_.data(), dw, dh)));
  depth_w_ = dw;
  depth_h_ = dh;
  photo_ = EnginePhoto();
  photo_.width = ycc.width;
  photo_.height = ycc.height;
  photo_.orientation = orientation;
  photo_.working_scale = scale;
  // What it was rendered with: lens_model.h's blur at infinity is 2 * (2.8 / f) * scale * d_focus
  // px, d_focus = 1 / FocalDistance, so the f-number comes back from the two.
  RenderParams& cur = photo_.current;
  cur.focus =
      FocusAtPoint(static_cast<int32_t>(fx * ycc.width), static_cast<int32_t>(fy * ycc.height));
  cur.f_number = 2.8f;
  if (has_focus && blur_inf > 0 && focal_distance > 0) {
    const double f = 5.6 * scale / (focal_distance * blur_inf * ycc.width);
    if (std::isfinite(f)) cur.f_number = static_cast<float>(std::clamp(f, 1.4, 16.0));
  }
  return Status::Ok();
}

Status RefocusEngine::MakePreviewInputs() {
  const int32_t w = photo_.width, h = photo_.height, side = config_.preview_side;
  int32_t step = 1;
  while ((std::max(w, h) + step - 1) / step > side) ++step;
  preview_step_ = step;
  const int32_t scale = photo_.working_scale;
  int32_t pw, ph;
  if (scale % step == 0) {
    // The depth map as it is, upsampled by the render stage as at full size.
    preview_scale_ = scale / step;
    preview_dw_ = depth_w_;
    preview_dh_ = depth_h_;
    pw = depth_w_ * preview_scale_;
    ph = depth_h_ * preview_scale_;
    preview_disp_ = disp_q8_.data();
  } else {
    // Nearest depth per preview pixel, in preview pixels per view step.
    preview_scale_ = 1;
    pw = w / step;
    ph = h / step;
    preview_dw_ = pw;
    preview_dh_ = ph;
    for (int32_t y = 0; y < ph; ++y) {
      const int32_t sy = std::min((y * step + step / 2) / scale, depth_h_ - 1);
      for (int32_t x = 0; x < pw; ++x) {
        const int32_t sx = std::min((x * step + step / 2) / scale, depth_w_ - 1);
        const int64_t d = disp_q8_[static_cast<size_t>(sy) * depth_w_ + sx];
        pdisp_q8_[static_cast<size_t>(y) * pw + x] =
            static_cast<uint16_t>(std::min<int64_t>((d * scale + step / 2) / step, 65535));
      }
    }
    preview_disp_ = pdisp_q8_.data();
  }
  if (pw < 16 || ph < 16) {
    return Status(Code::kUnsupported, "a %dx%d photo is too small to preview", w, h);
  }
  photo_.preview_width = pw;
  photo_.preview_height = ph;
  if (step > 1) {
    BoxDown(y_.data(), w, h, step, py_.data(), pw, ph);
    const int32_t cw = (w + 1) / 2, ch = (h + 1) / 2;
    BoxDown(cb_.data(), cw, ch, step, pcb_.data(), (pw + 1) / 2, (ph + 1) / 2);
    BoxDown(cr_.data(), cw, ch, step, pcr_.data(), (pw + 1) / 2, (ph + 1) / 2);
  }
  return Status::Ok();
}

void RefocusEngine::WaitForCamera() {
  CameraYield yield(camera_busy_, &paused_strips_);
  yield.OnStrip(ConstPlanarU8(), 0, 0);
}

Status RefocusEngine::RenderInto(RenderStage* stage, const RenderParams& params, bool preview) {
  if (!loaded_) return Status(Code::kInvalidArgument, "refocus engine: render before Load");
  LB_RETURN_IF_ERROR(RenderStage::ValidateParams(params));
  const int32_t step = preview ? preview_step_ : 1;
  RenderConfig rc;
  rc.width = preview ? photo_.preview_width : photo_.width;
  rc.height = preview ? photo_.preview_height : photo_.height;
  rc.working_scale = preview ? preview_scale_ : photo_.working_scale;
  rc.working_width = preview ? preview_dw_ : depth_w_;
  rc.working_height = preview ? preview_dh_ : depth_h_;
  rc.max_radius = std::max(1, (config_.max_blur_radius + step / 2) / step);
  rc.workers = pool_->workers();
  LB_RETURN_IF_ERROR(RenderStage::Validate(rc));
  const size_t capacity = preview ? preview_bytes_ : full_bytes_;
  if (RenderStage::RequiredBytes(rc) > capacity) {
    return Status(Code::kOutOfMemory, "refocus engine: render needs more than its %zu bytes",
                  capacity);
  }
  Arena arena(preview ? preview_block_.get() : full_block_.get(), capacity);
  LB_RETURN_IF_ERROR(stage->Configure(rc, arena));
  stage->SetRunner(pool_.get());
  ConstPlanarU8 ref;
  ref.count = 3;
  const int32_t cw = (rc.width + 1) / 2, ch = (rc.height + 1) / 2;
  const bool own = !preview || step == 1;
  const int32_t stride = own ? photo_.width : rc.width;
  const int32_t cstride = own ? (photo_.width + 1) / 2 : cw;
  ref.planes[0] = {own ? y_.data() : py_.data(), rc.width, rc.height, 1, stride};
  ref.planes[1] = {own ? cb_.data() : pcb_.data(), cw, ch, 1, cstride};
  ref.planes[2] = {own ? cr_.data() : pcr_.data(), cw, ch, 1, cstride};
  const ConstImageU16 disp = {preview ? preview_disp_ : disp_q8_.data(), rc.working_width,
                              rc.working_height, 1, rc.working_width};
  RenderParams p = params;
  if (preview && step > 1) {
    FocusRegion& f = p.focus;
    if (f.width > 0 && f.height > 0) {
      f = {f.x / step, f.y / step, std::max(1, f.width / step), std::max(1, f.height / step)};
    }
  }
  WaitForCamera();
  return stage->Begin(ref, disp, p);
}

Status RefocusEngine::RenderPreview(const RenderParams& params) {
  output_size_ = 0;
  LB_RETURN_IF_ERROR(RenderInto(preview_.get(), params, true));
  JpegMetadata meta;  // no EXIF (no allocation) unless the photo must be turned
  if (photo_.orientation > 1) meta.orientation = photo_.orientation;
  LB_RETURN_IF_ERROR(writer_->BeginMemory(&scratch_, photo_.preview_width, photo_.preview_height,
                                          config_.preview_quality, meta));
  CameraYield yield(camera_busy_, &paused_strips_);
  LB_RETURN_IF_ERROR(WriteStrips(preview_.get(), &yield, writer_.get()));
  output_size_ = scratch_.size();
  return Status::Ok();
}

Status RefocusEngine::RenderFull(const RenderParams& params) {
  output_size_ = 0;
  LB_RETURN_IF_ERROR(RenderInto(full_.get(), params, false));
  JpegMetadata meta;
  if (photo_.orientation > 1) meta.orientation = photo_.orientation;
  LB_RETURN_IF_ERROR(
      writer_->BeginMemory(&scratch_, photo_.width, photo_.height, config_.quality, meta));
  CameraYield yield(camera_busy_, &paused_strips_);
  LB_RETURN_IF_ERROR(WriteStrips(full_.get(), &yield, writer_.get()));
  output_size_ = scratch_.size();
  return Status::Ok();
}

Status RefocusEngine::Save(const RenderParams& params, const char* out_path) {
  output_size_ = 0;
  LB_RETURN_IF_ERROR(RenderInto(full_.get(), params, false));
  RerenderSource source;
  source.disp_q8 = {disp_q8_.data(), depth_w_, depth_h_, 1, depth_w_};
  source.range = range_;
  source.original_jpeg = &original_;
  source.orientation = photo_.orientation;
  source.width = photo_.width;
  source.height = photo_.height;
  CameraYield yield(camera_busy_, &paused_strips_);
  return WriteRerendered(full_.get(), params, source, config_.quality, "refocusd web", &yield,
                         nullptr, out_path);
}

}  // namespace lb
