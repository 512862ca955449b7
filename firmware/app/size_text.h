// "WxH" as the command line and refocusd.conf write a frame size: two decimal numbers joined by
// an 'x', each within [lo, hi]. Overflow-safe: "4294967616x240" is an error, not 320x240.
#pragma once

#include <cstdint>

namespace lb {

bool ParseSizeText(const char* text, int32_t lo, int32_t hi, int32_t* width, int32_t* height);

}  // namespace lb
