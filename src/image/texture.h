// A colour that may vary over the surface: factor × texel (glTF's baseColorFactor × texture).
#pragma once
#include <cmath>
#include <memory>
#include <vector>
#include "core/common.h"
#include "spectral/spectral.h"

namespace pl {

struct Image {
  int width = 0, height = 0;
  std::vector<Spectrum> texels;  // linear RGB, row 0 at the top (glTF uv (0,0) is top-left)
  std::vector<float> alpha;      // coverage (linear), per texel; empty when the image has none
};

// Bilinear lookup with repeat wrapping (the glTF default sampler) of texel(i, j), i across.
template <typename T, typename Texel>
T bilinearRepeat(const Image& image, const Vec2& uv, const Texel& texel) {
  float x = (uv.x - std::floor(uv.x)) * image.width - 0.5f;
  float y = (uv.y - std::floor(uv.y)) * image.height - 0.5f;
  int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  float fx = x - x0, fy = y - y0;
  auto at = [&](int i, int j) {
    i = ((i % image.width) + image.width) % image.width;
    j = ((j % image.height) + image.height) % image.height;
    return texel(size_t(j) * image.width + i);
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) + fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// KHR_texture_transform: uv' = T(offset)·R(rotation)·S(scale)·uv, as the extension's GLSL
// states it: u' = cos·sx·u − sin·sy·v + ox, v' = sin·sx·u + cos·sy·v + oy.
struct UvTransform {
  Vec2 offset{0.0f}, scale{1.0f};
  float cosRotation = 1.0f, sinRotation = 0.0f;  // of the rotation, radians (setRotation)
  void setRotation(float radians) { cosRotation = std::cos(radians), sinRotation = std::sin(radians); }
  bool identity() const { return offset == Vec2(0.0f) && scale == Vec2(1.0f) && cosRotation == 1.0f && sinRotation == 0.0f; }
  Vec2 apply(const Vec2& uv) const {
    const Vec2 p = scale * uv;
    return Vec2(cosRotation * p.x - sinRotation * p.y, sinRotation * p.x + cosRotation * p.y) + offset;
  }
};

class ColorTexture {
 public:
  ColorTexture(const Spectrum& factor = Spectrum(1.0f), std::shared_ptr<const Image> image = nullptr,
               const UvTransform& transform = {})
      : factor_(factor), image_(std::move(image)), spectrum_(image_ ? nullptr : std::make_shared<LazySpectrum>()),
        transform_(transform), transformed_(!transform.identity()) {}

  // In spectral mode, the uplifted reflectance at the path's wavelengths (spectral/spectral.h);
  // a constant colour's spectrum is tabulated once. `tint` (a vertex colour, linear RGB)
  // multiplies the colour before the uplift.
  PL_HOT_INLINE Spectrum eval(const Vec2& uv, const SampledWavelengths& lambda, const Spectrum& tint = Spectrum(1.0f)) const {
    // A constant colour in RGB: the case on nearly every vertex, kept small enough to inline
    // (× a white tint is exact, so this is the general branch's value bit for bit).
    if (!lambda.spectral && !image_) return factor_ * tint;
    return evalGeneral(uv, lambda, tint);
  }
  Spectrum evalRGB(const Vec2& surfaceUV) const {
    if (!image_) return factor_;
    const Vec2 uv = transformed_ ? transform_.apply(surfaceUV) : surfaceUV;
    Spectrum c = bilinearRepeat<Spectrum>(*image_, uv, [&](size_t k) { return image_->texels[k]; });
    return factor_ * c;
  }
  bool isConstant() const { return !image_; }
  const Image* image() const { return image_.get(); }
  const Spectrum& factor() const { return factor_; }

 private:
  // eval() beyond a constant RGB colour: a texture image, or the spectral uplift.
  Spectrum evalGeneral(const Vec2& uv, const SampledWavelengths& lambda, const Spectrum& tint) const {
    const bool white = tint == Spectrum(1.0f);
    if (!lambda.spectral) return white ? evalRGB(uv) : evalRGB(uv) * tint;
    if (!spectrum_ || !white) return spectralReflectance(white ? evalRGB(uv) : evalRGB(uv) * tint, lambda);
    const auto& table = spectrum_->get([&](LazySpectrum::Table& t) {
      const RGBUplift& u = RGBUplift::instance();
      for (int i = 0; i < kCieSamples; ++i) t[i] = u.reflectance(factor_, kLambdaMin + float(i));
    });
    return LazySpectrum::at(table, lambda.lambda);
  }
  Spectrum factor_;
  std::shared_ptr<const Image> image_;
  std::shared_ptr<const LazySpectrum> spectrum_;  // shared by copies of a constant texture
  UvTransform transform_;
  bool transformed_ = false;
};

// glTF coverage: baseColorFactor's alpha × the base-colour texture's alpha channel (linear),
// looked up through the base-colour texture's transform. 1 where the image has no alpha.
class AlphaTexture {
 public:
  AlphaTexture(float factor, std::shared_ptr<const Image> image, const UvTransform& transform)
      : factor_(factor), image_(image && !image->alpha.empty() ? std::move(image) : nullptr), transform_(transform) {}
  float eval(const Vec2& surfaceUV) const {
    if (!image_) return factor_;
    const Vec2 uv = transform_.identity() ? surfaceUV : transform_.apply(surfaceUV);
    return factor_ * bilinearRepeat<float>(*image_, uv, [&](size_t k) { return image_->alpha[k]; });
  }
  bool isConstant() const { return !image_; }
  float factor() const { return factor_; }

 private:
  float factor_;
  std::shared_ptr<const Image> image_;
  UvTransform transform_;
};

// glTF normalTexture: a tangent-space normal per texel, n = normalize((2c − 1) · (scale, scale, 1))
// of the linear texel c, in the frame (tangent, bitangent, normal) with bitangent =
// w · normal × tangent (+X right, +Y up, +Z out of the surface, as the specification states).
struct NormalMap {
  std::shared_ptr<const Image> image;  // linear
  UvTransform transform;
  float scale = 1.0f;
  Vec3 eval(const Vec2& surfaceUV) const {
    const Vec2 uv = transform.identity() ? surfaceUV : transform.apply(surfaceUV);
    Spectrum c = bilinearRepeat<Spectrum>(*image, uv, [&](size_t k) { return image->texels[k]; });
    Vec3 n(scale * (2 * c.x - 1), scale * (2 * c.y - 1), 2 * c.z - 1);
    float len = glm::length(n);
    return len > 0 ? n / len : Vec3(0, 0, 1);
  }
};

}  // namespace pl
