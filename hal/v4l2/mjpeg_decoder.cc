#include "hal/v4l2/mjpeg_decoder.h"

#include <csetjmp>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <new>

// jpeglib.h uses FILE and size_t without including their headers: <cstdio> comes first.
#include <jerror.h>
#include <jpeglib.h>

#include "hal/v4l2/mjpeg_check.h"

namespace lb {
namespace {

// libjpeg-turbo's SIMD code wants 32-byte aligned objects whose sizes it may round up to the next
// 32 bytes, and sample rows padded to 64 samples (its own manager's guarantees); a cache line of
// alignment keeps to both.
constexpr size_t kAlign = 64;
// What does not grow with the width (colour conversion, range limit, derived Huffman and
// dequantisation tables, the MCU's blocks, the standard Huffman tables), with room for other
// libjpeg-turbo versions.
constexpr size_t kFixedArenaBytes = size_t{64} << 10;
// Sample rows kept per column: more for 4:2:0 than 4:2:2 (context rows for its smooth
// upsampling), most for luma sampled 1x4, the tallest layout, with a third to spare.
// mjpeg_decoder_test checks every layout peaks under two thirds of the arena.
constexpr size_t kArenaBytesPerColumn = 96;

size_t RoundUp(size_t n, size_t to) { return (n + to - 1) / to * to; }

}  // namespace

struct MjpegDecoder::Impl {
  jpeg_decompress_struct cinfo = {};
  jpeg_error_mgr err = {};
  jpeg_source_mgr src = {};
  bool created = false;
  void (*default_self_destruct)(j_common_ptr) = nullptr;

  // The arena: image objects from the bottom (`low` bytes used), permanent ones from the top
  // (down to `high`). Two ends, because libjpeg makes permanent tables while an image is open:
  // one bump pointer reset to a mark would free them with the image.
  std::unique_ptr<uint8_t[]> arena_memory;
  uint8_t* base = nullptr;
  size_t size = 0, low = 0, high = 0, peak = 0;
  uint64_t allocations = 0;

  std::unique_ptr<uint8_t[]> row_memory;
  uint8_t* rows = nullptr;
  size_t row_stride = 0;
  int32_t width = 0, height = 0;

  // Where a libjpeg error or warning, or a failed arena request, jumps back to.
  jmp_buf jump;
  Code code = Code::kCorruptData;
  char message[JMSG_LENGTH_MAX + 96] = {};
  size_t data_size = 0;
  int32_t rows_delivered = 0;

  ~Impl() {
    if (created) jpeg_destroy_decompress(&cinfo);
  }

  static Impl* Of(j_common_ptr cinfo) { return static_cast<Impl*>(cinfo->client_data); }

  [[noreturn]] void Fail(Code c, const char* format, ...) __attribute__((format(printf, 3, 4))) {
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof(message), format, args);
    va_end(args);
    code = c;
    longjmp(jump, 1);
  }

  // Every request of libjpeg, small, large or row storage, ends here.
  void* Take(int pool, size_t bytes) {
    if (pool != JPOOL_IMAGE && pool != JPOOL_PERMANENT) {
      Fail(Code::kInternal, "libjpeg asked for memory pool %d", pool);
    }
    const size_t free = high - low;
    if (bytes > free || RoundUp(bytes, kAlign) > free) {
      Fail(Code::kOutOfMemory,
           "the frame needs more than the %zu-byte decoding arena (%zu bytes asked, %zu free)",
           size, bytes, free);
    }
    const size_t n = RoundUp(bytes, kAlign);
    void* p;
    if (pool == JPOOL_IMAGE) {
      p = base + low;
      low += n;
    } else {
      high -= n;
      p = base + high;
    }
    ++allocations;
    if (low + (size - high) > peak) peak = low + (size - high);
    return p;
  }

  // `count` x `each` bytes, refused before the product can wrap.
  void* TakeArray(int pool, size_t count, size_t each) {
    if (each != 0 && count > size / each) {
      Fail(Code::kOutOfMemory, "the frame needs %zu x %zu bytes, more than the %zu-byte arena",
           count, each, size);
    }
    return Take(pool, count * each);
  }

  static void* AllocSmall(j_common_ptr cinfo, int pool, size_t bytes) {
    return Of(cinfo)->Take(pool, bytes);
  }
  static JSAMPARRAY AllocSarray(j_common_ptr cinfo, int pool, JDIMENSION samples,
                                JDIMENSION count) {
    Impl* d = Of(cinfo);
    const size_t row = RoundUp(samples, kAlign) * sizeof(JSAMPLE);
    auto* result = static_cast<JSAMPARRAY>(d->TakeArray(pool, count, sizeof(JSAMPROW)));
    auto* block = static_cast<JSAMPLE*>(d->TakeArray(pool, count, row));
    for (JDIMENSION i = 0; i < count; ++i) result[i] = block + row * i;
    return result;
  }
  static JBLOCKARRAY AllocBarray(j_common_ptr cinfo, int pool, JDIMENSION blocks,
                                 JDIMENSION count) {
    Impl* d = Of(cinfo);
    auto* result = static_cast<JBLOCKARRAY>(d->TakeArray(pool, count, sizeof(JBLOCKROW)));
    auto* block = static_cast<JBLOCKROW>(d->TakeArray(pool, count, blocks * sizeof(JBLOCK)));
    for (JDIMENSION i = 0; i < count; ++i) result[i] = block + static_cast<size_t>(blocks) * i;
    return result;
  }
  // Whole-image arrays: only progressive, multi-scan and buffered-image decoding ask for them.
  [[noreturn]] static void NoWholeImage(j_common_ptr cinfo) {
    Of(cinfo)->Fail(Code::kUnsupported,
                    "the frame needs a whole-image buffer (a progressive or multi-scan JPEG); "
                    "MJPEG is decoded a strip at a time");
  }
  static jvirt_sarray_ptr RequestSarray(j_common_ptr cinfo, int, boolean, JDIMENSION, JDIMENSION,
                                        JDIMENSION) {
    NoWholeImage(cinfo);
  }
  static jvirt_barray_ptr RequestBarray(j_common_ptr cinfo, int, boolean, JDIMENSION, JDIMENSION,
                                        JDIMENSION) {
    NoWholeImage(cinfo);
  }
  // Called for every image, whole-image arrays or not: none were made, so nothing to do.
  static void RealizeArrays(j_common_ptr) {}
  static JSAMPARRAY AccessSarray(j_common_ptr cinfo, jvirt_sarray_ptr, JDIMENSION, JDIMENSION,
                                 boolean) {
    NoWholeImage(cinfo);
  }
  static JBLOCKARRAY AccessBarray(j_common_ptr cinfo, jvirt_barray_ptr, JDIMENSION, JDIMENSION,
                                  boolean) {
    NoWholeImage(cinfo);
  }
  static void FreePool(j_common_ptr cinfo, int pool) {
    Impl* d = Of(cinfo);
    d->low = 0;
    if (pool == JPOOL_PERMANENT) d->high = d->size;
  }
  // The default manager still owns what jpeg_create_decompress made before it was replaced, and
  // itself: its own self_destruct frees both.
  static void SelfDestruct(j_common_ptr cinfo) {
    Impl* d = Of(cinfo);
    d->low = 0;
    d->high = d->size;
    if (d->default_self_destruct != nullptr) d->default_self_destruct(cinfo);
  }

  static void OnError(j_common_ptr cinfo) {
    char text[JMSG_LENGTH_MAX];
    cinfo->err->format_message(cinfo, text);
    Of(cinfo)->Fail(Code::kCorruptData, "%s", text);
  }
  // Warnings are corrupt data ("premature end of data segment", then grey rows) but for two
  // that say nothing about the pixels; trace messages (level >= 0) are dropped.
  static void OnMessage(j_common_ptr cinfo, int level) {
    if (level >= 0) return;
    const int c = cinfo->err->msg_code;
    if (c == JWRN_JFIF_MAJOR || c == JWRN_ADOBE_XFORM) return;
    OnError(cinfo);
  }
  static void OnOutput(j_common_ptr) {}

  static void OnInit(j_decompress_ptr) {}
  static void OnTerm(j_decompress_ptr) {}
  // The whole frame is in the buffer from the start: asked for more, the data has ended.
  static boolean OnFill(j_decompress_ptr cinfo) {
    Impl* d = Of(reinterpret_cast<j_common_ptr>(cinfo));
    d->Fail(Code::kCorruptData, "truncated: libjpeg wants more than the frame's %zu bytes",
            d->data_size);
  }
  static void OnSkip(j_decompress_ptr cinfo, long count) {
    if (count <= 0) return;
    if (static_cast<size_t>(count) > cinfo->src->bytes_in_buffer) OnFill(cinfo);
    cinfo->src->next_input_byte += count;
    cinfo->src->bytes_in_buffer -= static_cast<size_t>(count);
  }

  bool Create();
  Status Run(const uint8_t* data, size_t bytes, const FrameInfo& info, FrameSink& sink,
             bool* began);
  Status Body(const FrameInfo& info, FrameSink& sink, bool* began);
};

bool MjpegDecoder::Impl::Create() {
  cinfo.err = jpeg_std_error(&err);
  err.error_exit = OnError;
  err.emit_message = OnMessage;
  err.output_message = OnOutput;
  cinfo.client_data = this;  // kept by jpeg_create_decompress, like cinfo.err
  // Destroys whatever a failed create made too.
  created = true;
  // jpeg_create_decompress fails only when it cannot get its first few kilobytes.
  if (setjmp(jump) != 0) return false;
  jpeg_create_decompress(&cinfo);
  jpeg_memory_mgr* mem = cinfo.mem;
  default_self_destruct = mem->self_destruct;
  // All of them: the default alloc_sarray and alloc_barray call the default alloc_small and
  // alloc_large directly, not through these pointers.
  mem->alloc_small = AllocSmall;
  mem->alloc_large = AllocSmall;
  mem->alloc_sarray = AllocSarray;
  mem->alloc_barray = AllocBarray;
  mem->request_virt_sarray = RequestSarray;
  mem->request_virt_barray = RequestBarray;
  mem->realize_virt_arrays = RealizeArrays;
  mem->access_virt_sarray = AccessSarray;
  mem->access_virt_barray = AccessBarray;
  mem->free_pool = FreePool;
  mem->self_destruct = SelfDestruct;
  src.init_source = OnInit;
  src.fill_input_buffer = OnFill;
  src.skip_input_data = OnSkip;
  src.resync_to_restart = jpeg_resync_to_restart;
  src.term_source = OnTerm;
  cinfo.src = &src;
  return true;
}

Status MjpegDecoder::Impl::Run(const uint8_t* data, size_t bytes, const FrameInfo& info,
                               FrameSink& sink, bool* began) {
  src.next_input_byte = data;
  src.bytes_in_buffer = bytes;
  data_size = bytes;
  rows_delivered = 0;
  // Body keeps only trivially destructible locals: a longjmp out of libjpeg skips its frame.
  if (setjmp(jump) != 0) {
    // Frees the image pool (the arena's bottom) and readies the decompressor for the next frame.
    jpeg_abort_decompress(&cinfo);
    if (*began) {
      return Status(code, "corrupt after %d of %d rows went to the sink: %s", rows_delivered,
                    height, message);
    }
    return Status(code, "%s", message);
  }
  Status status = Body(info, sink, began);
  jpeg_abort_decompress(&cinfo);
  return status;
}

Status MjpegDecoder::Impl::Body(const FrameInfo& info, FrameSink& sink, bool* began) {
  jpeg_read_header(&cinfo, TRUE);
  if (cinfo.image_width != static_cast<JDIMENSION>(width) ||
      cinfo.image_height != static_cast<JDIMENSION>(height)) {
    return Status(Code::kCorruptData, "the frame is %ux%u, the mode %dx%d", cinfo.image_width,
                  cinfo.image_height, width, height);
  }
  if (cinfo.progressive_mode || cinfo.arith_code) {
    return Status(Code::kUnsupported, "a progressive or arithmetic-coded frame");
  }
  switch (cinfo.jpeg_color_space) {
    case JCS_YCbCr:
    case JCS_RGB:
    case JCS_GRAYSCALE:
      break;
    default:
      return Status(Code::kUnsupported, "colour space %d with %d components",
                    static_cast<int>(cinfo.jpeg_color_space), cinfo.num_components);
  }
  cinfo.out_color_space = JCS_RGB;
  cinfo.dct_method = JDCT_ISLOW;
  jpeg_start_decompress(&cinfo);
  if (cinfo.output_width != static_cast<JDIMENSION>(width) ||
      cinfo.output_height != static_cast<JDIMENSION>(height) || cinfo.output_components != 3) {
    return Status(Code::kInternal, "libjpeg gives %ux%u x %d, %dx%d x 3 expected",
                  cinfo.output_width, cinfo.output_height, cinfo.output_components, width, height);
  }
  FrameInfo frame = info;
  frame.format = PixelFormat::kRgb8;
  frame.width = width;
  frame.height = height;
  *began = true;
  LB_RETURN_IF_ERROR(sink.BeginFrame(frame));
  JSAMPROW pointers[kStripRows];
  for (int32_t i = 0; i < kStripRows; ++i) pointers[i] = rows + row_stride * i;
  while (cinfo.output_scanline < cinfo.output_height) {
    const int32_t y0 = static_cast<int32_t>(cinfo.output_scanline);
    const int32_t n = height - y0 < kStripRows ? height - y0 : kStripRows;
    for (int32_t got = 0; got < n;) {
      const JDIMENSION r =
          jpeg_read_scanlines(&cinfo, pointers + got, static_cast<JDIMENSION>(n - got));
      if (r == 0) return Status(Code::kInternal, "libjpeg gave no rows at row %d", y0 + got);
      got += static_cast<int32_t>(r);
    }
    FrameRows strip;
    strip.y0 = y0;
    strip.height = n;
    strip.planes[0] = rows;
    strip.strides[0] = static_cast<ptrdiff_t>(row_stride);
    LB_RETURN_IF_ERROR(sink.Rows(strip));
    rows_delivered = y0 + n;
  }
  // Reads to EOI: data left over in the scan is a warning, so corrupt, here too.
  jpeg_finish_decompress(&cinfo);
  return sink.EndFrame();
}

MjpegDecoder::MjpegDecoder() = default;
MjpegDecoder::~MjpegDecoder() = default;

size_t MjpegDecoder::ArenaBytes(int32_t width) {
  const size_t columns = RoundUp(width > 0 ? static_cast<size_t>(width) : 1, kAlign);
  return kFixedArenaBytes + columns * kArenaBytesPerColumn;
}

Status MjpegDecoder::Configure(int32_t width, int32_t height) {
  if (impl_ != nullptr && impl_->width == width && impl_->height == height) return Status::Ok();
  Release();
  if (width < 1 || height < 1 || width > kMaxFrameSide || height > kMaxFrameSide) {
    return Status(Code::kInvalidArgument, "MJPEG frame size %dx%d outside 1x1..%dx%d", width,
                  height, kMaxFrameSide, kMaxFrameSide);
  }
  std::unique_ptr<Impl> d(new (std::nothrow) Impl);
  if (d == nullptr) return Status(Code::kOutOfMemory, "MJPEG decoder: out of memory");
  d->width = width;
  d->height = height;
  d->size = ArenaBytes(width);
  d->high = d->size;
  d->row_stride = RoundUp(static_cast<size_t>(width) * 3, kAlign);
  d->arena_memory.reset(new (std::nothrow) uint8_t[d->size + kAlign]);
  d->row_memory.reset(new (std::nothrow) uint8_t[d->row_stride * kStripRows + kAlign]);
  if (d->arena_memory == nullptr || d->row_memory == nullptr) {
    return Status(Code::kOutOfMemory, "MJPEG decoder: cannot allocate %zu bytes",
                  d->size + d->row_stride * kStripRows);
  }
  auto aligned = [](uint8_t* p) {
    return p + (kAlign - reinterpret_cast<uintptr_t>(p) % kAlign) % kAlign;
  };
  d->base = aligned(d->arena_memory.get());
  d->rows = aligned(d->row_memory.get());
  if (!d->Create()) return Status(d->code, "MJPEG decoder: %s", d->message);
  impl_ = std::move(d);
  return Status::Ok();
}

void MjpegDecoder::Release() { impl_.reset(); }

Status MjpegDecoder::Decode(const uint8_t* data, size_t size, const FrameInfo& info,
                            FrameSink& sink, bool* began) {
  *began = false;
  if (impl_ == nullptr) return Status(Code::kInternal, "MJPEG decode before Configure");
  LB_RETURN_IF_ERROR(CheckMjpegFrame(data, size, impl_->width, impl_->height));
  return impl_->Run(data, size, info, sink, began);
}

size_t MjpegDecoder::arena_bytes() const { return impl_ ? impl_->size : 0; }
size_t MjpegDecoder::arena_peak() const { return impl_ ? impl_->peak : 0; }
uint64_t MjpegDecoder::arena_allocations() const { return impl_ ? impl_->allocations : 0; }

}  // namespace lb
