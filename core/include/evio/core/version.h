#pragma once
/// @file version.h
/// The program's version, as written into output files and `evio --version`.

namespace evio {

/// "evio <major.minor.patch>", the version of project() in the top-level
/// CMakeLists.txt (its only source), e.g. "evio 0.1.0".
const char* evioVersion();

}  // namespace evio
