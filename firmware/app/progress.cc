#include "firmware/app/progress.h"

#include <unistd.h>

#include <cstring>

namespace lb {

TerminalProgress::TerminalProgress(FILE* out) : out_(out) {
  enabled_ = out != nullptr && isatty(fileno(out)) == 1;
}

void TerminalProgress::Update(const char* stage, int32_t percent) {
  if (!enabled_) return;
  percent = percent < 0 ? 0 : (percent > 100 ? 100 : percent);
  // Redrawn only when it changes: a terminal over a serial line is slow.
  if (drawn_ && percent == percent_ && stage_ != nullptr && strcmp(stage, stage_) == 0) return;
  stage_ = stage;
  percent_ = percent;
  // \r to the line's start, then erase to its end (ECMA-48 EL), so a shorter line leaves no tail.
  fprintf(out_, "\r%s %3d%%\033[K", stage, percent);
  fflush(out_);
  drawn_ = true;
}

void TerminalProgress::Clear() {
  if (!drawn_) return;
  fputs("\r\033[K", out_);
  fflush(out_);
  drawn_ = false;
}

}  // namespace lb
