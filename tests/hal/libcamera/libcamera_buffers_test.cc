// Where the libcamera sensor finds a frame's planes in a FrameBuffer, and what it does with each
// completed frame's status and sequence number; no camera needed.
#include <gtest/gtest.h>
#include <libcamera/framebuffer.h>

#include <cstddef>
#include <cstdint>

#include "hal/libcamera/buffer_layout.h"
#include "hal/libcamera/frame_check.h"
#include "hal/libcamera/libcamera_version.h"

namespace lb {
namespace {

constexpr int32_t kW = 64, kH = 48;
constexpr ptrdiff_t kStride = 128;  // padded rows, as a camera's buffers have
constexpr size_t kLuma = kStride * kH;

TEST(BufferLayoutTest, ThreeI420PlanesInOneDmabuf) {
  // How libcamera describes a Raspberry Pi YUV420 buffer: three planes on one fd.
  const size_t chroma = kLuma / 4;
  const BufferPlane planes[3] = {{7, 0, kLuma}, {7, kLuma, chroma}, {7, kLuma + chroma, chroma}};
  PlaneLayout l;
  ASSERT_TRUE(LayOutPlanes(PixelFormat::kI420, kW, kH, kStride, planes, 3, &l).ok());
  EXPECT_EQ(l.count, 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(l.source[k], k);
    EXPECT_EQ(l.offset[k], planes[k].offset);
    EXPECT_EQ(l.stride[k], k == 0 ? kStride : kStride / 2);
  }
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(MappedExtent(planes, 3, i), kLuma + 2 * chroma);
}

TEST(BufferLayoutTest, OnePlaneBuffersHoldTheChromaAfterTheLuma) {
  const BufferPlane i420[1] = {{3, 0, kLuma * 3 / 2}};
  PlaneLayout l;
  ASSERT_TRUE(LayOutPlanes(PixelFormat::kI420, kW, kH, kStride, i420, 1, &l).ok());
  EXPECT_EQ(l.offset[1], kLuma);
  EXPECT_EQ(l.offset[2], kLuma + kLuma / 4);
  EXPECT_EQ(l.source[2], 0);
  EXPECT_EQ(l.stride[2], kStride / 2);
  const BufferPlane nv12[1] = {{3, 4096, kLuma * 3 / 2}};  // at an offset in its dmabuf
  ASSERT_TRUE(LayOutPlanes(PixelFormat::kNv12, kW, kH, kStride, nv12, 1, &l).ok());
  EXPECT_EQ(l.count, 2);
  EXPECT_EQ(l.offset[0], 4096u);
  EXPECT_EQ(l.offset[1], 4096 + kLuma);
  EXPECT_EQ(l.stride[1], kStride);
  EXPECT_EQ(MappedExtent(nv12, 1, 0), 4096 + kLuma * 3 / 2);
}

TEST(BufferLayoutTest, PlanesInTheirOwnDmabufs) {
  const BufferPlane planes[2] = {{4, 0, kLuma}, {5, 0, kLuma / 2}};
  PlaneLayout l;
  ASSERT_TRUE(LayOutPlanes(PixelFormat::kNv12, kW, kH, kStride, planes, 2, &l).ok());
  EXPECT_EQ(l.source[1], 1);
  EXPECT_EQ(l.offset[1], 0u);
  EXPECT_EQ(MappedExtent(planes, 2, 0), kLuma);
  EXPECT_EQ(MappedExtent(planes, 2, 1), kLuma / 2);
  const BufferPlane xrgb[1] = {{6, 0, kStride * 2 * kH}};
  ASSERT_TRUE(LayOutPlanes(PixelFormat::kBgrx8, kW, kH, kStride * 2, xrgb, 1, &l).ok());
  EXPECT_EQ(l.count, 1);
  EXPECT_EQ(l.stride[0], kStride * 2);
}

TEST(BufferLayoutTest, RefusesWhatItCannotRead) {
  const BufferPlane four[4] = {{1, 0, kLuma}, {1, 0, kLuma}, {1, 0, kLuma}, {1, 0, kLuma}};
  PlaneLayout l;
  EXPECT_EQ(LayOutPlanes(PixelFormat::kI420, kW, kH, kStride, four, 4, &l).code(),
            Code::kUnsupported);
  EXPECT_EQ(LayOutPlanes(PixelFormat::kI420, kW, kH, kStride, four, 0, &l).code(),
            Code::kUnsupported);
  const BufferPlane short_chroma[1] = {{1, 0, kLuma * 3 / 2 - 1}};
  EXPECT_EQ(LayOutPlanes(PixelFormat::kI420, kW, kH, kStride, short_chroma, 1, &l).code(),
            Code::kCorruptData);
  const BufferPlane packed[1] = {{1, 0, kLuma}};
  EXPECT_EQ(LayOutPlanes(PixelFormat::kBgrx8, kW, kH, kStride, packed, 1, &l).code(),
            Code::kCorruptData);  // rows of 64 x 4 bytes cannot be 128 apart
}

libcamera::FrameMetadata Frame(libcamera::FrameMetadata::Status status, unsigned sequence) {
  libcamera::FrameMetadata md{};
  md.status = status;
  md.sequence = sequence;
  return md;
}

constexpr auto kSuccess = libcamera::FrameMetadata::FrameSuccess;

TEST(FrameCheckTest, FramesInSequenceAreDeliveredAndAGapAbandons) {
  FrameSequence sequence;
  uint32_t missing = 9;
  EXPECT_EQ(CheckFrame(Frame(kSuccess, 10), 0, &sequence, &missing), FrameVerdict::kDeliver);
  EXPECT_EQ(missing, 0u);
  EXPECT_EQ(CheckFrame(Frame(kSuccess, 11), 1, &sequence, &missing), FrameVerdict::kDeliver);
  EXPECT_EQ(CheckFrame(Frame(kSuccess, 13), 2, &sequence, &missing), FrameVerdict::kDropped);
  EXPECT_EQ(missing, 1u);
  EXPECT_EQ(CheckFrame(Frame(libcamera::FrameMetadata::FrameError, 14), 2, &sequence, &missing),
            FrameVerdict::kFailed);
  EXPECT_EQ(CheckFrame(Frame(libcamera::FrameMetadata::FrameCancelled, 15), 2, &sequence, &missing),
            FrameVerdict::kFailed);
  EXPECT_FALSE(IsStartupFrame(Frame(kSuccess, 16)));
}

#if LB_LIBCAMERA_AT_LEAST(0, 5, 2)
// Startup frames neither fail the burst nor start the sequence check: the frames metering and
// requeueing used up after them are no gap.
TEST(FrameCheckTest, StartupFramesAreSkippedAndTheSequenceStartsAfterThem) {
  constexpr auto kStartup = libcamera::FrameMetadata::FrameStartup;
  FrameSequence sequence;
  uint32_t missing = 0;
  for (unsigned s = 0; s < 3; ++s) {
    EXPECT_TRUE(IsStartupFrame(Frame(kStartup, s)));
    EXPECT_EQ(CheckFrame(Frame(kStartup, s), 0, &sequence, &missing), FrameVerdict::kSkip);
  }
  EXPECT_EQ(CheckFrame(Frame(kSuccess, 6), 0, &sequence, &missing), FrameVerdict::kDeliver);
  EXPECT_EQ(CheckFrame(Frame(kSuccess, 7), 1, &sequence, &missing), FrameVerdict::kDeliver);
  // Once the burst has begun a startup frame is skipped still, but counted in the sequence:
  // the next frame follows it without a gap, and a gap before it is a drop.
  EXPECT_EQ(CheckFrame(Frame(kStartup, 8), 2, &sequence, &missing), FrameVerdict::kSkip);
  EXPECT_EQ(CheckFrame(Frame(kSuccess, 9), 2, &sequence, &missing), FrameVerdict::kDeliver);
  EXPECT_EQ(CheckFrame(Frame(kStartup, 11), 3, &sequence, &missing), FrameVerdict::kDropped);
  EXPECT_EQ(missing, 1u);
}
#endif

}  // namespace
}  // namespace lb
