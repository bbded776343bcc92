#pragma once
/// @file cpu_features.h
/// What the running CPU supports, for code paths chosen at run time (the
/// EKLT cost's AVX and AVX-512 lanes, the renderer's and the textures' AVX2 lanes).
/// Each answer is computed once; false on other architectures and compilers.

namespace evio {

bool cpuHasAvx();
bool cpuHasAvx2();
bool cpuHasAvx512f();

}  // namespace evio
