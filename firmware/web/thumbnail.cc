#include "firmware/web/thumbnail.h"

#include <unistd.h>

#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "firmware/codecs/exif.h"

// After <cstdio>: jpeglib.h uses FILE without declaring it.
#include <jpeglib.h>

namespace lb {
namespace {

constexpr int32_t kMaxSide = 16384;

struct ErrorManager {
  jpeg_error_mgr pub;
  jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

// Errors, and warnings (corrupt data), come back here instead of exit().
void OnError(j_common_ptr cinfo) {
  ErrorManager* err = reinterpret_cast<ErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, err->message);
  longjmp(err->jump, 1);
}
void OnMessage(j_common_ptr cinfo, int level) {
  if (level < 0) OnError(cinfo);  // a warning: the data is corrupt
}

// Everything the decode-shrink-encode loop holds, in one trivially destructible block so that a
// longjmp out of libjpeg skips no destructor.
struct Work {
  jpeg_decompress_struct in;
  jpeg_compress_struct out;
  bool in_made = false, out_made = false;
  FILE* file = nullptr;
  unsigned char* jpeg = nullptr;  // jpeg_mem_dest's buffer (malloc'd by libjpeg)
  unsigned long jpeg_size = 0;
  JSAMPLE* row = nullptr;    // one decoded row
  uint32_t* sums = nullptr;  // one output row of sums
  JSAMPLE* out_row = nullptr;
  int32_t* column = nullptr;  // output column of each input column
  int32_t* column_count = nullptr;

  void Release() {
    if (in_made) jpeg_destroy_decompress(&in);
    if (out_made) jpeg_destroy_compress(&out);
    if (file != nullptr) fclose(file);
    free(jpeg);
    free(row);
    free(sums);
    free(out_row);
    free(column);
    free(column_count);
  }
};

// The EXIF Orientation in the saved APP1 markers, 0 when none.
int32_t OrientationOf(jpeg_saved_marker_ptr marker) {
  for (; marker != nullptr; marker = marker->next) {
    if (marker->marker != JPEG_APP0 + 1 || marker->data_length < 6 ||
        memcmp(marker->data, "Exif\0\0", 6) != 0) {
      continue;
    }
    // As a file would hold it: SOI, then the APP1 segment.
    std::vector<uint8_t> file = {0xff,
                                 0xd8,
                                 0xff,
                                 0xe1,
                                 static_cast<uint8_t>((marker->data_length + 2) >> 8),
                                 static_cast<uint8_t>(marker->data_length + 2)};
    file.insert(file.end(), marker->data, marker->data + marker->data_length);
    return ExifOrientation(file.data(), file.size());
  }
  return 0;
}

// Returns 0 on success, 1 on a libjpeg error (message in err), 2 on an oversized image, 3 when
// out of memory.
int Shrink(Work* w, ErrorManager* err, int32_t width, int quality) {
  if (setjmp(err->jump) != 0) return 1;
  w->in.err = jpeg_std_error(&err->pub);
  err->pub.error_exit = OnError;
  err->pub.emit_message = OnMessage;
  jpeg_create_decompress(&w->in);
  w->in_made = true;
  jpeg_stdio_src(&w->in, w->file);
  jpeg_save_markers(&w->in, JPEG_APP0 + 1, 0xffff);  // EXIF: the orientation to carry over
  jpeg_read_header(&w->in, TRUE);
  if (w->in.image_width > kMaxSide || w->in.image_height > kMaxSide) return 2;
  // Smallest M/8 with image_width * M / 8 >= width.
  const int64_t src_w = w->in.image_width;
  int64_t m = (static_cast<int64_t>(width) * 8 + src_w - 1) / src_w;
  m = m < 1 ? 1 : (m > 8 ? 8 : m);
  w->in.scale_num = static_cast<unsigned>(m);
  w->in.scale_denom = 8;
  w->in.out_color_space = JCS_RGB;
  w->in.dct_method = JDCT_ISLOW;
  jpeg_start_decompress(&w->in);
  const int32_t in_w = static_cast<int32_t>(w->in.output_width);
  const int32_t in_h = static_cast<int32_t>(w->in.output_height);
  const int32_t out_w = in_w < width ? in_w : width;
  int32_t out_h = static_cast<int32_t>((static_cast<int64_t>(in_h) * out_w + in_w / 2) / in_w);
  out_h = out_h < 1 ? 1 : out_h;

  w->row = static_cast<JSAMPLE*>(malloc(static_cast<size_t>(in_w) * 3));
  w->sums = static_cast<uint32_t*>(calloc(static_cast<size_t>(out_w) * 3, sizeof(uint32_t)));
  w->out_row = static_cast<JSAMPLE*>(malloc(static_cast<size_t>(out_w) * 3));
  w->column = static_cast<int32_t*>(malloc(static_cast<size_t>(in_w) * sizeof(int32_t)));
  w->column_count = static_cast<int32_t*>(calloc(static_cast<size_t>(out_w), sizeof(int32_t)));
  if (!w->row || !w->sums || !w->out_row || !w->column || !w->column_count) return 3;
  for (int32_t x = 0; x < in_w; ++x) {
    w->column[x] = static_cast<int32_t>(static_cast<int64_t>(x) * out_w / in_w);
    ++w->column_count[w->column[x]];
  }

  w->out.err = &err->pub;
  jpeg_create_compress(&w->out);
  w->out_made = true;
  jpeg_mem_dest(&w->out, &w->jpeg, &w->jpeg_size);
  w->out.image_width = static_cast<JDIMENSION>(out_w);
  w->out.image_height = static_cast<JDIMENSION>(out_h);
  w->out.input_components = 3;
  w->out.in_color_space = JCS_RGB;
  jpeg_set_defaults(&w->out);
  jpeg_set_quality(&w->out, quality, TRUE);
  jpeg_start_compress(&w->out, TRUE);
  // The photo's EXIF Orientation on the thumbnail too, so the gallery turns it as the browser
  // turns the photo itself.
  const int32_t orientation = OrientationOf(w->in.marker_list);
  if (orientation > 1) {
    ExifTags tags;
    tags.orientation = orientation;
    std::vector<uint8_t> exif;
    if (BuildExif(tags, out_w, out_h, &exif).ok()) {
      jpeg_write_marker(&w->out, JPEG_APP0 + 1, exif.data(), static_cast<unsigned>(exif.size()));
    }
  }

  // Input row y belongs to output row y * out_h / in_h; a finished output row is the average of
  // its input rows and columns.
  int32_t rows_in = 0, current = 0;
  for (int32_t y = 0; y < in_h; ++y) {
    JSAMPROW rp = w->row;
    jpeg_read_scanlines(&w->in, &rp, 1);
    const int32_t oy = static_cast<int32_t>(static_cast<int64_t>(y) * out_h / in_h);
    if (oy != current) {
      for (int32_t x = 0; x < out_w * 3; ++x) {
        const uint32_t n = static_cast<uint32_t>(w->column_count[x / 3] * rows_in);
        w->out_row[x] = static_cast<JSAMPLE>((w->sums[x] + n / 2) / n);
        w->sums[x] = 0;
      }
      JSAMPROW op = w->out_row;
      jpeg_write_scanlines(&w->out, &op, 1);
      rows_in = 0;
      current = oy;
    }
    for (int32_t x = 0; x < in_w; ++x) {
      uint32_t* s = w->sums + w->column[x] * 3;
      s[0] += w->row[x * 3];
      s[1] += w->row[x * 3 + 1];
      s[2] += w->row[x * 3 + 2];
    }
    ++rows_in;
  }
  for (int32_t x = 0; x < out_w * 3; ++x) {
    const uint32_t n = static_cast<uint32_t>(w->column_count[x / 3] * rows_in);
    w->out_row[x] = static_cast<JSAMPLE>((w->sums[x] + n / 2) / n);
  }
  JSAMPROW op = w->out_row;
  jpeg_write_scanlines(&w->out, &op, 1);
  jpeg_finish_compress(&w->out);
  jpeg_finish_decompress(&w->in);
  return 0;
}

}  // namespace

Status MakeThumbnail(int fd, int32_t width, int quality, std::vector<uint8_t>* out) {
  out->clear();
  if (width < 1) return Status(Code::kInvalidArgument, "thumbnail width %d", width);
  Work w;
  const int own = dup(fd);
  if (own < 0) return Status(Code::kIoError, "thumbnail: cannot duplicate the descriptor");
  w.file = fdopen(own, "rb");
  if (w.file == nullptr) {
    close(own);
    return Status(Code::kIoError, "thumbnail: fdopen failed");
  }
  ErrorManager err;
  err.message[0] = '\0';
  const int result = Shrink(&w, &err, width, quality);
  Status s = Status::Ok();
  if (result == 1) {
    s = Status(Code::kCorruptData, "not a readable JPEG: %s", err.message);
  } else if (result == 2) {
    s = Status(Code::kUnsupported, "larger than %d px a side", kMaxSide);
  } else if (result == 3) {
    s = Status(Code::kOutOfMemory, "thumbnail: out of memory");
  } else {
    out->assign(w.jpeg, w.jpeg + w.jpeg_size);
  }
  w.Release();
  return s;
}

}  // namespace lb
