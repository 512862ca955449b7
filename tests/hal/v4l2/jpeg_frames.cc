#include "tests/hal/v4l2/jpeg_frames.h"

#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>

// jpeglib.h uses FILE and size_t without including their headers: <cstdio> comes first.
#include <jpeglib.h>

namespace lb::jpegtest {
namespace {

struct Errors {
  jpeg_error_mgr pub;
  jmp_buf jump;
};

void OnError(j_common_ptr cinfo) { longjmp(reinterpret_cast<Errors*>(cinfo->err)->jump, 1); }
void Quiet(j_common_ptr, int) {}

// The segments before the first scan: calls visit(code, start, length of the whole segment).
template <typename Visit>
size_t WalkHeader(const std::vector<uint8_t>& jpeg, Visit visit) {
  size_t pos = 2;
  while (pos + 4 <= jpeg.size() && jpeg[pos] == 0xFF) {
    const uint8_t code = jpeg[pos + 1];
    const size_t length = 2 + ((size_t{jpeg[pos + 2]} << 8) | jpeg[pos + 3]);
    visit(code, pos, length);
    pos += length;
    if (code == 0xDA) return pos;
  }
  return 0;
}

}  // namespace

Rgb TestPicture(int32_t width, int32_t height, uint32_t seed) {
  Rgb p;
  p.width = width;
  p.height = height;
  p.pixels.resize(size_t(width) * height * 3);
  uint32_t state = seed * 2654435761u + 12345u;
  for (int32_t y = 0; y < height; ++y) {
    for (int32_t x = 0; x < width; ++x) {
      const double u = double(x) / width, v = double(y) / height;
      const double texture = 18 * std::sin(x * 0.21 + seed) * std::cos(y * 0.17);
      state = state * 1664525u + 1013904223u;
      const double noise = double(state >> 29) - 3.5;  // -3.5..3.5
      const double rgb[3] = {40 + 170 * u + texture + noise, 60 + 140 * v - texture / 2 + noise,
                             200 - 120 * u * v + texture / 3 + noise};
      uint8_t* out = &p.pixels[(size_t(y) * width + x) * 3];
      for (int c = 0; c < 3; ++c) {
        out[c] = static_cast<uint8_t>(rgb[c] < 0 ? 0 : rgb[c] > 255 ? 255 : std::lround(rgb[c]));
      }
    }
  }
  return p;
}

std::vector<uint8_t> Encode(const Rgb& picture, const EncodeOptions& options) {
  jpeg_compress_struct cinfo = {};
  Errors err;
  cinfo.err = jpeg_std_error(&err.pub);
  err.pub.error_exit = OnError;
  unsigned char* out = nullptr;
  unsigned long out_size = 0;
  std::vector<uint8_t> result;
  if (setjmp(err.jump) != 0) {
    jpeg_destroy_compress(&cinfo);
    free(out);
    return {};
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &out, &out_size);
  cinfo.image_width = static_cast<JDIMENSION>(picture.width);
  cinfo.image_height = static_cast<JDIMENSION>(picture.height);
  cinfo.input_components = 3;
  cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, options.quality, TRUE);
  const Sampling s = options.sampling;
  const int h = s == Sampling::k422 || s == Sampling::k420 ? 2 : 1;
  const int v = s == Sampling::k420 ? 2 : s == Sampling::k1x4 ? 4 : 1;
  cinfo.comp_info[0].h_samp_factor = h;
  cinfo.comp_info[0].v_samp_factor = v;
  if (options.progressive) jpeg_simple_progression(&cinfo);
  cinfo.restart_in_rows = options.restart_rows;
  jpeg_start_compress(&cinfo, TRUE);
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(picture.at(0, static_cast<int32_t>(cinfo.next_scanline)));
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  result.assign(out, out + out_size);
  jpeg_destroy_compress(&cinfo);
  free(out);
  return result;
}

std::vector<uint8_t> WithoutHuffmanTables(const std::vector<uint8_t>& jpeg) {
  std::vector<uint8_t> out(jpeg.begin(), jpeg.begin() + 2);
  size_t end = WalkHeader(jpeg, [&](uint8_t code, size_t start, size_t length) {
    if (code != 0xC4) out.insert(out.end(), jpeg.begin() + start, jpeg.begin() + start + length);
  });
  out.insert(out.end(), jpeg.begin() + end, jpeg.end());
  return out;
}

int CountHeaderMarkers(const std::vector<uint8_t>& jpeg, uint8_t code) {
  int n = 0;
  WalkHeader(jpeg, [&](uint8_t c, size_t, size_t) { n += c == code; });
  return n;
}

std::vector<uint8_t> HeaderSegments(const std::vector<uint8_t>& jpeg, uint8_t code) {
  std::vector<uint8_t> out;
  WalkHeader(jpeg, [&](uint8_t c, size_t start, size_t length) {
    if (c == code) out.insert(out.end(), jpeg.begin() + start, jpeg.begin() + start + length);
  });
  return out;
}

size_t ScanStart(const std::vector<uint8_t>& jpeg) {
  return WalkHeader(jpeg, [](uint8_t, size_t, size_t) {});
}

Rgb DecodeWithLibjpeg(const std::vector<uint8_t>& jpeg) {
  jpeg_decompress_struct cinfo = {};
  Errors err;
  cinfo.err = jpeg_std_error(&err.pub);
  err.pub.error_exit = OnError;
  err.pub.emit_message = Quiet;
  Rgb p;
  if (setjmp(err.jump) != 0) {
    jpeg_destroy_decompress(&cinfo);
    return {};
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, jpeg.data(), static_cast<unsigned long>(jpeg.size()));
  jpeg_read_header(&cinfo, TRUE);
  cinfo.out_color_space = JCS_RGB;
  jpeg_start_decompress(&cinfo);
  p.width = static_cast<int32_t>(cinfo.output_width);
  p.height = static_cast<int32_t>(cinfo.output_height);
  p.pixels.resize(size_t(p.width) * p.height * 3);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = &p.pixels[size_t(cinfo.output_scanline) * p.width * 3];
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return p;
}

}  // namespace lb::jpegtest
