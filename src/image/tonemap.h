// From linear radiance to display values, for PNGs and figures only (EXR stays linear and
// untouched). Exposure first, a tone curve second, the sRGB transfer curve last:
//   display = sRGB(curve(2^EV · L)).
// Curves: `clamp` cuts at 1 (the default, and what photonlab's PNGs always were); `aces` is
// Narkowicz's fit of the ACES filmic curve, f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14),
// which rolls highlights off instead of cutting them: f(1) = 0.80, f(4) = 0.97, white only
// from x ≈ 7.2 (2.9 EV above 1), so a caustic's core keeps its shape.
#pragma once
#include <algorithm>
#include <cmath>
#include <string>

#include "core/common.h"

namespace pl {

enum class ToneCurve { Clamp, ACES };

struct Display {
  double exposure = 0.0;  // EV: linear values are multiplied by 2^exposure
  ToneCurve curve = ToneCurve::Clamp;
  // --exposure auto: the exposure is metered from the image (meteredExposure) when it is written.
  bool autoExposure = false;
  bool isDefault() const { return exposure == 0.0 && curve == ToneCurve::Clamp && !autoExposure; }
};

// Automatic exposure, the metering rule: the log-average luminance of the lit pixels goes to
// middle grey, EV = log2(0.18 / exp(mean ln Y)), Y = 0.2126 R + 0.7152 G + 0.0722 B of linear
// sRGB (Reinhard et al. 2002, "Photographic tone reproduction", eq. 1, with the key a = 0.18).
// Pixels with Y ≤ 0 (nothing lit: the background of a model lit by a lamp) and non-finite ones
// are left out, so a small lit object on black is exposed for itself; an image with none lit
// keeps EV 0. The result is held within ±20 EV.
inline double meteredExposure(const float* rgb, size_t pixels) {
  double sum = 0;
  size_t lit = 0;
  for (size_t i = 0; i < pixels; ++i) {
    const double y = 0.2126 * rgb[3 * i] + 0.7152 * rgb[3 * i + 1] + 0.0722 * rgb[3 * i + 2];
    if (!(y > 0) || !std::isfinite(y)) continue;
    sum += std::log(y);
    ++lit;
  }
  if (lit == 0) return 0.0;
  return std::clamp(std::log2(0.18) - sum / double(lit) / std::log(2.0), -20.0, 20.0);
}

inline float acesFilmic(float x) {
  x = std::max(x, 0.0f);
  return std::min(1.0f, x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f));
}

inline float srgbTransfer(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

// The inverse of srgbTransfer: an encoded value in [0, 1] back to linear.
inline float srgbDecode(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

// A linear value's display value in [0, 1] (non-finite values show as 0).
inline float displayValue(float linear, const Display& d) {
  if (!std::isfinite(linear)) return 0.0f;
  float x = linear * float(std::exp2(d.exposure));
  return srgbTransfer(d.curve == ToneCurve::ACES ? acesFilmic(x) : x);
}

inline ToneCurve parseToneCurve(const std::string& name) {
  if (name == "clamp") return ToneCurve::Clamp;
  if (name == "aces") return ToneCurve::ACES;
  throw Error("unknown tone curve '" + name + "' (clamp, aces)");
}
inline const char* toneCurveName(ToneCurve c) { return c == ToneCurve::ACES ? "aces" : "clamp"; }

}  // namespace pl
