// A SIMD-lane kernel compiled once per instruction set (core/lanes.h says why). A .cpp file
// includes every header its kernel needs, then
//
//   #define PL_LANES_KERNEL "integrators/path_lanes_kernel.h"
//   #include "core/lanes_copies.h"
//
// which includes the kernel twice, with PL_LANES_ISA set to avx512 (under `#pragma GCC target`
// for x86-64-v4) and to baseline (no target: any x86-64 CPU, or another family). The kernel header
// includes core/lanes.h (this instruction set's helpers, pl::lanes::PL_LANES_ISA) and puts its
// own code in a namespace named by PL_LANES_ISA; the file calls the copy lanes::bestIsa() names.
//
// Headers first included inside a `#pragma GCC target` region would have their inline
// functions compiled for that instruction set, and the linker could keep such a copy for the
// whole program: a kernel header includes nothing but core/lanes.h, whose own includes come
// here first.
//
// No #pragma once: a file may hold several kernels (each with its own PL_LANES_KERNEL).
#ifndef PL_LANES_KERNEL
#error "define PL_LANES_KERNEL (the kernel header) before including core/lanes_copies.h"
#endif
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/common.h"
#include "core/lanes_isa.h"

#if PL_LANES_TARGETS
#define PL_LANES_ISA avx512
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
#include PL_LANES_KERNEL
#pragma GCC pop_options
#undef PL_LANES_ISA
#else
// Elsewhere (another compiler or CPU family) both names hold the same, untargeted copy.
#define PL_LANES_ISA avx512
#include PL_LANES_KERNEL
#undef PL_LANES_ISA
#endif

#define PL_LANES_ISA baseline
#include PL_LANES_KERNEL
#undef PL_LANES_ISA
