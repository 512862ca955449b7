// What refocusd checks before it says "ready", and what `refocusd --check-config` checks once
// the configuration reads: the camera (Sensor::Probe: there, and a device its backend can drive)
// and the photo folder (CheckPhotoFolder). Each problem is one message naming the device or the
// folder, so a journal line says what to plug in, mount or fix.
#pragma once

#include "algo/core/status.h"

namespace lb {

// The photo folder exists, is a folder and a file can be created in it. Writing is the one test
// that holds for every user and mount: root passes every permission check (access(2) and a
// chmod'ed folder tell root nothing), and a read-only or full medium only shows when something
// is written. A hidden empty file is created and removed at once; kNotFound when the folder or
// one of its parents is missing or not a folder, kIoError when it cannot be written.
Status CheckPhotoFolder(const char* dir);

}  // namespace lb
