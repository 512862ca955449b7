#include "firmware/codecs/jpeg_writer.h"

// clang-format off
#include <cstdio>  // jpeglib.h needs FILE and size_t first
#include <jpeglib.h>
// clang-format on

#include <csetjmp>
#include <cstring>
#include <new>

namespace lb {

namespace {

constexpr int32_t kStripRows = JpegWriter::kStripRows;
constexpr size_t kOutputBuffer = 16384;

// Luma width that libjpeg reads per row (whole MCUs), and the chroma width likewise.
int32_t PaddedWidth(int32_t width) { return (width + 15) / 16 * 16; }

}  // namespace

struct JpegWriter::State {
  jpeg_compress_struct cinfo;
  jpeg_error_mgr err;
  jpeg_destination_mgr dest;
  jmp_buf jump;
  bool created = false;  // jpeg_create_compress succeeded
  AtomicFile* file = nullptr;
  std::vector<uint8_t>* memory = nullptr;
  Status sink_status;  // why the destination stopped, when it did
  // JpegMetadata::segments_later: the output so far, whose first `splice` bytes are the headers
  // before the late segments.
  bool holding = false;
  std::vector<uint8_t> held;
  size_t splice = 0;
  int32_t width = 0, height = 0, next_row = 0;
  bool copy_rows = false;             // width not a multiple of 16: rows go through `pad`
  JSAMPARRAY pad[3] = {};             // padded copies, from libjpeg's image pool
  JSAMPROW rows[3][kStripRows] = {};  // what jpeg_write_raw_data reads
  JSAMPARRAY planes[3] = {rows[0], rows[1], rows[2]};
  JOCTET buffer[kOutputBuffer];
};

namespace {

JpegWriter::State* StateOf(j_common_ptr cinfo) {
  return static_cast<JpegWriter::State*>(cinfo->client_data);
}

[[noreturn]] void OnError(j_common_ptr cinfo) { longjmp(StateOf(cinfo)->jump, 1); }

// The sink failed: `sink_status` says why; unwind through the error handler like libjpeg does.
[[noreturn]] void SinkFailed(j_compress_ptr cinfo) {
  OnError(reinterpret_cast<j_common_ptr>(cinfo));
}
void OnMessage(j_common_ptr, int) {}  // warnings (e.g. extra rows) are not failures here

// Appends to a vector; false when memory runs out.
bool Append(const uint8_t* data, size_t bytes, std::vector<uint8_t>* out) {
  try {
    out->insert(out->end(), data, data + bytes);
  } catch (const std::bad_alloc&) {
    return false;
  }
  return true;
}

// Hands `bytes` at `data` to the sink; on failure records why and returns false.
bool Emit(JpegWriter::State* s, const uint8_t* data, size_t bytes) {
  if (bytes == 0) return true;
  if (s->file != nullptr) {
    s->sink_status = s->file->Write(data, bytes);
    return s->sink_status.ok();
  }
  if (!Append(data, bytes, s->memory)) {
    s->sink_status =
        Status(Code::kOutOfMemory, "in-memory jpeg: out of memory at %zu bytes", s->memory->size());
    return false;
  }
  return true;
}

// Hands `bytes` of the output buffer on: to the sink, or to the held output while late segments
// are awaited.
bool Drain(JpegWriter::State* s, size_t bytes) {
  if (!s->holding) return Emit(s, s->buffer, bytes);
  if (!Append(s->buffer, bytes, &s->held)) {
    s->sink_status = Status(Code::kOutOfMemory,
                            "jpeg: out of memory holding %zu bytes for the "
                            "late segments",
                            s->held.size());
    return false;
  }
  return true;
}

// An APPn segment's bytes as libjpeg's jpeg_write_marker lays them out.
bool EmitSegment(JpegWriter::State* s, const JpegSegment& seg) {
  const size_t length = seg.payload.size() + 2;
  const uint8_t head[4] = {0xFF, seg.marker, static_cast<uint8_t>(length >> 8),
                           static_cast<uint8_t>(length & 255)};
  return Emit(s, head, sizeof(head)) && Emit(s, seg.payload.data(), seg.payload.size());
}

// Valid APPn segments for jpeg_write_marker.
bool SegmentsOk(const std::vector<JpegSegment>& segments, const JpegSegment** bad) {
  for (const JpegSegment& seg : segments) {
    if (seg.marker < JPEG_APP0 || seg.marker > JPEG_APP0 + 15 ||
        seg.payload.size() > JpegSegment::kMaxPayload) {
      *bad = &seg;
      return false;
    }
  }
  return true;
}

void InitDestination(j_compress_ptr cinfo) {
  JpegWriter::State* s = StateOf(reinterpret_cast<j_common_ptr>(cinfo));
  cinfo->dest->next_output_byte = s->buffer;
  cinfo->dest->free_in_buffer = kOutputBuffer;
}

boolean EmptyBuffer(j_compress_ptr cinfo) {
  JpegWriter::State* s = StateOf(reinterpret_cast<j_common_ptr>(cinfo));
  if (!Drain(s, kOutputBuffer)) SinkFailed(cinfo);
  cinfo->dest->next_output_byte = s->buffer;
  cinfo->dest->free_in_buffer = kOutputBuffer;
  return TRUE;
}

void TermDestination(j_compress_ptr cinfo) {
  JpegWriter::State* s = StateOf(reinterpret_cast<j_common_ptr>(cinfo));
  if (!Drain(s, kOutputBuffer - cinfo->dest->free_in_buffer)) SinkFailed(cinfo);
}

}  // namespace

JpegWriter::JpegWriter() : state_(new State) {}

JpegWriter::~JpegWriter() {
  if (state_->created) jpeg_destroy_compress(&state_->cinfo);
}

Status JpegWriter::Failed(Status status) {
  State* s = state_.get();
  if (s->created) {
    jpeg_destroy_compress(&s->cinfo);
    s->created = false;
  }
  if (s->file != nullptr) s->file->Abort();
  if (s->memory != nullptr) s->memory->clear();
  s->file = nullptr;
  s->memory = nullptr;
  s->holding = false;
  std::vector<uint8_t>().swap(s->held);
  active_ = false;
  return status;
}

Status JpegWriter::LibjpegFailure() {
  State* s = state_.get();
  if (!s->sink_status.ok()) return Failed(s->sink_status);
  char text[JMSG_LENGTH_MAX];
  (*s->err.format_message)(reinterpret_cast<j_common_ptr>(&s->cinfo), text);
  return Failed(Status(Code::kInternal, "%s: jpeg encoder: %s",
                       s->file ? s->file->path() : "in-memory jpeg", text));
}

Status JpegWriter::Begin(AtomicFile* out, int32_t width, int32_t height, int quality,
                         const JpegMetadata& meta) {
  if (active_) return Status(Code::kBusy, "jpeg writer: Begin while an image is in progress");
  if (out == nullptr || !out->is_open()) {
    return Status(Code::kInvalidArgument, "jpeg writer: output file is not open");
  }
  state_->file = out;
  state_->memory = nullptr;
  return Start(width, height, quality, meta);
}

Status JpegWriter::BeginMemory(std::vector<uint8_t>* out, int32_t width, int32_t height,
                               int quality, const JpegMetadata& meta) {
  if (active_) return Status(Code::kBusy, "jpeg writer: Begin while an image is in progress");
  if (out == nullptr) return Status(Code::kInvalidArgument, "jpeg writer: no output buffer");
  out->clear();
  state_->file = nullptr;
  state_->memory = out;
  return Start(width, height, quality, meta);
}

Status JpegWriter::Start(int32_t width, int32_t height, int quality, const JpegMetadata& meta) {
  State* s = state_.get();
  const char* name = s->file ? s->file->path() : "in-memory jpeg";
  if (width <= 0 || height <= 0 || width > JPEG_MAX_DIMENSION || height > JPEG_MAX_DIMENSION) {
    return Failed(Status(Code::kInvalidArgument, "%s: cannot encode a %dx%d image", name,
                         static_cast<int>(width), static_cast<int>(height)));
  }
  if (quality < 1 || quality > 100) {
    return Failed(
        Status(Code::kInvalidArgument, "%s: jpeg quality %d not in 1..100", name, quality));
  }
  const JpegSegment* bad = nullptr;
  if (!SegmentsOk(meta.extra_segments, &bad)) {
    return Failed(Status(Code::kInvalidArgument, "%s: bad APP segment (marker 0x%02X, %zu bytes)",
                         name, bad->marker, bad->payload.size()));
  }
  std::vector<uint8_t> exif;
  if (meta.has_exif()) {
    Status status = BuildExif(meta, width, height, &exif);
    if (!status.ok()) return Failed(status.Prefix("%s: ", name));
  }
  s->width = width;
  s->height = height;
  s->next_row = 0;
  s->copy_rows = width % 16 != 0;
  s->sink_status = Status::Ok();
  s->holding = false;
  s->held.clear();
  s->splice = 0;
  s->cinfo.client_data = s;
  s->cinfo.err = jpeg_std_error(&s->err);
  s->err.error_exit = OnError;
  s->err.emit_message = OnMessage;
  s->dest.init_destination = InitDestination;
  s->dest.empty_output_buffer = EmptyBuffer;
  s->dest.term_destination = TermDestination;
  const std::vector<uint8_t>* exif_ptr = &exif;
  if (setjmp(s->jump) != 0) return LibjpegFailure();
  jpeg_create_compress(&s->cinfo);
  s->created = true;
  s->cinfo.dest = &s->dest;
  s->cinfo.image_width = static_cast<JDIMENSION>(width);
  s->cinfo.image_height = static_cast<JDIMENSION>(height);
  s->cinfo.input_components = 3;
  s->cinfo.in_color_space = JCS_YCbCr;
  jpeg_set_defaults(&s->cinfo);  // YCbCr with 2x2 luma sampling: 4:2:0
  jpeg_set_quality(&s->cinfo, quality, TRUE);
  s->cinfo.raw_data_in = TRUE;
  s->cinfo.dct_method = JDCT_ISLOW;  // exact integer DCT: the same bytes on every platform
  s->cinfo.write_JFIF_header = exif_ptr->empty() ? TRUE : FALSE;
  jpeg_start_compress(&s->cinfo, TRUE);
  if (!exif_ptr->empty()) {
    jpeg_write_marker(&s->cinfo, JPEG_APP0 + 1, exif_ptr->data(),
                      static_cast<unsigned int>(exif_ptr->size()));
  }
  for (const JpegSegment& seg : meta.extra_segments) {
    jpeg_write_marker(&s->cinfo, seg.marker, seg.payload.data(),
                      static_cast<unsigned int>(seg.payload.size()));
  }
  if (meta.segments_later) {
    // Everything so far (SOI, EXIF or JFIF, the segments given now) goes before the late
    // segments: it moves to the held output, and the splice point is its end. The frame and
    // scan headers come with the first strip, after it.
    s->holding = true;
    if (!Drain(s, kOutputBuffer - s->dest.free_in_buffer)) SinkFailed(&s->cinfo);
    s->dest.next_output_byte = s->buffer;
    s->dest.free_in_buffer = kOutputBuffer;
    s->splice = s->held.size();
  }
  if (s->copy_rows) {
    // libjpeg reads whole blocks, so odd widths go through rows padded by edge replication.
    const JDIMENSION luma = static_cast<JDIMENSION>(PaddedWidth(width));
    s->pad[0] = (*s->cinfo.mem->alloc_sarray)(reinterpret_cast<j_common_ptr>(&s->cinfo),
                                              JPOOL_IMAGE, luma, kStripRows);
    for (int p = 1; p < 3; ++p) {
      s->pad[p] = (*s->cinfo.mem->alloc_sarray)(reinterpret_cast<j_common_ptr>(&s->cinfo),
                                                JPOOL_IMAGE, luma / 2, kStripRows / 2);
    }
  }
  active_ = true;
  return Status::Ok();
}

Status JpegWriter::WriteStrip(const ConstPlanarU8& strip, int32_t rows) {
  if (!active_) return Status(Code::kInternal, "jpeg writer: WriteStrip without Begin");
  State* s = state_.get();
  const char* name = s->file ? s->file->path() : "in-memory jpeg";
  const int32_t left = s->height - s->next_row;
  if (rows <= 0 || rows > kStripRows || rows > left || (rows < kStripRows && rows != left)) {
    return Failed(Status(Code::kInvalidArgument,
                         "%s: strip of %d rows at row %d of %d (16 per strip, the last may be "
                         "shorter)",
                         name, static_cast<int>(rows), static_cast<int>(s->next_row),
                         static_cast<int>(s->height)));
  }
  const int32_t crows = (rows + 1) / 2, cwidth = (s->width + 1) / 2;
  bool ok = strip.count == 3 && strip.planes[0].data != nullptr &&
            strip.planes[0].width == s->width && strip.planes[0].height >= rows;
  for (int p = 1; p < 3 && ok; ++p) {
    ok = strip.planes[p].data != nullptr && strip.planes[p].width == cwidth &&
         strip.planes[p].height >= crows;
  }
  if (!ok) {
    return Failed(Status(Code::kInvalidArgument,
                         "%s: strip is not YCbCr 4:2:0 of width %d with %d rows", name,
                         static_cast<int>(s->width), static_cast<int>(rows)));
  }
  for (int p = 0; p < 3; ++p) {
    const ConstImageU8& plane = strip.planes[p];
    const int32_t have = p == 0 ? rows : crows, want = p == 0 ? kStripRows : kStripRows / 2;
    const int32_t padded = p == 0 ? PaddedWidth(s->width) : PaddedWidth(s->width) / 2;
    for (int32_t y = 0; y < want; ++y) {
      if (y >= have) {  // a short last strip repeats its last row
        s->rows[p][y] = s->rows[p][have - 1];
        continue;
      }
      if (!s->copy_rows) {
        s->rows[p][y] = const_cast<JSAMPROW>(plane.Row(y));
        continue;
      }
      JSAMPROW out = s->pad[p][y];
      memcpy(out, plane.Row(y), static_cast<size_t>(plane.width));
      memset(out + plane.width, plane.Row(y)[plane.width - 1],
             static_cast<size_t>(padded - plane.width));
      s->rows[p][y] = out;
    }
  }
  if (setjmp(s->jump) != 0) return LibjpegFailure();
  jpeg_write_raw_data(&s->cinfo, s->planes, kStripRows);
  s->next_row += rows;
  return Status::Ok();
}

bool JpegWriter::holding() const { return active_ && state_->holding; }

Status JpegWriter::InsertSegments(const std::vector<JpegSegment>& segments) {
  if (!active_) return Status(Code::kInternal, "jpeg writer: InsertSegments without Begin");
  State* s = state_.get();
  const char* name = s->file ? s->file->path() : "in-memory jpeg";
  if (!s->holding) {
    return Failed(Status(Code::kInternal, "%s: segments inserted twice or not announced", name));
  }
  const JpegSegment* bad = nullptr;
  if (!SegmentsOk(segments, &bad)) {
    return Failed(Status(Code::kInvalidArgument, "%s: bad APP segment (marker 0x%02X, %zu bytes)",
                         name, bad->marker, bad->payload.size()));
  }
  // The held headers, the segments, then what the strips encoded meanwhile; libjpeg's buffer
  // holds only bytes after those.
  bool ok = Emit(s, s->held.data(), s->splice);
  for (size_t i = 0; ok && i < segments.size(); ++i) ok = EmitSegment(s, segments[i]);
  ok = ok && Emit(s, s->held.data() + s->splice, s->held.size() - s->splice);
  s->holding = false;
  std::vector<uint8_t>().swap(s->held);
  if (!ok) return Failed(s->sink_status);
  return Status::Ok();
}

Status JpegWriter::Finish() {
  if (!active_) return Status(Code::kInternal, "jpeg writer: Finish without Begin");
  State* s = state_.get();
  if (s->holding) {
    return Failed(Status(Code::kInvalidArgument, "%s: finished before the late segments came",
                         s->file ? s->file->path() : "in-memory jpeg"));
  }
  if (s->next_row != s->height) {
    return Failed(Status(Code::kInvalidArgument, "%s: finished after %d of %d rows",
                         s->file ? s->file->path() : "in-memory jpeg",
                         static_cast<int>(s->next_row), static_cast<int>(s->height)));
  }
  if (setjmp(s->jump) != 0) return LibjpegFailure();
  jpeg_finish_compress(&s->cinfo);
  jpeg_destroy_compress(&s->cinfo);
  s->created = false;
  s->file = nullptr;
  s->memory = nullptr;
  active_ = false;
  return Status::Ok();
}

Status EncodeYCbCr420(const ConstPlanarU8& image, int quality, std::vector<uint8_t>* jpeg) {
  const int32_t width = image.planes[0].width, height = image.planes[0].height;
  if (image.count != 3 || image.planes[1].height < (height + 1) / 2 ||
      image.planes[2].height < (height + 1) / 2) {
    return Status(Code::kInvalidArgument, "in-memory jpeg: image is not YCbCr 4:2:0");
  }
  JpegWriter writer;
  LB_RETURN_IF_ERROR(writer.BeginMemory(jpeg, width, height, quality, JpegMetadata()));
  for (int32_t y = 0; y < height; y += kStripRows) {
    const int32_t rows = height - y < kStripRows ? height - y : kStripRows;
    ConstPlanarU8 strip = image;
    strip.planes[0] = image.planes[0].Crop(0, y, width, rows);
    for (int p = 1; p < 3; ++p) {
      strip.planes[p] = image.planes[p].Crop(0, y / 2, image.planes[p].width, (rows + 1) / 2);
    }
    LB_RETURN_IF_ERROR(writer.WriteStrip(strip, rows));
  }
  return writer.Finish();
}

}  // namespace lb
