// refocus: the host command line. Thin: every subcommand is a function in *_command.cc.
#include <cstdio>
#include <cstring>

#include "firmware/cli/commands.h"
#include "firmware/platform/cpu_features.h"
#include "firmware/storage/temp_registry.h"

namespace {

const char kUsage[] =
    "usage: refocus COMMAND [options]\n"
    "\n"
    "Lens blur from a short burst: depth by graph cuts, then a synthetic shallow depth of field.\n"
    "\n"
    "Commands:\n"
    "  run        burst (files, a folder or the synthetic scene) -> refocused JPEG\n"
#ifdef LB_HAVE_DEPTH_COMMAND
    "  depth      views (auto or rectified geometry) -> disparity map (PFM) and a preview\n"
#endif
#ifdef LB_HAVE_RERENDER_COMMAND
    "  rerender   refocusable JPEG -> the same photo with a new focus\n"
#endif
#ifdef LB_HAVE_INFO_COMMAND
    "  info       what a photo carries for refocusing (depth, original, focus)\n"
#endif
    "\n"
    "'refocus COMMAND --help' describes a command's options.\n";

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (!strcmp(argv[1], "--version")) {
    printf("refocus %s\n", LB_VERSION);
    return 0;
  }
  // An interrupted run leaves no hidden temporary behind (temp_registry.h).
  lb::RemoveTemporariesOnSignals();
  lb::UseThisCpu();  // the row kernels this processor runs (NEON on a 32-bit ARM that has it)
  const char* cmd = argv[1];
  if (!strcmp(cmd, "run")) return lb::cli::RunCommand(argc - 1, argv + 1);
#ifdef LB_HAVE_DEPTH_COMMAND
  if (!strcmp(cmd, "depth")) return lb::cli::DepthCommand(argc - 1, argv + 1);
#endif
#ifdef LB_HAVE_RERENDER_COMMAND
  if (!strcmp(cmd, "rerender")) return lb::cli::RerenderCommand(argc - 1, argv + 1);
#endif
#ifdef LB_HAVE_INFO_COMMAND
  if (!strcmp(cmd, "info")) return lb::cli::InfoCommand(argc - 1, argv + 1);
#endif
  fprintf(stderr, "refocus: unknown command '%s'\n\n%s", cmd, kUsage);
  return 2;
}
