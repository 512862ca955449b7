// The hidden temporaries in flight, for a signal handler to remove: AtomicFile registers each
// one at Open and forgets it once it is renamed or unlinked. Fixed slots, so registering never
// allocates and the handler reads them safely.
#pragma once

namespace lb::temp_registry {

inline constexpr int kSlots = 16;
inline constexpr int kMaxPath = 1024;

// False when every slot is taken: the file is still written, only its removal on a signal is
// lost.
bool Add(const char* path);
void Remove(const char* path);
// Unlinks every registered temporary. Async-signal-safe.
void UnlinkAll();

}  // namespace lb::temp_registry

namespace lb {

// For the command-line programs: SIGINT, SIGTERM and SIGHUP remove every registered temporary,
// then end the process by the same signal, as it would have ended without the handler.
void RemoveTemporariesOnSignals();

}  // namespace lb
