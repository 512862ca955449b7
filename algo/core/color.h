// Row converters between the sensor formats and the pipeline's two internal formats:
// RGB8 (working views) and JFIF full-range YCbCr (the full-resolution reference and the output).
// Coefficients are Q15 (BT.601); every result is rounded half up and clamped to 0..255.
#pragma once

#include <cstdint>

#include "algo/core/frame.h"

namespace lb {

// Converts one row of `width` pixels of any PixelFormat to RGB8. For the 4:2:0 formats, `u` and
// `v` are the chroma rows that cover this row: NV12's UV row in `u` (`v` unused), I420's U and V
// rows; for other formats both are ignored. `range` applies to the YUV formats.
void RowToRgb8(PixelFormat format, YuvRange range, const uint8_t* src, const uint8_t* u,
               const uint8_t* v, int32_t width, uint8_t* rgb);

// One row of RGB8 to full-range luma.
void RowRgb8ToY(const uint8_t* rgb, int32_t width, uint8_t* y);

// Two RGB8 rows (the same pointer twice for a lone last row) to one row of 4:2:0 chroma:
// each output sample is the chroma of the 2x2 block's mean colour.
void RowsRgb8ToCbCr420(const uint8_t* rgb0, const uint8_t* rgb1, int32_t width, uint8_t* cb,
                       uint8_t* cr);

// Full-range YCbCr to RGB8 for one pixel (for previews and tests).
void YCbCrToRgb8(int32_t y, int32_t cb, int32_t cr, uint8_t* rgb);

}  // namespace lb
