// Names the photos in the output folder IMG_YYYYMMDD_HHMMSS_NNNN.jpg (local time of the press).
// NNNN counts photos 0001..9999 and then starts again at 0001; it continues after the highest
// number already in the folder, so names stay unique within one second and across restarts, and
// a name that exists is never chosen (so never overwritten by this daemon).
#pragma once

#include <time.h>

#include <cstddef>
#include <cstdint>

#include "algo/core/status.h"

namespace lb {

class PhotoNamer {
 public:
  static constexpr int32_t kMaxCounter = 9999;
  static constexpr size_t kMaxDir = 960;

  // Scans `dir` (copied): removes the hidden temporaries a killed process can leave behind
  // (".IMG_....jpg.XXXXXX") and continues the counter. A folder that does not exist yet (a card
  // not mounted) is not an error: *removed is 0 and the count starts at 0001.
  Status Scan(const char* dir, int* removed);

  // The first free name from the counter on, for the time `t`. Does not advance the counter.
  Status Next(const tm& t, char* path, size_t size);
  // The photo named by the last Next was saved: the next one gets the following number.
  void Used() { next_ = chosen_ % kMaxCounter + 1; }

  int32_t next_counter() const { return next_; }

  // "IMG_YYYYMMDD_HHMMSS_NNNN.jpg" -> true and NNNN.
  static bool IsPhotoName(const char* name, int32_t* counter);
  // "." + a photo name + ".XXXXXX" (AtomicFile's temporary for it).
  static bool IsTemporaryName(const char* name);

 private:
  char dir_[kMaxDir] = ".";
  int32_t next_ = 1;
  int32_t chosen_ = 1;
};

}  // namespace lb
