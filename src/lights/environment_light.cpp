#include "lights/environment_light.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "core/frame.h"

namespace pl {

namespace {
// A float as a person wrote it (0.8, not 0.800000012).
std::string shortNumber(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", double(v));
  return buf;
}
std::string rgbText(const Spectrum& c) { return shortNumber(c.r) + ", " + shortNumber(c.g) + ", " + shortNumber(c.b); }

// cos θ_j at the top edge of row j of an H-row map: θ_j = jπ/H.
double rowEdge(int j, int height) { return std::cos(kPi * double(j) / double(height)); }
}  // namespace

EnvironmentLight::EnvironmentLight(ImageRGB map, float rotationDegrees, std::string description)
    : Light(LightType::kInfinite), map_(std::move(map)), description_(std::move(description)) {
  const float a = rotationDegrees * (kPi / 180.0f);
  cos_ = std::cos(a), sin_ = std::sin(a);
  const int W = map_.width, H = map_.height;
  // Texel (i, j) spans Δφ = 2π/W and cosθ from rowEdge(j) down to rowEdge(j + 1).
  std::vector<float> rowWeights(static_cast<size_t>(H));
  columns_.reserve(size_t(H));
  double luminanceIntegral = 0.0;
  glm::dvec3 integral(0.0);
  for (int j = 0; j < H; ++j) {
    const double dOmega = (2.0 * kPi / W) * (rowEdge(j, H) - rowEdge(j + 1, H));
    std::vector<float> w(static_cast<size_t>(W));
    double rowLuminance = 0.0;
    for (int i = 0; i < W; ++i) {
      Spectrum L = map_.at(i, j);
      w[size_t(i)] = luminance(L);
      rowLuminance += w[size_t(i)];
      integral += glm::dvec3(L) * dOmega;
    }
    columns_.emplace_back(w);
    rowWeights[size_t(j)] = float(rowLuminance * dOmega);
    luminanceIntegral += rowLuminance * dOmega;
  }
  rows_ = PiecewiseConstant1D(rowWeights);
  inverseLuminanceIntegral_ = luminanceIntegral > 0 ? float(1.0 / luminanceIntegral) : 0.0f;
  integral_ = Spectrum(integral);
}

std::unique_ptr<EnvironmentLight> EnvironmentLight::constant(const Spectrum& radiance) {
  ImageRGB map(1, 1);
  map.set(0, 0, radiance);
  return std::make_unique<EnvironmentLight>(std::move(map), 0.0f, "constant " + rgbText(radiance) + " W/(m2 sr)");
}

void EnvironmentLight::preprocess(const Vec3& center, float radius) {
  center_ = center;
  radius_ = std::max(radius, 1e-6f);
}

std::pair<int, int> EnvironmentLight::texel(const Vec3& d) const {
  const Vec3 l = toLocal(d);
  float u = std::atan2(l.x, -l.z) * kInv2Pi;
  if (u < 0) u += 1.0f;
  float v = std::acos(std::clamp(l.y, -1.0f, 1.0f)) * kInvPi;
  int i = std::min(int(u * float(map_.width)), map_.width - 1);
  int j = std::min(int(v * float(map_.height)), map_.height - 1);
  return {std::max(i, 0), std::max(j, 0)};
}

Spectrum EnvironmentLight::radiance(const Vec3& d, const SampledWavelengths& lambda, float* pdf) const {
  if (map_.width == 1 && map_.height == 1) {  // one colour: its spectrum cached
    if (pdf) *pdf = luminance(map_.at(0, 0)) * inverseLuminanceIntegral_;
    return emit(map_.at(0, 0), lambda);
  }
  auto [i, j] = texel(d);
  Spectrum L = map_.at(i, j);
  if (pdf) *pdf = luminance(L) * inverseLuminanceIntegral_;
  return lambda.spectral ? spectralEmission(L, lambda) : L;
}

float EnvironmentLight::pdf(const Vec3& d) const {
  auto [i, j] = texel(d);
  return luminance(map_.at(i, j)) * inverseLuminanceIntegral_;
}

Vec3 EnvironmentLight::sampleDirection(const Vec2& u, float* pdf) const {
  float tRow, tColumn;
  const size_t j = rows_.sample(u.y, &tRow);
  const size_t i = columns_[j].sample(u.x, &tColumn);
  const int W = map_.width, H = map_.height;
  // Uniform in solid angle inside the texel: φ and cosθ uniform over its ranges.
  const double top = rowEdge(int(j), H), bottom = rowEdge(int(j) + 1, H);
  const float cosTheta = float(top - double(tRow) * (top - bottom));
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  const Vec2 sc = sinCos2Pi((float(i) + tColumn) / float(W));  // (sin φ, cos φ)
  *pdf = luminance(map_.at(int(i), int(j))) * inverseLuminanceIntegral_;
  return toWorld(Vec3(sinTheta * sc.x, cosTheta, -sinTheta * sc.y));
}

bool EnvironmentLight::sampleLi(const Vec3&, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const {
  s->wi = sampleDirection(u, &s->pdf);
  if (!(s->pdf > 0)) return false;
  s->distance = INFINITY;
  s->Li = radiance(s->wi, lambda);
  return true;
}

EmittedRay EnvironmentLight::sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const {
  float pdfDir;
  const Vec3 d = sampleDirection(uDirection, &pdfDir);  // towards the sky; the photon goes along −d
  const Frame frame(d);
  const Vec2 disc = sampleConcentricDisc(uPosition) * radius_;
  const Vec3 origin = center_ + d * radius_ + frame.s * disc.x + frame.t * disc.y;
  const float pdfPos = 1.0f / (kPi * radius_ * radius_);
  EmittedRay e{Ray{origin, -d}, pdfDir > 0 ? radiance(d, lambda) / (pdfDir * pdfPos) : Spectrum(0.0f)};
  e.pdfPos = pdfPos;
  e.pdfDir = pdfDir;
  return e;
}

void EnvironmentLight::pdfLe(const Ray& ray, const Vec3&, float* pdfPos, float* pdfDir) const {
  *pdfPos = 1.0f / (kPi * radius_ * radius_);
  *pdfDir = pdf(-ray.d);
}

std::string EnvironmentSpec::describe() const {
  if (map.empty() && !sky.empty()) return sky + " sky (CIE), mean radiance " + rgbText(radiance * scale) + " W/(m2 sr)";
  if (map.empty()) return "constant " + rgbText(radiance * scale) + " W/(m2 sr)";
  std::string s = "map " + map;
  if (rotation != 0) s += ", rotated " + shortNumber(rotation) + " deg";
  if (scale != 1) s += ", scale " + shortNumber(scale);
  return s;
}

EnvironmentSpec defaultEnvironment() {
  EnvironmentSpec e;
  e.enabled = true;
  e.radiance = Spectrum(1.0f);
  e.sky = "overcast";
  return e;
}

ImageRGB overcastSky(const Spectrum& mean, int rows) {
  // Band [μb, μa] of cosθ (dω ∝ dμ): the mean of (1 + 2μ)/3 is (1 + μa + μb)/3 above the horizon.
  const int H = rows + rows % 2;  // even: the horizon is a row edge
  std::vector<double> L(static_cast<size_t>(H));
  double integral = 0;
  for (int j = 0; j < H; ++j) {
    const double a = rowEdge(j, H), b = rowEdge(j + 1, H);
    L[size_t(j)] = j < H / 2 ? (1 + a + b) / 3 : 0.7 / 3;
    integral += L[size_t(j)] * 2 * kPi * (a - b);
  }
  ImageRGB map(1, H);
  for (int j = 0; j < H; ++j) map.set(0, j, mean * float(L[size_t(j)] * 4 * kPi / integral));
  return map;
}

EnvironmentSpec parseEnvironment(const std::string& text, const std::string& field) {
  EnvironmentSpec e;
  e.enabled = true;
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t comma; (comma = text.find(',', start)) != std::string::npos; start = comma + 1)
    parts.push_back(text.substr(start, comma - start));
  parts.push_back(text.substr(start));
  std::vector<double> values;
  for (const std::string& p : parts) {
    char* end = nullptr;
    double v = std::strtod(p.c_str(), &end);
    if (p.empty() || end != p.c_str() + p.size()) break;
    values.push_back(v);
  }
  if (text == "overcast") {
    e.sky = text;
    return e;
  }
  if (values.size() != parts.size()) {  // not numbers: a file
    if (parts.size() > 1 && !values.empty())
      throw Error(field + ": expected R,G,B radiance (or one number) or an image file, got '" + text + "'");
    e.map = text;
    return e;
  }
  if (values.size() != 1 && values.size() != 3)
    throw Error(field + ": expected R,G,B radiance (or one number) or an image file, got '" + text + "'");
  for (double v : values)
    if (!(v >= 0) || !std::isfinite(v)) throw Error(field + ": radiance must be finite and >= 0, got '" + text + "'");
  e.radiance = values.size() == 1 ? Spectrum(float(values[0])) : Spectrum(float(values[0]), float(values[1]), float(values[2]));
  return e;
}

std::unique_ptr<EnvironmentLight> makeEnvironment(const EnvironmentSpec& spec, const ImageReader& read,
                                                  const std::string& field) {
  if (!(spec.scale >= 0) || !std::isfinite(spec.scale)) throw Error(field + ": scale must be finite and >= 0");
  if (!std::isfinite(spec.rotation)) throw Error(field + ": rotation must be a finite angle in degrees");
  if (spec.map.empty() && !spec.sky.empty())
    return std::make_unique<EnvironmentLight>(overcastSky(spec.radiance * spec.scale), spec.rotation, spec.describe());
  if (spec.map.empty()) return EnvironmentLight::constant(spec.radiance * spec.scale);
  if (!std::filesystem::is_regular_file(spec.map)) throw Error(field + ": file not found: " + spec.map);
  if (!read) throw Error(field + ": " + spec.map + ": no image reader here to read an environment map");
  ImageRGB map = read(spec.map);
  if (map.width < 1 || map.height < 1) throw Error(spec.map + ": " + field + ": the image is empty");
  bool lit = false;
  for (float& v : map.data) {
    if (!std::isfinite(v) || v < 0)
      throw Error(spec.map + ": " + field + ": texel values must be finite and >= 0 (found " + formatNumber(v) + ")");
    v *= spec.scale;
    lit |= v > 0;
  }
  if (!lit) throw Error(spec.map + ": " + field + ": the map is black everywhere");
  return std::make_unique<EnvironmentLight>(std::move(map), spec.rotation, spec.describe());
}

}  // namespace pl
