// Sets a V4L2 control found by its name, for VM scenarios that inject faults through vivid's
// error-injection controls while another process streams:
//   v4l2_ctrl DEVICE "Percentage of Dropped Buffers" 100
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: v4l2_ctrl DEVICE NAME VALUE\n");
    return 2;
  }
  const int fd = open(argv[1], O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    fprintf(stderr, "v4l2_ctrl: %s: %s\n", argv[1], strerror(errno));
    return 1;
  }
  v4l2_query_ext_ctrl q;
  memset(&q, 0, sizeof(q));
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  while (ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &q) == 0) {
    if (strcmp(q.name, argv[2]) == 0) {
      v4l2_control c = {q.id, atoi(argv[3])};
      if (ioctl(fd, VIDIOC_S_CTRL, &c) != 0) {
        fprintf(stderr, "v4l2_ctrl: %s: setting '%s': %s\n", argv[1], argv[2], strerror(errno));
        return 1;
      }
      printf("v4l2_ctrl: %s: '%s' = %s\n", argv[1], argv[2], argv[3]);
      close(fd);
      return 0;
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  fprintf(stderr, "v4l2_ctrl: %s: no control named '%s'\n", argv[1], argv[2]);
  return 1;
}
