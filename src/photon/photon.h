// A stored photon in 20 bytes: position (3 floats), flux as RGBE (Ward's shared exponent,
// 8-bit mantissas, stochastically rounded so the encoding is unbiased), incident direction
// octahedrally encoded in 2 × 15 bits, and the path type in the two spare bits.
#pragma once
#include <cstring>

#include "core/common.h"
#if defined(__SSE2__)  // every x86-64 processor
#include <emmintrin.h>
#endif

namespace pl {

struct Photon {
  // The path that brought the photon here, in Heckbert's notation (2 bits of `type()`).
  enum Type : uint8_t {
    kIndirect = 0,  // at least one diffuse or glossy bounce before this hit
    kDirect = 1,    // L D: first hit after leaving the light
    kCaustic = 2,   // L S+ D: only specular bounces before this hit
  };
  // Masks of accepted types for gathers.
  static constexpr uint8_t kAcceptAll = 0b111, kAcceptIndirect = 1 << kIndirect, kAcceptCaustic = 1 << kCaustic,
                           kAcceptDirect = 1 << kDirect;

  float position[3];
  uint8_t rgbe[4];
  uint16_t direction[2];  // bit 0 of each: flags

  Photon() = default;
  // `dither` in [0, 1) rounds the flux mantissas: a uniform random number makes the encoding
  // unbiased even when every photon carries the same flux (one light, no colour); 0.5 rounds
  // to nearest, which is biased in that case by up to 1/512.
  Photon(const Vec3& p, const Vec3& wi, const Spectrum& flux, Type type, float dither = 0.5f) {
    position[0] = p.x, position[1] = p.y, position[2] = p.z;
    setFlux(flux, dither);
    setDirection(wi, type);
  }
  Vec3 p() const { return Vec3(position[0], position[1], position[2]); }

  // --- flux: RGBE ---
  // Exponents are read from and written to the float bits directly: this runs once per stored
  // photon, where frexp/ldexp/lround were a large share of photon tracing (docs: Performance).
  void setFlux(const Spectrum& f, float dither) {
    float m = maxComponent(f);
    if (!(m > 1e-30f && m < 1e30f)) {  // zero, negative, NaN or absurd: store nothing
      std::memset(rgbe, 0, 4);
      return;
    }
    float scale;
    int e = sharedExponent(m, dither, &scale);
#if defined(__SSE2__)
    // mantissa() on the three channels at once, bit for bit (tested): the same operations in
    // the same order, and maxps/minps pick NaN's second operand as std::max/min do here. The
    // scalar form compiles to a compare-and-branch per clamp.
    __m128 c = _mm_setr_ps(f.r, f.g, f.b, 0.0f);
    c = _mm_add_ps(_mm_mul_ps(_mm_max_ps(c, _mm_setzero_ps()), _mm_set1_ps(scale)), _mm_set1_ps(dither));
    __m128i q = _mm_cvttps_epi32(_mm_min_ps(c, _mm_set1_ps(255.0f)));
    q = _mm_packus_epi16(_mm_packs_epi32(q, q), q);  // 32 → 16 → 8 bits, each value ≤ 255
    uint32_t bytes = (uint32_t(_mm_cvtsi128_si32(q)) & 0xffffffu) | uint32_t(e + 128) << 24;
    std::memcpy(rgbe, &bytes, 4);  // x86 is little-endian: rgbe[0] = R
#else
    rgbe[0] = mantissa(f.r, scale, dither);
    rgbe[1] = mantissa(f.g, scale, dither);
    rgbe[2] = mantissa(f.b, scale, dither);
    rgbe[3] = uint8_t(e + 128);
#endif
  }
  // The exponent e of the largest channel m > 0, and the scale 2^(8−e) that takes m's mantissa
  // to [128, 256) after dithering.
  static int sharedExponent(float m, float dither, float* scale) {
    int e = exponentOf(m);  // m = frac · 2^e, frac in [0.5, 1): m·2^(8−e) in [128, 256)
    *scale = powerOfTwo(8 - e);
    if (m * *scale + dither >= 256.0f) *scale *= 0.5f, ++e;  // rounds up to 256: next exponent
    return e;
  }
  // Each channel is at most m, so its mantissa is at most m's, below 256 after the exponent
  // step. The clamp covers a compiler fusing one multiply-add into an FMA but not another.
  static uint8_t mantissa(float c, float scale, float dither) {
    return uint8_t(std::min(255.0f, std::max(0.0f, c) * scale + dither));
  }
  Spectrum flux() const {
    if (rgbe[3] == 0) return Spectrum(0.0f);
    return Spectrum(rgbe[0], rgbe[1], rgbe[2]) * powerOfTwo(int(rgbe[3]) - 128 - 8);
  }
  static int exponentOf(float x) {  // frexp's exponent for a normal positive float
    uint32_t bits;
    std::memcpy(&bits, &x, 4);
    return int((bits >> 23) & 255) - 126;
  }
  static float powerOfTwo(int e) {  // 2^e for −126 ≤ e ≤ 127
    uint32_t bits = uint32_t(std::clamp(e + 127, 1, 254)) << 23;
    float x;
    std::memcpy(&x, &bits, 4);
    return x;
  }

  // --- direction: octahedral map (Meyer et al. 2010), 15 bits per coordinate ---
  void setDirection(const Vec3& w, uint8_t flags) {
    float invL1 = 1.0f / (std::abs(w.x) + std::abs(w.y) + std::abs(w.z));
#if defined(__SSE2__)
    // octahedral() and quantise() on (u, v) at once, bit for bit (tested): the scalar form's
    // fold needs two selects through the integer registers.
    const __m128 magnitude = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    __m128 uv = _mm_mul_ps(_mm_setr_ps(w.x, w.y, 0.0f, 0.0f), _mm_set1_ps(invL1));
    __m128 vu = _mm_shuffle_ps(uv, uv, _MM_SHUFFLE(3, 2, 0, 1));
    // copysign(1 − |v|, u), copysign(1 − |u|, v): 1 − |v| ≥ 0, so OR-ing in u's sign bit is copysign.
    __m128 folded = _mm_or_ps(_mm_sub_ps(_mm_set1_ps(1.0f), _mm_and_ps(vu, magnitude)), _mm_andnot_ps(magnitude, uv));
    __m128 lower = _mm_cmplt_ps(_mm_set1_ps(w.z), _mm_setzero_ps());
    uv = _mm_or_ps(_mm_and_ps(lower, folded), _mm_andnot_ps(lower, uv));
    uv = _mm_add_ps(_mm_mul_ps(uv, _mm_set1_ps(16383.5f)), _mm_set1_ps(16384.0f));
    __m128i q = _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(uv, _mm_setzero_ps()), _mm_set1_ps(32767.0f)));
    q = _mm_or_si128(_mm_slli_epi32(q, 1), _mm_setr_epi32(flags & 1, (flags >> 1) & 1, 0, 0));
    direction[0] = uint16_t(_mm_cvtsi128_si32(q));
    direction[1] = uint16_t(_mm_extract_epi16(q, 2));
#else
    Vec2 uv = octahedral(w, invL1);
    direction[0] = uint16_t(quantise(uv.x) << 1 | (flags & 1u));
    direction[1] = uint16_t(quantise(uv.y) << 1 | ((flags >> 1) & 1u));
#endif
  }
  // (u, v) of unit w on the octahedron |u| + |v| + |z| = 1, invL1 = 1/(|x| + |y| + |z|).
  static Vec2 octahedral(const Vec3& w, float invL1) {
    float u = w.x * invL1, v = w.y * invL1;
    // The lower hemisphere folds over the diagonals. Photons arrive from either side as often,
    // so the fold is selected without a branch (common.h, select).
    bool lower = w.z < 0;
    float fu = std::copysign(1 - std::abs(v), u), fv = std::copysign(1 - std::abs(u), v);
    return Vec2(select(lower, fu, u), select(lower, fv, v));
  }
  // u, v in [−1, 1] up to rounding: the clamp keeps the 15-bit code in range.
  static unsigned quantise(float x) { return unsigned(std::min(32767.0f, std::max(0.0f, x * 16383.5f + 16384.0f))); }
  Vec3 wi() const {
    float u = (direction[0] >> 1) / 32767.0f * 2 - 1, v = (direction[1] >> 1) / 32767.0f * 2 - 1;
    Vec3 w(u, v, 1 - std::abs(u) - std::abs(v));
    if (w.z < 0) {
      float pu = w.x, pv = w.y;
      w.x = (1 - std::abs(pv)) * (pu >= 0 ? 1.0f : -1.0f);
      w.y = (1 - std::abs(pu)) * (pv >= 0 ? 1.0f : -1.0f);
    }
    return glm::normalize(w);
  }
  Type type() const { return Type((direction[0] & 1) | ((direction[1] & 1) << 1)); }
};

static_assert(sizeof(Photon) == 20, "a photon record is 20 bytes");

}  // namespace pl
