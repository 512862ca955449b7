// The codecs as the file sensor's decoder (sim/files/image_decoder.h): PPM/PGM, PNG and JPEG
// through image_file.h, the camera tags through exif.h.
#pragma once

#include "sim/files/image_decoder.h"

namespace lb {

// One stateless instance for the life of the program.
const ImageDecoder& CodecImageDecoder();

}  // namespace lb
