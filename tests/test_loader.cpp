// The glTF loader: what it accepts (buffers as data URIs, files and GLB chunks, hierarchies,
// the material and light mapping) and one test per kind of bad input, each a one-line error
// naming the file and the element.
#include <sys/resource.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <functional>
#include <set>

#include "bsdfs/dielectric.h"
#include "bsdfs/metallic_roughness.h"
#include "integrator_helpers.h"
#include "scene_helpers.h"
#include "render/renderer.h"
#include "ggx_reference.h"
#include "gltf_fixture.h"
#include "scene/gltf_factories.h"
#include "scene/gltf_loader.h"

using namespace pl;
using namespace pl::test;
using Catch::Matchers::Contains;

namespace {

std::string loadError(const std::string& path) {
  try {
    loadGltf(path);
  } catch (const Error& e) {
    std::string msg = e.what();
    CHECK(msg.find('\n') == std::string::npos);  // one line
    CHECK_THAT(msg, Contains(path));             // names the file
    return msg;
  }
  FAIL("loading " << path << " did not fail");
  return "";
}

}  // namespace

TEST_CASE("loader: a valid scene - as .gltf with a data URI - an external .bin - and .glb") {
  GltfFixture f;
  for (const std::string& path : {f.write("ok.gltf"), f.writeWithExternalBuffer("ext.gltf"), f.writeGlb("ok.glb")}) {
    INFO(path);
    auto scene = loadGltf(path);
    CHECK(scene->triangleCount() == 2);
    REQUIRE(scene->lights().size() == 1);
    CHECK(scene->totalPower().g == Approx(4 * kPi * 2.0f));  // point: Φ = 4πI
    CHECK(scene->camera().position.y == Approx(2.0f));
    CHECK(scene->camera().forward.y == Approx(-1.0f).margin(1e-5));  // −Z rotated to look down
    // The floor is hit straight below the camera, flat-shaded (no NORMAL): face normal.
    SurfaceHit hit;
    REQUIRE(scene->intersect(Ray{Vec3(0.3f, 2, 0.2f), Vec3(0, -1, 0)}, &hit));
    CHECK(hit.t == Approx(2.0f));
    CHECK(std::abs(hit.shading.n.y) == Approx(1.0f));
  }
}

TEST_CASE("loader: node hierarchy and transforms - non-indexed triangles - NORMAL interpolation") {
  GltfFixture f;
  // Parent translates by (5, 0, 0) and scales the child's mesh by 2.
  f.doc["nodes"][0] = {{"translation", {5, 0, 0}}, {"children", {3}}};
  f.doc["nodes"].push_back({{"mesh", 0}, {"scale", {2, 2, 2}}});
  auto scene = loadGltf(f.write("hier.gltf"));
  CHECK(scene->bounds().lo.x == Approx(3.0f));
  CHECK(scene->bounds().hi.x == Approx(7.0f));
  // Non-indexed: 6 vertices, drawn in order.
  GltfFixture g;
  float p[18] = {-1, 0, -1, -1, 0, 1, 1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0, -1};
  float n[18] = {0, 1, 0, 0, 1, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 0, 0};
  g.bin.resize(144);
  std::memcpy(g.bin.data(), p, 72);
  std::memcpy(g.bin.data() + 72, n, 72);
  g.doc["buffers"][0]["byteLength"] = 144;
  g.doc["bufferViews"] = json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 72}},
                                      {{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 72}}});
  g.doc["accessors"][0]["count"] = 6;
  g.doc["accessors"][1] = {{"bufferView", 1}, {"componentType", 5126}, {"count", 6}, {"type", "VEC3"}};
  g.doc["meshes"][0]["primitives"][0].erase("indices");
  g.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 1;
  auto s2 = loadGltf(g.write("nonindexed.gltf"));
  CHECK(s2->triangleCount() == 2);
  SurfaceHit hit;
  // First triangle, near the vertex at (1, 0, 1) whose normal is +x: interpolated normal tilts.
  REQUIRE(s2->intersect(Ray{Vec3(0.9f, 1, 0.9f), Vec3(0, -1, 0)}, &hit));
  CHECK(hit.shading.n.x > 0.3f);
  CHECK(hit.ng.y == Approx(1.0f).margin(1e-5));  // counter-clockwise seen from above: faces up
}

TEST_CASE("loader: material mapping and KHR_materials_* defaults") {
  GltfFixture f;
  json& mats = f.doc["materials"];
  mats = json::array();
  mats.push_back({{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});                               // 0 dielectric mix
  mats.push_back({{"pbrMetallicRoughness", {{"metallicFactor", 1.0}, {"roughnessFactor", 0.0}}}});      // 1 mirror
  mats.push_back({{"pbrMetallicRoughness", {{"metallicFactor", 1.0}, {"roughnessFactor", 0.4}}}});      // 2 ggx
  mats.push_back({{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},         // 3 glass
                                  {"KHR_materials_volume", {{"thicknessFactor", 0.1}, {"attenuationDistance", 0.25},
                                                            {"attenuationColor", {0.5, 0.75, 1.0}}}}}}});
  mats.push_back({{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}}},      // 4 thin, rough
                  {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});
  mats.push_back({{"extras", {{"photonlab", {{"phong", {{"kd", 0.3}, {"ks", {0.5, 0.5, 0.5}}, {"exponent", 30}}}}}}}});  // 5
  mats.push_back({{"emissiveFactor", {1.0, 0.5, 0.25}},                                                 // 6 emitter
                  {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8.0}}}}},
                  {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});
  mats.push_back({{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},                                 // 7 lambertian
                  {"extras", {{"photonlab", {{"bsdf", "lambertian"}}}}}});
  mats.push_back({{"pbrMetallicRoughness", {{"metallicFactor", 0.5}, {"roughnessFactor", 0.3}}}});      // 8 mix
  mats.push_back({{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}}},      // 9 thin, smooth: a pane
                  {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}}});
  mats.push_back({{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 0.5}}}}},      // 10 half thin, smooth
                  {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}}});
  for (int i = 0; i < 11; ++i) f.doc["meshes"][0]["primitives"].push_back(
      {{"attributes", {{"POSITION", 0}}}, {"indices", 1}, {"material", i}});
  auto scene = loadGltf(f.write("materials.gltf"));
  const auto& m = scene->materials();
  CHECK(std::string(m[0].bsdf->name()) == "metallic-roughness");  // the specification's 4 % specular layer
  CHECK(std::string(m[1].bsdf->name()) == "mirror");
  CHECK(std::string(m[2].bsdf->name()) == "ggx");
  CHECK(std::string(m[3].bsdf->name()) == "dielectric");
  CHECK(static_cast<const Dielectric*>(m[3].bsdf.get())->eta() == Approx(1.5f));  // KHR_materials_ior default
  CHECK(m[3].absorbs());  // Beer–Lambert inside: 0.5, 0.75, 1 per 0.25 m
  CHECK(m[3].attenuationDistance == 0.25f);
  CHECK(m[3].attenuationColor.factor() == Spectrum(0.5f, 0.75f, 1.0f));
  CHECK_FALSE(m[0].absorbs());
  CHECK(scene->hasAbsorbingVolumes());
  CHECK(std::string(m[4].bsdf->name()) == "metallic-roughness, thin-walled transmission");  // glTF's roughness 1
  CHECK(hasSmoothTransmission(m[4].bsdf->flags()));
  CHECK(std::string(m[5].bsdf->name()) == "phong");
  CHECK(std::string(m[7].bsdf->name()) == "lambertian");
  CHECK(std::string(m[8].bsdf->name()) == "metallic-roughness");
  CHECK_FALSE(hasSmoothTransmission(m[8].bsdf->flags()));
  CHECK(std::string(m[9].bsdf->name()) == "thin dielectric");  // the delta limit
  CHECK(std::string(m[10].bsdf->name()) == "metallic-roughness, thin-walled transmission");
  // The Lambertian marker is only for diffuse materials; anything else is an error naming it.
  GltfFixture bad;
  bad.doc["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 0.5;
  CHECK_THAT(loadError(bad.write("lambertian-metal.gltf")),
             Contains("materials[0].extras.photonlab.bsdf: \"lambertian\" needs metallicFactor 0"));
  bad.doc["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 0.0;
  bad.doc["materials"][0]["extras"]["photonlab"]["bsdf"] = "ggx";
  CHECK_THAT(loadError(bad.write("unknown-bsdf.gltf")), Contains("materials[0].extras.photonlab.bsdf: must be \"lambertian\""));
  GltfFixture volume;
  volume.doc["materials"][0]["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                                              {"KHR_materials_volume", {{"thicknessFactor", 1.0}, {"attenuationDistance", 0.0}}}};
  CHECK_THAT(loadError(volume.write("volume-distance.gltf")), Contains("materials[0].KHR_materials_volume.attenuationDistance: must be a distance > 0"));
  volume.doc["materials"][0]["extensions"]["KHR_materials_volume"] = {{"thicknessFactor", 1.0}, {"attenuationColor", {0.5, 1.5, 0.5}}};
  CHECK_THAT(loadError(volume.write("volume-colour.gltf")), Contains("materials[0].KHR_materials_volume.attenuationColor: value"));
  volume.doc["materials"][0]["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", 1.5}}}};
  CHECK_THAT(loadError(volume.write("transmission-factor.gltf")), Contains("materials[0].KHR_materials_transmission.transmissionFactor: must be in [0, 1]"));
  CHECK(m[6].emission.r == Approx(8.0f));
  CHECK(m[6].emission.b == Approx(2.0f));
  // Emissive triangles became area lights: Φ = π·Le·A per face, A = 4 m².
  Spectrum areaPower(0.0f);
  for (auto& l : scene->lights())
    if (!l->isDelta()) areaPower += l->power();
  CHECK(areaPower.r == Approx(kPi * 8.0f * 4.0f));
}


TEST_CASE("loader: extras.photonlab power and warn_exponent on lights") {
  GltfFixture f;
  f.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({
      {{"type", "point"}, {"intensity", 123.0}, {"extras", {{"photonlab", {{"power", 50.0}}}}}},
      {{"type", "spot"}, {"spot", json::object()}, {"extras", {{"photonlab", {{"power", 20.0}, {"warn_exponent", 10.0}}}}}},
      {{"type", "spot"}, {"spot", json::object()}, {"intensity", 3.0}},  // spec defaults: inner 0, outer π/4
  });
  for (int i = 1; i < 3; ++i)
    f.doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}, {"translation", {0, 1, 0}}});
  f.doc["scenes"][0]["nodes"] = {0, 1, 2, 3, 4};
  auto scene = loadGltf(f.write("lights.gltf"));
  REQUIRE(scene->lights().size() == 3);
  CHECK(scene->lights()[0]->power().g == Approx(50.0f));
  CHECK(std::string(scene->lights()[1]->name()) == "warn");
  CHECK(scene->lights()[1]->power().g == Approx(20.0f));
  float co = std::cos(kPi / 4);
  CHECK(scene->lights()[2]->power().g == Approx(3.0f * 2 * kPi * (1 - co) / 3).epsilon(1e-4));
}

TEST_CASE("loader errors: missing file - malformed JSON") {
  CHECK_THAT(loadError(GltfFixture::dir() + "/does-not-exist.gltf"), Contains("file: does not exist"));
  CHECK_THAT(loadError(GltfFixture::writeText("bad.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [")), Contains("json"));
  CHECK_THAT(loadError(GltfFixture::writeText("truncated.glb", "glTF\x02\x00\x00\x00")), Contains("glb"));
}

TEST_CASE("loader errors: short buffer - missing external buffer - view past the buffer") {
  GltfFixture f;
  f.bin.resize(40);  // byteLength still claims 72
  loadError(f.write("short.gltf"));
  GltfFixture g;
  std::string path = g.writeWithExternalBuffer("missing-bin.gltf");
  std::filesystem::remove(path + ".bin");
  CHECK_THAT(loadError(path), Contains("buffers[0].uri: file not found") && Contains("missing-bin.gltf.bin"));
  // A percent-encoded URI names the decoded file; present, it loads.
  GltfFixture e;
  std::string spaced = e.writeWithExternalBuffer("with space.gltf");
  json doc = json::parse(std::ifstream(spaced));
  doc["buffers"][0]["uri"] = "with%20space.gltf.bin";
  std::ofstream(spaced) << doc.dump();
  CHECK(loadGltf(spaced)->triangleCount() == 2);
  // A missing texture file: named by its image, not "unsupported image".
  GltfFixture t;
  t.doc["images"] = {{{"uri", "textures/albedo.png"}}};
  t.doc["textures"] = {{{"source", 0}}};
  t.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  CHECK_THAT(loadError(t.write("missing-image.gltf")), Contains("images[0].uri: file not found") && Contains("albedo.png"));
  GltfFixture h;
  h.doc["bufferViews"][1]["byteLength"] = 400;
  CHECK_THAT(loadError(h.write("view.gltf")), Contains("bufferViews[1]"));
}

TEST_CASE("loader errors: index out of range - huge accessor count - non-finite values") {
  GltfFixture f;
  uint32_t bad = 7;
  std::memcpy(f.bin.data() + 48 + 8, &bad, 4);
  CHECK_THAT(loadError(f.write("index.gltf")), Contains("indices"));
  GltfFixture g;
  g.doc["accessors"][0]["count"] = 1000000000;  // checked against the data, never allocated
  CHECK_THAT(loadError(g.write("count.gltf")), Contains("accessors[0]"));
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  CHECK(usage.ru_maxrss < 512 * 1024);  // KiB: far below the 12 GB that count would take
  GltfFixture h;
  float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(h.bin.data() + 4, &nan, 4);
  CHECK_THAT(loadError(h.write("nan.gltf")), Contains("not finite"));
  GltfFixture k;
  k.doc["nodes"][2]["translation"] = {0, 1e39, 0};  // parses to +inf
  loadError(k.write("inf.gltf"));
}

TEST_CASE("loader: a file without a camera is seen from the automatic three-quarter view, framed whole at any aspect") {
  // The fixture's floor is the square [-1, 1]² at y = 0: bounding sphere centre 0, radius √2.
  // The view (scene/camera.h): from azimuth 45° (between +Z and +X), elevation 30°, yfov 40°, at
  // distance R/sin h, h the smaller half-angle, so the sphere touches the view cone: a ray at
  // angle h from the axis towards the limiting edge is tangent to the sphere, and its tangent
  // point, at distance √(D² − R²) = D·cos h, lands on that edge of the image.
  GltfFixture f;
  f.doc["scenes"][0]["nodes"] = {0, 2};
  std::vector<std::string> warnings;
  auto scene = loadGltf(f.write("nocamera.gltf"), &warnings);
  CHECK(scene->fileCameras().empty());
  CHECK_THAT(scene->cameraSource, Contains("automatic"));
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Contains("no perspective camera"));
  const float R = std::sqrt(2.0f), pi = 3.14159265f;
  struct Case {
    int width, height;
    float half;  // the limiting half-angle: vertical 20°, or horizontal atan(tan 20° · aspect)
    bool vertical;
  };
  for (Case k : {Case{64, 64, 20 * pi / 180, true}, Case{128, 64, 20 * pi / 180, true},
                 Case{32, 64, std::atan(std::tan(20 * pi / 180) * 0.5f), false}}) {
    INFO(k.width << "x" << k.height);
    GltfLoadOptions o;
    o.aspect = float(k.width) / float(k.height);
    const Camera c = loadGltf(f.write("nocamera.gltf"), nullptr, o)->camera();
    const float D = R / std::sin(k.half);
    const Vec3 away(std::cos(pi / 6) * std::sin(pi / 4), std::sin(pi / 6), std::cos(pi / 6) * std::cos(pi / 4));
    CHECK(glm::length(c.position - D * away) < 1e-4f * D);
    CHECK(glm::length(c.forward + away) < 1e-5f);
    CHECK(std::abs(c.yfov - 40 * pi / 180) < 1e-6f);
    CHECK(std::abs(c.up.y) > 0.5f);  // upright: +Y up
    // Every corner of the floor is in the image.
    for (float x : {-1.0f, 1.0f})
      for (float z : {-1.0f, 1.0f}) {
        Vec2 r;
        CHECK(c.raster(glm::normalize(Vec3(x, 0, z) - c.position), k.width, k.height, &r));
      }
    // The tangent point towards the limiting edge lies on the sphere and on that edge.
    const Vec3 edge = k.vertical ? c.up : c.right;
    const Vec3 d = std::cos(k.half) * c.forward + std::sin(k.half) * edge * 0.99999f;
    const Vec3 tangent = c.position + D * std::cos(k.half) * glm::normalize(d);
    CHECK(std::abs(glm::length(tangent) - R) < 1e-3f * R);
    Vec2 r;
    REQUIRE(c.raster(glm::normalize(d), k.width, k.height, &r));
    if (k.vertical) CHECK(r.y < 0.01f * k.height);
    else CHECK(r.x > 0.99f * k.width);
  }
}

TEST_CASE("loader: every camera a file places is listed, the first renders, and GltfLoadOptions::camera picks another") {
  GltfFixture f;
  f.doc["nodes"].push_back({{"name", "Top"}, {"camera", 1}, {"translation", {0, 3, 0}}, {"rotation", {-0.7071068, 0, 0, 0.7071068}}});
  f.doc["cameras"].push_back({{"type", "perspective"}, {"name", "wide"}, {"perspective", {{"yfov", 1.2}, {"znear", 0.01}}}});
  f.doc["cameras"].push_back({{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.01}, {"zfar", 10}}}});
  f.doc["nodes"].push_back({{"camera", 2}});
  f.doc["scenes"][0]["nodes"] = {0, 1, 2, 3, 4};
  const std::string path = f.write("cameras.gltf");
  std::vector<std::string> warnings;
  auto first = loadGltf(path, &warnings);
  REQUIRE(first->fileCameras().size() == 2);  // the orthographic one is not usable
  CHECK_THAT(first->fileCameras()[1].name, Contains("nodes[3] 'Top', cameras[1] 'wide'"));
  CHECK(first->camera().position.y == Approx(2));
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Contains("orthographic"));
  GltfLoadOptions o;
  o.camera = 1;
  auto second = loadGltf(path, nullptr, o);
  CHECK(second->camera().position.y == Approx(3));
  CHECK(second->camera().yfov == Approx(1.2));
  CHECK(second->camera().forward.y == Approx(-1).margin(1e-5));
  o.camera = 2;
  try {
    loadGltf(path, nullptr, o);
    FAIL("no error for a camera the file does not have");
  } catch (const Error& e) {
    CHECK_THAT(std::string(e.what()), Contains(path) && Contains("--camera") && Contains("2 perspective cameras"));
  }
}

TEST_CASE("loader: a file without lights is lit by the default environment, an overcast sky of mean radiance 1, with a warning") {
  GltfFixture g;
  g.doc["scenes"][0]["nodes"] = {0, 1};
  std::vector<std::string> warnings;
  auto scene = loadGltf(g.write("nolight.gltf"), &warnings);
  REQUIRE(scene->lights().size() == 1);
  REQUIRE(scene->environment() != nullptr);
  CHECK(scene->triangleCount() == 2);
  // ∫ L dω over the sphere = 4π·1, the same in every channel.
  CHECK_THAT(scene->environment()->description(), Contains("overcast sky"));
  CHECK(scene->environment()->integral().r == Approx(4 * kPi).epsilon(1e-5));
  CHECK(scene->environment()->integral().b == Approx(4 * kPi).epsilon(1e-5));
  CHECK_THAT(scene->environmentSource, Contains("default environment"));
  int said = 0;
  for (auto& w : warnings) said += w.find("no light") != std::string::npos && w.find("default environment") != std::string::npos;
  CHECK(said == 1);
  // A file with a light gets no sky.
  GltfFixture lit;
  CHECK(loadGltf(lit.write("lit.gltf"))->environment() == nullptr);
  // Emissive materials without a punctual light: the scene's lights in a radiometric file
  // (photonlab's own scenes), self-illumination under the default sky in a photometric one.
  GltfFixture glowing;
  glowing.doc["scenes"][0]["nodes"] = {0, 1};
  glowing.doc["materials"][0]["emissiveFactor"] = {1.0, 1.0, 1.0};
  CHECK(loadGltf(glowing.write("glowing-radiometric.gltf"))->environment() == nullptr);
  glowing.doc["asset"].erase("extras");
  warnings.clear();
  auto photometric = loadGltf(glowing.write("glowing-photometric.gltf"), &warnings);
  REQUIRE(photometric->environment() != nullptr);
  CHECK_THAT(photometric->environmentSource, Contains("default environment"));
  CHECK(photometric->lights().size() == 3);  // the sky and the floor's two triangles
  said = 0;
  for (auto& w : warnings) said += w.find("self-illumination") != std::string::npos && w.find("--env 0 none") != std::string::npos;
  CHECK(said == 1);
  GltfLoadOptions none;
  none.environment = parseEnvironment("0", "--env");
  CHECK(average(loadGltf(glowing.write("glowing-dark.gltf"), nullptr, none)->environment()->power()) == 0.0f);
}

TEST_CASE("loader errors: bad light and material values") {
  GltfFixture h;
  h.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {{"photonlab", {{"power", -5}}}};
  CHECK_THAT(loadError(h.write("negpower.gltf")), Contains("power"));
  GltfFixture k;
  k.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {2.0, 0.5, 0.5, 1};
  CHECK_THAT(loadError(k.write("basecolor.gltf")), Contains("baseColorFactor"));
  GltfFixture m;
  m.doc["materials"][0]["extras"] = {{"photonlab", {{"phong", {{"kd", 0.6}, {"ks", 0.6}, {"exponent", 10}}}}}};
  CHECK_THAT(loadError(m.write("phong.gltf")), Contains("energy conservation"));
  GltfFixture n;
  n.doc["cameras"][0]["perspective"]["yfov"] = -1;
  CHECK_THAT(loadError(n.write("yfov.gltf")), Contains("yfov"));
  GltfFixture c;
  c.doc["nodes"][0]["children"] = {0};  // a cycle
  loadError(c.write("cycle.gltf"));
}

TEST_CASE("loader errors: a value of the wrong JSON type names the element - .gltf and .glb") {
  // tinygltf treats such a property as absent (a translation of [0, "x", 0] became none, with
  // no message); photonlab checks the types first (scene/gltf_schema.h).
  struct Case {
    std::function<void(nlohmann::json&)> edit;
    std::string message;
  } cases[] = {
      {[](auto& d) { d["nodes"][1]["translation"] = {0, "x", 0}; }, "nodes[1].translation[1]: must be a number, got a string (\"x\")"},
      {[](auto& d) { d["nodes"][1]["translation"] = {0, 1}; }, "nodes[1].translation: must be an array of 3 numbers, got an array of 2"},
      {[](auto& d) { d["nodes"][1]["rotation"] = "identity"; }, "nodes[1].rotation: must be an array of 4 numbers, got a string"},
      {[](auto& d) { d["nodes"][0]["mesh"] = "0"; }, "nodes[0].mesh: must be an index"},
      {[](auto& d) { d["nodes"][0]["mesh"] = 0.5; }, "nodes[0].mesh: must be an index (an integer, 0 or more), got a number (0.5)"},
      {[](auto& d) { d["nodes"][0]["children"] = {-1}; }, "nodes[0].children[0]: must be an index"},
      {[](auto& d) { d["scenes"][0]["nodes"] = 0; }, "scenes[0].nodes: must be an array of indices"},
      {[](auto& d) { d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = "0"; }, "meshes[0].primitives[0].attributes.POSITION: must be an index"},
      {[](auto& d) { d["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"][2] = nullptr; },
       "materials[0].pbrMetallicRoughness.baseColorFactor[2]: must be a number, got null"},
      {[](auto& d) { d["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = "0"; },
       "materials[0].pbrMetallicRoughness.metallicFactor: must be a number, got a string"},
      {[](auto& d) { d["materials"][0]["doubleSided"] = 1; }, "materials[0].doubleSided: must be true or false, got a number (1)"},
      {[](auto& d) { d["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = "1.5"; },
       "materials[0].extensions.KHR_materials_ior.ior: must be a number"},
      {[](auto& d) { d["cameras"][0]["perspective"]["yfov"] = "0.8"; }, "cameras[0].perspective.yfov: must be a number"},
      {[](auto& d) { d["accessors"][0]["count"] = "4"; }, "accessors[0].count: must be an index"},
      {[](auto& d) { d["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = "2"; },
       "extensions.KHR_lights_punctual.lights[0].intensity: must be a number"},
      {[](auto& d) { d["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = {1, 1}; },
       "extensions.KHR_lights_punctual.lights[0].color: must be an array of 3 numbers"},
      {[](auto& d) { d["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {{"photonlab", {{"power", "5 W"}}}}; },
       "extensions.KHR_lights_punctual.lights[0].extras.photonlab.power: must be a number"},
      {[](auto& d) { d["nodes"] = {{"mesh", 0}}; }, "nodes: must be an array of objects, got an object"},
  };
  int i = 0;
  for (const Case& c : cases) {
    GltfFixture f;
    c.edit(f.doc);
    std::string name = "type-" + std::to_string(i++);
    for (const std::string& path : {f.write(name + ".gltf"), f.writeGlb(name + ".glb")}) {
      std::string e = loadError(path);
      INFO(path << " => " << e);
      CHECK_THAT(e, Contains(path + ": " + c.message));
    }
  }
  // The schema's types, unknown properties and 1.0 as an integer still load.
  GltfFixture ok;
  ok.doc["nodes"][0]["mesh"] = 0.0;
  ok.doc["nodes"][0]["someTool"] = {{"anything", "goes"}};
  ok.doc["materials"][0]["extensions"]["VENDOR_unknown"] = {{"x", "y"}};
  CHECK_NOTHROW(loadGltf(ok.write("types-ok.gltf")));
}

namespace {

// A PNG of one row, written the plainest valid way (one stored deflate block): `samples` are the
// row's samples in order, `bits` 8 or 16 (big-endian, as PNG stores them), colour type 0 (grey),
// 2 (RGB), 4 (grey + alpha) or 6 (RGBA).
std::vector<uint8_t> pngRow(int width, int colorType, int bits, const std::vector<uint16_t>& samples) {
  auto crc = [](const std::vector<uint8_t>& d, size_t from) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = from; i < d.size(); ++i) {
      c ^= d[i];
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1)));
    }
    return ~c;
  };
  auto be32 = [](std::vector<uint8_t>& d, uint32_t v) {
    for (int i = 3; i >= 0; --i) d.push_back(uint8_t(v >> (8 * i)));
  };
  std::vector<uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  auto chunk = [&](const char* type, const std::vector<uint8_t>& data) {
    be32(out, uint32_t(data.size()));
    const size_t start = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    be32(out, crc(out, start));
  };
  std::vector<uint8_t> ihdr;
  be32(ihdr, uint32_t(width));
  be32(ihdr, 1);
  ihdr.insert(ihdr.end(), {uint8_t(bits), uint8_t(colorType), 0, 0, 0});
  chunk("IHDR", ihdr);
  std::vector<uint8_t> raw = {0};  // filter type 0 for the row
  for (uint16_t v : samples) {
    if (bits == 16) raw.push_back(uint8_t(v >> 8));
    raw.push_back(uint8_t(v & 0xFF));
  }
  std::vector<uint8_t> z = {0x78, 0x01, 0x01, uint8_t(raw.size() & 0xFF), uint8_t(raw.size() >> 8),
                            uint8_t(~raw.size() & 0xFF), uint8_t((~raw.size() >> 8) & 0xFF)};
  z.insert(z.end(), raw.begin(), raw.end());
  uint32_t a = 1, b = 0;  // Adler-32 of the raw data
  for (uint8_t v : raw) a = (a + v) % 65521, b = (b + a) % 65521;
  be32(z, b << 16 | a);
  chunk("IDAT", z);
  chunk("IEND", {});
  return out;
}

// The fixture's floor with a 2×1 base-colour texture (the image at `dataUri`) spread across it,
// u = (x + 1)/2, v = (z + 1)/2, times `factor`.
// The fixture's floor with TEXCOORD_0 u = (x + 1)/2, v = (z + 1)/2 and textures[0] the image at
// `dataUri`, which no material uses yet.
// A floor lit by a light, against its expected image per pixel through every path that carries
// the light: shadow rays (direct, 64 spp), light tracing (512 paths per pixel) and photons
// alone (PPM, 16 passes × 100k, 3 cm), seeds 1 and 2, as checkAgreesPerPixel accepts them.
void checkFloorEveryPath(const Scene& scene, const ImageRGB& expected) {
  RenderOptions small;
  small.width = expected.width, small.height = expected.height;
  for (const char* name : {"direct", "light"}) {
    INFO(name);
    checkAgreesPerPixel([&](uint64_t seed) {
      RenderOptions o = small;
      o.seed = seed;
      o.spp = std::string(name) == "direct" ? 64 : 512;
      return render(scene, *makeIntegrator(name, o), o, nullptr);
    }, expected);
  }
  INFO("photons alone (ppm)");
  checkAgreesPerPixel([&](uint64_t seed) {
    RenderOptions o = small;
    o.seed = seed;
    return makeWith("ppm", {{"passes", 16}, {"photons_per_pass", 100000}, {"radius", 0.03f}})->render(scene, o, nullptr);
  }, expected);
}

GltfFixture floorWithTexture(const std::string& dataUri) {
  GltfFixture f;
  float uv[8] = {0, 0, 0, 1, 1, 1, 1, 0};
  f.bin.resize(104);
  std::memcpy(f.bin.data() + 72, uv, 32);
  f.doc["buffers"][0]["byteLength"] = 104;
  f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 32}});
  f.doc["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}});
  f.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 2;
  f.doc["images"] = {{{"uri", dataUri}}};
  f.doc["textures"] = {{{"source", 0}}};
  return f;
}

std::unique_ptr<Scene> floorTextured(const std::string& dataUri, const std::vector<double>& factor, const std::string& name) {
  GltfFixture f = floorWithTexture(dataUri);
  f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = factor;
  return loadGltf(f.write(name));
}
std::unique_ptr<Scene> floorTextured(const std::vector<uint8_t>& png, const std::string& name) {
  return floorTextured("data:image/png;base64," + base64(png), {1.0, 1.0, 1.0, 1.0}, name);
}

// The albedo at the floor point (x, 0, 0): u = 0.25 and 0.75 at x = ∓0.5 are the texel centres.
Spectrum albedoAt(const Scene& scene, float x) {
  SurfaceHit hit;
  REQUIRE(scene.intersect(Ray{Vec3(x, 1, 0), Vec3(0, -1, 0)}, &hit));
  return hit.bsdf->eval(Vec3(0, 0, 1), Vec3(0, 0, 1), hit.uv) * kPi;
}

}  // namespace

TEST_CASE("loader: emissiveTexture - each point emits its texel, sRGB-decoded, times the factor - black triangles are no lights") {
  // The fixture's 2 m × 2 m floor (4 m², one-sided) made emissive: factor 1 × strength 3 × a
  // uniform texture of sRGB 188/255, linear ((188/255 + 0.055)/1.055)^2.4 = 0.50288 (by hand):
  // Le = 1.50864 everywhere, power π·Le·A = 18.957 W over its two triangles.
  auto emissive = [](const std::vector<uint8_t>& png, const std::string& name, std::vector<std::string>* warnings) {
    GltfFixture f = floorWithTexture("data:image/png;base64," + base64(png));
    f.doc["materials"][0]["emissiveFactor"] = {1.0, 1.0, 1.0};
    f.doc["materials"][0]["emissiveTexture"] = {{"index", 0}};
    f.doc["materials"][0]["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 3.0}};
    f.doc["extensionsUsed"].push_back("KHR_materials_emissive_strength");
    return loadGltf(f.write(name), warnings);
  };
  std::vector<std::string> warnings;
  auto lit = emissive(pngRow(2, 0, 8, {188, 188}), "emissive-texture.gltf", &warnings);
  for (auto& w : warnings) CHECK(w.find("emissiveTexture") == std::string::npos);
  double area = 0;
  int areaLights = 0;
  for (auto& l : lit->lights())
    if (std::string(l->name()) == "area") area += l->power().g, ++areaLights;
  CHECK(areaLights == 2);
  CHECK(area == Approx(kPi * 3 * 0.50288 * 4).epsilon(1e-4));
  // A hit on the floor sees the texel's Le; from below (one-sided), nothing.
  SurfaceHit hit;
  REQUIRE(lit->intersect(Ray{Vec3(0.3f, 1, 0.2f), Vec3(0, -1, 0)}, &hit));
  REQUIRE(hit.light);
  CHECK(hit.light->L(hit.uv, Vec3(0, 1, 0), SampledWavelengths::rgb()).g == Approx(3 * 0.50288).epsilon(1e-4));
  CHECK(hit.light->L(hit.uv, Vec3(0, -1, 0), SampledWavelengths::rgb()).g == 0.0f);
  // An all-black texture: the factor alone would light the floor, the texels do not.
  auto dark = emissive(pngRow(2, 0, 8, {0, 0}), "emissive-black.gltf", nullptr);
  for (auto& l : dark->lights()) CHECK(std::string(l->name()) != "area");
  REQUIRE(dark->intersect(Ray{Vec3(0.3f, 1, 0.2f), Vec3(0, -1, 0)}, &hit));
  CHECK(hit.light == nullptr);
}

TEST_CASE("loader: KHR_texture_transform moves, turns and scales a texture's uv as the extension's GLSL does") {
  // The floor's 2×1 texture [sRGB 188, 0] → linear [0.50288, 0]; u = (x + 1)/2, v = (z + 1)/2.
  // uv' = T(offset)·R(rotation)·S(scale)·uv: u' = cos·sx·u − sin·sy·v + ox, v' = sin·sx·u + cos·sy·v + oy.
  auto albedo = [](const Scene& scene, float x, float z) {
    SurfaceHit hit;
    REQUIRE(scene.intersect(Ray{Vec3(x, 1, z), Vec3(0, -1, 0)}, &hit));
    return hit.bsdf->eval(Vec3(0, 0, 1), Vec3(0, 0, 1), hit.uv).g * kPi;
  };
  auto load = [](const json& transform, const std::string& name, std::vector<std::string>* warnings = nullptr) {
    GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 0, 8, {188, 0})));
    f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}, {"extensions", {{"KHR_texture_transform", transform}}}};
    f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1.0, 1.0, 1.0, 1.0};
    f.doc["extensionsUsed"].push_back("KHR_texture_transform");
    return loadGltf(f.write(name), warnings);
  };
  const float lit = 0.50288f;
  std::vector<std::string> warnings;
  auto none = load(json::object(), "tt-none.gltf", &warnings);
  for (auto& w : warnings) CHECK(w.find("KHR_texture_transform") == std::string::npos);  // implemented: no warning
  CHECK(albedo(*none, -0.5f, 0) == Approx(lit).epsilon(1e-4));  // u = 0.25: texel 0
  CHECK(albedo(*none, 0.5f, 0) == Approx(0).margin(1e-6));      // u = 0.75: texel 1
  // offset ½ in u: the texels swap.
  auto shifted = load({{"offset", {0.5, 0.0}}}, "tt-offset.gltf");
  CHECK(albedo(*shifted, -0.5f, 0) == Approx(0).margin(1e-6));
  CHECK(albedo(*shifted, 0.5f, 0) == Approx(lit).epsilon(1e-4));
  // rotation π/2: u' = −v, so the texture now varies with z: z = −½ (v = ¼) reads u' = −¼ ≡ ¾.
  auto turned = load({{"rotation", kPi / 2}}, "tt-rotation.gltf");
  CHECK(albedo(*turned, 0, -0.5f) == Approx(0).margin(1e-5));
  CHECK(albedo(*turned, 0, 0.5f) == Approx(lit).epsilon(1e-4));
  // scale 2 in u: u' = 2u, at x = −½ u' = ½, between the texels (bilinear: half of each);
  // at x = −¾ (u = ⅛) u' = ¼, texel 0.
  auto scaled = load({{"scale", {2.0, 1.0}}}, "tt-scale.gltf");
  CHECK(albedo(*scaled, -0.5f, 0) == Approx(lit / 2).epsilon(1e-4));
  CHECK(albedo(*scaled, -0.75f, 0) == Approx(lit).epsilon(1e-4));
}

TEST_CASE("loader: grey-scale and 16-bit PNG textures decode to the sRGB values they store") {
  // sRGB⁻¹ by hand: 188/255 (and 48316/65535, the same fraction) → ((0.73725 + 0.055)/1.055)^2.4
  // = 0.50288; 1000/65535 = 0.015259 is on the linear segment: /12.92 = 0.0011810, where its
  // high byte alone (3/255) would give 0.000910.
  auto grey = floorTextured(pngRow(2, 0, 8, {188, 0}), "grey.gltf");
  Spectrum g = albedoAt(*grey, -0.5f);
  CHECK(g.r == Approx(0.50288).epsilon(1e-3));
  CHECK(g.g == Approx(0.50288).epsilon(1e-3));
  CHECK(g.b == Approx(0.50288).epsilon(1e-3));
  CHECK(albedoAt(*grey, 0.5f).r == Approx(0.0f).margin(1e-7));
  auto deep = floorTextured(pngRow(2, 2, 16, {48316, 1000, 65535, 0, 0, 0}), "rgb16.gltf");
  Spectrum d = albedoAt(*deep, -0.5f);
  CHECK(d.r == Approx(0.50288).epsilon(1e-3));
  CHECK(d.g == Approx(0.0011810).epsilon(2e-3));
  CHECK(d.b == Approx(1.0f));
  auto greyAlpha = floorTextured(pngRow(2, 4, 16, {48316, 65535, 0, 65535}), "grey-alpha16.gltf");
  CHECK(albedoAt(*greyAlpha, -0.5f).b == Approx(0.50288).epsilon(1e-3));
}

TEST_CASE("loader: metallicRoughnessTexture is linear - G roughness, B metallic, times the factors") {
  // One 2×1 RGB PNG used twice: as baseColorTexture (sRGB) and as metallicRoughnessTexture
  // (linear data). Left texel (0, 128, 0): roughness 128/255 = 0.50196, metallic 0, base
  // sRGB⁻¹(128/255) = ((0.50196 + 0.055)/1.055)^2.4 = 0.21586 green. Right texel (0, 64, 255)
  // with metallicFactor 0.5: roughness 64/255 = 0.25098, metallic 0.5.
  GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 2, 8, {0, 128, 0, 0, 64, 255})));
  f.doc["materials"][0] = {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}},
                                                     {"metallicRoughnessTexture", {{"index", 0}}},
                                                     {"metallicFactor", 0.5}}}};
  auto scene = loadGltf(f.write("metallic-roughness-texture.gltf"));
  const BSDF& bsdf = *scene->materials()[0].bsdf;
  REQUIRE(std::string(bsdf.name()) == "metallic-roughness");
  MetallicRoughness left(ColorTexture(Spectrum(0, 0.21586f, 0)), ColorTexture(Spectrum(1, 0.50196f, 0)));
  MetallicRoughness right(ColorTexture(Spectrum(0, 0.051269f, 1)), ColorTexture(Spectrum(1, 0.25098f, 0.5f)));
  Vec3 a = glm::normalize(Vec3(0.3f, 0.1f, 0.9f)), b = glm::normalize(Vec3(-0.5f, 0.2f, 0.6f));
  Spectrum l = bsdf.eval(a, b, Vec2(0.25f, 0.5f)), L = left.eval(a, b, Vec2(0));
  Spectrum r = bsdf.eval(a, b, Vec2(0.75f, 0.5f)), R = right.eval(a, b, Vec2(0));
  for (int c = 0; c < 3; ++c) {
    CHECK(l[c] == Approx(L[c]).epsilon(2e-3));
    CHECK(r[c] == Approx(R[c]).epsilon(2e-3));
  }
}

TEST_CASE("loader: alphaMode MASK cuts the surface out below alphaCutoff - BLEND lets rays through with probability 1 − alpha") {
  // The floor (y = 0) with a 2×1 RGBA texture: left texel alpha 255 (1), right 64 (0.25098).
  // Rays straight down at texel centres (x = ∓0.5, z = 0), each from a different height, so each
  // is a different ray to BLEND's hash.
  auto floor = [](const std::string& mode, double alphaFactor, const std::string& name) {
    GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 6, 8, {200, 200, 200, 255, 200, 200, 200, 64})));
    f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1.0, 1.0, 1.0, alphaFactor};
    f.doc["materials"][0]["alphaMode"] = mode;
    return loadGltf(f.write(name));
  };
  const int N = 20000;
  auto fractions = [&](const Scene& scene, float x) {  // of closest hits, of occluded shadow rays
    int hits = 0, blocked = 0;
    for (int i = 0; i < N; ++i) {
      Ray r{Vec3(x, 1.0f + i * 1e-4f, 0.0f), Vec3(0, -1, 0), 0.0f, INFINITY};
      SurfaceHit h;
      bool hit = scene.intersect(r, &h);
      if (hit) CHECK(h.p.y == Approx(0.0f).margin(1e-5));
      hits += hit;
      SurfaceHit again;  // the same ray decides the same way
      REQUIRE(scene.intersect(r, &again) == hit);
      Ray shadow = r;
      shadow.tmax = 4.0f;  // past the floor from every origin (y ≤ 3)
      blocked += scene.occluded(shadow);
    }
    return std::pair<double, double>(double(hits) / N, double(blocked) / N);
  };
  auto opaque = floor("OPAQUE", 1.0, "alpha-opaque.gltf");
  CHECK(fractions(*opaque, 0.5f).first == 1.0);  // alpha ignored
  auto mask = floor("MASK", 1.0, "alpha-mask.gltf");  // cutoff 0.5 by default
  CHECK(fractions(*mask, -0.5f) == std::pair<double, double>(1.0, 1.0));
  CHECK(fractions(*mask, 0.5f) == std::pair<double, double>(0.0, 0.0));
  // BLEND: a Bernoulli(α) per ray; σ of the fraction = √(α(1 − α)/N) = 0.0031 at α = 0.251, 4σ.
  auto blend = floor("BLEND", 1.0, "alpha-blend.gltf");
  CHECK(fractions(*blend, -0.5f) == std::pair<double, double>(1.0, 1.0));
  auto [hit, blocked] = fractions(*blend, 0.5f);
  CHECK(hit == Approx(0.25098).margin(4 * 0.0031));
  CHECK(blocked == Approx(0.25098).margin(4 * 0.0031));
  // The factor's alpha multiplies: 0.5 × 1 on the left texel.
  auto half = floor("BLEND", 0.5, "alpha-blend-half.gltf");
  CHECK(fractions(*half, -0.5f).first == Approx(0.5).margin(4 * 0.0036));
  // MASK with alphaCutoff 0.2 keeps the right texel (0.251 ≥ 0.2).
  {
    GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 6, 8, {200, 200, 200, 255, 200, 200, 200, 64})));
    f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    f.doc["materials"][0]["alphaMode"] = "MASK";
    f.doc["materials"][0]["alphaCutoff"] = 0.2;
    CHECK(fractions(*loadGltf(f.write("alpha-cutoff.gltf")), 0.5f).first == 1.0);
    f.doc["materials"][0]["alphaMode"] = "CUTOUT";
    CHECK_THAT(loadError(f.write("alpha-bad.gltf")), Contains("materials[0].alphaMode: must be OPAQUE, MASK or BLEND"));
  }
}

TEST_CASE("loader: normalTexture tilts the shading normal in its tangent frame - tangents from the uvs or from TANGENT") {
  // The fixture's floor (y = 0, face normal +y, u = (x + 1)/2, v = (z + 1)/2) with a normal map
  // whose every texel is (218, 128, 218): tangent-space n = 2c − 1 = (0.709804, 0.003922,
  // 0.709804), tilted 45° towards the tangent.
  auto floor = [](const std::string& name, const std::function<void(GltfFixture&)>& edit) {
    GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 2, 8, {218, 128, 218, 218, 128, 218})));
    f.doc["materials"][0]["normalTexture"] = {{"index", 0}};
    edit(f);
    return loadGltf(f.write(name));
  };
  auto shadingNormal = [](const Scene& scene) {
    SurfaceHit h;
    REQUIRE(scene.intersect(Ray{Vec3(0.3f, 1, 0.2f), Vec3(0, -1, 0), 0, INFINITY}, &h));
    return h.shading.n;
  };
  const float c = 218 / 255.0f * 2 - 1, g = 128 / 255.0f * 2 - 1;
  auto expect = [](const Vec3& n, const Vec3& e) {
    Vec3 unit = glm::normalize(e);
    INFO("shading normal " << n.x << " " << n.y << " " << n.z << ", expected " << unit.x << " " << unit.y << " " << unit.z);
    CHECK(glm::dot(n, unit) == Approx(1.0f).epsilon(1e-5));
  };
  // Generated: t = ∂p/∂u = +x, bitangent n × t = +y × +x = −z.
  auto generated = floor("normal-generated.gltf", [](GltfFixture&) {});
  expect(shadingNormal(*generated), c * Vec3(1, 0, 0) + g * Vec3(0, 0, -1) + c * Vec3(0, 1, 0));
  // scale 0.5 halves x and y of the tangent-space normal.
  auto scaled = floor("normal-scaled.gltf", [](GltfFixture& f) { f.doc["materials"][0]["normalTexture"]["scale"] = 0.5; });
  expect(shadingNormal(*scaled), 0.5f * c * Vec3(1, 0, 0) + 0.5f * g * Vec3(0, 0, -1) + c * Vec3(0, 1, 0));
  // Given TANGENT (0, 0, 1, w): t = +z, bitangent w (+y × +z) = w (+x).
  for (float w : {1.0f, -1.0f}) {
    auto given = floor("normal-tangent.gltf", [&](GltfFixture& f) {
      float tangents[16] = {0, 0, 1, w, 0, 0, 1, w, 0, 0, 1, w, 0, 0, 1, w};
      size_t offset = f.bin.size();
      f.bin.resize(offset + 64);
      std::memcpy(f.bin.data() + offset, tangents, 64);
      f.doc["buffers"][0]["byteLength"] = f.bin.size();
      f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", 64}});
      f.doc["accessors"].push_back({{"bufferView", f.doc["bufferViews"].size() - 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC4"}});
      f.doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = f.doc["accessors"].size() - 1;
    });
    expect(shadingNormal(*given), c * Vec3(0, 0, 1) + g * w * Vec3(1, 0, 0) + c * Vec3(0, 1, 0));
  }
  // Rendered: a directional light straight down, E = 3 W/m², lights the tilted Lambertian floor
  // (ρ = 0.5) by L = ρ/π · E · (n_s · ŷ) = ρ/π · E · c/|(c, g, c)| = 0.33761 at every pixel: the
  // direct integrator's estimate is exact here, so only float rounding separates them.
  auto lit = floor("normal-lit.gltf", [](GltfFixture& f) {
    f.doc["extensions"]["KHR_lights_punctual"]["lights"][0] = {{"type", "directional"}, {"intensity", 3.0}};
    f.doc["nodes"][2]["rotation"] = {-0.7071068, 0, 0, 0.7071068};  // −Z (the light's direction) to −Y
  });
  RenderOptions ro;
  ro.width = ro.height = 8;
  ro.spp = 4;
  ImageRGB image = render(*lit, *makeIntegrator("direct", {}), ro, nullptr);
  const double expected = 0.5 / kPi * 3.0 * c / std::sqrt(2 * c * c + g * g);
  for (float v : image.data) REQUIRE(v == Approx(expected).epsilon(1e-4));
  // The same level from the light side, per pixel: light tracing's splats, PPM's photons alone and
  // the bidirectional merges.
  // Both see the floor's flux per unit of geometric area, E (n_g · ŷ), so both need Veach's
  // correction |wi·n_s|/|wi·n_g| to arrive at the reflection equation's E (n_s · ŷ); without it they
  // give ρ/π · E, 41% too bright. 16×16 pixels, seeds 1 and 2: light tracing 512 paths per pixel
  // (~230 splats in a pixel, 7% noise), PPM 16 passes of 100k paths at a 3 cm radius (~700
  // photons, 4%); the view ends 0.15 m inside the floor's edge, beyond the radius. Acceptance as
  // the light-transport tests: median and mean ratio within 1 ± 0.02, p99 |t| < 4.5.
  ImageRGB level(16, 16);
  for (float& v : level.data) v = float(expected);
  auto agree = [&](const std::function<ImageRGB(uint64_t)>& renderSeed) { checkAgreesPerPixel(renderSeed, level); };
  RenderOptions small;
  small.width = small.height = 16;
  {
    INFO("light tracing");
    agree([&](uint64_t seed) {
      RenderOptions o = small;
      o.spp = 512;
      o.seed = seed;
      return render(*lit, *makeIntegrator("light", o), o, nullptr);
    });
  }
  {
    INFO("photons alone (ppm)");
    agree([&](uint64_t seed) {
      RenderOptions o = small;
      o.seed = seed;
      return makeWith("ppm", {{"passes", 16}, {"photons_per_pass", 100000}, {"radius", 0.03f}})->render(*lit, o, nullptr);
    });
  }
  // Merging: bpm has only its merges, vcm weighs them against connections that carry the shading
  // normal's cosines, so an uncorrected merge would shift its level too. bpm 512 iterations of 256
  // light paths at a 5 cm radius (~150 merges per pixel), vcm 64.
  for (const char* name : {"bpm", "vcm"}) {
    INFO(name);
    agree([&](uint64_t seed) {
      RenderOptions o = small;
      o.seed = seed;
      o.spp = std::string(name) == "bpm" ? 512 : 64;
      return makeWith(name, {{"spp", o.spp}, {"radius", 0.05}})->render(*lit, o, nullptr);
    });
  }
}

TEST_CASE("loader: a metallic-roughness metal floor under a directional light is D G1 G1 F E/(4 cos) per pixel - shadow rays, light tracing, photons") {
  // The fixture's floor with metallicRoughnessTexture texels (0, 128, 255): metallic 1, roughness
  // 128/255, so α = roughness² and the material is the specification's metal lobe alone,
  // f = D(m) G1(o) G1(i) F(o·m) / (4 μo μi) with Schlick's F = F0 + (1 − F0)(1 − o·m)⁵, F0 the
  // base colour (green 0.8: the channel compared). A directional light straight down (E = 3 W/m²,
  // wi = ŷ, μi = 1) and the camera 2 m above: each point x reflects L(x) = f(wo(x), ŷ) E towards
  // the camera, computed here from the GGX formulas by hand and averaged over each pixel's
  // footprint (6×6 midpoint rule). Shadow rays (64 spp), light tracing (512 paths per pixel, the
  // BSDF in importance mode) and PPM's photons alone (16 passes × 100k, 3 cm) at 16×16, seeds 1
  // and 2; acceptance as the light-transport tests: median and mean ratio within 1 ± 0.02, p99
  // |t| < 4.5. The highlight is 3.6× the image's corners; α = roughness instead of roughness²
  // would make its centre 4× darker.
  GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 2, 8, {0, 128, 255, 0, 128, 255})));
  f.doc["materials"][0].erase("extras");
  f.doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorFactor", {0.9, 0.8, 0.3, 1.0}}, {"metallicFactor", 1.0},
                                                   {"roughnessFactor", 1.0}, {"metallicRoughnessTexture", {{"index", 0}}}};
  f.doc["extensions"]["KHR_lights_punctual"]["lights"][0] = {{"type", "directional"}, {"intensity", 3.0}};
  f.doc["nodes"][2]["rotation"] = {-0.7071068, 0, 0, 0.7071068};
  auto scene = loadGltf(f.write("metal-floor.gltf"));
  REQUIRE(std::string(scene->materials()[0].bsdf->name()) == "metallic-roughness");

  const double roughness = 128 / 255.0, alpha = roughness * roughness, F0 = 0.8, E = 3.0;
  auto G1 = [&](double cosTheta) {
    double tan2 = (1 - cosTheta * cosTheta) / (cosTheta * cosTheta);
    return 2 / (1 + std::sqrt(1 + alpha * alpha * tan2));
  };
  auto L = [&](const Vec3& x) {
    glm::dvec3 wo = glm::normalize(glm::dvec3(0, 2, 0) - glm::dvec3(x)), wi(0, 1, 0), m = glm::normalize(wo + wi);
    double c2 = m.y * m.y, a2 = alpha * alpha;
    double D = a2 / (kPi * std::pow(c2 * (a2 - 1) + 1, 2));
    double F = F0 + (1 - F0) * std::pow(1 - glm::dot(wo, m), 5);
    return D * G1(wo.y) * G1(1.0) * F / (4 * wo.y * 1.0) * E * 1.0;
  };
  const int W = 16;
  ImageRGB expected = expectedFloorImage(*scene, W, W, L, 6);
  checkFloorEveryPath(*scene, expected);
}

TEST_CASE("loader: a required extension photonlab lacks is a one-line error naming it - ignored features are one warning each") {
  GltfFixture d;
  d.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_draco_mesh_compression"};
  d.doc["extensionsRequired"] = {"KHR_lights_punctual", "KHR_draco_mesh_compression"};
  CHECK_THAT(loadError(d.write("draco.gltf")),
             Contains("extensionsRequired[1]: KHR_draco_mesh_compression is required by the file and photonlab does not implement it"));
  GltfFixture m;
  m.doc["extensionsRequired"] = {"KHR_lights_punctual"};  // implemented: loads
  m.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_iridescence", "KHR_materials_anisotropy", "KHR_materials_variants",
                            "KHR_materials_transmission"};
  m.doc["materials"][0]["name"] = "seat";
  m.doc["materials"][0].erase("extras");  // the specification's material, not the fixture's Lambertian
  m.doc["materials"][0]["extensions"] = {{"KHR_materials_iridescence", json::object()}, {"KHR_materials_anisotropy", json::object()}};
  m.doc["materials"][0]["extensions"]["KHR_materials_transmission"] = {{"transmissionFactor", 0.5}};
  m.doc["materials"][0]["extensions"]["KHR_materials_ior"] = {{"ior", 1.4}};
  for (int i = 0; i < 3; ++i)
    m.doc["materials"].push_back({{"extensions", {{"KHR_materials_iridescence", json::object()},
                                                  {"KHR_materials_transmission", {{"transmissionFactor", 0.5}}},
                                                  {"KHR_materials_ior", {{"ior", 1.4}}}}},
                                  {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});
  std::vector<std::string> warnings;
  loadGltf(m.write("ignored.gltf"), &warnings);
  auto count = [&](const std::string& text) {
    return std::count_if(warnings.begin(), warnings.end(), [&](const std::string& w) { return w.find(text) != std::string::npos; });
  };
  CHECK(count("KHR_materials_iridescence") == 1);
  CHECK(count("materials[0] 'seat' (and 3 more): KHR_materials_iridescence is not implemented: ignored") == 1);
  CHECK(count("materials[0] 'seat': KHR_materials_anisotropy is not implemented: ignored") == 1);
  CHECK(count("extensionsUsed: KHR_materials_variants is not implemented: ignored") == 1);
  CHECK(count("KHR_lights_punctual") == 0);
  // The loader's own approximations are said the same way: once for the four materials. Thin-
  // walled transmission itself is rendered (docs: reference/gltf.md), so nothing else is said of it.
  CHECK(count("materials[0] 'seat' (and 3 more): KHR_materials_ior on a rough thin-walled surface is ignored") == 1);
  CHECK(count("KHR_materials_transmission") == 0);
  // A core feature not read: the occlusion texture, once per feature.
  GltfFixture v;
  v.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 0;  // any VEC3 accessor
  v.doc["materials"][0]["occlusionTexture"] = {{"index", 0}};
  v.doc["textures"] = {{{"source", 0}}};
  v.doc["images"] = {{{"uri", "data:image/png;base64," + base64(pngRow(1, 0, 8, {255}))}}};
  std::vector<std::string> more;
  loadGltf(v.write("colour.gltf"), &more);
  warnings = more;
  CHECK(count("COLOR_0") == 0);  // read (test below), not warned
  CHECK(count("materials[0]: occlusionTexture is ignored") == 1);
}

TEST_CASE("loader: baseColorTexture × factor - sRGB texels decoded to linear - looked up by TEXCOORD_0") {
  // A 2×1 BMP: left texel sRGB (255, 0, 0), right texel sRGB (0, 0, 188) ≈ linear 0.5 blue.
  std::vector<uint8_t> bmp = {'B', 'M', 62, 0, 0, 0, 0, 0, 0, 0, 54, 0, 0, 0,  // file header
                              40, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 1, 0, 24, 0, 0, 0, 0, 0, 8, 0, 0, 0,
                              0x13, 0x0B, 0, 0, 0x13, 0x0B, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  // DIB header
                              0, 0, 255, 188, 0, 0, 0, 0};  // BGR BGR + padding to 4 bytes
  auto scene = floorTextured("data:image/bmp;base64," + base64(bmp), {1.0, 1.0, 0.5, 1.0}, "texture.gltf");
  auto albedoAt = [&](float x) { return ::albedoAt(*scene, x); };
  Spectrum left = albedoAt(-0.5f), right = albedoAt(0.5f);  // u = 0.25 and 0.75: texel centres
  CHECK(left.r == Approx(1.0f));
  CHECK(left.b == Approx(0.0f).margin(1e-6));
  CHECK(right.r == Approx(0.0f).margin(1e-6));
  CHECK(right.b == Approx(0.5f * 0.5029f).epsilon(2e-3));  // factor 0.5 × sRGB⁻¹(188/255)
}

// A file without photonlab's marker, as other tools write them.
void photonlabExtrasErase(GltfFixture& f) { f.doc["asset"].erase("extras"); }

TEST_CASE("loader: units - photometric (cd, lx, nits) by default, divided by 683 lm/W - radiometric when the file or --units says") {
  // The fixture's point light has intensity 2 and photonlab's own marker (radiometric): 2 W/sr,
  // Φ = 4π·2. Without the marker the 2 is candela: 2/683 W/sr.
  auto pointPower = [](const std::unique_ptr<Scene>& s) {
    for (auto& l : s->lights())
      if (std::string(l->name()) == "point") return double(l->power().g);
    return -1.0;
  };
  GltfFixture radiometric;
  auto r = loadGltf(radiometric.write("units-radiometric.gltf"));
  CHECK(pointPower(r) == Approx(4 * kPi * 2).epsilon(1e-6));
  CHECK_THAT(r->units, Contains("radiometric (asset.extras.photonlab.units)"));
  GltfFixture photometric;
  photonlabExtrasErase(photometric);
  photometric.doc["materials"][0]["emissiveFactor"] = {1.0, 1.0, 1.0};
  photometric.doc["materials"][0]["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 683.0}};
  photometric.doc["extensionsUsed"].push_back("KHR_materials_emissive_strength");
  auto p = loadGltf(photometric.write("units-photometric.gltf"));
  CHECK(pointPower(p) == Approx(4 * kPi * 2 / 683).epsilon(1e-6));
  CHECK(p->materials()[0].emission.g == Approx(1.0f).epsilon(1e-6));  // 683 nits = 1 W/(m² sr)
  CHECK_THAT(p->units, Contains("photometric") && Contains("683"));
  // --units overrides the file either way.
  GltfLoadOptions o;
  o.units = "radiometric";
  CHECK(pointPower(loadGltf(photometric.write("units-photometric.gltf"), nullptr, o)) == Approx(4 * kPi * 2).epsilon(1e-6));
  o.units = "photometric";
  CHECK(pointPower(loadGltf(radiometric.write("units-radiometric.gltf"), nullptr, o)) == Approx(4 * kPi * 2 / 683).epsilon(1e-6));
  // extras.photonlab.power stays in watts whatever the units.
  photometric.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {{"photonlab", {{"power", 5.0}}}};
  CHECK(pointPower(loadGltf(photometric.write("units-power.gltf"))) == Approx(5.0).epsilon(1e-6));
  GltfFixture bad;
  bad.doc["asset"]["extras"]["photonlab"]["units"] = "kelvin";
  CHECK_THAT(loadError(bad.write("units-bad.gltf")), Contains("asset.extras.photonlab.units") && Contains("radiometric"));
}

TEST_CASE("loader: KHR_mesh_quantization - integer positions, normals and texture coordinates dequantised as the spec says") {
  // The fixture's floor, (−1, 0, −1)–(1, 0, 1), stored quantised: POSITION as unsigned shorts
  // 0..2 (not normalised) under a node translation of (−1, 0, −1); NORMAL as normalised signed
  // bytes (0, 127, 0) = (0, 1, 0); TEXCOORD_0 as normalised signed bytes, (127, −128) = (1, −1)
  // (max(c/127, −1)). Elements padded to 4 bytes, as the extension requires.
  GltfFixture q;
  std::vector<uint8_t> bin;
  auto u16 = [&](uint16_t v) { bin.push_back(uint8_t(v & 255)), bin.push_back(uint8_t(v >> 8)); };
  const uint16_t corners[4][3] = {{0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {2, 0, 0}};
  for (auto& c : corners) u16(c[0]), u16(c[1]), u16(c[2]), u16(0);  // 8-byte stride
  for (int i = 0; i < 4; ++i) bin.insert(bin.end(), {0, 127, 0, 0});  // normals, 4-byte stride
  const int8_t uv[4][2] = {{0, 0}, {0, 127}, {127, 127}, {127, -128}};
  for (auto& t : uv) bin.insert(bin.end(), {uint8_t(t[0]), uint8_t(t[1]), 0, 0});
  const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
  const size_t indexOffset = bin.size();
  bin.resize(bin.size() + 24);
  std::memcpy(bin.data() + indexOffset, indices, 24);
  q.bin = bin;
  q.doc["buffers"][0]["byteLength"] = bin.size();
  q.doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 32}, {"byteStride", 8}},
                          {{"buffer", 0}, {"byteOffset", 32}, {"byteLength", 16}, {"byteStride", 4}},
                          {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 16}, {"byteStride", 4}},
                          {{"buffer", 0}, {"byteOffset", indexOffset}, {"byteLength", 24}}};
  q.doc["accessors"] = {
      {{"bufferView", 0}, {"componentType", 5123}, {"count", 4}, {"type", "VEC3"}, {"min", {0, 0, 0}}, {"max", {2, 0, 2}}},
      {{"bufferView", 1}, {"componentType", 5120}, {"normalized", true}, {"count", 4}, {"type", "VEC3"}},
      {{"bufferView", 2}, {"componentType", 5120}, {"normalized", true}, {"count", 4}, {"type", "VEC2"}},
      {{"bufferView", 3}, {"componentType", 5125}, {"count", 6}, {"type", "SCALAR"}}};
  q.doc["meshes"][0]["primitives"][0]["attributes"] = {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}};
  q.doc["meshes"][0]["primitives"][0]["indices"] = 3;
  q.doc["nodes"][0]["translation"] = {-1, 0, -1};
  q.doc["extensionsUsed"].push_back("KHR_mesh_quantization");
  q.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  auto scene = loadGltf(q.write("quantized.gltf"));
  GltfFixture plain;
  auto reference = loadGltf(plain.write("quantized-reference.gltf"));
  REQUIRE(scene->triangleCount() == 2);
  for (uint32_t t = 0; t < 2; ++t)
    for (int k = 0; k < 3; ++k) CHECK(scene->trianglePositions(t)[k] == reference->trianglePositions(t)[k]);
  SurfaceHit hit;
  // (0.9, −0.9) on the second triangle (corners 0, 2, 3) has barycentrics (0.05, 0.05, 0.9):
  // uv = 0.05·(0, 0) + 0.05·(1, 1) + 0.9·(1, −1) = (0.95, −0.85).
  REQUIRE(scene->intersect(Ray{Vec3(0.9f, 1, -0.9f), Vec3(0, -1, 0)}, &hit));
  CHECK(glm::length(hit.shading.n - Vec3(0, 1, 0)) < 1e-6f);
  CHECK(hit.uv.x == Approx(0.95f).margin(1e-4));
  CHECK(hit.uv.y == Approx(-0.85f).margin(1e-4));
  // Without the extension, integer positions are refused, naming it.
  q.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  q.doc.erase("extensionsRequired");
  CHECK_THAT(loadError(q.write("quantized-undeclared.gltf")), Contains("POSITION") && Contains("KHR_mesh_quantization"));
}

namespace {
// The fixture's floor, and a second quad (with tilted NORMALs and uvs, and a material of its own)
// placed by three nodes: scaled, rotated, and mirrored. `instanced`: the three nodes share one
// mesh; otherwise each has its own copy of it, as a file without instancing would.
GltfFixture threeQuads(bool instanced, bool emissive) {
  GltfFixture f;
  float normals[12] = {0.3f, 1, 0, 0, 1, 0.3f, -0.3f, 1, 0, 0, 1, -0.3f};
  float uvs[8] = {0, 0, 0, 1, 1, 1, 1, 0};
  f.bin.resize(72 + 48 + 32);
  std::memcpy(f.bin.data() + 72, normals, 48);
  std::memcpy(f.bin.data() + 120, uvs, 32);
  f.doc["buffers"][0]["byteLength"] = f.bin.size();
  f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 48}});
  f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 120}, {"byteLength", 32}});
  f.doc["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}});
  f.doc["accessors"].push_back({{"bufferView", 3}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}});
  json material = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.6, 0.9, 1}}, {"metallicFactor", 0}}},
                   {"extras", {{"photonlab", {{"bsdf", "lambertian"}}}}}};
  if (emissive) material["emissiveFactor"] = {1.0, 0.5, 0.25};
  f.doc["materials"].push_back(material);
  json quad = {{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 2}, {"TEXCOORD_0", 3}}}, {"indices", 1}, {"material", 1}}}}};
  f.doc["meshes"].push_back(quad);
  if (!instanced) f.doc["meshes"].push_back(quad), f.doc["meshes"].push_back(quad);
  f.doc["nodes"].push_back({{"mesh", 1}, {"translation", {0, 0.4, 0}}, {"scale", {0.3, 0.3, 0.3}}});
  f.doc["nodes"].push_back({{"mesh", instanced ? 1 : 2}, {"translation", {0.5, 0.7, 0.2}},
                            {"rotation", {0.2588190, 0, 0, 0.9659258}}, {"scale", {0.2, 0.2, 0.25}}});
  f.doc["nodes"].push_back({{"mesh", instanced ? 1 : 3}, {"translation", {-0.5, 0.6, -0.1}}, {"scale", {-0.25, 0.25, 0.3}}});
  f.doc["scenes"][0]["nodes"] = {0, 1, 2, 3, 4, 5};
  return f;
}

// The same three placements through EXT_mesh_gpu_instancing: one node whose attributes hold the
// three translations, rotations and scales.
GltfFixture threeQuadsGpuInstanced(bool emissive) {
  GltfFixture f = threeQuads(true, emissive);
  float trs[30] = {0, 0.4f, 0, 0.5f, 0.7f, 0.2f, -0.5f, 0.6f, -0.1f,                       // TRANSLATION
                   0, 0, 0, 1, 0.2588190f, 0, 0, 0.9659258f, 0, 0, 0, 1,                    // ROTATION
                   0.3f, 0.3f, 0.3f, 0.2f, 0.2f, 0.25f, -0.25f, 0.25f, 0.3f};               // SCALE
  const size_t at = f.bin.size();
  f.bin.resize(at + sizeof(trs));
  std::memcpy(f.bin.data() + at, trs, sizeof(trs));
  f.doc["buffers"][0]["byteLength"] = f.bin.size();
  const int view = int(f.doc["bufferViews"].size()), accessor = int(f.doc["accessors"].size());
  f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", sizeof(trs)}});
  f.doc["accessors"].push_back({{"bufferView", view}, {"byteOffset", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  f.doc["accessors"].push_back({{"bufferView", view}, {"byteOffset", 36}, {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});
  f.doc["accessors"].push_back({{"bufferView", view}, {"byteOffset", 84}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  f.doc["nodes"][3] = {{"mesh", 1}, {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes",
                        {{"TRANSLATION", accessor}, {"ROTATION", accessor + 1}, {"SCALE", accessor + 2}}}}}}}};
  f.doc["scenes"][0]["nodes"] = {0, 1, 2, 3};
  f.doc["extensionsUsed"].push_back("EXT_mesh_gpu_instancing");
  return f;
}
}  // namespace

namespace {
// Rays from a 64×64 grid above and below [-1, 1]², aimed inwards (those of the grid's diagonals
// through the diagonals of the meshes' quads, where a BVH that is not watertight lets some
// through): each must find the same
// surface in scenes a and b (the hit point, the geometric and shading normals, the uv, the
// material, emission), and in each scene the numbered triangle's corners with the hit's
// barycentrics give back the hit point, surfaceAt() the same surface, and the corners' order the
// front face. Returns the number of rays that hit.
struct SurfaceAgreement {
  int hitsA = 0, hitsB = 0, both = 0;
};
SurfaceAgreement sameSurfaces(const Scene& a, const Scene& b) {
  SurfaceAgreement r;
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j)
      for (float side : {1.0f, -1.0f}) {  // from above and from below
        Vec3 o(-1 + (i + 0.5f) / 32, side > 0 ? 2.0f : -1.0f, -1 + (j + 0.5f) / 32);
        Vec3 target(0.8f * o.x, 0.5f, 0.8f * o.z);
        Ray ray{o, glm::normalize(target - o), 0.0f, INFINITY};
        SurfaceHit ha, hb;
        bool fa = a.intersect(ray, &ha), fb = b.intersect(ray, &hb);
        INFO("ray from " << o.x << ", " << o.y << ", " << o.z << " hits " << ha.p.x << ", " << ha.p.y << ", " << ha.p.z << " / " << hb.p.x << ", " << hb.p.y << ", " << hb.p.z);
        // A ray through an edge that two triangles share meets either (they differ in their
        // normals where the mesh bends there); elsewhere both scenes meet the same triangle.
        auto onEdge = [](const SurfaceHit& h) { return std::min({1 - h.barycentric.x - h.barycentric.y, h.barycentric.x, h.barycentric.y}) < 1e-4f; };
        r.hitsA += fa, r.hitsB += fb;
        if (fa != fb) CHECK(onEdge(fa ? ha : hb));  // the other scene's BVH let it through an edge
        if (!fa || !fb) continue;
        ++r.both;
        CHECK(ha.t == Approx(hb.t).epsilon(1e-5));
        CHECK(glm::length(ha.p - hb.p) < 1e-5f);
        if (!onEdge(ha) || !onEdge(hb)) {
          CHECK(glm::dot(ha.ng, hb.ng) > 0.99999f);
          CHECK(glm::dot(ha.shading.n, hb.shading.n) > 0.99999f);
        }
        CHECK(glm::length(ha.uv - hb.uv) < 1e-5f);
        CHECK(a.triangleMaterial(ha.primitive) == b.triangleMaterial(hb.primitive));
        CHECK((ha.light != nullptr) == (hb.light != nullptr));
        if (ha.light) {
          const SampledWavelengths& rgb = SampledWavelengths::rgb();
          Spectrum La = ha.light->L(ha.uv, -ray.d, rgb), Lb = hb.light->L(hb.uv, -ray.d, rgb);
          CHECK(glm::length(La - Lb) < 1e-6f);  // both emit towards the ray, or neither
        }
        for (const auto& [scene, h] : {std::pair{&a, ha}, std::pair{&b, hb}}) {
          auto v = scene->trianglePositions(h.primitive);
          Vec3 p = (1 - h.barycentric.x - h.barycentric.y) * v[0] + h.barycentric.x * v[1] + h.barycentric.y * v[2];
          CHECK(glm::length(p - h.p) < 1e-5f);
          SurfaceHit s = scene->surfaceAt(h.primitive, h.barycentric.x, h.barycentric.y);
          CHECK(glm::length(s.p - h.p) < 1e-5f);
          CHECK(glm::dot(s.shading.n, h.shading.n) > 0.99999f);
          Vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);  // the corners' order is the front face's
          CHECK(glm::dot(n, h.ng) > 0);
        }
      }
  return r;
}

// Scenes a and b lit by emissive surfaces render the same 32² images, region by region (4×4
// pixels, 8×8 for PPM) within their noise: through shadow rays (path, 64 spp) and through photons alone
// (PPM, 8 passes of 50 000 photons), two seeds each.
void sameImages(const Scene& a, const Scene& b) {
  RenderOptions o;
  o.width = o.height = 32;
  for (const char* name : {"path", "ppm"}) {
    INFO(name);
    auto image = [&](const Scene& s, uint64_t seed) {
      RenderOptions r = o;
      r.seed = seed;
      if (std::string(name) == "path") {
        r.spp = 64;
        return render(s, *makeIntegrator(name, r), r, nullptr);
      }
      return makeWith("ppm", {{"passes", 8}, {"photons_per_pass", 50000}, {"radius", 0.05f}})->render(s, r, nullptr);
    };
    // z's variance comes from two seeds' pixels: with t-like tails, E[z²] = ν/(ν − 2) for ν
    // degrees of freedom. Path-traced pixels are independent (ν ≈ 30 over 4×4 pixels); PPM's
    // neighbours share photons, which leaves ν ≈ 5 at 4×4 (mean z² 1.7 ± 0.34 over the 192
    // regions: 2.0 failed by chance), so its regions are 8×8 (ν > 20, mean z² ≈ 1.1 ± 0.2).
    RegionAgreement r = regions(image(a, 1), image(a, 2), image(b, 3), image(b, 4), std::string(name) == "ppm" ? 8 : 4, 1e-6);
    INFO("mean z2 " << r.meanZ2 << ", worst |z| " << r.worst << ", correlation factor " << r.correlation);
    CHECK(r.meanZ2 < 2.0);
    CHECK(r.worst < 5.0);
  }
}

// The file loaded with the given BVH layout.
std::unique_ptr<Scene> loadWithBvh(const std::string& path, Scene::BvhLayout bvh) {
  GltfLoadOptions options;
  options.bvh = bvh;
  return loadGltf(path, nullptr, options);
}

}  // namespace

TEST_CASE("loader: a mesh placed by several nodes - or by EXT_mesh_gpu_instancing - is stored once (Embree instances) and renders as its copies would") {
  // The same three placements of one quad, instanced and as three copies (which the loader
  // stores in world space, transformed as before). Every ray of a grid must find the same
  // surface in both: the hit point, the geometric and shading normals (inverse transpose; the
  // mirrored placement keeps its front face), the uv, the material; and the numbered triangle's
  // corners with the hit's barycentrics give back the hit point in both.
  for (int gpu : {0, 1})
  for (bool emissive : {false, true}) {
    INFO("emissive " << emissive << (gpu ? ", EXT_mesh_gpu_instancing" : ", three nodes"));
    std::vector<std::string> warnings;
    auto a = loadGltf(gpu ? threeQuadsGpuInstanced(emissive).write("gpu-instanced.gltf") : threeQuads(true, emissive).write("instanced.gltf"),
                      &warnings);
    CHECK(warnings.empty());
    auto b = loadGltf(threeQuads(false, emissive).write("copies.gltf"));
    CHECK(a->triangleCount() == 8);
    CHECK(b->triangleCount() == 8);
    CHECK(a->storedTriangleCount() == 4);  // the floor and the quad, once
    CHECK(b->storedTriangleCount() == 8);
    CHECK(a->instanceCount() == 3);
    CHECK(b->instanceCount() == 0);
    for (int k = 0; k < 3; ++k) {
      CHECK(a->bounds().lo[k] == Approx(b->bounds().lo[k]).margin(1e-5));
      CHECK(a->bounds().hi[k] == Approx(b->bounds().hi[k]).margin(1e-5));
    }
    // Emission: one area light per placed triangle, facing as its copy does, the same power.
    CHECK(a->lights().size() == b->lights().size());
    CHECK(a->lights().size() == (emissive ? 7u : 1u));
    for (int c = 0; c < 3; ++c) CHECK(a->totalPower()[c] == Approx(b->totalPower()[c]).epsilon(1e-5));

    SurfaceAgreement r = sameSurfaces(*a, *b);
    CHECK(r.hitsA == r.hitsB);  // the same BVH layout in both: the same edges let rays through
    CHECK(r.both > 4000);
  }
}

TEST_CASE("loader: instanced and copied meshes give the same image - path tracer and photons") {
  // The emissive quads light the floor: through shadow rays (path) and through photons alone
  // (PPM, whose photons start on the instanced lights). Region by region (4×4 pixels) the two
  // files' images agree within their noise.
  auto a = loadGltf(threeQuads(true, true).write("instanced-lit.gltf"));
  auto b = loadGltf(threeQuads(false, true).write("copies-lit.gltf"));
  sameImages(*a, *b);
}

namespace {
// Every triangle of a scene as its world-space corners, each rotated to start at its smallest
// corner (a rotation keeps the facing), sorted: equal lists are the same triangles, facing the
// same ways, whatever their order and first corners.
std::vector<std::array<float, 9>> triangleSet(const Scene& scene) {
  std::vector<std::array<float, 9>> set;
  for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
    auto v = scene.trianglePositions(t);
    auto less = [](const Vec3& p, const Vec3& q) { return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z); };
    int first = int(std::min_element(v.begin(), v.end(), less) - v.begin());
    std::array<float, 9> c;
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) c[3 * k + i] = v[(first + k) % 3][i];
    set.push_back(c);
  }
  std::sort(set.begin(), set.end());
  return set;
}
}  // namespace

TEST_CASE("scene: the compact layout pairs triangles across shared edges into Embree quads - every ray meets the surface it meets with the fast layout") {
  SECTION("files: the floor and a quad placed three times - instanced, mirrored, emissive") {
    for (bool instanced : {true, false})
      for (bool emissive : {false, true}) {
        INFO((instanced ? "instanced" : "copies") << (emissive ? ", emissive" : ""));
        const std::string file = threeQuads(instanced, emissive).write("layouts.gltf");
        auto a = loadWithBvh(file, Scene::BvhLayout::Fast), b = loadWithBvh(file, Scene::BvhLayout::Compact);
        CHECK(!a->compactBvh());
        CHECK(b->compactBvh());
        // Every quad of the file is the triangles (0, 1, 2) and (0, 2, 3), which run their
        // diagonal 0-2 in opposite directions: each stored triangle pairs.
        CHECK(a->pairedTriangleCount() == 0);
        CHECK(b->pairedTriangleCount() == b->storedTriangleCount());
        CHECK(b->lights().size() == a->lights().size());
        for (int c = 0; c < 3; ++c) CHECK(b->totalPower()[c] == Approx(a->totalPower()[c]).epsilon(1e-5));
        CHECK(triangleSet(*b) == triangleSet(*a));
        SurfaceAgreement r = sameSurfaces(*a, *b);
        CHECK(r.both > 4000);
        CHECK(r.hitsB >= r.hitsA);  // the compact layout is watertight (Embree's robust mode)
      }
  }
  SECTION("a mesh in code: a shuffled grid, and triangles that must stay single") {
    // A wavy 9×9-vertex grid over [-1, 1]² with normals and uvs, written as two families of
    // triangles (as scripts/load_benchmark.py writes its grid) in a scrambled order; and above
    // it an emissive mesh of what must stay single (a triangle alone, one with a repeated
    // corner, two that run their shared edge the same way, so face opposite ways) beside one
    // proper pair.
    auto build = [](Scene::BvhLayout layout) {
      auto scene = std::make_unique<Scene>();
      scene->setBvhLayout(layout);
      const uint32_t grey = lambertian(*scene, 0.5f);
      const uint32_t glow = scene->addMaterial(
          {"glow", std::make_unique<Lambertian>(ColorTexture(Spectrum(0.5f))), Spectrum(1, 2, 3), false});
      const int n = 9;
      std::vector<Vec3> P, N;
      std::vector<Vec2> UV;
      for (int z = 0; z < n; ++z)
        for (int x = 0; x < n; ++x) {
          const float fx = -1 + 2.0f * x / (n - 1), fz = -1 + 2.0f * z / (n - 1);
          P.push_back(Vec3(fx, 0.05f * std::sin(3 * fx) * std::cos(3 * fz), fz));
          N.push_back(glm::normalize(Vec3(0.2f * fx, 1, 0.1f * fz)));
          UV.push_back(Vec2((fx + 1) / 2, (fz + 1) / 2));
        }
      std::vector<std::array<uint32_t, 3>> tris;
      for (int family : {0, 1})
        for (int z = 0; z + 1 < n; ++z)
          for (int x = 0; x + 1 < n; ++x) {
            const uint32_t a = z * n + x, b = a + 1, c = a + n, d = c + 1;
            tris.push_back(family == 0 ? std::array<uint32_t, 3>{a, c, b} : std::array<uint32_t, 3>{b, c, d});
          }
      std::vector<uint32_t> I;
      for (size_t i = 0; i < tris.size(); ++i)  // 37 is prime to the 128 triangles: a permutation
        for (uint32_t v : tris[(i * 37) % tris.size()]) I.push_back(v);
      scene->addMesh(P, N, UV, I, grey);
      std::vector<Vec3> Q = {
          {-0.8f, 0.6f, -0.8f}, {-0.8f, 0.6f, -0.5f}, {-0.5f, 0.6f, -0.8f},   // alone
          {0.5f, 0.6f, 0.5f},   {0.5f, 0.6f, 0.8f},   {0.8f, 0.6f, 0.5f},     // a repeated corner
          {-0.2f, 0.6f, 0.5f},  {-0.2f, 0.6f, 0.8f},  {0.1f, 0.6f, 0.5f}, {-0.5f, 0.6f, 0.5f},  // same-way edge
          {0.2f, 0.6f, -0.4f},  {0.5f, 0.6f, -0.4f},  {0.5f, 0.6f, -0.1f}, {0.2f, 0.6f, -0.1f}};  // a pair
      scene->addMesh(Q, {}, {}, {0, 1, 2, 3, 3, 4, 6, 7, 8, 6, 7, 9, 10, 13, 12, 10, 12, 11}, glow);
      scene->addLight(std::make_unique<PointLight>(Vec3(0, 3, 0), Spectrum(10.0f)));
      scene->commit();
      return scene;
    };
    auto a = build(Scene::BvhLayout::Fast), b = build(Scene::BvhLayout::Compact);
    CHECK(b->compactBvh());
    // Each grid triangle's longest edge is its cell's diagonal (cells 0.25 wide, height steps
    // under 0.04), across which its cell partner lies: all 128 pair; above, the one pair.
    CHECK(b->pairedTriangleCount() == 128 + 2);
    CHECK(b->triangleCount() == a->triangleCount());
    CHECK(b->lights().size() == a->lights().size());  // the non-degenerate emissive triangles
    for (int c = 0; c < 3; ++c) CHECK(b->totalPower()[c] == Approx(a->totalPower()[c]).epsilon(1e-5));
    CHECK(triangleSet(*b) == triangleSet(*a));
    // Every ray crosses the grid inside its square: the compact layout, watertight (Embree's
    // robust mode, its Plücker test), meets it with each, even through the quads' diagonals.
    SurfaceAgreement r = sameSurfaces(*a, *b);
    CHECK(r.hitsB == 2 * 64 * 64);
    CHECK(r.both > 8000);
  }
  SECTION("alphaMode MASK and BLEND on quads: both halves") {
    // The alpha test's floor, one quad: x = -0.5 and x = 0.5 at z = 0 lie on its two halves.
    for (const char* mode : {"MASK", "BLEND"}) {
      INFO(mode);
      GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 6, 8, {200, 200, 200, 255, 200, 200, 200, 64})));
      f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
      f.doc["materials"][0]["alphaMode"] = mode;
      auto scene = loadWithBvh(f.write("alpha-quads.gltf"), Scene::BvhLayout::Compact);
      CHECK(scene->pairedTriangleCount() == scene->storedTriangleCount());
      const int N = 20000;
      auto fraction = [&](float x) {
        int hits = 0;
        for (int i = 0; i < N; ++i) {
          SurfaceHit h;
          hits += scene->intersect(Ray{Vec3(x, 1.0f + i * 1e-4f, 0.0f), Vec3(0, -1, 0), 0.0f, INFINITY}, &h);
        }
        return double(hits) / N;
      };
      CHECK(fraction(-0.5f) == 1.0);  // alpha 1
      // alpha 0.251: MASK (cutoff 0.5) cuts it out; BLEND keeps a Bernoulli(0.251) fraction,
      // σ = √(α(1 − α)/N) = 0.0031, 4σ.
      if (std::string(mode) == "MASK") CHECK(fraction(0.5f) == 0.0);
      else CHECK(fraction(0.5f) == Approx(0.25098).margin(4 * 0.0031));
    }
  }
}

TEST_CASE("scene: the compact layout renders what the fast one does - path tracer and photons, emissive quads") {
  // The two layouts' images agree (sameImages), through shadow rays and through photons alone
  // (PPM, whose photons start on the paired lights).
  const std::string file = threeQuads(true, true).write("layouts-lit.gltf");
  auto a = loadWithBvh(file, Scene::BvhLayout::Fast), b = loadWithBvh(file, Scene::BvhLayout::Compact);
  sameImages(*a, *b);
}

namespace {
// Two hits are the same bit for bit: every number and every pointer a SurfaceHit holds.
bool sameBits(const SurfaceHit& a, const SurfaceHit& b) {
  auto bits = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  return bits(a.t, b.t) && bits(a.p, b.p) && bits(a.ng, b.ng) && bits(a.shading.s, b.shading.s) &&
         bits(a.shading.t, b.shading.t) && bits(a.shading.n, b.shading.n) && bits(a.uv, b.uv) && bits(a.color, b.color) &&
         bits(a.barycentric, b.barycentric) && a.primitive == b.primitive && a.bsdf == b.bsdf &&
         a.material == b.material && a.light == b.light && a.lightIndex == b.lightIndex;
}

// Packets of eight rays through the scene's box, against the one-ray query lane by lane.
// Half the packets are incoherent (random origins and directions), half coherent (one origin,
// directions within a narrow cone, flagged coherent). About a fifth of the lanes are inactive,
// every fourth packet has a lane Embree would reject (a NaN direction), every seventh packet
// one active lane. Returns the lanes that hit.
int samePacketAnswers(const Scene& scene) {
  Rng rng(5, 6);
  const Bounds& b = scene.bounds();
  const Vec3 ext = 1.2f * (b.hi - b.lo) + Vec3(0.5f), lo = 0.5f * (b.lo + b.hi) - 0.5f * ext;  // flat scenes too
  auto inside = [&] { return lo + ext * Vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
  int hits = 0;
  for (int packet = 0; packet < 4000; ++packet) {
    const bool coherent = packet % 2 == 1;
    const Vec3 origin = inside(), axis = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    Ray rays[Scene::kPacket];
    bool active[Scene::kPacket];
    for (int k = 0; k < Scene::kPacket; ++k) {
      const Vec3 jitter = 0.05f * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f);
      rays[k] = coherent ? Ray{origin, glm::normalize(axis + jitter), 0.0f, INFINITY}
                         : Ray{inside(), sampleUniformSphere(Vec2(rng.uniform(), rng.uniform())), 0.0f, INFINITY};
      active[k] = packet % 7 == 0 ? k == 5 : rng.uniform() < 0.8f;
    }
    if (packet % 4 == 0) rays[3].d.y = NAN;
    SurfaceHit packetHits[Scene::kPacket];
    bool found[Scene::kPacket];
    scene.intersect(rays, active, coherent, packetHits, found);
    for (int k = 0; k < Scene::kPacket; ++k) {
      INFO("packet " << packet << ", lane " << k);
      if (!active[k]) {
        CHECK(!found[k]);
        continue;
      }
      SurfaceHit one;
      const bool f = scene.intersect(rays[k], &one);
      CHECK(found[k] == f);
      if (f && found[k]) CHECK(sameBits(one, packetHits[k]));
      hits += f;
    }
  }
  return hits;
}
}  // namespace

TEST_CASE("scene: packet queries (rtcIntersect8) answer each lane as the one-ray query does, bit for bit - instances, both layouts, alpha") {
  // The path tracer traces eight pixels' camera rays together (integrators/path.cpp) and
  // promises the image of one pixel at a time: that rests on these hits being the same to the
  // last bit.
  SECTION("the mirror-and-glass Cornell box (18 k triangles, shading normals)") {
    auto scene = loadGltf(std::string(PHOTONLAB_SOURCE_DIR) + "/scenes/cornell-spheres.gltf");
    CHECK(samePacketAnswers(*scene) > 3000);
  }
  SECTION("a quad placed three times, instanced or copied, emissive, fast and compact layouts") {
    for (bool instanced : {true, false})
      for (auto layout : {Scene::BvhLayout::Fast, Scene::BvhLayout::Compact}) {
        INFO((instanced ? "instanced" : "copies") << (layout == Scene::BvhLayout::Compact ? ", compact" : ", fast"));
        auto scene = loadWithBvh(threeQuads(instanced, true).write("packets.gltf"), layout);
        CHECK(samePacketAnswers(*scene) > 1000);
      }
  }
  SECTION("alphaMode BLEND: each ray's coin is its own, whichever query asks") {
    GltfFixture f = floorWithTexture("data:image/png;base64," + base64(pngRow(2, 6, 8, {200, 200, 200, 255, 200, 200, 200, 64})));
    f.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    f.doc["materials"][0]["alphaMode"] = "BLEND";
    auto scene = loadGltf(f.write("packets-alpha.gltf"));
    CHECK(samePacketAnswers(*scene) > 1000);
  }
}

TEST_CASE("loader: COLOR_0 multiplies the base colour per vertex - per pixel through shadow rays, light tracing and photons - and its alpha the coverage") {
  // The fixture's floor (ρ = 0.5, Lambertian) with COLOR_0 as normalised unsigned bytes, RGBA.
  // Grey vertex colours c = (0.2, 1.0, 0.6, 0.4) at (−1, −1), (−1, 1), (1, 1), (1, −1) (x, z):
  // linear in the barycentrics of each of the two triangles (0, 1, 2) and (0, 2, 3). Under a
  // directional light straight down (E = 3 W/m²) a point reflects L(x) = ρ c(x) E / π, c(x)
  // interpolated here by hand. Acceptance as the other per-pixel floor tests.
  auto floorWithColors = [](const std::vector<uint8_t>& rgba) {
    GltfFixture f;
    f.bin.resize(88);
    std::memcpy(f.bin.data() + 72, rgba.data(), 16);
    f.doc["buffers"][0]["byteLength"] = 88;
    f.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 16}});
    f.doc["accessors"].push_back({{"bufferView", 2}, {"componentType", 5121}, {"normalized", true}, {"count", 4}, {"type", "VEC4"}});
    f.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 2;
    return f;
  };
  const double c[4] = {51 / 255.0, 1.0, 153 / 255.0, 102 / 255.0};
  GltfFixture f = floorWithColors({51, 51, 51, 255, 255, 255, 255, 255, 153, 153, 153, 255, 102, 102, 102, 255});
  f.doc["extensions"]["KHR_lights_punctual"]["lights"][0] = {{"type", "directional"}, {"intensity", 3.0}};
  f.doc["nodes"][2]["rotation"] = {-0.7071068, 0, 0, 0.7071068};
  auto scene = loadGltf(f.write("vertex-colours.gltf"));
  auto colourAt = [&](const Vec3& x) {
    // Triangle (0, 1, 2) where z ≥ x (above the diagonal from (−1, −1) to (1, 1)), else (0, 2, 3).
    const double px = x.x, pz = x.z;
    if (pz >= px) {  // p = v0 + s (v1 − v0) + t (v2 − v0): v1 − v0 = (0, 2), v2 − v0 = (2, 2)
      double t = (px + 1) / 2, s = (pz + 1) / 2 - t;
      return (1 - s - t) * c[0] + s * c[1] + t * c[2];
    }
    double s = (pz + 1) / 2, t = (px + 1) / 2 - s;  // v2 − v0 = (2, 2), v3 − v0 = (2, 0)
    return (1 - s - t) * c[0] + s * c[2] + t * c[3];
  };
  auto L = [&](const Vec3& x) { return 0.5 * colourAt(x) * 3.0 / kPi; };
  const int W = 16;
  ImageRGB expected = expectedFloorImage(*scene, W, W, L, 6);
  checkFloorEveryPath(*scene, expected);
  // Per channel: a colour (1, 0.5, 0.25) everywhere gives ρ·(1, 0.5, 0.25) (byte 128 = 0.50196,
  // 64 = 0.25098).
  auto tinted = loadGltf(floorWithColors({255, 128, 64, 255, 255, 128, 64, 255, 255, 128, 64, 255, 255, 128, 64, 255}).write("tint.gltf"));
  SurfaceHit hit;
  REQUIRE(tinted->intersect(Ray{Vec3(0.3f, 1, -0.2f), Vec3(0, -1, 0)}, &hit));
  Spectrum rho = hit.bsdf->eval(Vec3(0, 0, 1), Vec3(0, 0, 1), bsdfContext(hit)) * kPi;
  CHECK(rho.r == Approx(0.5).epsilon(1e-5));
  CHECK(rho.g == Approx(0.5 * 128 / 255.0).epsilon(1e-5));
  CHECK(rho.b == Approx(0.5 * 64 / 255.0).epsilon(1e-5));
  // Alpha: a BLEND material with factor 1 and no texture, COLOR_0 alpha 64/255 everywhere: rays
  // pass with probability 1 − 0.25098 (σ = 0.0031 over 20000 rays; 4σ).
  GltfFixture b = floorWithColors({255, 255, 255, 64, 255, 255, 255, 64, 255, 255, 255, 64, 255, 255, 255, 64});
  b.doc["materials"][0]["alphaMode"] = "BLEND";
  auto blend = loadGltf(b.write("colour-alpha.gltf"));
  int hits = 0;
  for (int i = 0; i < 20000; ++i) hits += blend->intersect(Ray{Vec3(0.2f, 1.0f + i * 1e-4f, 0.1f), Vec3(0, -1, 0)}, &hit);
  CHECK(hits / 20000.0 == Approx(64 / 255.0).margin(4 * 0.0031));
}

TEST_CASE("glTF factory tables: each row is the first to apply to its own case - the last material row takes any - names unique") {
  auto firstMaterialRow = [](const GltfMaterial& m) {
    for (const BSDFFactory& f : bsdfFactories())
      if (f.applies(m)) return std::string(f.name);
    return std::string("none");
  };
  GltfMaterial plain;  // the specification's defaults: metallic 1, roughness 1
  plain.metallic = 0.0f;
  CHECK(firstMaterialRow(plain) == "metallic-roughness");
  GltfMaterial metal;
  metal.roughness = 0.4f;
  CHECK(firstMaterialRow(metal) == "ggx");
  metal.roughness = 0.0f;
  CHECK(firstMaterialRow(metal) == "mirror");
  metal.mrTextured = true;  // a texture may vary metallic and roughness: the full model
  CHECK(firstMaterialRow(metal) == "metallic-roughness");
  GltfMaterial glass = plain;
  glass.transmission = 1.0, glass.thickness = 0.1;
  CHECK(firstMaterialRow(glass) == "dielectric");
  GltfMaterial pane = plain;
  pane.transmission = 1.0, pane.roughness = 0.0f;
  CHECK(firstMaterialRow(pane) == "thin dielectric");
  pane.transmission = 0.5;  // partly transmissive: the rough model's lobe
  CHECK(firstMaterialRow(pane) == "metallic-roughness");
  GltfMaterial wall = plain;
  wall.lambertian = true;
  CHECK(firstMaterialRow(wall) == "lambertian");
  std::set<std::string> names;
  for (const BSDFFactory& f : bsdfFactories()) CHECK(names.insert(f.name).second);
  CHECK(bsdfFactories().back().applies(GltfMaterial()));

  auto firstLightRow = [](const std::string& type, double warn) {
    GltfLight l;
    l.type = type, l.warnExponent = warn;
    for (const LightFactory& f : lightFactories())
      if (f.applies(l)) return std::string(f.name);
    return std::string("none");
  };
  CHECK(firstLightRow("point", -1) == "point");
  CHECK(firstLightRow("spot", -1) == "spot");
  CHECK(firstLightRow("spot", 8) == "warn spotlight");
  CHECK(firstLightRow("directional", -1) == "directional");
  CHECK(firstLightRow("area", -1) == "none");  // the loader's one-line error names the field
  names.clear();
  for (const LightFactory& f : lightFactories()) CHECK(names.insert(f.name).second);
}

TEST_CASE("loader: views from the command line - look-at projects known points as the pinhole does, orbit frames the bounds whole, fov alone replaces the file camera's") {
  GltfFixture g;
  const std::string path = g.write("views.gltf");
  auto rasterOf = [](const Scene& scene, const Vec3& p, int W, int H, Vec2* r) {
    CameraSample s;
    const bool seen = scene.camera().sampleWi(p, W, H, &s);
    *r = s.raster;
    return seen;
  };
  Vec2 r;
  // From 5 m on +Z, a 90° field: tan 45° = 1, so (x, y, 0) lands at ((x/5 + 1)/2·W, (1 − y/5)/2·H).
  GltfLoadOptions o;
  o.view.kind = CameraView::Kind::LookAt;
  o.view.from = Vec3(0, 0, 5);
  o.view.fov = 90;
  auto lookAt = loadGltf(path, nullptr, o);
  REQUIRE(rasterOf(*lookAt, Vec3(2.5f, 0, 0), 100, 100, &r));
  CHECK(r.x == Approx(75).margin(1e-3));
  CHECK(r.y == Approx(50).margin(1e-3));
  REQUIRE(rasterOf(*lookAt, Vec3(0, -2.5f, 0), 100, 100, &r));
  CHECK(r.x == Approx(50).margin(1e-3));
  CHECK(r.y == Approx(75).margin(1e-3));
  CHECK(lookAt->cameraSource == "--look-from/--look-at");
  // --up +X: the image's up is +X, its right −Y.
  o.view.up = Vec3(1, 0, 0);
  auto turned = loadGltf(path, nullptr, o);
  REQUIRE(rasterOf(*turned, Vec3(2.5f, 0, 0), 100, 100, &r));
  CHECK(r.x == Approx(50).margin(1e-3));
  CHECK(r.y == Approx(25).margin(1e-3));
  // --orbit 90,0: on +X of the bounds' centre, looking along −X; every corner of the bounds in
  // the image, at any aspect (the framing fits the bounding sphere).
  for (float aspect : {1.0f, 2.0f, 0.5f}) {
    INFO("aspect " << aspect);
    GltfLoadOptions orbit;
    orbit.view.kind = CameraView::Kind::Orbit;
    orbit.view.azimuth = 90, orbit.view.elevation = 0;
    orbit.aspect = aspect;
    auto scene = loadGltf(path, nullptr, orbit);
    const Camera& c = scene->camera();
    CHECK(c.forward.x == Approx(-1).margin(1e-6));
    CHECK(c.position.x > scene->bounds().center().x);
    const int H = 100, W = int(std::lround(100 * aspect));
    const Bounds& b = scene->bounds();
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner(k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z);
      CHECK(rasterOf(*scene, corner, W, H, &r));
    }
  }
  // --fov alone: the file's camera, narrower; without a view, the file's own 0.8 rad.
  GltfLoadOptions narrow;
  narrow.view.fov = 30;
  auto file = loadGltf(path), narrowed = loadGltf(path, nullptr, narrow);
  CHECK(file->camera().yfov == Approx(0.8f));
  CHECK(narrowed->camera().yfov == Approx(glm::radians(30.0f)));
  CHECK(narrowed->camera().position == file->camera().position);
}

TEST_CASE("loader: the default sky is radiance 1 in the file's units - as bright as an emissive factor of 1 - and KHR_materials_unlit emits its base colour") {
  // A photometric file (the glTF default) with a glowing floor and no punctual light: the sky is
  // 1 nit, 1/683 W/(m²·sr), exactly the floor's emission (emissive factor 1, in nits).
  GltfFixture glowing;
  glowing.doc["scenes"][0]["nodes"] = {0, 1};
  glowing.doc["materials"][0]["emissiveFactor"] = {1.0, 1.0, 1.0};
  glowing.doc["asset"].erase("extras");
  auto scene = loadGltf(glowing.write("nit-sky.gltf"));
  REQUIRE(scene->environment() != nullptr);
  CHECK(scene->environment()->integral().g == Approx(4 * kPi / kLumensPerWatt).epsilon(1e-5));
  CHECK(scene->materials()[0].emission.g == Approx(1.0f / kLumensPerWatt));
  CHECK_THAT(scene->units, Contains("the default sky, where the file has no light, is an overcast sky of mean radiance 1 in these units"));
  CHECK_THAT(scene->environmentSource, Contains("default environment (1 nit)"));
  // Unlit: the base colour (0.25, 0.5, 1) emitted, nothing reflected, no "not implemented";
  // required by the file, it loads.
  GltfFixture unlit;
  unlit.doc["materials"][0] = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.25, 0.5, 1.0, 1.0}}}},
                               {"extensions", {{"KHR_materials_unlit", json::object()}}}};
  unlit.doc["extensionsUsed"].push_back("KHR_materials_unlit");
  unlit.doc["extensionsRequired"] = {"KHR_materials_unlit"};
  std::vector<std::string> warnings;
  auto u = loadGltf(unlit.write("unlit.gltf"), &warnings);
  const Material& m = u->materials()[0];
  CHECK(m.emission == Spectrum(0.25f, 0.5f, 1.0f));
  const Vec3 up(0, 0, 1), out = glm::normalize(Vec3(0.3f, 0.2f, 1));
  CHECK(isBlack(m.bsdf->eval(up, out, BSDFContext())));
  for (const auto& w : warnings) CHECK(w.find("not implemented") == std::string::npos);
}

TEST_CASE("loader: KHR_materials_sheen and KHR_materials_clearcoat layer the material - sheen under the coat - and bad factors are one line") {
  GltfFixture layered;
  layered.doc["materials"][0] = {
      {"name", "paint"},
      {"pbrMetallicRoughness", {{"baseColorFactor", {0.6, 0.1, 0.1, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.5}}},
      {"extensions",
       {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", 0.3}, {"clearcoatNormalTexture", {{"index", 0}}}}},
        {"KHR_materials_sheen", {{"sheenColorFactor", {0.5, 0.5, 0.5}}, {"sheenRoughnessFactor", 0.5}}}}}};
  layered.doc["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_materials_sheen"};
  std::vector<std::string> warnings;
  auto scene = loadGltf(layered.write("layered.gltf"), &warnings);
  const BSDF& bsdf = *scene->materials()[0].bsdf;
  CHECK(std::string(bsdf.name()) == "clearcoat over sheen over metallic-roughness");
  CHECK(bool(bsdf.flags() & kGlossyReflection));
  for (const auto& w : warnings) CHECK(w.find("not implemented") == std::string::npos);
  CHECK(std::count_if(warnings.begin(), warnings.end(), [](const std::string& w) {
          return w.find("materials[0] 'paint': KHR_materials_clearcoat.clearcoatNormalTexture is ignored") != std::string::npos;
        }) == 1);
  // Factors zero (the defaults): no layer at all; over glass, none either, and said.
  GltfFixture bare;
  bare.doc["materials"][0] = {{"extensions", {{"KHR_materials_clearcoat", json::object()}, {"KHR_materials_sheen", json::object()}}}};
  CHECK(std::string(loadGltf(bare.write("bare.gltf"))->materials()[0].bsdf->name()) == "ggx");  // glTF's default: metallic 1
  GltfFixture glass;
  glass.doc["materials"][0] = {{"extensions",
                                {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                                 {"KHR_materials_volume", {{"thicknessFactor", 0.1}}},
                                 {"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}}}}}};
  warnings.clear();
  CHECK(std::string(loadGltf(glass.write("glass.gltf"), &warnings)->materials()[0].bsdf->name()) == "dielectric");
  CHECK(std::count_if(warnings.begin(), warnings.end(), [](const std::string& w) {
          return w.find("clearcoat over a smooth glass or mirror is ignored") != std::string::npos;
        }) == 1);
  // Out of range: one line naming the field.
  GltfFixture bad;
  bad.doc["materials"][0] = {{"extensions", {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1.5}}}}}};
  CHECK_THAT(loadError(bad.write("bad-coat.gltf")), Contains("materials[0].KHR_materials_clearcoat.clearcoatFactor: must be in [0, 1]"));
  GltfFixture badSheen;
  badSheen.doc["materials"][0] = {{"extensions", {{"KHR_materials_sheen", {{"sheenColorFactor", {0.5, 2.0, 0.5}}}}}}};
  CHECK_THAT(loadError(badSheen.write("bad-sheen.gltf")), Contains("materials[0].KHR_materials_sheen.sheenColorFactor"));
}

TEST_CASE("loader: a clear-coated black floor under a directional light is c F D G1 G1 E/(4 cos) per pixel - shadow rays, light tracing, photons") {
  // As the metal floor above, with the coat alone: a Lambertian base of albedo 0 under
  // KHR_materials_clearcoat (factor c = 0.8, roughness 0.5: α = 0.25), so f = c F(o·m) D(m)
  // G1(o) G1(i) / (4 μo μi) with F = 0.04 + 0.96 (1 − o·m)⁵, the GGX formulas of
  // tests/ggx_reference.h. Sun straight down (E = 3 W/m²), camera 2 m above; acceptance as there.
  GltfFixture f;
  f.doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorFactor", {0.0, 0.0, 0.0, 1.0}}, {"metallicFactor", 0.0}};
  f.doc["materials"][0]["extensions"] = {{"KHR_materials_clearcoat", {{"clearcoatFactor", 0.8}, {"clearcoatRoughnessFactor", 0.5}}}};
  f.doc["extensions"]["KHR_lights_punctual"]["lights"][0] = {{"type", "directional"}, {"intensity", 3.0}};
  f.doc["nodes"][2]["rotation"] = {-0.7071068, 0, 0, 0.7071068};
  auto scene = loadGltf(f.write("coat-floor.gltf"));
  REQUIRE(std::string(scene->materials()[0].bsdf->name()) == "clearcoat over lambertian");
  const double c = 0.8, alpha = 0.25, E = 3.0;
  auto L = [&](const Vec3& x) {
    glm::dvec3 wo = glm::normalize(glm::dvec3(0, 2, 0) - glm::dvec3(x)), wi(0, 1, 0), m = glm::normalize(wo + wi);
    return c * schlick004(glm::dot(wo, m)) * ggxD(m.y, alpha) * ggxG1(wo.y, alpha) * ggxG1(1.0, alpha) / (4 * wo.y) * E;
  };
  const int W = 16;
  ImageRGB expected = expectedFloorImage(*scene, W, W, L, 6);
  checkFloorEveryPath(*scene, expected);
}
