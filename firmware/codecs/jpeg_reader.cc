// JPEG through libjpeg-turbo's libjpeg API. The default error manager calls exit() and libjpeg
// only warns about corrupt data ("Premature end of JPEG file", then grey padding): our manager
// turns errors and corrupt-data warnings into a longjmp back to JpegReader::Run, and our source
// manager fails at the end of the data instead of inventing an EOI marker.
#include <cinttypes>
#include <csetjmp>
#include <cstdio>
#include <cstring>

// clang-format off: jpeglib.h needs <cstdio> first and jerror.h after it.
#include <jerror.h>
#include <jpeglib.h>
// clang-format on

#include "firmware/codecs/decoder.h"

namespace lb::codecs {
namespace {

// A real progressive JPEG has about ten scans; thousands of tiny ones are a decoding-time attack.
constexpr int kMaxScans = 256;
constexpr size_t kInputChunk = 4096;

class JpegReader {
 public:
  JpegReader(ByteSource& src, const DecodeRequest& request) : src_(src), request_(request) {}
  ~JpegReader() { jpeg_destroy_decompress(&cinfo_); }

  Status Run();

 private:
  struct ErrorManager {
    jpeg_error_mgr pub;
    JpegReader* self;
  };
  struct SourceManager {
    jpeg_source_mgr pub;
    JpegReader* self;
  };
  struct ProgressManager {
    jpeg_progress_mgr pub;
    JpegReader* self;
  };

  static JpegReader* Self(j_common_ptr cinfo) {
    return reinterpret_cast<ErrorManager*>(cinfo->err)->self;
  }
  [[noreturn]] void Fail(Code code) {
    code_ = code;
    longjmp(jump_, 1);
  }
  static void OnError(j_common_ptr cinfo) {
    JpegReader* self = Self(cinfo);
    (*cinfo->err->format_message)(cinfo, self->message_);
    self->Fail(Code::kCorruptData);
  }
  static void OnMessage(j_common_ptr cinfo, int level) {
    if (level >= 0) return;  // trace messages
    const int code = cinfo->err->msg_code;
    // Warnings that say nothing about the pixels; every other warning means corrupt data.
    if (code == JWRN_JFIF_MAJOR || code == JWRN_ADOBE_XFORM || code == JWRN_BOGUS_ICC) return;
    OnError(cinfo);
  }
  static void OnOutput(j_common_ptr) {}
  static void OnInit(j_decompress_ptr) {}
  static void OnTerm(j_decompress_ptr) {}
  static boolean OnFill(j_decompress_ptr cinfo) {
    JpegReader* self = Self(reinterpret_cast<j_common_ptr>(cinfo));
    const size_t n = self->src_.Read(self->input_, kInputChunk);
    if (n == 0) {
      self->ended_ = true;
      self->Fail(self->src_.error() != 0 ? Code::kIoError : Code::kCorruptData);
    }
    cinfo->src->next_input_byte = self->input_;
    cinfo->src->bytes_in_buffer = n;
    return TRUE;
  }
  static void OnSkip(j_decompress_ptr cinfo, long count) {
    if (count <= 0) return;
    size_t left = static_cast<size_t>(count);
    while (left > cinfo->src->bytes_in_buffer) {
      left -= cinfo->src->bytes_in_buffer;
      OnFill(cinfo);
    }
    cinfo->src->next_input_byte += left;
    cinfo->src->bytes_in_buffer -= left;
  }
  static void OnProgress(j_common_ptr cinfo) {
    auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
    if (d->input_scan_number > kMaxScans) {
      JpegReader* self = Self(cinfo);
      snprintf(self->message_, sizeof(self->message_), "more than %d scans", kMaxScans);
      self->Fail(Code::kCorruptData);
    }
  }

  Status Decode();

  ByteSource& src_;
  const DecodeRequest& request_;
  jpeg_decompress_struct cinfo_ = {};
  ErrorManager error_ = {};
  SourceManager source_ = {};
  ProgressManager progress_ = {};
  jmp_buf jump_;
  Code code_ = Code::kCorruptData;
  bool ended_ = false;
  char message_[JMSG_LENGTH_MAX] = {};
  uint8_t input_[kInputChunk];
  Buffer rows_;
};

Status JpegReader::Run() {
  const char* name = request_.name;
  cinfo_.err = jpeg_std_error(&error_.pub);
  error_.pub.error_exit = OnError;
  error_.pub.emit_message = OnMessage;
  error_.pub.output_message = OnOutput;
  error_.self = this;
  if (setjmp(jump_) != 0) {
    if (ended_ && code_ == Code::kIoError) {
      return Status(Code::kIoError, "%s: read error: %s", name, strerror(src_.error()));
    }
    if (ended_) {
      return Status(Code::kCorruptData, "%s: truncated: JPEG data ends after %" PRIu64 " bytes",
                    name, src_.consumed());
    }
    return Status(code_, "%s: JPEG %s", name, message_);
  }
  jpeg_create_decompress(&cinfo_);
  source_.pub.init_source = OnInit;
  source_.pub.fill_input_buffer = OnFill;
  source_.pub.skip_input_data = OnSkip;
  source_.pub.resync_to_restart = jpeg_resync_to_restart;
  source_.pub.term_source = OnTerm;
  source_.self = this;
  cinfo_.src = &source_.pub;
  progress_.pub.progress_monitor = OnProgress;
  progress_.self = this;
  cinfo_.progress = &progress_.pub;
  // Decode() may longjmp back here: it keeps only trivially destructible locals.
  return Decode();
}

Status JpegReader::Decode() {
  const char* name = request_.name;
  jpeg_read_header(&cinfo_, TRUE);
  LB_RETURN_IF_ERROR(CheckImageSize(name, cinfo_.image_width, cinfo_.image_height));
  PixelFormat format = PixelFormat::kRgb8;
  switch (cinfo_.jpeg_color_space) {
    case JCS_GRAYSCALE:
      format = PixelFormat::kGray8;
      cinfo_.out_color_space = JCS_GRAYSCALE;
      break;
    case JCS_YCbCr:
    case JCS_RGB:
      cinfo_.out_color_space = JCS_RGB;
      break;
    case JCS_CMYK:
    case JCS_YCCK:
      return Status(Code::kUnsupported, "%s: CMYK JPEG is not supported (save it as RGB)", name);
    default:
      return Status(Code::kUnsupported,
                    "%s: JPEG with %d components in an unknown colour space is not supported", name,
                    cinfo_.num_components);
  }
  if (request_.min_width > 0) {
    // The IDCT itself shrinks the image: a thumbnail of a 12 MP photo decodes an eighth of it.
    const int64_t full = cinfo_.image_width;
    const int64_t m = (int64_t{request_.min_width} * 8 + full - 1) / full;
    cinfo_.scale_num = static_cast<unsigned>(m < 1 ? 1 : m > 8 ? 8 : m);
    cinfo_.scale_denom = 8;
    jpeg_calc_output_dimensions(&cinfo_);
  }
  const int32_t width =
      static_cast<int32_t>(request_.min_width > 0 ? cinfo_.output_width : cinfo_.image_width);
  const int32_t height =
      static_cast<int32_t>(request_.min_width > 0 ? cinfo_.output_height : cinfo_.image_height);
  if (!SetHeader(request_, format, width, height)) return Status::Ok();

  jpeg_start_decompress(&cinfo_);
  const int channels = format == PixelFormat::kGray8 ? 1 : 3;
  if (cinfo_.output_components != channels ||
      cinfo_.output_width != static_cast<JDIMENSION>(width) ||
      cinfo_.output_height != static_cast<JDIMENSION>(height)) {
    return Status(Code::kInternal, "%s: libjpeg output is %ux%u x %d, expected %dx%d x %d", name,
                  cinfo_.output_width, cinfo_.output_height, cinfo_.output_components, width,
                  height, channels);
  }
  const size_t row_bytes = static_cast<size_t>(cinfo_.output_width) * channels;
  uint8_t* rows = nullptr;
  LB_RETURN_IF_ERROR(
      RowBuffer(request_, static_cast<uint64_t>(row_bytes) * kImageStripRows, &rows_, &rows));
  JSAMPROW pointers[kImageStripRows];
  for (int32_t y = 0; y < kImageStripRows; ++y) {
    pointers[y] = rows + row_bytes * static_cast<size_t>(y);
  }

  LB_RETURN_IF_ERROR(BeginFrame(request_));
  for (int32_t y0 = 0; y0 < height; y0 += kImageStripRows) {
    const int32_t n = StripRows(y0, height);
    int32_t done = 0;
    while (done < n) {
      const JDIMENSION got =
          jpeg_read_scanlines(&cinfo_, pointers + done, static_cast<JDIMENSION>(n - done));
      if (got == 0) {
        return Status(Code::kInternal, "%s: libjpeg returned no rows at row %d", name, y0 + done);
      }
      done += static_cast<int32_t>(got);
    }
    LB_RETURN_IF_ERROR(DeliverRows(request_, rows, row_bytes, y0, n));
  }
  // Reads on to the EOI marker, so corrupt or missing data after the last row is still an error.
  jpeg_finish_decompress(&cinfo_);
  return request_.sink->EndFrame();
}

}  // namespace

Status DecodeJpeg(ByteSource& src, const DecodeRequest& request) {
  JpegReader reader(src, request);
  return reader.Run();
}

}  // namespace lb::codecs
