// What `refocus run` and `rerender` tell the person waiting: one line on stderr, redrawn in place
// ("render  45%"), when stderr is a terminal; nothing otherwise, so logs and pipes stay clean.
#pragma once

#include <cstdint>
#include <cstdio>

namespace lb {

class Progress {
 public:
  virtual ~Progress() = default;
  // `stage` ("capture", "depth", "render", "write") is `percent` (0..100) done.
  virtual void Update(const char* stage, int32_t percent) = 0;
  // The work is over (done or failed): the line is cleared for what is printed next.
  virtual void Clear() = 0;
};

class TerminalProgress final : public Progress {
 public:
  // Draws on `out` only when it is a terminal.
  explicit TerminalProgress(FILE* out);
  ~TerminalProgress() override { Clear(); }
  void Update(const char* stage, int32_t percent) override;
  void Clear() override;
  bool enabled() const { return enabled_; }

 private:
  FILE* out_;
  bool enabled_ = false;
  bool drawn_ = false;
  const char* stage_ = nullptr;
  int32_t percent_ = -1;
};

}  // namespace lb
