// Writing a disparity map out of the product: a PFM (Middlebury's float format, px per view step
// for the reference view) and a colour-mapped PNG preview, through AtomicFile like every file
// the product writes. Encode* fill an open AtomicFile and leave the commit to the caller, so
// a command with two outputs can prepare both before either is renamed into place.
#pragma once

#include <cstdint>

#include "algo/core/image.h"
#include "algo/core/status.h"
#include "firmware/storage/atomic_file.h"

namespace lb {

// Single-channel PFM ("Pf"), little-endian (scale -1), rows bottom to top, values
// (map - bias_q8) / 256: signed disparities for a map lifted by DepthStage::MapBiasQ8.
Status WriteDisparityPfm(const char* path, ConstImageU16 disp_q8, int32_t bias_q8 = 0);
Status EncodeDisparityPfm(AtomicFile* out, ConstImageU16 disp_q8, int32_t bias_q8 = 0);

// RGB8 colour of a disparity on a blue (far) - cyan - green - yellow - red (near) ramp over
// [min_q8, max_q8]; values outside are clamped.
void DisparityColour(int32_t disp_q8, int32_t min_q8, int32_t max_q8, uint8_t rgb[3]);

// The preview PNG: one DisparityColour per pixel. Allocates one row.
Status WriteDisparityPreview(const char* path, ConstImageU16 disp_q8, int32_t min_q8,
                             int32_t max_q8);
Status EncodeDisparityPreview(AtomicFile* out, ConstImageU16 disp_q8, int32_t min_q8,
                              int32_t max_q8);

}  // namespace lb
