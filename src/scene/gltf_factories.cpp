#include "scene/gltf_factories.h"

#include <tiny_gltf.h>

#include "bsdfs/clearcoat.h"
#include "bsdfs/dielectric.h"
#include "bsdfs/ggx_conductor.h"
#include "bsdfs/lambertian.h"
#include "bsdfs/metallic_roughness.h"
#include "bsdfs/mirror.h"
#include "bsdfs/phong.h"
#include "bsdfs/sheen.h"
#include "bsdfs/thin_dielectric.h"
#include "lights/directional_light.h"
#include "lights/point_light.h"
#include "lights/spot_light.h"
#include "lights/warn_spotlight.h"

namespace pl {

const std::vector<BSDFFactory>& bsdfFactories() {
  static const std::vector<BSDFFactory> table = {
      // extras.photonlab.phong = {kd, ks, exponent}: the course notes' modified Phong.
      {"phong", [](const GltfMaterial& m) { return m.extras && m.extras->IsObject() && m.extras->Has("phong"); },
       [](const GltfMaterial& m, GltfReader& r, Material&) -> std::unique_ptr<BSDF> {
         const tinygltf::Value& ph = m.extras->Get("phong");
         const std::string el = m.element + ".extras.photonlab.phong";
         if (!ph.IsObject() || !ph.Has("kd") || !ph.Has("ks") || !ph.Has("exponent") || !ph.Get("exponent").IsNumber())
           r.fail(el, "needs {kd, ks, exponent}");
         const Spectrum kd = r.spectrum(ph.Get("kd"), el + ".kd"), ks = r.spectrum(ph.Get("ks"), el + ".ks");
         const float n = float(ph.Get("exponent").GetNumberAsDouble());
         r.checkRange(el + ".kd", kd, 0.0f, 1.0f);
         r.checkRange(el + ".ks", ks, 0.0f, 1.0f);
         r.checkRange(el + ".kd+ks (energy conservation)", kd + ks, 0.0f, 1.0f);
         if (!(n >= 0 && n < 1e6f)) r.fail(el + ".exponent", "must be in [0, 1e6)");
         return std::make_unique<Phong>(kd, ks, n);
       }},
      // Transmission with a volume: smooth glass, Beer–Lambert inside (Scene::transmittance).
      {"dielectric", [](const GltfMaterial& m) { return m.transmission > 0 && m.thickness > 0; },
       [](const GltfMaterial& m, GltfReader&, Material& out) -> std::unique_ptr<BSDF> {
         out.attenuationColor = ColorTexture(m.attenuationColor);
         out.attenuationDistance = float(m.attenuationDistance);
         return std::make_unique<Dielectric>(float(m.ior), m.dispersion > 0 ? float(20.0 / m.dispersion) : 0.0f);
       }},
      // Thin-walled, smooth and wholly transmissive (a window pane): the delta limit of the
      // metallic-roughness transmission lobe, so that photons and paths pass straight through.
      {"thin dielectric",
       [](const GltfMaterial& m) {
         return m.transmission == 1 && m.transmissionTexture < 0 && m.metallic == 0 && m.roughness == 0 && !m.mrTextured;
       },
       [](const GltfMaterial& m, GltfReader&, Material&) -> std::unique_ptr<BSDF> {
         return std::make_unique<ThinDielectric>(m.base, float(m.ior));
       }},
      {"lambertian", [](const GltfMaterial& m) { return m.lambertian && m.transmission == 0; },
       [](const GltfMaterial& m, GltfReader&, Material&) -> std::unique_ptr<BSDF> { return std::make_unique<Lambertian>(m.base); }},
      // The metal lobe's limit α → 0, a delta.
      {"mirror", [](const GltfMaterial& m) { return m.metallic == 1.0f && m.roughness == 0.0f && !m.mrTextured; },
       [](const GltfMaterial& m, GltfReader&, Material&) -> std::unique_ptr<BSDF> { return std::make_unique<Mirror>(m.base); }},
      // The metal lobe alone.
      {"ggx", [](const GltfMaterial& m) { return m.metallic == 1.0f && !m.mrTextured; },
       [](const GltfMaterial& m, GltfReader&, Material&) -> std::unique_ptr<BSDF> {
         return std::make_unique<GGXConductor>(m.base, m.roughness * m.roughness);
       }},
      {"metallic-roughness", [](const GltfMaterial&) { return true; },
       [](const GltfMaterial& m, GltfReader& r, Material&) -> std::unique_ptr<BSDF> {
         ColorTexture mr = m.metallicRoughness();
         ColorTexture through = m.transmissionColor();
         if (m.transmission > 0 && m.ior != 1.5)
           r.ignored("KHR_materials_ior on a rough thin-walled surface is ignored (its Fresnel layer is glTF's ior 1.5)");
         return std::make_unique<MetallicRoughness>(m.base, std::move(mr), std::move(through));
       }},
  };
  return table;
}

const std::vector<BSDFLayerFactory>& bsdfLayerFactories() {
  static const std::vector<BSDFLayerFactory> table = {
      {"sheen", [](const GltfMaterial& m) { return m.sheen > 0; },
       [](const GltfMaterial& m, GltfReader&) -> std::unique_ptr<BSDFLayer> {
         return std::make_unique<Sheen>(m.sheenColor(), m.sheenRoughness());
       }},
      {"clearcoat", [](const GltfMaterial& m) { return m.clearcoat > 0; },
       [](const GltfMaterial& m, GltfReader&) -> std::unique_ptr<BSDFLayer> {
         return std::make_unique<Clearcoat>(m.clearcoatWeight(), m.clearcoatRoughness());
       }},
  };
  return table;
}

const std::vector<LightFactory>& lightFactories() {
  // extras.photonlab.power (a white light's flux, scaled by its colour) replaces the intensity.
  static const std::vector<LightFactory> table = {
      {"point", [](const GltfLight& l) { return l.type == "point"; },
       [](const GltfLight& l, GltfReader&) -> std::unique_ptr<Light> {
         return std::make_unique<PointLight>(l.position, l.power >= 0 ? PointLight::intensityForPower(l.color * float(l.power)) : l.I);
       }},
      // A spot with extras.photonlab.warn_exponent: Warn's c·cosˢθ instead of glTF's cone falloff.
      {"warn spotlight", [](const GltfLight& l) { return l.type == "spot" && l.warnExponent >= 0; },
       [](const GltfLight& l, GltfReader&) -> std::unique_ptr<Light> {
         const float s = float(l.warnExponent);
         return std::make_unique<WarnSpotlight>(l.position, l.direction,
                                                l.power >= 0 ? WarnSpotlight::cForPower(l.color * float(l.power), s) : l.I, s);
       }},
      {"spot", [](const GltfLight& l) { return l.type == "spot"; },
       [](const GltfLight& l, GltfReader& r) -> std::unique_ptr<Light> {
         const float inner = l.innerCone, outer = l.outerCone;
         if (!(inner >= 0 && inner < outer && outer <= kPi / 2 + 1e-6f))
           r.fail(l.element + ".spot", "need 0 ≤ innerConeAngle < outerConeAngle ≤ π/2");
         return std::make_unique<SpotLight>(l.position, l.direction,
                                            l.power >= 0 ? SpotLight::intensityForPower(l.color * float(l.power), inner, outer) : l.I,
                                            inner, outer);
       }},
      {"directional", [](const GltfLight& l) { return l.type == "directional"; },
       [](const GltfLight& l, GltfReader&) -> std::unique_ptr<Light> {
         return std::make_unique<DirectionalLight>(l.direction, l.power >= 0 ? l.color : l.I, float(l.power));
       }},
  };
  return table;
}

}  // namespace pl
