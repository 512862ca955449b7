#include "firmware/jpeg/png_memory.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>

namespace lb {
namespace {

// libpng reports errors through a callback that must not return: keep the text, then unwind to
// the setjmp in the calling function.
struct PngContext {
  char message[160] = {};
  const uint8_t* in = nullptr;
  size_t in_size = 0;
  size_t in_pos = 0;
  std::vector<uint8_t>* out = nullptr;
  bool out_of_memory = false;
};

void OnPngError(png_structp png, png_const_charp text) {
  PngContext* ctx = static_cast<PngContext*>(png_get_error_ptr(png));
  snprintf(ctx->message, sizeof(ctx->message), "%s", text);
  png_longjmp(png, 1);
}

void OnPngWarning(png_structp, png_const_charp) {}

void WriteBytes(png_structp png, png_bytep data, size_t size) {
  PngContext* ctx = static_cast<PngContext*>(png_get_io_ptr(png));
  try {
    ctx->out->insert(ctx->out->end(), data, data + size);
  } catch (const std::bad_alloc&) {
    ctx->out_of_memory = true;
    png_error(png, "out of memory");
  }
}

void FlushBytes(png_structp) {}

void ReadBytes(png_structp png, png_bytep data, size_t size) {
  PngContext* ctx = static_cast<PngContext*>(png_get_io_ptr(png));
  if (size > ctx->in_size - ctx->in_pos) png_error(png, "truncated");
  memcpy(data, ctx->in + ctx->in_pos, size);
  ctx->in_pos += size;
}

}  // namespace

Status EncodeGrayPng(ConstImageU16 values, int bits, std::vector<uint8_t>* png) {
  png->clear();
  if (values.empty() || values.channels != 1 || (bits != 8 && bits != 16)) {
    return Status(Code::kInvalidArgument, "depth png: need a one-channel image and 8 or 16 bits");
  }
  PngContext ctx;
  ctx.out = png;
  std::vector<uint8_t> row(static_cast<size_t>(values.width) * (bits / 8));
  png_structp write =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, OnPngError, OnPngWarning);
  png_infop info = write ? png_create_info_struct(write) : nullptr;
  if (info == nullptr) {
    png_destroy_write_struct(&write, nullptr);
    return Status(Code::kOutOfMemory, "depth png: cannot create the encoder");
  }
  if (setjmp(png_jmpbuf(write)) != 0) {
    png_destroy_write_struct(&write, &info);
    png->clear();
    return Status(ctx.out_of_memory ? Code::kOutOfMemory : Code::kInternal, "depth png: %s",
                  ctx.message);
  }
  png_set_write_fn(write, &ctx, WriteBytes, FlushBytes);
  png_set_IHDR(write, info, static_cast<png_uint_32>(values.width),
               static_cast<png_uint_32>(values.height), bits, PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(write, info);
  for (int32_t y = 0; y < values.height; ++y) {
    const uint16_t* in = values.Row(y);
    // PNG samples are big-endian: write the bytes ourselves rather than depend on host order.
    for (int32_t x = 0; x < values.width; ++x) {
      if (bits == 8) {
        row[x] = static_cast<uint8_t>(in[x] > 255 ? 255 : in[x]);
      } else {
        row[2 * x] = static_cast<uint8_t>(in[x] >> 8);
        row[2 * x + 1] = static_cast<uint8_t>(in[x]);
      }
    }
    png_write_row(write, row.data());
  }
  png_write_end(write, nullptr);
  png_destroy_write_struct(&write, &info);
  return Status::Ok();
}

Status DecodeGrayPng(const uint8_t* data, size_t size, const char* name, int32_t max_side,
                     int32_t expect_width, int32_t expect_height, GrayPng* out) {
  out->values.clear();
  out->width = out->height = out->bits = 0;
  if (size < 8 || png_sig_cmp(data, 0, 8) != 0) {
    return Status(Code::kCorruptData, "%s: not a PNG", name);
  }
  PngContext ctx;
  ctx.in = data;
  ctx.in_size = size;
  std::vector<uint8_t> row;
  png_structp read = png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx, OnPngError, OnPngWarning);
  png_infop info = read ? png_create_info_struct(read) : nullptr;
  if (info == nullptr) {
    png_destroy_read_struct(&read, nullptr, nullptr);
    return Status(Code::kOutOfMemory, "%s: cannot create the PNG decoder", name);
  }
  if (setjmp(png_jmpbuf(read)) != 0) {
    png_destroy_read_struct(&read, &info, nullptr);
    out->values.clear();
    return Status(Code::kCorruptData, "%s: PNG: %s", name, ctx.message);
  }
  png_set_read_fn(read, &ctx, ReadBytes);
  png_set_user_limits(read, static_cast<png_uint_32>(max_side), static_cast<png_uint_32>(max_side));
  png_read_info(read, info);
  const png_uint_32 width = png_get_image_width(read, info);
  const png_uint_32 height = png_get_image_height(read, info);
  const int depth = png_get_bit_depth(read, info);
  const int color = png_get_color_type(read, info);
  if (color != PNG_COLOR_TYPE_GRAY) png_error(read, "not a greyscale image without alpha");
  if (png_get_interlace_type(read, info) != PNG_INTERLACE_NONE) png_error(read, "interlaced");
  if ((expect_width > 0 && width != static_cast<png_uint_32>(expect_width)) ||
      (expect_height > 0 && height != static_cast<png_uint_32>(expect_height))) {
    snprintf(ctx.message, sizeof(ctx.message), "image is %ux%u, expected %dx%d",
             static_cast<unsigned>(width), static_cast<unsigned>(height),
             static_cast<int>(expect_width), static_cast<int>(expect_height));
    png_longjmp(read, 1);
  }
  if (depth < 8) png_set_expand_gray_1_2_4_to_8(read);
  png_read_update_info(read, info);
  row.resize(png_get_rowbytes(read, info));
  out->width = static_cast<int32_t>(width);
  out->height = static_cast<int32_t>(height);
  out->bits = depth == 16 ? 16 : 8;
  // Grow with the rows actually decoded, so a header that lies about its size costs nothing.
  for (png_uint_32 y = 0; y < height; ++y) {
    png_read_row(read, row.data(), nullptr);
    for (png_uint_32 x = 0; x < width; ++x) {
      out->values.push_back(depth == 16 ? static_cast<uint16_t>((row[2 * x] << 8) | row[2 * x + 1])
                                        : row[x]);
    }
  }
  png_read_end(read, nullptr);
  png_destroy_read_struct(&read, &info, nullptr);
  return Status::Ok();
}

}  // namespace lb
