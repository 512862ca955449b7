#include "firmware/codecs/png_writer.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <new>

namespace lb {
namespace {

// libpng reports errors through a callback that must not return: keep the text, then unwind to
// the setjmp in Encode. Everything that must survive that longjmp lives here.
struct PngOutput {
  char message[160] = {};
  std::vector<uint8_t>* out = nullptr;
  bool out_of_memory = false;
};

void OnError(png_structp png, png_const_charp text) {
  auto* ctx = static_cast<PngOutput*>(png_get_error_ptr(png));
  snprintf(ctx->message, sizeof(ctx->message), "%s", text);
  png_longjmp(png, 1);
}

void OnWarning(png_structp, png_const_charp) {}

void WriteBytes(png_structp png, png_bytep data, size_t size) {
  auto* ctx = static_cast<PngOutput*>(png_get_io_ptr(png));
  try {
    ctx->out->insert(ctx->out->end(), data, data + size);
  } catch (const std::bad_alloc&) {
    ctx->out_of_memory = true;
    png_error(png, "out of memory");
  }
}

void FlushBytes(png_structp) {}

// Fills `row` with image row y in PNG's byte layout (samples big-endian).
using RowFn = void (*)(const void* image, int32_t y, uint8_t* row);

struct Layout {
  int32_t width = 0, height = 0;
  int bits = 8;
  int color = PNG_COLOR_TYPE_GRAY;
  bool srgb = false;  // an sRGB chunk, as libpng's simplified writer gives colour images
  // zlib's fastest level and every row filtered against the one above, instead of libpng's
  // level 6 trying all five filters per row: a depth map's rows are alike, smooth or flat
  // between edges, so the Up filter alone does most of the work. Writing the photo's XMP gets
  // much faster, for a depth image somewhat larger but still small beside the photo.
  bool fast = false;
  size_t row_bytes = 0;
};

Status Encode(const char* name, const Layout& layout, const void* image, RowFn fill,
              std::vector<uint8_t>* png) {
  PngOutput ctx;
  ctx.out = png;
  std::vector<uint8_t> row(layout.row_bytes);
  png_structp write = png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, OnError, OnWarning);
  png_infop info = write ? png_create_info_struct(write) : nullptr;
  if (info == nullptr) {
    png_destroy_write_struct(&write, nullptr);
    return Status(Code::kOutOfMemory, "%s: cannot create the encoder", name);
  }
  if (setjmp(png_jmpbuf(write)) != 0) {
    png_destroy_write_struct(&write, &info);
    png->clear();
    return Status(ctx.out_of_memory ? Code::kOutOfMemory : Code::kInternal, "%s: %s", name,
                  ctx.message);
  }
  png_set_write_fn(write, &ctx, WriteBytes, FlushBytes);
  png_set_IHDR(write, info, static_cast<png_uint_32>(layout.width),
               static_cast<png_uint_32>(layout.height), layout.bits, layout.color,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (layout.srgb) png_set_sRGB(write, info, PNG_sRGB_INTENT_PERCEPTUAL);
  if (layout.fast) {
    png_set_compression_level(write, 1);
    png_set_filter(write, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  }
  png_write_info(write, info);
  for (int32_t y = 0; y < layout.height; ++y) {
    fill(image, y, row.data());
    png_write_row(write, row.data());
  }
  png_write_end(write, info);
  png_destroy_write_struct(&write, &info);
  return Status::Ok();
}

void GrayRow8(const void* image, int32_t y, uint8_t* row) {
  const ConstImageU16& values = *static_cast<const ConstImageU16*>(image);
  const uint16_t* in = values.Row(y);
  for (int32_t x = 0; x < values.width; ++x)
    row[x] = static_cast<uint8_t>(in[x] > 255 ? 255 : in[x]);
}

// Big-endian bytes written by hand rather than depend on the host's order.
void GrayRow16(const void* image, int32_t y, uint8_t* row) {
  const ConstImageU16& values = *static_cast<const ConstImageU16*>(image);
  const uint16_t* in = values.Row(y);
  for (int32_t x = 0; x < values.width; ++x) {
    row[2 * x] = static_cast<uint8_t>(in[x] >> 8);
    row[2 * x + 1] = static_cast<uint8_t>(in[x]);
  }
}

void RgbRow(const void* image, int32_t y, uint8_t* row) {
  const ConstImageU8& rgb = *static_cast<const ConstImageU8*>(image);
  memcpy(row, rgb.Row(y), static_cast<size_t>(rgb.width) * 3);
}

}  // namespace

Status EncodeGrayPng(ConstImageU16 values, int bits, std::vector<uint8_t>* png) {
  png->clear();
  if (values.empty() || values.channels != 1 || (bits != 8 && bits != 16)) {
    return Status(Code::kInvalidArgument, "depth png: need a one-channel image and 8 or 16 bits");
  }
  Layout layout;
  layout.width = values.width;
  layout.height = values.height;
  layout.bits = bits;
  layout.row_bytes = static_cast<size_t>(values.width) * static_cast<size_t>(bits / 8);
  layout.fast = true;
  return Encode("depth png", layout, &values, bits == 8 ? GrayRow8 : GrayRow16, png);
}

Status EncodeRgbPng(ConstImageU8 rgb, std::vector<uint8_t>* png) {
  png->clear();
  if (rgb.empty() || rgb.channels != 3) {
    return Status(Code::kInvalidArgument, "png: need a three-channel image");
  }
  Layout layout;
  layout.width = rgb.width;
  layout.height = rgb.height;
  layout.color = PNG_COLOR_TYPE_RGB;
  layout.srgb = true;
  layout.row_bytes = static_cast<size_t>(rgb.width) * 3;
  return Encode("png", layout, &rgb, RgbRow, png);
}

}  // namespace lb
