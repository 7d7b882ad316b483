// Spectral rendering support (--spectral): RGB-to-spectrum uplift, the wavelengths a path
// carries, and the film's projection of spectral samples back to linear sRGB.
//
// A path in spectral mode carries three wavelengths λ₀ + k·Δ/3 (k = 0, 1, 2, wrapped into
// 360–830 nm, Δ = 470 nm; λ₀ uniform): the hero-wavelength scheme of Wilkie et al. 2014 with 3
// wavelengths instead of 4, so that the renderer's Spectrum (three floats) holds the path's
// values at its wavelengths unchanged. Each wavelength is uniformly distributed, so the film's
// estimate ∫ L(λ) x̄(λ) dλ ≈ Δ/3 · Σₖ L(λₖ) x̄(λₖ) is unbiased. A dispersive refraction keeps the
// hero wavelength only (its value × 3, the others 0), as in pbrt-v4.
#pragma once
#include <array>
#include <mutex>
#include <vector>

#include "core/common.h"
#include "spectral/cie.h"

namespace pl {

// Sets the three wavelengths from one uniform number (stratified rotation of λ₀).
Vec3 sampleWavelengths(float u);

// The wavelengths a path carries (as pbrt-v4's SampledWavelengths), passed explicitly to
// everything that depends on them: textures, lights, dielectrics, the film. In RGB mode
// (`spectral` false) the path's values are RGB and nothing consults `lambda`.
struct SampledWavelengths {
  Vec3 lambda{550.0f};    // nm
  bool spectral = false;
  bool heroOnly = false;  // after a dispersive refraction: only lambda.x carries a value

  static SampledWavelengths sample(float u) {
    SampledWavelengths w;
    w.spectral = true;
    w.lambda = sampleWavelengths(u);
    return w;
  }
  // RGB rendering: what RGB-only callers (photon gathers, tests) pass.
  static const SampledWavelengths& rgb() {
    static const SampledWavelengths w;
    return w;
  }
  // A dispersive refraction follows the hero wavelength alone from here on (the BSDF sample
  // that does it says so, and weights the hero's value ×3 the first time).
  void terminateSecondary() { heroOnly = true; }
};

// ∫ D65 ȳ dλ over the 1 nm table: the white illuminant's normalisation, so that an emitter of
// RGB (1, 1, 1) has luminance Y = 1 in spectral mode as in RGB mode.
double d65Luminance();

// The linear sRGB of a spectral radiance sample: Δ/3 · Σₖ v_k · W(λₖ), with W = the
// D65-white-normalised XYZ→sRGB projection of the matching functions.
Spectrum spectralToRGB(const Spectrum& values, const Vec3& lambda);
// The same in two steps: the sample's XYZ (never negative for non-negative values), then sRGB.
Vec3 spectralToXYZ(const Spectrum& values, const Vec3& lambda);
Spectrum spectralXYZToRGB(const Vec3& xyz);

// Reflectance spectrum for an RGB albedo in [0, 1]³, in [0, 1] at every wavelength, whose sRGB
// under D65 is that RGB (the round trip is exact up to the fit of the 9³ grid's nodes).
// Built on first use (about 0.6 s): tetrahedral interpolation between node spectra, each a
// sigmoid-polynomial σ(c₀t² + c₁t + c₂) fitted as Jakob & Hanika (2019) do. Interpolating
// between nodes keeps both properties: RGB is linear in the spectrum, and convex combinations
// of [0, 1] spectra stay in [0, 1]. Greys are flat spectra.
class RGBUplift {
 public:
  static const RGBUplift& instance();
  float reflectance(const Vec3& rgb, float lambda) const;
  // sRGB (D65-normalised) of a reflectance tabulated at the 471 1-nm samples.
  Vec3 rgbOfReflectance(const std::vector<float>& spectrum) const;
  float nodeError() const { return worstNodeError_; }  // worst RGB error of a grid node's fit

  static constexpr int kGrid = 9;

 private:
  RGBUplift();
  std::vector<float> fitNode(const Vec3& rgb) const;
  std::vector<float> nodes_;   // kGrid³ × kCieSamples
  std::array<Vec3, kCieSamples> projection_;  // RGB per unit reflectance at each 1 nm sample
  float worstNodeError_ = 0.0f;
};

// A spectrum tabulated at the 471 1-nm samples, built on first use (thread-safe): per-object
// constants (a texture's colour, a light's emission) are uplifted once, not at every lookup.
class LazySpectrum {
 public:
  using Table = std::array<float, kCieSamples>;
  template <typename Build>
  const Table& get(Build&& build) const {
    std::call_once(once_, [&] { build(table_); });
    return table_;
  }
  static float at(const Table& t, float lambda) {
    float x = lambda - kLambdaMin;
    if (!(x >= 0.0f) || x > float(kCieSamples - 1)) return 0.0f;
    int i = std::min(int(x), kCieSamples - 2);
    float f = x - float(i);
    return (1.0f - f) * t[i] + f * t[i + 1];
  }
  static Spectrum at(const Table& t, const Vec3& lambda) { return Spectrum(at(t, lambda.x), at(t, lambda.y), at(t, lambda.z)); }

 private:
  mutable std::once_flag once_;
  mutable Table table_{};
};

// What textures and lights call: in spectral mode, the value at the path's wavelengths; in RGB
// mode, `rgb` unchanged.
Spectrum spectralReflectance(const Spectrum& rgb, const SampledWavelengths& lambda);  // albedos, clamped to [0, 1]
Spectrum spectralEmission(const Spectrum& rgb, const SampledWavelengths& lambda);     // radiance, intensity, flux: max·ρ(rgb/max)·D65/Y
// Emission spectra tabulated at the 1 nm samples (what a light caches, LazySpectrum::at reads):
//   emissionTable: the uplift of a colour with max component 1, times D65 (spectralEmission's);
//   blackbodyTable: Planck's law at T kelvin, scaled to luminance Y = 1 (a light's intensity
//     keeps its meaning);
//   equalEnergyTable: the equal-energy illuminant E, flat, at luminance 1.
void emissionTable(const Vec3& unitColour, LazySpectrum::Table* t);
void blackbodyTable(double kelvin, LazySpectrum::Table* t);
void equalEnergyTable(LazySpectrum::Table* t);
// Their linear sRGB, for RGB mode (E is slightly pink next to D65's white).
Vec3 blackbodyRGB(double kelvin);
Vec3 equalEnergyRGB();

}  // namespace pl
