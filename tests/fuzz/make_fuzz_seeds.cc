// Writes small seeds for the reader fuzzers, one folder per fuzzer: OUT/pnm, OUT/png, OUT/jpeg
// (some with EXIF: focal length, 35 mm focal length, orientation), OUT/xmp (refocusable JPEGs
// and XMP packets, with fuzz_xmp's mode byte first), OUT/dd (the same with Dynamic Depth, for
// fuzz_dd) and OUT/conf (the packaged refocusd.conf and variants). Generated at run time with
// the reference encoders and the firmware's own EXIF and XMP writers, so no third-party file is
// committed (tests/fuzz/corpus/ holds what fuzzing found).
#include <png.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "algo/core/image.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/refocusable/dynamic_depth.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "firmware/refocusable/xmp_writer.h"
#include "tests/firmware/codecs/test_images.h"

namespace {

using lb::test::Bytes;

int failures = 0;

void Save(const std::string& dir, const std::string& name, const Bytes& bytes) {
  mkdir(dir.c_str(), 0755);
  if (!lb::test::WriteFile(dir + "/" + name, bytes)) {
    fprintf(stderr, "make_fuzz_seeds: cannot write %s/%s\n", dir.c_str(), name.c_str());
    ++failures;
  }
}

std::vector<uint16_t> Ramp(size_t count, int maxval) {
  std::vector<uint16_t> samples(count);
  for (size_t i = 0; i < count; ++i) samples[i] = static_cast<uint16_t>((i * 37) % (maxval + 1));
  return samples;
}

void Pnm(const std::string& dir) {
  Save(dir, "rgb8_comments.ppm",
       lb::test::EncodePnm("P6", 4, 3, 255, Ramp(36, 255), " # comment\n"));
  Save(dir, "gray16.pgm", lb::test::EncodePnm("P5", 3, 2, 65535, Ramp(6, 65535)));
  Save(dir, "gray_maxval1023.pgm", lb::test::EncodePnm("P5", 5, 2, 1023, Ramp(10, 1023)));
  Save(dir, "rgb_maxval15.ppm", lb::test::EncodePnm("P6", 2, 2, 15, Ramp(12, 15)));
  Save(dir, "gray_strips.pgm", lb::test::EncodePnm("P5", 3, 20, 255, Ramp(60, 255)));
}

Bytes Png(int width, int height, int color_type, int bit_depth, bool interlaced,
          bool transparent = false) {
  lb::test::PngSpec spec{width, height, color_type, bit_depth, interlaced, {}, {}, transparent};
  const int channels[] = {1, 0, 3, 1, 2, 0, 4};
  const size_t row_bytes =
      (static_cast<size_t>(width) * static_cast<size_t>(channels[color_type]) * bit_depth + 7) / 8;
  for (size_t i = 0; i < row_bytes * static_cast<size_t>(height); ++i) {
    spec.rows.push_back(static_cast<uint8_t>(color_type == 3 ? i % 3 : i * 13));
  }
  if (color_type == PNG_COLOR_TYPE_PALETTE) spec.palette_rgb = {0, 0, 0, 200, 10, 10, 9, 250, 9};
  Bytes out;
  if (!lb::test::EncodePng(spec, &out)) ++failures;
  return out;
}

void PngSeeds(const std::string& dir) {
  Save(dir, "rgb8.png", Png(5, 18, PNG_COLOR_TYPE_RGB, 8, false));
  Save(dir, "gray8.png", Png(4, 4, PNG_COLOR_TYPE_GRAY, 8, false));
  Save(dir, "rgb16.png", Png(3, 3, PNG_COLOR_TYPE_RGB, 16, false));
  Save(dir, "gray16.png", Png(3, 3, PNG_COLOR_TYPE_GRAY, 16, false));
  Save(dir, "rgba8.png", Png(3, 3, PNG_COLOR_TYPE_RGB_ALPHA, 8, false));
  Save(dir, "gray_alpha16.png", Png(3, 3, PNG_COLOR_TYPE_GRAY_ALPHA, 16, false));
  Save(dir, "palette2.png", Png(6, 3, PNG_COLOR_TYPE_PALETTE, 2, false));
  Save(dir, "gray1.png", Png(9, 2, PNG_COLOR_TYPE_GRAY, 1, false));
  Save(dir, "adam7_rgb8.png", Png(11, 9, PNG_COLOR_TYPE_RGB, 8, true));
  Save(dir, "adam7_palette4.png", Png(7, 7, PNG_COLOR_TYPE_PALETTE, 4, true));
  Save(dir, "palette8_trns.png", Png(4, 4, PNG_COLOR_TYPE_PALETTE, 8, false, true));
  Save(dir, "gray4_trns.png", Png(5, 3, PNG_COLOR_TYPE_GRAY, 4, false, true));
}

Bytes Jpeg(int width, int height, int components, bool progressive) {
  std::vector<uint8_t> pixels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < components; ++c) pixels.push_back(lb::test::Smooth(x, y, c));
    }
  }
  Bytes out;
  if (!lb::test::EncodeJpeg(width, height, components, pixels.data(), 75, progressive, &out)) {
    ++failures;
  }
  return out;
}

// `jpeg` with APPn segments inserted right after SOI.
Bytes WithSegments(const Bytes& jpeg, const std::vector<lb::JpegSegment>& segments) {
  Bytes out(jpeg.begin(), jpeg.begin() + 2);
  for (const lb::JpegSegment& seg : segments) {
    const size_t n = seg.payload.size() + 2;
    out.insert(out.end(),
               {0xFF, seg.marker, static_cast<uint8_t>(n >> 8), static_cast<uint8_t>(n)});
    out.insert(out.end(), seg.payload.begin(), seg.payload.end());
  }
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  return out;
}

lb::JpegSegment App1(const Bytes& payload) {
  lb::JpegSegment seg;
  seg.marker = 0xE1;
  seg.payload = payload;
  return seg;
}

// EXIF the way the firmware writes it (libexif, little-endian).
Bytes FirmwareExif(int32_t focal_35mm, int32_t orientation, int width, int height) {
  lb::JpegMetadata meta;
  meta.make = "LensBlur";
  meta.model = "PS-1";
  meta.software = "refocus";
  meta.datetime_original = "2024:05:17 10:11:12";
  meta.f_number = 2.8f;
  meta.focal_35mm = focal_35mm;
  meta.orientation = orientation;
  Bytes payload;
  if (!lb::BuildExif(meta, width, height, &payload).ok()) ++failures;
  return payload;
}

void Put16(Bytes* b, uint16_t v) { b->insert(b->end(), {uint8_t(v >> 8), uint8_t(v)}); }
void Put32(Bytes* b, uint32_t v) {
  b->insert(b->end(), {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)});
}
// One big-endian IFD entry whose value fits the 4-byte field (or is an offset).
void Entry(Bytes* b, uint16_t tag, uint16_t format, uint32_t count, uint32_t value,
           bool short_value) {
  Put16(b, tag);
  Put16(b, format);
  Put32(b, count);
  if (short_value) {
    Put16(b, static_cast<uint16_t>(value));
    Put16(b, 0);
  } else {
    Put32(b, value);
  }
}

// A camera's EXIF by hand, big-endian ("MM"): IFD0 Orientation and the EXIF IFD pointer; EXIF
// IFD FocalLength (RATIONAL) and FocalLengthIn35mmFilm. `orientation_format` 3 is SHORT (right);
// 4 (LONG) is the wrong type (libexif's loader turns it into a SHORT).
Bytes CameraExif(uint16_t orientation, uint16_t orientation_format, uint16_t focal_35mm) {
  Bytes b = {'E', 'x', 'i', 'f', 0, 0, 'M', 'M', 0, 42};
  Put32(&b, 8);  // IFD0 at 8 (offsets count from the TIFF header)
  // IFD0: 2 entries (2 + 2 * 12 + 4 = 30 bytes), so the EXIF IFD is at 8 + 30 = 38.
  Put16(&b, 2);
  Entry(&b, 0x0112, orientation_format, 1, orientation, orientation_format == 3);
  Entry(&b, 0x8769, 4, 1, 38, false);
  Put32(&b, 0);  // no IFD1
  // EXIF IFD: 2 entries (30 bytes), the rational after it at 38 + 30 = 68.
  Put16(&b, 2);
  Entry(&b, 0x920A, 5, 1, 68, false);
  Entry(&b, 0xA405, 3, 1, focal_35mm, true);
  Put32(&b, 0);
  Put32(&b, 45);  // FocalLength 4.5 mm
  Put32(&b, 10);
  return b;
}

void JpegSeeds(const std::string& dir) {
  const Bytes rgb = Jpeg(16, 16, 3, false);
  Save(dir, "rgb.jpg", rgb);
  Save(dir, "gray.jpg", Jpeg(9, 17, 1, false));
  Save(dir, "progressive.jpg", Jpeg(20, 12, 3, true));
  Save(dir, "cmyk.jpg", Jpeg(8, 8, 4, false));
  // With EXIF, as the file sensor reads it from the first frame of a burst.
  Save(dir, "exif_firmware.jpg", WithSegments(rgb, {App1(FirmwareExif(28, 6, 16, 16))}));
  Save(dir, "exif_firmware_no_focal.jpg", WithSegments(rgb, {App1(FirmwareExif(0, 3, 16, 16))}));
  Save(dir, "exif_camera_be.jpg", WithSegments(rgb, {App1(CameraExif(8, 3, 24))}));
  Save(dir, "exif_bad_types.jpg", WithSegments(rgb, {App1(CameraExif(6, 4, 5))}));
}

// fuzz_xmp's inputs start with a mode byte: 0 the whole file, 1 a main XMP packet, 2 a main
// packet, NUL, an extended packet.
Bytes Mode(uint8_t mode, const std::string& text) {
  Bytes out = {mode};
  out.insert(out.end(), text.begin(), text.end());
  return out;
}

std::string PacketText(const lb::JpegSegment& seg) {
  const size_t skip = sizeof(lb::kXmpSignature);
  return seg.payload.size() < skip ? std::string()
                                   : std::string(seg.payload.begin() + skip, seg.payload.end());
}

// fuzz_dd's: Dynamic Depth beside GDepth, the whole file (mode 0), and the main packet, NUL, the
// items that follow the primary (mode 1); with a confidence map in the 8-bit one.
void DdSeeds(const std::string& dir, const std::string& suffix, const Bytes& picture,
             const lb::JpegSegment& exif, lb::RefocusableXmp* xmp) {
  lb::DynamicDepthExtras extras;
  if (suffix == "8") xmp->depth.confidence = xmp->depth.data;  // 8-bit grey, the depth's size
  std::vector<lb::JpegSegment> segments;
  Bytes items;
  const auto append = [&items](const uint8_t* data, size_t size) {
    items.insert(items.end(), data, data + size);
    return lb::Status::Ok();
  };
  if (!lb::SetDynamicDepth(extras, xmp).ok() || !lb::BuildXmpSegments(*xmp, &segments).ok() ||
      !lb::WriteDynamicDepthItems(*xmp, extras, append).ok()) {
    ++failures;
    return;
  }
  segments.insert(segments.begin(), exif);
  Bytes file = {0};
  const Bytes jpeg = WithSegments(picture, segments);
  file.insert(file.end(), jpeg.begin(), jpeg.end());
  file.insert(file.end(), items.begin(), items.end());
  Save(dir, "file_dd" + suffix + ".bin", file);
  Bytes device =
      Mode(1, std::string("<x:xmpmeta xmlns:x=\"adobe:ns:meta/\"><rdf:RDF xmlns:rdf=\"") +
                  "http://www.w3.org/1999/02/22-rdf-syntax-ns#\">" + xmp->extra_description +
                  "</rdf:RDF></x:xmpmeta>");
  device.push_back(0);
  device.insert(device.end(), items.begin(), items.end());
  Save(dir, "device_dd" + suffix + ".bin", device);
}

void XmpSeeds(const std::string& dir, const std::string& dd_dir) {
  const Bytes picture = Jpeg(24, 16, 3, false);
  for (int bits : {8, 16}) {
    const int32_t w = 12, h = 8;
    std::vector<uint16_t> disp(static_cast<size_t>(w) * h);
    for (int32_t i = 0; i < w * h; ++i)
      disp[i] = static_cast<uint16_t>(256 + (i % w + i / w) * 200);
    lb::RefocusableXmp xmp;
    const lb::DisparityRange range = {0, 16 << 8};
    if (!lb::SetDepthFromDisparity(lb::MakeView<const uint16_t>(disp.data(), w, h), range, bits,
                                   &xmp)
             .ok()) {
      ++failures;
      continue;
    }
    xmp.has_focus = bits == 16;
    xmp.focus = {0.0125, 0.25, 0.375, 0.625};
    if (bits == 16) xmp.image = picture;  // GImage: the all-in-focus original
    std::vector<lb::JpegSegment> segments;
    if (!lb::BuildXmpSegments(xmp, &segments).ok() || segments.empty()) {
      ++failures;
      continue;
    }
    std::vector<lb::JpegSegment> all = {App1(FirmwareExif(28, 1, 24, 16))};
    all.insert(all.end(), segments.begin(), segments.end());
    const Bytes file = WithSegments(picture, all);
    lb::RefocusableImage check;
    const lb::Status read = lb::ReadRefocusable(file.data(), file.size(), "seed.jpg", &check);
    if (!read.ok()) {
      fprintf(stderr, "make_fuzz_seeds: the refocusable seed does not read back: %s\n",
              read.message());
      ++failures;
    }
    const std::string suffix = bits == 16 ? "16" : "8";
    Bytes whole = {0};
    whole.insert(whole.end(), file.begin(), file.end());
    Save(dir, "file_depth" + suffix + ".bin", whole);
    const std::string main = PacketText(segments[0]);
    Save(dir, "packet_depth" + suffix + ".bin", Mode(1, main));
    // The same fields as extended XMP behind an empty main packet.
    Save(dir, "extended_depth" + suffix + ".bin",
         Mode(2, std::string("<x:xmpmeta xmlns:x=\"adobe:ns:meta/\"/>") + '\0' + main));
    DdSeeds(dd_dir, suffix, picture, all[0], &xmp);
  }
}

// refocusd.conf: the packaged file and variants (one per kind of line and error).
std::string ReadText(const char* path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) {
    fprintf(stderr, "make_fuzz_seeds: cannot read %s\n", path);
    ++failures;
  }
  return text.str();
}

Bytes Text(const std::string& s) { return Bytes(s.begin(), s.end()); }

void ConfSeeds(const std::string& dir) {
  Save(dir, "refocusd.conf", Text(ReadText(LB_PACKAGED_CONF)));
  Save(dir, "empty.conf", Bytes());
  Save(dir, "synthetic_native.conf",
       Text("# test rig\nbackend = synthetic\nresolution = native\nseed = 7\n"));
  Save(dir, "every_key.conf",
       Text("backend = libcamera\ndevice = /base/soc/i2c0mux/i2c@1/imx219@10\n"
            "resolution = 640x480\nframes = 16\nfps = 30\nframe_timeout_ms = 100\n"
            "seed = 2147483647\nbutton = /dev/input/by-path/platform-gpio-keys-event\n"
            "debounce_ms = 500\nbusy_press = refuse\ncapture_retries = 5\n"
            "output_dir = /media/card/DCIM\nquality = 1\nmake = Make # not a comment\n"
            "model = M\nlabels = 256\ngeometry = rectified\nfocal_35mm = 28\n"
            "working_size = 320x240\nfocus = region 10,20,30,40\nf_number = 1.4\n"
            "aperture = 6-blade\naperture_rotation = -15.5\nblade_curvature = 0.25\n"
            "highlight_threshold = 200\nhighlight_gain = 4\nmax_blur_radius = 128\n"
            "log_level = debug\n"));
  Save(dir, "crlf_tabs.conf",
       Text("\tbackend\t=\tv4l2\r\nfocus = point 100,100\r\n  # indented comment\r\n"
            "aperture = disc\r\nlog_level=warning"));
  Save(dir, "unknown_key.conf", Text("frames = 5\nburst = 5\n"));
  Save(dir, "twice.conf", Text("quality = 90\nquality = 91\n"));
  Save(dir, "no_equals.conf", Text("labels 32\n"));
  Save(dir, "no_value.conf", Text("device =\n"));
  Save(dir, "bad_numbers.conf", Text("fps = 1e3\nf_number = nan\n"));
  Save(dir, "focus_xy.conf", Text("focus = 100,120\nresolution = 640x480\n"));
  Save(dir, "focus_xywh_native.conf", Text("resolution = native\nfocus = 1,2,65535,3\n"));
  Save(dir, "focus_outside.conf", Text("resolution = 320x240\nfocus = region 320,10,40,40\n"));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: make_fuzz_seeds OUT_DIR\n");
    return 2;
  }
  const std::string out = argv[1];
  mkdir(out.c_str(), 0755);
  Pnm(out + "/pnm");
  PngSeeds(out + "/png");
  JpegSeeds(out + "/jpeg");
  XmpSeeds(out + "/xmp", out + "/dd");
  ConfSeeds(out + "/conf");
  return failures == 0 ? 0 : 1;
}
