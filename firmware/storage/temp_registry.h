// The hidden temporaries in flight, for a signal handler to remove: AtomicFile registers each
// one at Open and forgets it once it is renamed or unlinked. Fixed slots, so registering never
// allocates and the handler reads them safely.
#pragma once

#include <signal.h>

namespace lb::temp_registry {

inline constexpr int kSlots = 16;
inline constexpr int kMaxPath = 1024;

// False when every slot is taken: the file is still written, only its removal on a signal is
// lost.
bool Add(const char* path);
void Remove(const char* path);
// Unlinks every registered temporary. Async-signal-safe.
void UnlinkAll();
// A file of the command is in place: from now on the signals below no longer end the process,
// which finishes what little is left (a photo's command commits its output last), so an
// interrupted command has left the old file or ends as if not interrupted, never both.
// AtomicFile calls it with the signals blocked from before its rename, so none falls between.
void MarkCommitted();
// The signals that end a command (RemoveTemporariesOnSignals) and that a commit holds off.
inline constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

}  // namespace lb::temp_registry

namespace lb {

// For the command-line programs: SIGINT, SIGTERM and SIGHUP remove every registered temporary,
// then end the process by the same signal, as it would have ended without the handler; once a
// file is committed after this call (MarkCommitted) they are ignored. Threads the program starts
// start with them blocked (firmware/platform/signals_blocked.h), so the handler runs on the thread
// that commits.
void RemoveTemporariesOnSignals();

}  // namespace lb
