// glTF materials to BSDFs and glTF lights to lights, through tables: a new BSDF or light is its
// own file (src/bsdfs/, src/lights/) plus one row here. The loader reads and checks a material's
// or a light's fields (scene/gltf_loader.cpp); the rows are tried in order, and the first that
// applies makes the object.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bsdfs/bsdf.h"
#include "bsdfs/layered.h"
#include "image/texture.h"
#include "lights/light.h"
#include "scene/scene.h"

namespace tinygltf {
class Value;
}

namespace pl {

// What a row may ask of the loader: a message naming the file and the field (fail: the load
// stops), a feature it ignores (said once per file), and typed, checked values.
class GltfReader {
 public:
  [[noreturn]] virtual void fail(const std::string& element, const std::string& what) const = 0;
  virtual void ignored(const std::string& what) = 0;
  virtual Spectrum spectrum(const tinygltf::Value& v, const std::string& element) = 0;  // a number or [r, g, b]
  virtual void checkRange(const std::string& element, const Spectrum& s, float lo, float hi) = 0;

 protected:
  ~GltfReader() = default;
};

// A glTF material in the specification's terms, its extensions read and checked.
struct GltfMaterial {
  std::string element;  // "materials[3]", for messages
  ColorTexture base{Spectrum(1.0f)};  // baseColorFactor × baseColorTexture
  float metallic = 1.0f, roughness = 1.0f;
  bool mrTextured = false;  // a metallicRoughnessTexture
  std::function<ColorTexture()> metallicRoughness;  // factor (1, roughness, metallic) × that texture, loaded when asked
  double transmission = 0.0, thickness = 0.0, ior = 1.5, dispersion = 0.0;  // KHR_materials_transmission, _volume, _ior, _dispersion
  int transmissionTexture = -1;
  std::function<ColorTexture()> transmissionColor;  // transmissionFactor × the texture's R, loaded when asked
  Spectrum attenuationColor{1.0f};
  double attenuationDistance = INFINITY;
  // KHR_materials_clearcoat: factor × clearcoatTexture's R, and roughness factor × its texture's
  // G (in a ColorTexture's G channel); KHR_materials_sheen: colour factor × texture, and
  // roughness factor × its texture's alpha. Textures loaded when asked.
  float clearcoat = 0.0f, sheen = 0.0f;  // clearcoatFactor; the largest of sheenColorFactor
  std::function<ColorTexture()> clearcoatWeight, clearcoatRoughness, sheenColor;
  std::function<AlphaTexture()> sheenRoughness;
  bool lambertian = false;                  // extras.photonlab.bsdf = "lambertian"
  const tinygltf::Value* extras = nullptr;  // extras.photonlab, or null
};

// One row of the material table. make() may set what else the material carries (the medium
// inside a glass volume).
struct BSDFFactory {
  const char* name;
  std::function<bool(const GltfMaterial&)> applies;
  std::function<std::unique_ptr<BSDF>(const GltfMaterial&, GltfReader&, Material&)> make;
};
const std::vector<BSDFFactory>& bsdfFactories();

// A layer over what the material rows made, tried in order, each applied when it applies:
// sheen, then clearcoat over it (the specification's order). A base with only delta lobes
// (glass, a mirror) is left bare, said once per file.
struct BSDFLayerFactory {
  const char* name;
  std::function<bool(const GltfMaterial&)> applies;
  std::function<std::unique_ptr<BSDFLayer>(const GltfMaterial&, GltfReader&)> make;
};
const std::vector<BSDFLayerFactory>& bsdfLayerFactories();

// A KHR_lights_punctual light, its photonlab extras read and checked.
struct GltfLight {
  std::string element, type;   // type: "point", "spot" or "directional"
  Vec3 position{0.0f}, direction{0.0f, 0.0f, -1.0f};
  Spectrum color{1.0f}, I{0.0f};  // I = colour × intensity: W/sr (directional: W/m²)
  double power = -1.0;            // extras.photonlab.power (W), or −1: from the intensity
  double warnExponent = -1.0;     // extras.photonlab.warn_exponent, or −1
  float innerCone = 0.0f, outerCone = 0.0f;  // spot.innerConeAngle, outerConeAngle
};
struct LightFactory {
  const char* name;
  std::function<bool(const GltfLight&)> applies;
  std::function<std::unique_ptr<Light>(const GltfLight&, GltfReader&)> make;
};
const std::vector<LightFactory>& lightFactories();

}  // namespace pl
