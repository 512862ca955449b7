#include "tests/firmware/codecs/test_images.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>

#include <jpeglib.h>

namespace lb::test {

Bytes EncodePnm(const char* magic, int width, int height, int maxval,
                const std::vector<uint16_t>& samples, const std::string& header_gap) {
  std::string header = std::string(magic) + header_gap + std::to_string(width) + header_gap +
                       std::to_string(height) + header_gap + std::to_string(maxval) + "\n";
  Bytes out(header.begin(), header.end());
  for (uint16_t v : samples) {
    if (maxval > 255) out.push_back(static_cast<uint8_t>(v >> 8));
    out.push_back(static_cast<uint8_t>(v & 0xff));
  }
  return out;
}

namespace {

void AppendPng(png_structp png, png_bytep data, size_t size) {
  auto* out = static_cast<Bytes*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + size);
}
void FlushPng(png_structp) {}

}  // namespace

bool EncodePng(const PngSpec& spec, Bytes* out) {
  out->clear();
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, out, AppendPng, FlushPng);
  png_set_IHDR(png, info, spec.width, spec.height, spec.bit_depth, spec.color_type,
               spec.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (spec.color_type == PNG_COLOR_TYPE_PALETTE) {
    std::vector<png_color> colors(spec.palette_rgb.size() / 3);
    for (size_t i = 0; i < colors.size(); ++i) {
      colors[i] = {spec.palette_rgb[3 * i], spec.palette_rgb[3 * i + 1],
                   spec.palette_rgb[3 * i + 2]};
    }
    png_set_PLTE(png, info, colors.data(), static_cast<int>(colors.size()));
  }
  if (spec.transparent) {
    const png_byte alpha[1] = {0};
    png_color_16 value = {};
    if (spec.color_type == PNG_COLOR_TYPE_PALETTE) {
      png_set_tRNS(png, info, alpha, 1, nullptr);
    } else {
      png_set_tRNS(png, info, nullptr, 0, &value);
    }
  }
  png_write_info(png, info);
  const size_t row_bytes = png_get_rowbytes(png, info);
  std::vector<png_bytep> rows(spec.height);
  for (int y = 0; y < spec.height; ++y) {
    rows[y] = const_cast<png_bytep>(spec.rows.data() + row_bytes * y);
  }
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool EncodeJpeg(int width, int height, int components, const uint8_t* pixels, int quality,
                bool progressive, Bytes* out) {
  jpeg_compress_struct cinfo;
  jpeg_error_mgr err;
  cinfo.err = jpeg_std_error(&err);
  jpeg_create_compress(&cinfo);
  unsigned char* mem = nullptr;
  unsigned long mem_size = 0;  // NOLINT: libjpeg's type
  jpeg_mem_dest(&cinfo, &mem, &mem_size);
  cinfo.image_width = width;
  cinfo.image_height = height;
  cinfo.input_components = components;
  cinfo.in_color_space = components == 1 ? JCS_GRAYSCALE : components == 3 ? JCS_RGB : JCS_CMYK;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  if (progressive) jpeg_simple_progression(&cinfo);
  jpeg_start_compress(&cinfo, TRUE);
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(pixels) +
                   static_cast<size_t>(cinfo.next_scanline) * width * components;
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  out->assign(mem, mem + mem_size);
  jpeg_destroy_compress(&cinfo);
  free(mem);
  return true;
}

uint8_t Smooth(int x, int y, int c) { return static_cast<uint8_t>(40 + 2 * x + y + 30 * c); }

long FindPngChunk(const Bytes& png, const char* type) {
  size_t pos = 8;
  while (pos + 12 <= png.size()) {
    const uint32_t length = (uint32_t{png[pos]} << 24) | (uint32_t{png[pos + 1]} << 16) |
                            (uint32_t{png[pos + 2]} << 8) | png[pos + 3];
    if (memcmp(&png[pos + 4], type, 4) == 0) return static_cast<long>(pos);
    pos += 12 + static_cast<size_t>(length);
  }
  return -1;
}

bool WriteFile(const std::string& path, const Bytes& bytes) {
  FILE* f = fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = bytes.empty() || fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  return fclose(f) == 0 && ok;
}

}  // namespace lb::test
