#include "firmware/depth_out/depth_out.h"

#include <vector>

#include "firmware/codecs/pfm_writer.h"
#include "firmware/codecs/png_writer.h"

namespace lb {
namespace {

Status CheckMap(const char* path, ConstImageU16 disp_q8) {
  if (disp_q8.empty() || disp_q8.channels != 1) {
    return Status(Code::kInvalidArgument, "%s: no single-channel disparity map to write", path);
  }
  return Status::Ok();
}

}  // namespace

Status EncodeDisparityPfm(AtomicFile* out, ConstImageU16 disp_q8, int32_t bias_q8) {
  LB_RETURN_IF_ERROR(CheckMap(out->path(), disp_q8));
  PfmWriter pfm;
  LB_RETURN_IF_ERROR(pfm.Begin(out, disp_q8.width, disp_q8.height));
  std::vector<float> row(static_cast<size_t>(disp_q8.width));
  for (int32_t y = disp_q8.height - 1; y >= 0; --y) {
    const uint16_t* src = disp_q8.Row(y);
    for (int32_t x = 0; x < disp_q8.width; ++x) {
      row[x] = static_cast<float>(src[x] - bias_q8) / 256.0f;
    }
    LB_RETURN_IF_ERROR(pfm.WriteRow(row.data()));
  }
  return Status::Ok();
}

Status WriteDisparityPfm(const char* path, ConstImageU16 disp_q8, int32_t bias_q8) {
  LB_RETURN_IF_ERROR(CheckMap(path, disp_q8));
  AtomicFile out;
  LB_RETURN_IF_ERROR(out.Open(path));
  LB_RETURN_IF_ERROR(EncodeDisparityPfm(&out, disp_q8, bias_q8));
  return out.Commit();
}

void DisparityColour(int32_t disp_q8, int32_t min_q8, int32_t max_q8, uint8_t rgb[3]) {
  const int32_t span = max_q8 > min_q8 ? max_q8 - min_q8 : 1;
  int32_t v = disp_q8 < min_q8 ? min_q8 : (disp_q8 > max_q8 ? max_q8 : disp_q8);
  // Position on the ramp, 0..1023: four segments of 256.
  const int32_t t = static_cast<int32_t>((int64_t{v - min_q8} * 1023) / span);
  const int32_t seg = t >> 8, f = t & 255;
  static constexpr uint8_t kStops[5][3] = {
      {0, 0, 255}, {0, 255, 255}, {0, 255, 0}, {255, 255, 0}, {255, 0, 0}};
  for (int c = 0; c < 3; ++c) {
    const int32_t a = kStops[seg][c], b = kStops[seg + 1][c];
    rgb[c] = static_cast<uint8_t>(a + ((b - a) * f + 128) / 256);
  }
}

Status EncodeDisparityPreview(AtomicFile* out, ConstImageU16 disp_q8, int32_t min_q8,
                              int32_t max_q8) {
  LB_RETURN_IF_ERROR(CheckMap(out->path(), disp_q8));
  std::vector<uint8_t> pixels(static_cast<size_t>(disp_q8.width) * disp_q8.height * 3);
  for (int32_t y = 0; y < disp_q8.height; ++y) {
    for (int32_t x = 0; x < disp_q8.width; ++x) {
      DisparityColour(disp_q8.Row(y)[x], min_q8, max_q8,
                      &pixels[(static_cast<size_t>(y) * disp_q8.width + x) * 3]);
    }
  }
  std::vector<uint8_t> png;
  Status s = EncodeRgbPng(MakeView(pixels.data(), disp_q8.width, disp_q8.height, 3), &png);
  if (!s.ok()) return s.Prefix("%s: ", out->path());
  return out->Write(png.data(), png.size());
}

Status WriteDisparityPreview(const char* path, ConstImageU16 disp_q8, int32_t min_q8,
                             int32_t max_q8) {
  LB_RETURN_IF_ERROR(CheckMap(path, disp_q8));
  AtomicFile out;
  LB_RETURN_IF_ERROR(out.Open(path));
  LB_RETURN_IF_ERROR(EncodeDisparityPreview(&out, disp_q8, min_q8, max_q8));
  return out.Commit();
}

}  // namespace lb
