#include "tests/firmware/daemon/refocusd_process.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <linux/input.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

namespace lb::test {
namespace {

int64_t NowMs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000 + ts.tv_nsec / 1000000;
}

// A loopback port free now. refocusd refuses `web = ...:0` (a user could not find the page),
// so a test that wants any port gets one chosen here; another program taking it before
// refocusd binds is possible but unlikely, and shows as "cannot listen".
int FreeLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return 0;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof(a);
  int port = 0;
  if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0) {
    port = ntohs(a.sin_port);
  }
  close(fd);
  return port;
}

// `web = 127.0.0.1:0` in a test's settings: a free port instead.
std::string WithFreePort(std::string extra) {
  const std::string any = "web = 127.0.0.1:0\n";
  const size_t at = ("\n" + extra).find("\n" + any);
  if (at == std::string::npos) return extra;
  const int port = FreeLoopbackPort();
  if (port > 0) extra.replace(at, any.size(), "web = 127.0.0.1:" + std::to_string(port) + "\n");
  return extra;
}

}  // namespace

std::string RefocusdBinary() { return REFOCUSD_BIN; }

RefocusdProcess::RefocusdProcess(const std::string& dir, const std::string& extra_settings)
    : dir_(dir) {
  const std::string extra = WithFreePort(extra_settings);
  mkdir(out_dir().c_str(), 0755);
  mkfifo((dir_ + "/button").c_str(), 0600);
  // The base settings, each unless `extra` sets it (a key given twice is an error).
  const std::string base[][2] = {{"backend", "synthetic"},
                                 {"resolution", "160x120"},
                                 {"labels", "8"},
                                 {"button", dir_ + "/button"},
                                 {"output_dir", out_dir()}};
  std::string text;
  for (const auto& kv : base) {
    if (("\n" + extra).find("\n" + kv[0] + " =") == std::string::npos) {
      text += kv[0] + " = " + kv[1] + "\n";
    }
  }
  FILE* f = fopen((dir_ + "/refocusd.conf").c_str(), "w");
  if (f == nullptr) return;
  fputs((text + extra).c_str(), f);
  fclose(f);
}

RefocusdProcess::~RefocusdProcess() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  if (log_fd_ >= 0) close(log_fd_);
  if (button_fd_ >= 0) close(button_fd_);
}

bool RefocusdProcess::Start() {
  // Read-write, so opening does not wait for the reader, and writes never see a closed FIFO.
  if (button_fd_ < 0) button_fd_ = open((dir_ + "/button").c_str(), O_RDWR | O_CLOEXEC);
  int fds[2];
  if (button_fd_ < 0 || pipe2(fds, O_CLOEXEC) != 0) return false;
  const std::string bin = RefocusdBinary(), conf = dir_ + "/refocusd.conf";
  pid_ = fork();
  if (pid_ == 0) {
    dup2(fds[1], 2);
    execl(bin.c_str(), bin.c_str(), "--config", conf.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  if (log_fd_ >= 0) close(log_fd_);
  log_fd_ = fds[0];
  log_.clear();
  partial_.clear();
  return pid_ > 0;
}

void RefocusdProcess::ReadAvailable(int timeout_ms) {
  pollfd p = {log_fd_, POLLIN, 0};
  if (poll(&p, 1, timeout_ms) <= 0) return;
  char buf[4096];
  const ssize_t n = read(log_fd_, buf, sizeof(buf));
  if (n <= 0) {
    close(log_fd_);
    log_fd_ = -1;
    return;
  }
  partial_.append(buf, static_cast<size_t>(n));
  const size_t end = partial_.rfind('\n');
  if (end == std::string::npos) return;
  log_ += partial_.substr(0, end + 1);
  partial_.erase(0, end + 1);
}

bool RefocusdProcess::WaitForLine(const std::string& part, int timeout_ms) {
  const int64_t deadline = NowMs() + timeout_ms;
  for (;;) {
    if (log_.find(part) != std::string::npos) return true;
    const int64_t left = deadline - NowMs();
    if (left <= 0 || log_fd_ < 0) return false;
    ReadAvailable(static_cast<int>(std::min<int64_t>(left, 100)));
  }
}

int RefocusdProcess::Count(const std::string& part) const {
  int n = 0;
  for (size_t at = log_.find(part); at != std::string::npos; at = log_.find(part, at + 1)) ++n;
  return n;
}

void RefocusdProcess::Key(int code, int value) {
  input_event ev[2];
  memset(ev, 0, sizeof(ev));
  for (input_event& e : ev) {
    e.input_event_sec = static_cast<decltype(e.input_event_sec)>(event_time_);
    e.input_event_usec = static_cast<decltype(e.input_event_usec)>(
        (event_time_ - static_cast<double>(e.input_event_sec)) * 1e6);
  }
  ev[0].type = EV_KEY;
  ev[0].code = static_cast<uint16_t>(code);
  ev[0].value = value;
  ev[1].type = EV_SYN;
  ev[1].code = SYN_REPORT;
  if (write(button_fd_, ev, sizeof(ev)) != static_cast<ssize_t>(sizeof(ev))) perror("button fifo");
}

void RefocusdProcess::Press() {
  event_time_ += 1.0;
  Key(KEY_CAMERA, 1);
  event_time_ += 0.05;
  Key(KEY_CAMERA, 0);
}

void RefocusdProcess::HalfPress() {
  event_time_ += 1.0;
  Key(KEY_CAMERA_FOCUS, 1);
}

void RefocusdProcess::Signal(int sig) {
  if (pid_ > 0) kill(pid_, sig);
}

int RefocusdProcess::Wait(int timeout_ms) {
  if (pid_ <= 0) return -1;
  const int64_t deadline = NowMs() + timeout_ms;
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      pid_ = -1;
      // Whatever the child wrote last is still in the pipe.
      while (log_fd_ >= 0) ReadAvailable(100);
      if (WIFEXITED(status)) return WEXITSTATUS(status);
      return 128 + WTERMSIG(status);
    }
    if (NowMs() > deadline) return -1;
    if (log_fd_ >= 0) {
      ReadAvailable(10);
    } else {
      usleep(10000);
    }
  }
}

namespace {

// One "Name: N" field of /proc/PID/status, or -1.
long StatusField(pid_t pid, const char* field) {
  char path[64];
  snprintf(path, sizeof(path), "/proc/%d/status", static_cast<int>(pid));
  FILE* f = fopen(path, "r");
  if (f == nullptr) return -1;
  long value = -1;
  const size_t n = strlen(field);
  char line[256];
  while (fgets(line, sizeof(line), f)) {
    if (strncmp(line, field, n) == 0 && line[n] == ':' &&
        sscanf(line + n + 1, "%ld", &value) == 1) {
      break;
    }
  }
  fclose(f);
  return value;
}

}  // namespace

long RefocusdProcess::ResidentKib() const { return StatusField(pid_, "VmRSS"); }

int RefocusdProcess::Threads() const { return static_cast<int>(StatusField(pid_, "Threads")); }

int RefocusdProcess::OpenFds() const {
  char path[64];
  snprintf(path, sizeof(path), "/proc/%d/fd", static_cast<int>(pid_));
  DIR* d = opendir(path);
  if (d == nullptr) return -1;
  int n = 0;
  while (dirent* e = readdir(d)) n += e->d_name[0] != '.';
  closedir(d);
  return n;
}

int RunRefocusd(const std::vector<std::string>& args, std::string* output) {
  std::string cmd = "'" + RefocusdBinary() + "'";
  for (const std::string& a : args) cmd += " '" + a + "'";
  cmd += " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return -1;
  output->clear();
  char buf[1024];
  for (size_t n; (n = fread(buf, 1, sizeof(buf), p)) > 0;) output->append(buf, n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void ListPhotos(const std::string& dir, std::vector<std::string>* photos,
                std::vector<std::string>* temporaries) {
  photos->clear();
  temporaries->clear();
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) return;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name.rfind("IMG_", 0) == 0) photos->push_back(name);
    if (name.rfind(".IMG_", 0) == 0) temporaries->push_back(name);
  }
  closedir(d);
  std::sort(photos->begin(), photos->end());
}

}  // namespace lb::test
