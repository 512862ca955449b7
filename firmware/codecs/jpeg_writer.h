// JpegWriter: encodes the render stage's YCbCr 4:2:0 strips straight into a JPEG with
// libjpeg-turbo's raw-data path (no colour conversion, no full-resolution frame), with an EXIF
// APP1 segment (exif.h) and optional extra APP segments (the refocusable XMP).
// libjpeg errors and write failures come back as a Status; nothing calls exit().
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "algo/core/image.h"
#include "algo/core/status.h"
#include "firmware/codecs/exif.h"
#include "firmware/storage/atomic_file.h"

namespace lb {

// One APPn segment: `marker` is 0xE0 + n, `payload` the bytes after the length field
// (at most kMaxPayload).
struct JpegSegment {
  static constexpr size_t kMaxPayload = 65533;
  uint8_t marker = 0xE1;
  std::vector<uint8_t> payload;
};

// The EXIF tags (written when any is set; otherwise a JFIF header is) and the other segments.
struct JpegMetadata : ExifTags {
  std::vector<JpegSegment> extra_segments;  // written after the EXIF segment, in order
  // More segments follow extra_segments, given later by JpegWriter::InsertSegments: the
  // refocusable XMP is built on another thread while the first strips encode. The writer holds
  // its output in memory until then (what the strips encoded so far compress to), so the file's
  // bytes are the same as with every segment given at Begin.
  bool segments_later = false;
};

class JpegWriter {
 public:
  static constexpr int32_t kStripRows = 16;  // luma rows a strip (one iMCU row at 4:2:0)

  JpegWriter();
  ~JpegWriter();
  JpegWriter(const JpegWriter&) = delete;
  JpegWriter& operator=(const JpegWriter&) = delete;

  // Starts an image written through `out` (borrowed until Finish; the caller commits it after
  // Finish). On any failure the writer aborts `out`, so neither name is left on disk.
  Status Begin(AtomicFile* out, int32_t width, int32_t height, int quality,
               const JpegMetadata& meta);
  // The same into memory (`out` is cleared first).
  Status BeginMemory(std::vector<uint8_t>* out, int32_t width, int32_t height, int quality,
                     const JpegMetadata& meta);

  // Y, Cb, Cr planes of the next `rows` luma rows: kStripRows for every strip but the last, which
  // may be shorter; chroma planes hold (rows + 1) / 2 rows of (width + 1) / 2 samples.
  Status WriteStrip(const ConstPlanarU8& strip, int32_t rows);

  // The segments announced by JpegMetadata::segments_later, at any point after Begin and
  // before Finish: they go where Begin's segments end, and the held output follows them.
  Status InsertSegments(const std::vector<JpegSegment>& segments);
  // Whether the writer still waits for InsertSegments.
  bool holding() const;

  // Writes the end of the image and flushes it; every row must have been written, and the
  // segments announced at Begin inserted.
  Status Finish();

  bool active() const { return active_; }

  struct State;  // libjpeg structures, kept out of this header

 private:
  Status Start(int32_t width, int32_t height, int quality, const JpegMetadata& meta);
  Status Failed(Status status);  // releases libjpeg, aborts the file, returns `status`
  Status LibjpegFailure();       // the Status for an error libjpeg or the sink reported

  std::unique_ptr<State> state_;
  bool active_ = false;
};

// Encodes a whole YCbCr 4:2:0 image in memory with a JFIF header (the all-in-focus original
// embedded in the refocusable JPEG). Allocates.
Status EncodeYCbCr420(const ConstPlanarU8& image, int quality, std::vector<uint8_t>* jpeg);

}  // namespace lb
