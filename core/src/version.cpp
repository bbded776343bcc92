#include "evio/core/version.h"

// EVIO_VERSION is set by core/CMakeLists.txt from project(evio VERSION …).
#ifndef EVIO_VERSION
#error "EVIO_VERSION must be defined by the build"
#endif

namespace evio {

const char* evioVersion() { return "evio " EVIO_VERSION; }

}  // namespace evio
