// A virtual shutter button for VM scenarios: creates a uinput device that can send KEY_CAMERA
// and KEY_CAMERA_FOCUS (as the board's gpio-keys node does), prints its event node, then reads
// one action per line from standard input until end of file:
//   press        KEY_CAMERA down, 50 ms, up
//   down | up    KEY_CAMERA alone
//   repeat       KEY_CAMERA autorepeat (value 2)
//   half | unhalf  KEY_CAMERA_FOCUS down / up
//   sleep MS
// A shell drives it through a FIFO held open on a spare descriptor:
//   mkfifo /tmp/keys; uinput_key </tmp/keys >/tmp/keys.node & exec 3>/tmp/keys
//   echo press >&3
#include <fcntl.h>
#include <linux/uinput.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

bool Emit(int fd, int code, int value) {
  input_event ev[2];
  memset(ev, 0, sizeof(ev));
  ev[0].type = EV_KEY;
  ev[0].code = static_cast<uint16_t>(code);
  ev[0].value = value;
  ev[1].type = EV_SYN;
  ev[1].code = SYN_REPORT;
  return write(fd, ev, sizeof(ev)) == static_cast<ssize_t>(sizeof(ev));
}

int Fail(const char* what) {
  fprintf(stderr, "uinput_key: %s: %s\n", what, strerror(errno));
  return 1;
}

}  // namespace

int main() {
  int fd = open("/dev/uinput", O_WRONLY | O_CLOEXEC);
  if (fd < 0) return Fail("/dev/uinput");
  if (ioctl(fd, UI_SET_EVBIT, EV_KEY) < 0 || ioctl(fd, UI_SET_KEYBIT, KEY_CAMERA) < 0 ||
      ioctl(fd, UI_SET_KEYBIT, KEY_CAMERA_FOCUS) < 0) {
    return Fail("UI_SET_KEYBIT");
  }
  uinput_setup setup;
  memset(&setup, 0, sizeof(setup));
  setup.id.bustype = BUS_HOST;
  snprintf(setup.name, sizeof(setup.name), "lb-vm-shutter");
  if (ioctl(fd, UI_DEV_SETUP, &setup) < 0 || ioctl(fd, UI_DEV_CREATE) < 0) return Fail("create");
  char sysname[64] = {};
  if (ioctl(fd, UI_GET_SYSNAME(sizeof(sysname)), sysname) < 0) return Fail("UI_GET_SYSNAME");
  std::string node;
  for (int i = 0; i < 64 && node.empty(); ++i) {
    std::string dir =
        std::string("/sys/devices/virtual/input/") + sysname + "/event" + std::to_string(i);
    if (access(dir.c_str(), F_OK) == 0) node = "/dev/input/event" + std::to_string(i);
  }
  for (int wait = 0; wait < 200 && access(node.c_str(), R_OK) != 0; ++wait) usleep(10000);
  printf("%s\n", node.c_str());
  fflush(stdout);

  char line[128];
  int status = 0;
  while (fgets(line, sizeof(line), stdin)) {
    line[strcspn(line, "\r\n")] = '\0';
    bool ok = true;
    if (strcmp(line, "press") == 0) {
      ok = Emit(fd, KEY_CAMERA, 1);
      usleep(50000);
      ok = ok && Emit(fd, KEY_CAMERA, 0);
    } else if (strcmp(line, "down") == 0) {
      ok = Emit(fd, KEY_CAMERA, 1);
    } else if (strcmp(line, "up") == 0) {
      ok = Emit(fd, KEY_CAMERA, 0);
    } else if (strcmp(line, "repeat") == 0) {
      ok = Emit(fd, KEY_CAMERA, 2);
    } else if (strcmp(line, "half") == 0) {
      ok = Emit(fd, KEY_CAMERA_FOCUS, 1);
    } else if (strcmp(line, "unhalf") == 0) {
      ok = Emit(fd, KEY_CAMERA_FOCUS, 0);
    } else if (strncmp(line, "sleep ", 6) == 0) {
      usleep(static_cast<useconds_t>(atoi(line + 6)) * 1000);
    } else if (line[0] != '\0') {
      fprintf(stderr, "uinput_key: unknown action '%s'\n", line);
      status = 2;
    }
    if (!ok) status = Fail("write");
  }
  ioctl(fd, UI_DEV_DESTROY);
  close(fd);
  return status;
}
