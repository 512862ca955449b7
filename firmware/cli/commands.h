// Subcommands of the host command line `refocus`. Each takes the arguments after its name and
// returns the process exit code (0 success, 1 failure with a one-line message on stderr, 2 usage).
#pragma once

namespace lb::cli {

int RunCommand(int argc, char** argv);       // refocus run: burst -> refocused JPEG
int DepthCommand(int argc, char** argv);     // refocus depth: views -> disparity PFM (+ preview)
int RerenderCommand(int argc, char** argv);  // refocus rerender: refocusable JPEG -> new focus
int InfoCommand(int argc, char** argv);      // refocus info: what a photo carries for refocusing

}  // namespace lb::cli
