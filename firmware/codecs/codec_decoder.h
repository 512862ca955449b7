// The codecs as an ImageDecoder (hal/image_decoder.h), which the file sensor reads through:
// PPM/PGM, PNG and JPEG through image_file.h, the camera tags through exif.h.
#pragma once

#include "hal/image_decoder.h"

namespace lb {

// One stateless instance for the life of the program.
const ImageDecoder& CodecImageDecoder();

}  // namespace lb
