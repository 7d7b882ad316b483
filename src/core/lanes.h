// Sixteen values in one vector register: the arithmetic of code that runs 16 paths side by side
// in SIMD lanes (bench/least_path_loop_simd.cpp, integrators/path_lanes.cpp). GCC's vector
// extensions: +, −, ×, ÷ and comparisons act lane by lane (a comparison gives 0 or −1 per lane),
// and `mask ? a : b` selects.
//
// One copy per instruction set, in namespace pl::lanes::PL_LANES_ISA (so no #pragma once): a
// kernel that uses these helpers is compiled whole for AVX-512 and for baseline x86-64 by
// core/lanes_copies.h, and one is picked at run time (core/lanes_isa.h). Why not GCC's
// target_clones, which the kernels had before: GCC 12 lowers a vector comparison for the
// instruction set of the function it is written in, before inlining, and a target_clones
// function or a helper without a target is written for baseline x86-64, where a 64-byte vector
// is not a register. Every comparison whose mask was combined (&, |) or selected integers was
// then compiled lane by lane (vcomiss, seta, vpinsrd), at a cost the path tracer's profile
// showed (docs/pages/explanation/performance.md). Under
// `#pragma GCC target("arch=x86-64-v4")` they are one vcmpps each. (Without 64-byte registers,
// in the baseline copy or an AVX2 one, a 16-lane comparison is still split lane by lane.)
#ifndef PL_LANES_ISA
#error "core/lanes.h is included by a kernel through core/lanes_copies.h, which names the instruction set"
#endif
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/common.h"

// Vectors of 64 bytes passed between inlined helpers: GCC warns that their ABI differs without
// AVX-512. None crosses a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace pl::lanes::PL_LANES_ISA {

constexpr int kLanes = 16;
typedef float Floats __attribute__((vector_size(4 * kLanes)));
typedef int32_t Ints __attribute__((vector_size(4 * kLanes)));
typedef uint64_t Words __attribute__((vector_size(8 * kLanes / 2)));  // half the lanes, 64-bit
typedef float HalfFloats __attribute__((vector_size(4 * kLanes / 2)));

PL_HOT_INLINE Floats load(const float* p) {
  Floats v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
PL_HOT_INLINE Ints load(const int32_t* p) {
  Ints v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
PL_HOT_INLINE void store(float* p, Floats v) { std::memcpy(p, &v, sizeof v); }
PL_HOT_INLINE void store(int32_t* p, Ints v) { std::memcpy(p, &v, sizeof v); }
PL_HOT_INLINE Floats splat(float x) { return Floats{} + x; }
PL_HOT_INLINE Floats sqrt(Floats x) {
  for (int k = 0; k < kLanes; ++k) x[k] = std::sqrt(x[k]);  // one vsqrtps per register
  return x;
}
PL_HOT_INLINE Floats abs(Floats x) { return x < 0 ? -x : x; }
PL_HOT_INLINE Floats max(Floats a, Floats b) { return a > b ? a : b; }
PL_HOT_INLINE Floats min(Floats a, Floats b) { return a < b ? a : b; }
// Whether any lane of a mask is set: work that few lanes need is skipped when none does.
PL_HOT_INLINE bool any(Ints m) {
  int32_t r = 0;
  for (int k = 0; k < kLanes; ++k) r |= m[k];
  return r != 0;
}
// copysign(1, x), −0 giving −1 (as Frame's basis takes it).
PL_HOT_INLINE Floats signOf(Floats x) {
  Ints bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = (bits & INT32_MIN) | 0x3f800000;
  Floats s;
  std::memcpy(&s, &bits, sizeof s);
  return s;
}

// PCG32's output for eight 64-bit states (Rng::nextU32), in [0, 2³²).
PL_HOT_INLINE Words pcgOutput(Words old) {
  const Words xorshifted = (((old >> 18) ^ old) >> 27) & 0xffffffffu;
  const Words rot = old >> 59;
  return ((xorshifted >> rot) | (xorshifted << ((-rot) & 31))) & 0xffffffffu;
}

// Rng::uniform() for 16 streams (Rng::state() and increment() per lane), advancing only those
// where `draw` is set: 24 random mantissa bits, in [0, 1).
PL_HOT_INLINE Floats uniforms(uint64_t* state, const uint64_t* increment, Ints draw) {
  alignas(64) float out[kLanes];
  for (int half = 0; half < 2; ++half) {
    Words s, inc, mask;
    std::memcpy(&s, state + 8 * half, sizeof s);
    std::memcpy(&inc, increment + 8 * half, sizeof inc);
    for (int k = 0; k < 8; ++k) mask[k] = draw[8 * half + k] ? ~uint64_t(0) : 0;
    const Words next = s * 6364136223846793005ULL + inc;
    const Words kept = (next & mask) | (s & ~mask);
    std::memcpy(state + 8 * half, &kept, sizeof kept);
    const HalfFloats u = __builtin_convertvector(pcgOutput(s) >> 8, HalfFloats) * 0x1p-24f;
    std::memcpy(out + 8 * half, &u, sizeof u);
  }
  return load(out);
}

// sin 2πu and cos 2πu (core/sampling.h sinCos2Pi, lane by lane): the nearest quarter turn, then
// minimax polynomials on [−π/4, π/4].
PL_HOT_INLINE void sinCos2Pi(Floats u, Floats* sinOut, Floats* cosOut) {
  const Floats t = 4.0f * u;
  const Ints q = __builtin_convertvector(t + 0.5f, Ints);
  const Floats x = (t - __builtin_convertvector(q, Floats)) * (kPi / 2), x2 = x * x;
  const Floats s = x + x * x2 * (-1.6666654611e-1f + x2 * (8.3321608736e-3f + x2 * -1.9515295891e-4f));
  const Floats c = 1.0f - 0.5f * x2 + x2 * x2 * (4.166664568298827e-2f + x2 * (-1.388731625493765e-3f + x2 * 2.443315711809948e-5f));
  const Ints odd = (q & 1) != 0;
  const Floats s1 = odd ? c : s, c1 = odd ? s : c;
  *sinOut = (q & 2) != 0 ? -s1 : s1;
  *cosOut = ((q + 1) & 2) != 0 ? -c1 : c1;
}

// A 16 × 16 matrix's transpose, in place: rows[i][j] becomes rows[j][i]. Four stages, each
// swapping the off-diagonal blocks of size b (8, 4, 2, 1) between row pairs i, i + b: the
// transpose exchanges each bit of the row index with the same bit of the column index.
PL_HOT_INLINE void transpose(Floats rows[kLanes]) {
  for (int b = kLanes / 2; b >= 1; b /= 2) {
    Ints lo, hi;  // __builtin_shuffle's indices: 0–15 the first row, 16–31 the second
    for (int j = 0; j < kLanes; ++j) {
      const bool left = (j / b) % 2 == 0;
      lo[j] = left ? j : kLanes + j - b;
      hi[j] = left ? j + b : kLanes + j;
    }
    for (int i = 0; i < kLanes; ++i) {
      if (i & b) continue;
      const Floats a = rows[i], c = rows[i + b];
      rows[i] = __builtin_shuffle(a, c, lo);
      rows[i + b] = __builtin_shuffle(a, c, hi);
    }
  }
}

// Sixteen 64-byte records (one per lane, 16 floats each) as 16 vectors, one per field: field j
// of lane k is fields[j][k]. Sixteen whole-line loads and a transpose, instead of 256 scalar
// loads and stores (whose vector reloads the store buffer cannot forward).
PL_HOT_INLINE void gatherRecords(const void* const records[kLanes], Floats fields[kLanes]) {
  for (int k = 0; k < kLanes; ++k) std::memcpy(&fields[k], records[k], sizeof(Floats));
  transpose(fields);
}
PL_HOT_INLINE Ints bitsOf(Floats x) {
  Ints i;
  std::memcpy(&i, &x, sizeof i);
  return i;
}

// Duff et al.'s orthonormal basis (s, t, n) around unit normals n, 16 at once (core/frame.h
// Frame, the same arithmetic).
struct Frames {
  Floats sx, sy, sz, tx, ty, tz, nx, ny, nz;
  PL_HOT_INLINE Frames(Floats x, Floats y, Floats z) : nx(x), ny(y), nz(z) {
    const Floats sign = signOf(nz);
    const Floats a = -1.0f / (sign + nz), b = nx * ny * a;
    sx = 1.0f + sign * nx * nx * a, sy = sign * b, sz = -sign * nx;
    tx = b, ty = sign + ny * ny * a, tz = -ny;
  }
  // s·x + t·y + n·z.
  PL_HOT_INLINE void toWorld(Floats x, Floats y, Floats z, Floats* wx, Floats* wy, Floats* wz) const {
    *wx = sx * x + tx * y + nx * z;
    *wy = sy * x + ty * y + ny * z;
    *wz = sz * x + tz * y + nz * z;
  }
  // (v·s, v·t, v·n).
  PL_HOT_INLINE void toLocal(Floats vx, Floats vy, Floats vz, Floats* x, Floats* y, Floats* z) const {
    *x = vx * sx + vy * sy + vz * sz;
    *y = vx * tx + vy * ty + vz * tz;
    *z = vx * nx + vy * ny + vz * nz;
  }
};

}  // namespace pl::lanes::PL_LANES_ISA
