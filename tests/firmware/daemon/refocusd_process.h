// The real refocusd program as the host tests run it: a child process with the synthetic sensor,
// a FIFO standing in for the shutter button (input_event records, as evdev delivers them) and
// its log read back line by line from a pipe.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace lb::test {

class RefocusdProcess {
 public:
  // `dir` holds the configuration, the button FIFO and (unless `extra` sets output_dir) the
  // photo folder `dir`/out. `extra` is appended to the configuration; `web = 127.0.0.1:0` in it
  // becomes a port free at the time (refocusd itself refuses port 0).
  RefocusdProcess(const std::string& dir, const std::string& extra);
  ~RefocusdProcess();  // kills the child if it still runs

  bool Start();
  // Reads the log until a line containing `part` arrives; false after `timeout_ms` or when the
  // process ended.
  bool WaitForLine(const std::string& part, int timeout_ms);
  int Count(const std::string& part) const;
  const std::string& log() const { return log_; }

  void Press();
  void HalfPress();
  void Signal(int sig);
  // Exit status (0..255), 128 + signal when killed, -1 on timeout.
  int Wait(int timeout_ms);

  pid_t pid() const { return pid_; }
  std::string out_dir() const { return dir_ + "/out"; }
  // From /proc: resident memory in KiB, open descriptors, threads.
  long ResidentKib() const;
  int OpenFds() const;
  int Threads() const;

 private:
  void Key(int code, int value);
  void ReadAvailable(int timeout_ms);

  std::string dir_;
  pid_t pid_ = -1;
  int log_fd_ = -1;
  int button_fd_ = -1;
  double event_time_ = 1000.0;  // kernel-style event times, a second apart per press
  std::string log_, partial_;
};

std::string RefocusdBinary();
// Runs refocusd with `args`; returns the exit status and fills stdout + stderr.
int RunRefocusd(const std::vector<std::string>& args, std::string* output);
// IMG_*.jpg in `dir`, sorted; temporaries (".IMG_...") apart.
void ListPhotos(const std::string& dir, std::vector<std::string>* photos,
                std::vector<std::string>* temporaries);

}  // namespace lb::test
