// Colour from spectra (the course notes' colorimetry): a spectral power distribution projects on
// the CIE 1931 2° matching functions x̄, ȳ, z̄ to XYZ, and XYZ maps to linear sRGB by a 3×3 matrix.
#pragma once
#include "core/common.h"

namespace pl {

constexpr float kLambdaMin = 360.0f, kLambdaMax = 830.0f;  // nm: the range of the CIE tables
constexpr int kCieSamples = 471;                            // 1 nm steps, both ends included
extern const float kCieX[kCieSamples], kCieY[kCieSamples], kCieZ[kCieSamples];
extern const float kD65[kCieSamples];  // relative spectral power, 100 at 560 nm

// ∫ ȳ(λ) dλ over the table (1 nm Riemann sum, as the CIE defines it): 106.856895.
constexpr double kCieYIntegral = 106.856917;

// Linear interpolation in the 1 nm tables; zero outside 360–830 nm.
Vec3 cieXYZ(float lambda);
float d65(float lambda);

// sRGB (IEC 61966-2-1) primaries and D65 white, linear: RGB = M·XYZ with Y = 1 for white.
// Named as in the course notes (XYZToRGB / RGBToXYZ); RGB here is always linear sRGB.
Vec3 XYZToRGB(const Vec3& xyz);
Vec3 RGBToXYZ(const Vec3& rgb);

// Planck's law: spectral radiance of a blackbody at temperature T (kelvin), W/(m²·sr·m), at λ in nm.
double planck(double lambdaNm, double kelvin);

}  // namespace pl
