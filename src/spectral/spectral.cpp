#include "spectral/spectral.h"

#include <cmath>

#include "core/parallel.h"

namespace pl {

namespace {
constexpr float kRange = kLambdaMax - kLambdaMin;  // 470 nm

// The D65-normalised XYZ→sRGB projection: diag(1/w)·M with w = M·XYZ(D65)/Y(D65), so that D65
// (the white illuminant) maps to exactly (1, 1, 1) although the tables and the matrix agree on
// white only to 1e-3.
struct Projection {
  Vec3 whiteScale;
  double yD65;
  Projection() {
    double X = 0, Y = 0, Z = 0;
    for (int i = 0; i < kCieSamples; ++i) {
      X += double(kD65[i]) * kCieX[i];
      Y += double(kD65[i]) * kCieY[i];
      Z += double(kD65[i]) * kCieZ[i];
    }
    yD65 = Y;
    Vec3 w = XYZToRGB(Vec3(float(X / Y), 1.0f, float(Z / Y)));
    whiteScale = Vec3(1.0f) / w;
  }
  Vec3 rgb(const Vec3& xyz) const { return XYZToRGB(xyz) * whiteScale; }
};
const Projection& projection() {
  static const Projection p;
  return p;
}

inline double sigmoid(double x) { return 0.5 + x / (2.0 * std::sqrt(1.0 + x * x)); }
inline double sigmoidDerivative(double x) { return 0.5 / std::pow(1.0 + x * x, 1.5); }

bool solve3(double A[3][3], const double b[3], double x[3]) {
  double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
               A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  if (!(std::abs(det) > 1e-300)) return false;
  for (int k = 0; k < 3; ++k) {
    double M[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) M[r][c] = c == k ? b[r] : A[r][c];
    x[k] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
            M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
  }
  return true;
}
}  // namespace

Vec3 sampleWavelengths(float u) {
  Vec3 l;
  for (int k = 0; k < 3; ++k) {
    float x = u + float(k) / 3.0f;
    if (x >= 1.0f) x -= 1.0f;
    l[k] = kLambdaMin + kRange * x;
  }
  return l;
}

double d65Luminance() { return projection().yD65; }

Vec3 spectralToXYZ(const Spectrum& v, const Vec3& lambda) {
  Vec3 xyz(0.0f);
  for (int k = 0; k < 3; ++k) xyz += v[k] * cieXYZ(lambda[k]);
  // Δ/3 per wavelength sample (pdf 1/Δ each, three of them), per unit of the D65 luminance.
  return xyz * float(kRange / 3.0 / projection().yD65);
}

Spectrum spectralXYZToRGB(const Vec3& xyz) { return projection().rgb(xyz); }

Spectrum spectralToRGB(const Spectrum& v, const Vec3& lambda) { return spectralXYZToRGB(spectralToXYZ(v, lambda)); }

// ---------- RGB uplift ----------

RGBUplift::RGBUplift() {
  const Projection& p = projection();
  for (int i = 0; i < kCieSamples; ++i)
    projection_[i] = p.rgb(Vec3(kCieX[i], kCieY[i], kCieZ[i]) * float(kD65[i] / p.yD65));
  const int n = kGrid;
  nodes_.resize(size_t(n) * n * n * kCieSamples);
  std::vector<float> errors(size_t(n) * n * n);
  parallelFor(size_t(n) * n * n, 0, [&](size_t node, int) {  // each node independent: deterministic
    int r = int(node / (n * n)), g = int(node / n % n), b = int(node % n);
    Vec3 rgb = Vec3(r, g, b) / float(n - 1);
    std::vector<float> s = fitNode(rgb);
    std::copy(s.begin(), s.end(), nodes_.begin() + node * kCieSamples);
    Vec3 e = glm::abs(rgbOfReflectance(s) - rgb);
    errors[node] = std::max(e.x, std::max(e.y, e.z));
  });
  for (float e : errors) worstNodeError_ = std::max(worstNodeError_, e);
}

Vec3 RGBUplift::rgbOfReflectance(const std::vector<float>& s) const {
  Vec3 sum(0.0f);
  for (int i = 0; i < kCieSamples; ++i) sum += s[i] * projection_[i];
  return sum;
}

// Gauss–Newton on the 3 coefficients of σ(c₀t² + c₁t + c₂), t = (λ − 360)/470, for the 3
// equations RGB(σ) = rgb, walked from grey (c = 0, RGB 0.5) to the target in small steps so
// each solve starts near its answer (the continuation Jakob & Hanika use to build their tables).
// Greys are constant spectra, exactly.
std::vector<float> RGBUplift::fitNode(const Vec3& rgb) const {
  std::vector<float> s(kCieSamples);
  if (rgb.x == rgb.y && rgb.y == rgb.z) {
    std::fill(s.begin(), s.end(), rgb.x);
    return s;
  }
  double c[3] = {0, 0, 0};
  auto evaluate = [&](const double* cc, double* rgbOut, double J[3][3]) {
    double out[3] = {0, 0, 0};
    if (J)
      for (int ch = 0; ch < 3; ++ch)
        for (int k = 0; k < 3; ++k) J[ch][k] = 0;
    for (int i = 0; i < kCieSamples; ++i) {
      double t = double(i) / (kCieSamples - 1);
      double x = (cc[0] * t + cc[1]) * t + cc[2];
      double v = sigmoid(x);
      const Vec3& P = projection_[i];
      for (int ch = 0; ch < 3; ++ch) out[ch] += v * P[ch];
      if (J) {
        double d = sigmoidDerivative(x), basis[3] = {t * t, t, 1.0};
        for (int ch = 0; ch < 3; ++ch)
          for (int k = 0; k < 3; ++k) J[ch][k] += d * basis[k] * P[ch];
      }
    }
    for (int ch = 0; ch < 3; ++ch) rgbOut[ch] = out[ch];
  };
  const int steps = 8;
  for (int step = 1; step <= steps; ++step) {
    double f = double(step) / steps;
    double target[3];
    for (int ch = 0; ch < 3; ++ch) target[ch] = 0.5 + f * (rgb[ch] - 0.5);
    for (int it = 0; it < 50; ++it) {
      double now[3], J[3][3];
      evaluate(c, now, J);
      double r[3] = {now[0] - target[0], now[1] - target[1], now[2] - target[2]};
      double err = std::abs(r[0]) + std::abs(r[1]) + std::abs(r[2]);
      if (err < 1e-7) break;
      double delta[3], minusR[3] = {-r[0], -r[1], -r[2]};
      if (!solve3(J, minusR, delta)) break;
      // Damped: halve the step until the residual decreases.
      double scale = 1.0;
      for (int tries = 0; tries < 30; ++tries, scale *= 0.5) {
        double trial[3] = {c[0] + scale * delta[0], c[1] + scale * delta[1], c[2] + scale * delta[2]}, v[3];
        evaluate(trial, v, nullptr);
        double e2 = std::abs(v[0] - target[0]) + std::abs(v[1] - target[1]) + std::abs(v[2] - target[2]);
        if (e2 < err) {
          std::copy(trial, trial + 3, c);
          break;
        }
      }
    }
  }
  for (int i = 0; i < kCieSamples; ++i) {
    double t = double(i) / (kCieSamples - 1);
    s[i] = float(sigmoid((c[0] * t + c[1]) * t + c[2]));
  }
  return s;
}

const RGBUplift& RGBUplift::instance() {
  static const RGBUplift uplift;
  return uplift;
}

float RGBUplift::reflectance(const Vec3& rgbIn, float lambda) const {
  Vec3 rgb = glm::clamp(rgbIn, Vec3(0.0f), Vec3(1.0f));
  float x = lambda - kLambdaMin;
  if (!(x >= 0.0f) || x > float(kCieSamples - 1)) return 0.0f;
  int li = std::min(int(x), kCieSamples - 2);
  float lt = x - float(li);
  const int n = kGrid;
  Vec3 g = rgb * float(n - 1);
  int i0[3];
  float t[3];
  for (int k = 0; k < 3; ++k) {
    i0[k] = std::min(int(g[k]), n - 2);
    t[k] = g[k] - float(i0[k]);
  }
  // Tetrahedral (Kuhn) interpolation: the cell splits into 6 tetrahedra along its diagonal; the
  // 4 weights are barycentric, so RGB (linear in the spectrum) is reproduced exactly, spectra stay
  // in [0, 1], and a grey uses only grey nodes, so it stays flat.
  int order[3] = {0, 1, 2};
  if (t[order[0]] < t[order[1]]) std::swap(order[0], order[1]);
  if (t[order[1]] < t[order[2]]) std::swap(order[1], order[2]);
  if (t[order[0]] < t[order[1]]) std::swap(order[0], order[1]);
  int idx[3] = {i0[0], i0[1], i0[2]};
  auto node = [&]() { return &nodes_[((size_t(idx[0]) * n + idx[1]) * n + idx[2]) * kCieSamples]; };
  auto value = [&](const float* s) { return (1.0f - lt) * s[li] + lt * s[li + 1]; };
  float sum = (1.0f - t[order[0]]) * value(node());
  float previous = t[order[0]];
  for (int k = 0; k < 3; ++k) {
    ++idx[order[k]];
    float next = k < 2 ? t[order[k + 1]] : 0.0f;
    sum += (previous - next) * value(node());
    previous = next;
  }
  return sum;
}

Spectrum spectralReflectance(const Spectrum& rgb, const SampledWavelengths& ctx) {
  if (!ctx.spectral) return rgb;
  const RGBUplift& u = RGBUplift::instance();
  return Spectrum(u.reflectance(rgb, ctx.lambda.x), u.reflectance(rgb, ctx.lambda.y), u.reflectance(rgb, ctx.lambda.z));
}

Spectrum spectralEmission(const Spectrum& rgb, const SampledWavelengths& ctx) {
  if (!ctx.spectral) return rgb;
  float m = std::max(rgb.x, std::max(rgb.y, rgb.z));
  if (!(m > 0.0f)) return Spectrum(0.0f);
  const RGBUplift& u = RGBUplift::instance();
  Vec3 c = rgb / m;
  Spectrum out;
  for (int k = 0; k < 3; ++k) out[k] = m * u.reflectance(c, ctx.lambda[k]) * d65(ctx.lambda[k]);
  return out;
}

void emissionTable(const Vec3& unitColour, LazySpectrum::Table* t) {
  const RGBUplift& u = RGBUplift::instance();
  for (int i = 0; i < kCieSamples; ++i) (*t)[i] = u.reflectance(unitColour, kLambdaMin + float(i)) * kD65[i];
}

void blackbodyTable(double T, LazySpectrum::Table* t) {
  // Luminance 1 in the units where D65 has Y = 1: Σ B ȳ over the 1 nm samples, over Y_D65.
  double Y = 0;
  for (int i = 0; i < kCieSamples; ++i) Y += planck(kLambdaMin + i, T) * kCieY[i];
  double norm = d65Luminance() / Y;
  for (int i = 0; i < kCieSamples; ++i) (*t)[i] = float(planck(kLambdaMin + i, T) * norm);
}

void equalEnergyTable(LazySpectrum::Table* t) { t->fill(float(d65Luminance() / kCieYIntegral)); }

Vec3 equalEnergyRGB() {
  double X = 0, Y = 0, Z = 0;
  for (int i = 0; i < kCieSamples; ++i) X += kCieX[i], Y += kCieY[i], Z += kCieZ[i];
  return projection().rgb(Vec3(float(X / Y), 1.0f, float(Z / Y)));
}

Vec3 blackbodyRGB(double T) {
  double X = 0, Y = 0, Z = 0;
  for (int i = 0; i < kCieSamples; ++i) {
    double b = planck(kLambdaMin + i, T);
    X += b * kCieX[i];
    Y += b * kCieY[i];
    Z += b * kCieZ[i];
  }
  return projection().rgb(Vec3(float(X / Y), 1.0f, float(Z / Y)));  // luminance 1
}

}  // namespace pl
