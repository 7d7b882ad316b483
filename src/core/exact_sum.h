// An exact sum of floats: every float is an integer multiple of 2^-149 (the smallest
// subnormal), so a 320-bit two's-complement integer in units of 2^-149 holds any sum of up to
// 2^32 floats without rounding (|x| < 2^128: bit 149 + 128 + 32 = 309 < 319, the sign bit).
// Addition of integers is associative, so a render split into slices, each summed on its own,
// merges into exactly the sum the whole render makes, bit for bit, whatever the split
// (`photonlab render --sample-range`, `photonlab merge`). A double accumulator is not: adding
// a sample of 1e-3 to a sum of 1e7 rounds, and where it rounds depends on the grouping.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>

namespace pl {

class ExactSum {
 public:
  static constexpr int kLimbs = 5;

  void add(float x) {
    uint32_t bits;
    std::memcpy(&bits, &x, 4);
    const uint32_t exponent = (bits >> 23) & 0xFF, fraction = bits & 0x7FFFFF;
    if (exponent == 0xFF) return;  // callers pass finite values; ±inf/NaN are never added
    if (exponent == 0 && fraction == 0) return;
    // x = m · 2^(shift − 149): normal numbers carry the hidden bit, subnormals do not.
    const uint64_t m = exponent ? (fraction | 0x800000u) : fraction;
    const int shift = exponent ? int(exponent) - 1 : 0;
    // m · 2^shift spans limb `limb` and, when the 24-bit m crosses its top, the next one
    // (shift ≤ 253, so limb + 1 < kLimbs). Add or subtract there and carry (borrow) upwards only
    // as far as it goes: the same sum modulo 2^320 as a full-width add, in a few instructions.
    const int limb = shift / 64, offset = shift % 64;
    const uint64_t low = m << offset, high = offset > 40 ? m >> (64 - offset) : 0;
    if (bits >> 31) {
      const uint64_t before = limb_[limb];
      limb_[limb] = before - low;
      uint64_t borrow = before < low;
      for (int i = limb + 1; i < kLimbs && (borrow | (i == limb + 1 ? high : 0)); ++i) {
        const uint64_t sub = (i == limb + 1 ? high : 0) + borrow, v = limb_[i];  // high < 2^24: no overflow
        limb_[i] = v - sub;
        borrow = v < sub;
      }
    } else {
      const uint64_t sum = limb_[limb] + low;
      uint64_t carry = sum < low;
      limb_[limb] = sum;
      for (int i = limb + 1; i < kLimbs && (carry | (i == limb + 1 ? high : 0)); ++i) {
        const uint64_t add = (i == limb + 1 ? high : 0) + carry, v = limb_[i] + add;
        carry = v < add;
        limb_[i] = v;
      }
    }
  }

  void add(const ExactSum& o) { addLimbs(o.limb_); }

  // The sum rounded to the nearest double (ties to even).
  double value() const {
    uint64_t v[kLimbs];
    std::memcpy(v, limb_, sizeof v);
    const bool negative = v[kLimbs - 1] >> 63;
    if (negative) negate(v);
    int top = kLimbs - 1;
    while (top >= 0 && v[top] == 0) --top;
    if (top < 0) return 0.0;
    // The 64 bits from the highest set one down, the rest folded into a sticky bit: converting
    // that to double rounds exactly as the whole number would (64 > 53 + 2 bits).
    const int lead = 63 - __builtin_clzll(v[top]);
    const int high = top * 64 + lead;  // index of the highest set bit
    const int low = high - 63;         // index of the window's lowest bit
    uint64_t window;
    bool sticky = false;
    if (low <= 0) {  // the whole number fits in the window (then top = 0)
      window = v[0] << -low;
    } else {
      const int limb = low / 64, offset = low % 64;
      window = offset ? v[limb] >> offset | v[limb + 1] << (64 - offset) : v[limb];
      sticky = offset && (v[limb] << (64 - offset)) != 0;
      for (int i = 0; i < limb; ++i) sticky |= v[i] != 0;
    }
    if (sticky) window |= 1;  // below the 11 bits double drops: only breaks ties, as it should
    // × 2^(low − 149), exactly: the exponent lies in [−212, 171], a normal double's range.
    const double r = double(window) * powerOfTwo(low - 149);
    return negative ? -r : r;
  }

  const uint64_t* limbs() const { return limb_; }
  void setLimbs(const uint64_t* v) { std::memcpy(limb_, v, sizeof limb_); }
  bool operator==(const ExactSum& o) const { return std::memcmp(limb_, o.limb_, sizeof limb_) == 0; }

 private:
  static double powerOfTwo(int e) {  // 2^e for a normal double's exponent
    const uint64_t bits = uint64_t(e + 1023) << 52;
    double d;
    std::memcpy(&d, &bits, 8);
    return d;
  }
  static void negate(uint64_t* v) {
    uint64_t carry = 1;
    for (int i = 0; i < kLimbs; ++i) {
      v[i] = ~v[i] + carry;
      carry = carry && v[i] == 0;
    }
  }
  void addLimbs(const uint64_t* p) {
    unsigned __int128 carry = 0;
    for (int i = 0; i < kLimbs; ++i) {
      unsigned __int128 s = (unsigned __int128)limb_[i] + p[i] + carry;
      limb_[i] = uint64_t(s);
      carry = s >> 64;
    }
  }
  uint64_t limb_[kLimbs] = {};
};

}  // namespace pl
