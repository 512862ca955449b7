#include "firmware/app/rerender.h"

#include <vector>

#include "firmware/app/focus.h"
#include "firmware/app/refocusable.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/platform/arena_block.h"
#include "firmware/platform/worker_pool.h"
#include "firmware/storage/atomic_file.h"
#include "firmware/storage/input_file.h"

namespace lb {
namespace {

// A refocusable JPEG is read whole; larger than any the product writes at 8192x8192.
constexpr size_t kMaxFileBytes = size_t{512} << 20;

}  // namespace

Status Rerenderer::Load(const char* path) {
  std::vector<uint8_t> bytes;
  LB_RETURN_IF_ERROR(ReadInputFile(path, kMaxFileBytes, &bytes));
  return photo_.Decode(bytes.data(), bytes.size(), path);
}

void Rerenderer::StartFromFile(RenderParams* params, bool keep_focus, bool keep_f_number) const {
  if (!photo_.has_file_focus()) return;
  if (!keep_focus) params->focus = photo_.file_focus();
  if (!keep_f_number) params->f_number = photo_.file_f_number();
}

RerenderSource SourceOf(const RefocusablePhoto& photo) {
  RerenderSource source;
  source.disp_q8 = photo.disparity_q8();
  source.confidence = photo.confidence();
  source.range = photo.range();
  source.original_jpeg = &photo.original_jpeg();
  source.orientation = photo.orientation();
  source.width = photo.width();
  source.height = photo.height();
  return source;
}

Status Rerenderer::Render(const RerenderOptions& options, const char* out_path,
                          StripObserver* observer) {
  if (photo_.width() == 0) {
    return Status(Code::kInvalidArgument, "rerender before a file was loaded");
  }
  const RenderConfig rc =
      photo_.RenderConfigFor(options.max_blur_radius, WorkerPool::CountFor(options.threads));
  LB_RETURN_IF_ERROR(RenderStage::Validate(rc));
  ArenaBlock block;
  LB_RETURN_IF_ERROR(block.Reserve(RenderStage::RequiredBytes(rc), "to render"));
  Arena arena = block.arena();
  RenderStage render;
  WorkerPool pool;
  LB_RETURN_IF_ERROR(pool.Start(rc.workers));
  LB_RETURN_IF_ERROR(photo_.BeginRender(rc, arena, &pool, options.render, &render));
  return WriteRerendered(&render, options.render, SourceOf(photo_), options.quality,
                         "refocus rerender", observer, options.progress, out_path);
}

Status WriteRerendered(RenderStage* render, const RenderParams& params,
                       const RerenderSource& source, int quality, const char* software,
                       StripObserver* observer, Progress* progress, const char* out_path,
                       AtomicFile::Replace replace) {
  AtomicFile file;
  LB_RETURN_IF_ERROR(file.Open(out_path));
  JpegMetadata meta;
  meta.make = "LensBlur";
  meta.model = "Re-rendered";
  meta.software = software;
  meta.f_number = params.f_number;
  meta.orientation = source.orientation;
  DynamicDepthTrailer dd;
  LB_RETURN_IF_ERROR(BuildRefocusableSegments(source.disp_q8, source.range, *source.original_jpeg,
                                              FocusOf(*render, params, source.width, source.height),
                                              source.width, &meta.extra_segments, &dd,
                                              source.confidence));
  JpegWriter writer;
  LB_RETURN_IF_ERROR(writer.Begin(&file, source.width, source.height, quality, meta));
  LB_RETURN_IF_ERROR(WriteStrips(render, observer, &writer, progress));
  LB_RETURN_IF_ERROR(WriteDynamicDepthTrailer(dd, &file));
  return file.Commit(replace);
}

}  // namespace lb
