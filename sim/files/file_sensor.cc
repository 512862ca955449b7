#include "sim/files/file_sensor.h"

#include <dirent.h>
#include <sys/stat.h>

#include <strings.h>
#include <algorithm>
#include <cerrno>
#include <cstring>

namespace lb {
namespace {

constexpr int64_t kFrameIntervalNs = 33'000'000;

bool HasImageExtension(const char* file) {
  static const char* const kExtensions[] = {".ppm", ".pgm", ".pnm", ".png", ".jpg", ".jpeg"};
  const char* dot = strrchr(file, '.');
  if (dot == nullptr) return false;
  for (const char* ext : kExtensions) {
    if (strcasecmp(dot, ext) == 0) return true;
  }
  return false;
}

// Forwards one file's frame, stamping the burst timing and checking the file still matches
// what Configure saw (it may have been replaced in between).
class StampingSink final : public FrameSink {
 public:
  StampingSink(FrameSink& next, const SensorMode& mode, const char* path)
      : next_(next), mode_(mode), path_(path) {}

  Status BeginFrame(const FrameInfo& info) override {
    if (info.width != mode_.width || info.height != mode_.height || info.format != mode_.format) {
      return Status(Code::kCorruptData, "%s changed since Configure: now %dx%d %s, was %dx%d %s",
                    path_, info.width, info.height, PixelFormatName(info.format), mode_.width,
                    mode_.height, PixelFormatName(mode_.format));
    }
    FrameInfo stamped = info;
    stamped.timestamp_ns = kFrameIntervalNs * info.index;
    stamped.sequence = static_cast<uint32_t>(info.index);
    return next_.BeginFrame(stamped);
  }
  Status Rows(const FrameRows& rows) override { return next_.Rows(rows); }
  Status EndFrame() override { return next_.EndFrame(); }

 private:
  FrameSink& next_;
  const SensorMode& mode_;
  const char* path_;
};

}  // namespace

Status FileSensor::FromDirectory(const char* dir, const ImageDecoder& decoder,
                                 std::unique_ptr<FileSensor>* out) {
  if (dir == nullptr || dir[0] == '\0') {
    return Status(Code::kInvalidArgument, "file sensor: no directory given");
  }
  out->reset(new FileSensor(decoder));
  (*out)->dir_ = dir;
  return Status::Ok();
}

Status FileSensor::FromFiles(const std::vector<std::string>& paths, const ImageDecoder& decoder,
                             std::unique_ptr<FileSensor>* out) {
  if (paths.empty()) return Status(Code::kInvalidArgument, "file sensor: no image files given");
  out->reset(new FileSensor(decoder));
  (*out)->paths_ = paths;
  return Status::Ok();
}

void FileSensor::LimitSize(int32_t min_side, int32_t max_width, int32_t max_height) {
  min_side_ = min_side;
  max_width_ = max_width;
  max_height_ = max_height;
}

Status FileSensor::ListDirectory() {
  const char* dir = dir_.c_str();
  struct stat st = {};
  if (stat(dir, &st) != 0) {
    if (errno == ENOENT) return Status(Code::kNotFound, "%s: no such file or directory", dir);
    return Status(Code::kIoError, "%s: %s", dir, strerror(errno));
  }
  if (!S_ISDIR(st.st_mode)) return Status(Code::kInvalidArgument, "%s: not a directory", dir);
  DIR* listing = opendir(dir);
  if (listing == nullptr)
    return Status(Code::kIoError, "%s: cannot list: %s", dir, strerror(errno));
  std::vector<std::string> names;
  while (const dirent* entry = readdir(listing)) {
    // Hidden files are editor and OS litter (._IMG_1.JPG), never frames.
    if (entry->d_name[0] == '.' || !HasImageExtension(entry->d_name)) continue;
    names.emplace_back(entry->d_name);
  }
  closedir(listing);
  if (names.empty()) {
    return Status(Code::kNotFound, "%s: no image files (.ppm .pgm .png .jpg)", dir);
  }
  std::sort(names.begin(), names.end());
  const bool slash = dir_.back() == '/';
  paths_.clear();
  for (const std::string& n : names) paths_.push_back(slash ? dir_ + n : dir_ + "/" + n);
  return Status::Ok();
}

Status FileSensor::CheckLimits(const ImageHeader& first) const {
  if (max_width_ == 0) return Status::Ok();
  if (first.width < min_side_ || first.height < min_side_ || first.width > max_width_ ||
      first.height > max_height_) {
    return Status(Code::kUnsupported, "%s: %dx%d frames: refocus takes %dx%d .. %dx%d",
                  paths_[0].c_str(), first.width, first.height, min_side_, min_side_, max_width_,
                  max_height_);
  }
  return Status::Ok();
}

Status FileSensor::Configure(const SensorConfig& config, SensorMode* mode) {
  configured_ = false;
  if (!dir_.empty()) LB_RETURN_IF_ERROR(ListDirectory());
  ImageHeader first;
  for (size_t i = 0; i < paths_.size(); ++i) {
    ImageHeader info;
    LB_RETURN_IF_ERROR(decoder_.Probe(paths_[i].c_str(), &info));
    if (i == 0) {
      first = info;
      continue;
    }
    if (info.width != first.width || info.height != first.height) {
      return Status(Code::kInvalidArgument, "%s is %dx%d but %s is %dx%d", paths_[i].c_str(),
                    info.width, info.height, paths_[0].c_str(), first.width, first.height);
    }
    if (info.format != first.format) {
      return Status(Code::kInvalidArgument,
                    "%s is %s but %s is %s (all frames must have one pixel format)",
                    paths_[i].c_str(), PixelFormatName(info.format), paths_[0].c_str(),
                    PixelFormatName(first.format));
    }
  }
  LB_RETURN_IF_ERROR(CheckLimits(first));
  if ((config.width != 0 && config.width != first.width) ||
      (config.height != 0 && config.height != first.height)) {
    return Status(Code::kUnsupported, "%s: frames are %dx%d, cannot deliver the requested %dx%d",
                  paths_[0].c_str(), first.width, first.height, config.width, config.height);
  }
  mode_.width = first.width;
  mode_.height = first.height;
  mode_.format = first.format;
  mode_.frames = static_cast<int32_t>(paths_.size());
  const CameraTags tags = decoder_.Tags(paths_[0].c_str(), first.width, first.height);
  mode_.focal_px = tags.focal_px;
  mode_.orientation = tags.orientation;
  *mode = mode_;
  configured_ = true;
  return Status::Ok();
}

Status FileSensor::CaptureBurst(FrameSink& sink) {
  if (!configured_) return Status(Code::kInvalidArgument, "file sensor: not configured");
  for (size_t i = 0; i < paths_.size(); ++i) {
    StampingSink stamping(sink, mode_, paths_[i].c_str());
    LB_RETURN_IF_ERROR(decoder_.Stream(paths_[i].c_str(), static_cast<int32_t>(i), stamping));
  }
  return Status::Ok();
}

}  // namespace lb
