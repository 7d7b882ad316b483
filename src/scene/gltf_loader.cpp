#include "scene/gltf_loader.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <fstream>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/memory.h"
#include "scene/gltf_factories.h"
#include "image/tonemap.h"
#include "scene/gltf_schema.h"
#include "spectral/spectral.h"

namespace pl {
namespace {

std::string oneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// An accessor without a bufferView is all zeros (the spec allows it for sparse data): its
// count is not backed by any bytes in the file, so cap it.
constexpr size_t kMaxElementsWithoutData = 1u << 24;

// Scenes live within ±10⁷ m of the origin. Beyond that, float positions are too coarse for ray
// offsets, and near 10¹⁸ Embree rejects rays outright (an assertion in Debian's build). Found by
// fuzzing: a vertex at 1.5·10³⁷ m aborted the renderer.
constexpr float kMaxCoordinate = 1e7f;
inline bool withinScene(const Vec3& p) {
  return std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate && std::abs(p.z) <= kMaxCoordinate;
}

// Textures: the image's own header gives its size; check it before stb_image allocates from it
// (a 16-byte PNG can claim 100000 × 100000 pixels, 40 GB once decoded).
bool imageSizeFromHeader(const unsigned char* b, int n, uint64_t* w, uint64_t* h) {
  auto be32 = [&](int i) { return uint64_t(b[i]) << 24 | uint64_t(b[i + 1]) << 16 | uint64_t(b[i + 2]) << 8 | b[i + 3]; };
  if (n >= 24 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0) {
    *w = be32(16);
    *h = be32(20);
    return true;
  }
  if (n >= 4 && b[0] == 0xFF && b[1] == 0xD8) {  // JPEG: the first SOFn segment holds the size
    for (int i = 2; i + 9 < n;) {
      if (b[i] != 0xFF) return false;
      int marker = b[i + 1];
      int length = b[i + 2] << 8 | b[i + 3];
      if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
        *h = uint64_t(b[i + 5]) << 8 | b[i + 6];
        *w = uint64_t(b[i + 7]) << 8 | b[i + 8];
        return true;
      }
      if (length < 2) return false;
      i += 2 + length;
    }
  }
  return false;
}

constexpr uint64_t kMaxTextureSide = 32768;

bool loadImageChecked(tinygltf::Image* image, const int index, std::string* err, std::string* warn, int reqW, int reqH,
                      const unsigned char* bytes, int size, void* user) {
  uint64_t w = 0, h = 0;
  if (imageSizeFromHeader(bytes, size, &w, &h)) {
    if (w == 0 || h == 0 || w > kMaxTextureSide || h > kMaxTextureSide) {
      if (err) *err += "images[" + std::to_string(index) + "]: " + std::to_string(w) + " x " + std::to_string(h) +
                       " pixels (at most " + std::to_string(kMaxTextureSide) + " a side)";
      return false;
    }
    try {
      checkMemory(w * h * 4, "images[" + std::to_string(index) + "]");
    } catch (const Error& e) {
      if (err) *err += e.what();
      return false;
    }
  }
  return tinygltf::LoadImageData(image, index, err, warn, reqW, reqH, bytes, size, user);
}

class Loader {
 public:
  Loader(std::string path, std::vector<std::string>* warnings, GltfLoadOptions options = {})
      : path_(std::move(path)), warnings_(warnings), options_(options) {}
  // From memory (the fuzz target): `bytes` is the file; external URIs resolve against nothing.
  Loader(std::string name, const unsigned char* bytes, size_t size, std::vector<std::string>* warnings)
      : path_(std::move(name)), warnings_(warnings), bytes_(bytes), size_(size) {}

  std::unique_ptr<Scene> load() {
    parse();
    scene_ = std::make_unique<Scene>();
    scene_->source = path_;
    chooseUnits();
    quantized_ = std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), "KHR_mesh_quantization") !=
                 model_.extensionsUsed.end();
    loadMaterials();
    std::vector<int> roots;
    int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (!model_.scenes.empty()) {
      if (sceneIndex >= int(model_.scenes.size())) fail("scene", "index " + std::to_string(sceneIndex) + " out of range");
      roots = model_.scenes[sceneIndex].nodes;
    } else {  // no scenes array: every node that is nobody's child is a root
      std::vector<bool> isChild(model_.nodes.size(), false);
      for (auto& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && c < int(isChild.size())) isChild[c] = true;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!isChild[i]) roots.push_back(int(i));
    }
    // Which meshes are instanced, and room in the world for the others.
    meshUses_.assign(model_.meshes.size(), 0);
    for (int root : roots) countMeshUses(root, 0);
    size_t vertices = 0, triangles = 0;
    MeshAttributes attributes;
    for (size_t i = 0; i < model_.meshes.size(); ++i)
      if (meshUses_[i] == 1) meshTotals(int(i), &vertices, &triangles, &attributes);
    scene_->reserve(0, vertices, triangles, attributes);
    for (int root : roots) visit(root, Mat4(1.0f), 0);
    releaseFileData();
    addEnvironment();
    const auto& cameras = scene_->fileCameras();
    if (options_.camera >= int(cameras.size()))
      fail("--camera", std::to_string(options_.camera) + " is out of range: the file places " + std::to_string(cameras.size()) +
                           " perspective camera" + (cameras.size() == 1 ? "" : "s") + " (photonlab info lists them)");
    if (!cameras.empty()) {
      const Scene::FileCamera& chosen = cameras[size_t(std::max(options_.camera, 0))];
      scene_->setCamera(chosen.camera);
      scene_->cameraSource = chosen.name;
    }
    scene_->setBvhLayout(options_.bvh);
    scene_->commit();
    const CameraView& view = options_.view;
    checkCameraView(view);
    const float yfov = view.fov > 0 ? glm::radians(view.fov) : 0.69813170f;
    if (view.kind == CameraView::Kind::LookAt) {
      scene_->setCamera(lookAtCamera(view.from, view.at, view.up, yfov));
      scene_->cameraSource = "--look-from/--look-at";
    } else if (cameras.empty() || view.kind == CameraView::Kind::Orbit) {
      const Bounds& b = scene_->bounds();
      const float azimuth = view.kind == CameraView::Kind::Orbit ? glm::radians(view.azimuth) : 0.78539816f;
      const float elevation = view.kind == CameraView::Kind::Orbit ? glm::radians(view.elevation) : 0.52359878f;
      scene_->setCamera(b.empty() ? automaticCamera(Vec3(0.0f), 1.0f, options_.aspect, azimuth, elevation, yfov)
                                  : automaticCamera(b.center(), b.radius(), options_.aspect, azimuth, elevation, yfov));
      if (view.kind == CameraView::Kind::Orbit) {
        scene_->cameraSource = "--orbit (the bounds framed from azimuth " + formatNumber(view.azimuth) + "°, elevation " +
                               formatNumber(view.elevation) + "°)";
      } else {
        scene_->cameraSource = "automatic (three-quarter view of the bounds)";
        warn("no perspective camera: rendering from an automatic three-quarter view of the scene's bounds (--orbit and "
             "--look-from/--look-at choose another)");
      }
    } else if (view.fov > 0) {
      Camera c = scene_->camera();
      c.yfov = yfov;
      scene_->setCamera(c);
    }
    if (average(scene_->totalPower()) <= 0) warn("the lights emit no power: the image will be black");
    return std::move(scene_);
  }

 private:
  [[noreturn]] void fail(const std::string& element, const std::string& what) const {
    throw Error(path_ + ": " + element + ": " + what);
  }
  void warn(const std::string& what) {
    if (warnings_) warnings_->push_back(path_ + ": " + what);
  }
  // What the factory tables (scene/gltf_factories.h) may ask while making material `index`'s
  // BSDF or a light.
  class Reader final : public GltfReader {
   public:
    Reader(Loader& loader, size_t index) : loader_(loader), index_(index) {}
    [[noreturn]] void fail(const std::string& element, const std::string& what) const override { loader_.fail(element, what); }
    void ignored(const std::string& what) override { loader_.ignoredInMaterial(index_, what); }
    Spectrum spectrum(const tinygltf::Value& v, const std::string& element) override { return loader_.spectrumValue(v, element); }
    void checkRange(const std::string& element, const Spectrum& s, float lo, float hi) override {
      loader_.checkRange(element, s, lo, hi);
    }

   private:
    Loader& loader_;
    size_t index_;
  };

  // Which units the file's light values are in: --units, else asset.extras.photonlab.units (what
  // photonlab's scripts write: "radiometric"), else the glTF specification's photometric units.
  void chooseUnits() {
    std::string units = options_.units, source = "--units";
    if (units.empty()) {
      const tinygltf::Value* ex = photonlabExtras(model_.asset.extras);
      if (ex && ex->IsObject() && ex->Has("units")) {
        const tinygltf::Value& u = ex->Get("units");
        units = u.IsString() ? u.Get<std::string>() : "";
        source = "asset.extras.photonlab.units";
        if (units != "radiometric" && units != "photometric")
          fail(source, "must be \"radiometric\" or \"photometric\"");
      } else {
        units = "photometric";
        source = "the glTF default: the file does not say";
      }
    } else if (units != "radiometric" && units != "photometric") {
      fail("--units", "must be radiometric or photometric, got '" + units + "'");
    }
    lightScale_ = units == "photometric" ? 1.0f / kLumensPerWatt : 1.0f;
    scene_->units = (units == "photometric"
                         ? "photometric (" + source + "): cd, lx and nits divided by 683 lm/W"
                         : "radiometric (" + source + "): W/sr, W/m2 and W/(m2 sr) as written") +
                    "; the default sky, where the file has no light, is an overcast sky of mean radiance 1 in these "
                    "units, on average as bright as an emissive factor of 1";
  }

  // The sky: the caller's (--env, an experiment's env) over the file's
  // (extras.photonlab.environment), and the default one where the scene has no light: no
  // KHR_lights_punctual light and, in a radiometric file (photonlab's own scenes, or
  // --units radiometric), no emissive material either. In a photometric file (the glTF
  // default) emissive materials do not count as the scene's lighting: glTF's emission is
  // self-illumination, and viewers light such files with an environment (DamagedHelmet's glowing
  // visor rendered black before).
  void addEnvironment() {
    EnvironmentSpec spec = options_.environment;
    std::string field = "--env";
    if (!spec.enabled) {
      const tinygltf::Value* ex = photonlabExtras(model_.extras);
      if (ex && ex->IsObject() && ex->Has("environment")) {
        field = "extras.photonlab.environment";
        spec = fileEnvironment(ex->Get("environment"), field);
      }
    }
    if (!spec.enabled) {
      bool emissive = false;
      for (const Material& m : scene_->materials()) emissive |= !isBlack(m.emission);
      const bool radiometric = lightScale_ == 1.0f;
      if (!scene_->lights().empty() || (emissive && radiometric)) return;
      // Mean radiance 1 in the file's units (1 nit in a photometric file): an emissive factor
      // of 1 then shows about as bright as the sky, as glTF viewers show it, and a physical
      // file's own ratios (candela, lux, nits) are untouched.
      spec = defaultEnvironment();
      spec.radiance *= lightScale_;
      field = std::string("default environment") + (radiometric ? "" : " (1 nit)");
      if (emissive)
        warn("no KHR_lights_punctual light, and in photometric units emissive materials are self-illumination, not the "
             "scene's lighting: lit by the default environment too, " + spec.describe() +
             " (--env sets another, --env 0 none; --units radiometric makes the emitters the lights)");
      else
        warn("no light (neither KHR_lights_punctual lights nor emissive materials): lit by the default environment, " +
             spec.describe() + " (--env sets another)");
    }
    std::unique_ptr<EnvironmentLight> light;
    try {
      light = makeEnvironment(spec, options_.readImage, field);
    } catch (const Error& e) {
      if (field == "--env") throw;  // the command line's, not the file's
      throw Error(path_ + ": " + e.what());
    }
    scene_->environmentSource = field + ": " + light->description();
    scene_->addLight(std::move(light));
  }
  EnvironmentSpec fileEnvironment(const tinygltf::Value& v, const std::string& el) {
    if (!v.IsObject()) fail(el, "must be an object: {\"radiance\": [r, g, b]} or {\"map\": \"sky.exr\", \"rotate\": degrees, \"scale\": s}");
    EnvironmentSpec spec;
    spec.enabled = true;
    for (const std::string& key : v.Keys())
      if (key != "radiance" && key != "map" && key != "rotate" && key != "scale")
        fail(el + "." + key, "unknown key (radiance, map, rotate, scale)");
    if (v.Has("radiance") == v.Has("map")) fail(el, "give either radiance or map");
    if (v.Has("radiance")) {
      spec.radiance = spectrumValue(v.Get("radiance"), el + ".radiance");
      checkRange(el + ".radiance", spec.radiance, 0.0f, 1e30f);
    } else {
      if (!v.Get("map").IsString()) fail(el + ".map", "must be a file name (relative to the glTF file)");
      const std::string name = v.Get("map").Get<std::string>();
      if (bytes_) fail(el + ".map", "a file loaded from memory cannot refer to " + name);
      spec.map = (std::filesystem::path(path_).parent_path() / name).string();
    }
    double number;
    if (v.Has("rotate")) {
      if (!getNumber(v, "rotate", &number) || !std::isfinite(number)) fail(el + ".rotate", "must be an angle in degrees");
      spec.rotation = float(number);
    }
    if (v.Has("scale")) {
      if (!getNumber(v, "scale", &number) || !(number >= 0) || !std::isfinite(number)) fail(el + ".scale", "must be a number >= 0");
      spec.scale = float(number);
    }
    return spec;
  }

  // What is not a glTF file at all gets one line saying what is read, before any parser sees it:
  // a folder, a missing file, or bytes that are neither a .glb (magic "glTF") nor JSON (an
  // object: '{' after any white space), such as an .obj, an .fbx or an image.
  void checkIsGltf() const {
    std::string head;
    if (bytes_) {
      head.assign(reinterpret_cast<const char*>(bytes_), std::min<size_t>(size_, 256));
    } else {
      std::error_code ec;
      if (std::filesystem::is_directory(path_, ec)) fail("file", "is a folder; photonlab renders a glTF 2.0 file (.gltf or .glb)");
      if (!std::filesystem::exists(path_, ec)) fail("file", "does not exist");
      std::ifstream f(path_, std::ios::binary);
      if (!f) fail("file", std::string("cannot open (") + std::strerror(errno) + ")");
      head.resize(256);
      f.read(head.data(), std::streamsize(head.size()));
      head.resize(size_t(f.gcount()));
    }
    if (head.size() >= 4 && head.compare(0, 4, "glTF") == 0) return;
    const size_t first = head.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && head[first] == '{') return;
    std::string ext = std::filesystem::path(path_).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    fail("file", "not a glTF 2.0 file: photonlab reads .gltf (JSON) and .glb (binary glTF)" +
                     (ext.empty() || ext == ".gltf" || ext == ".glb" ? std::string()
                                                                    : "; convert the " + ext + " file to glTF, e.g. with Blender's exporter"));
  }

  void parse() {
    checkIsGltf();
    // tinygltf ignores a property of the wrong type, or reports it without saying where;
    // photonlab refuses a property of the wrong type first, naming the element (gltf_schema.h),
    // then a required extension it lacks and a missing external file (which tinygltf calls
    // "json" and "unsupported image"); a load from memory has no folder to look in.
    std::string directory;
    if (!bytes_) {
      directory = std::filesystem::path(path_).parent_path().string();
      if (directory.empty()) directory = ".";
    }
    const std::string problem = checkGltfDocument(jsonText(), directory);
    if (!problem.empty()) throw Error(path_ + ": " + problem);
    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(loadImageChecked, nullptr);
    std::string err, warn;
    bool ok, binary;
    if (bytes_) {
      if (size_ > UINT32_MAX) fail("file", "larger than 4 GiB");
      binary = size_ >= 4 && std::memcmp(bytes_, "glTF", 4) == 0;
      const std::string nowhere = "/nonexistent-photonlab-fuzz";
      ok = binary ? gltf.LoadBinaryFromMemory(&model_, &err, &warn, bytes_, unsigned(size_), nowhere)
                  : gltf.LoadASCIIFromString(&model_, &err, &warn, reinterpret_cast<const char*>(bytes_), unsigned(size_), nowhere);
    } else {
      std::ifstream f(path_, std::ios::binary);
      if (!f) fail("file", std::string("cannot open (") + std::strerror(errno) + ")");
      char magic[4] = {};
      f.read(magic, 4);
      binary = f.gcount() == 4 && std::memcmp(magic, "glTF", 4) == 0;
      f.close();
      ok = binary ? gltf.LoadBinaryFromFile(&model_, &err, &warn, path_) : gltf.LoadASCIIFromFile(&model_, &err, &warn, path_);
    }
    if (!ok || !err.empty()) fail(binary ? "glb" : "json", oneLine(err.empty() ? "cannot parse" : err));
    if (!warn.empty()) this->warn(oneLine(warn));
  }

  // The document's JSON: the file (or the fuzzer's bytes), or a .glb's first chunk when its
  // header holds together; "" for anything else (tinygltf then reports what is wrong).
  std::string jsonText() const {
    // The first 20 bytes tell a .glb (magic, version, length; chunk 0's length and type); only
    // its JSON chunk is read, not the binary chunk that follows (a large file's geometry).
    std::string bytes;
    uint64_t fileSize = 0;
    std::ifstream f;
    if (bytes_) {
      bytes.assign(reinterpret_cast<const char*>(bytes_), std::min<size_t>(size_, 20));
      fileSize = size_;
    } else {
      f.open(path_, std::ios::binary | std::ios::ate);
      fileSize = f ? uint64_t(f.tellg()) : 0;
      f.seekg(0);
      bytes.resize(size_t(std::min<uint64_t>(fileSize, 20)));
      f.read(bytes.data(), std::streamsize(bytes.size()));
    }
    const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    uint64_t offset = 0, length = fileSize;  // a .gltf: all of it
    if (binary) {
      uint32_t chunkLength, type;  // chunk 0: length, type "JSON", data
      if (bytes.size() < 20) return "";
      std::memcpy(&chunkLength, bytes.data() + 12, 4);
      std::memcpy(&type, bytes.data() + 16, 4);
      if (type != 0x4E4F534A || chunkLength > fileSize - 20) return "";
      offset = 20, length = chunkLength;
    }
    if (bytes_) return std::string(reinterpret_cast<const char*>(bytes_) + offset, size_t(length));
    bytes.resize(size_t(length));
    f.seekg(std::streamoff(offset));
    f.read(bytes.data(), std::streamsize(length));
    bytes.resize(size_t(f.gcount()));
    return bytes;
  }

  // ---------- accessors ----------
  // Which integer component types an attribute may have besides float: the core specification's
  // (texture coordinates: normalised unsigned bytes and shorts) and, in a file that uses
  // KHR_mesh_quantization, that extension's (POSITION: any byte or short, normalised or not;
  // NORMAL: normalised signed bytes and shorts; TEXCOORD_0: any byte or short). COLOR_0 may be
  // normalised unsigned bytes and shorts in the core specification.
  enum class Attribute { Position, Normal, Tangent, TexCoord, Color, Rotation };
  bool integerAllowed(Attribute a, int ct, bool normalized) const {
    const bool isUnsigned = ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    const bool isSigned = ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_SHORT;
    if ((a == Attribute::TexCoord || a == Attribute::Color) && isUnsigned && normalized) return true;  // core glTF
    if (a == Attribute::Rotation && isSigned && normalized) return true;  // EXT_mesh_gpu_instancing
    if (!quantized_) return false;
    switch (a) {
      case Attribute::Position: return isSigned || isUnsigned;
      case Attribute::Normal:
      case Attribute::Tangent: return isSigned && normalized;
      case Attribute::TexCoord: return isSigned || isUnsigned;
      case Attribute::Color:
      case Attribute::Rotation: return false;
    }
    return false;
  }

  // An attribute accessor checked against the file before anything is read or allocated from
  // it: its elements' place in the buffer, their count and component type.
  struct ElementView {
    const unsigned char* base = nullptr;  // null: no bufferView, every element zero (spec)
    size_t stride = 0, count = 0;
    int componentType = 0;
    bool normalized = false;
    std::string el;  // "accessors[3] (meshes[0].primitives[0].POSITION)", for messages
  };
  ElementView attributeView(int index, int components, Attribute attribute, const std::string& what) {
    const tinygltf::Accessor& acc = accessor(index, what);
    ElementView v;
    v.el = "accessors[" + std::to_string(index) + "] (" + what + ")";
    if (tinygltf::GetNumComponentsInType(acc.type) != components)
      fail(v.el, "expected " + std::to_string(components) + " components per element");
    int ct = acc.componentType;
    if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT && !integerAllowed(attribute, ct, acc.normalized))
      fail(v.el, "unsupported componentType " + std::to_string(ct) + (acc.normalized ? " (normalized)" : "") +
                     (quantized_ ? "" : " (integer attributes need KHR_mesh_quantization in extensionsUsed)"));
    // Validated against the data before anything is allocated from the file's count.
    if (!elementData(acc, v.el, &v.base, &v.stride)) {
      v.base = nullptr;
      if (acc.count > kMaxElementsWithoutData) fail(v.el, "count " + std::to_string(acc.count) + " without data");
    }
    v.count = acc.count;
    v.componentType = ct;
    v.normalized = acc.normalized;
    return v;
  }

  // Reads the elements of a checked accessor as `components` floats each, handing element i to
  // store(i, values): floats as stored, integers as the specification dequantises them
  // (normalised: c/255, c/65535, max(c/127, −1), max(c/32767, −1); otherwise the integer's value).
  template <int components, typename Store>
  void readElements(const ElementView& v, Store&& store) {
    float values[components] = {};
    if (!v.base) {  // no bufferView: all zeros (spec)
      for (size_t i = 0; i < v.count; ++i) store(i, values);
      return;
    }
    const int ct = v.componentType;
    const int compSize = tinygltf::GetComponentSizeInBytes(ct);
    for (size_t i = 0; i < v.count; ++i) {
      const unsigned char* e = v.base + i * v.stride;
      if (ct == TINYGLTF_COMPONENT_TYPE_FLOAT) {
        std::memcpy(values, e, sizeof(values));
      } else {
        for (int c = 0; c < components; ++c) {
          if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
            values[c] = v.normalized ? e[c] / 255.0f : float(e[c]);
          } else if (ct == TINYGLTF_COMPONENT_TYPE_BYTE) {
            int8_t b;
            std::memcpy(&b, e + c, 1);
            values[c] = v.normalized ? std::max(b / 127.0f, -1.0f) : float(b);
          } else if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
            uint16_t x;
            std::memcpy(&x, e + c * compSize, 2);
            values[c] = v.normalized ? x / 65535.0f : float(x);
          } else {
            int16_t x;
            std::memcpy(&x, e + c * compSize, 2);
            values[c] = v.normalized ? std::max(x / 32767.0f, -1.0f) : float(x);
          }
        }
      }
      // One test for every component: a sum of finite floats times 0 is 0, anything else NaN.
      float check = 0;
      for (int c = 0; c < components; ++c) check += values[c] - values[c];
      if (check != 0.0f) fail(v.el, "element " + std::to_string(i) + " is not finite");
      store(i, values);
    }
  }

  // An index accessor, checked: its element count and where they are.
  ElementView indexView(int index) {
    const tinygltf::Accessor& acc = accessor(index, "indices");
    ElementView v;
    v.el = "accessors[" + std::to_string(index) + "] (indices)";
    if (acc.type != TINYGLTF_TYPE_SCALAR) fail(v.el, "indices must be SCALAR");
    int ct = acc.componentType;
    if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(v.el, "indices must be unsigned byte, short or int");
    if (!elementData(acc, v.el, &v.base, &v.stride)) fail(v.el, "indices without a bufferView");
    v.count = acc.count;
    v.componentType = ct;
    return v;
  }
  void readIndices(const ElementView& v, uint32_t* out) {
    const int ct = v.componentType;
    if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT && v.stride == 4) {
      std::memcpy(out, v.base, v.count * 4);
      return;
    }
    for (size_t i = 0; i < v.count; ++i) {
      const unsigned char* e = v.base + i * v.stride;
      if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
        out[i] = e[0];
      } else if (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
        uint16_t x;
        std::memcpy(&x, e, 2);
        out[i] = x;
      } else {
        std::memcpy(&out[i], e, 4);
      }
    }
  }

  const tinygltf::Accessor& accessor(int index, const std::string& what) {
    if (index < 0 || index >= int(model_.accessors.size()))
      fail(what, "accessor index " + std::to_string(index) + " out of range");
    const tinygltf::Accessor& acc = model_.accessors[index];
    if (acc.sparse.isSparse) fail("accessors[" + std::to_string(index) + "]", "sparse accessors are not supported");
    return acc;
  }

  // Checks that every element of the accessor lies inside its buffer view and buffer, before
  // anything is allocated from its count. Returns false when the accessor has no bufferView.
  bool elementData(const tinygltf::Accessor& acc, const std::string& el, const unsigned char** base, size_t* stride) {
    if (acc.bufferView < 0) return false;
    if (acc.bufferView >= int(model_.bufferViews.size())) fail(el, "bufferView out of range");
    const tinygltf::BufferView& view = model_.bufferViews[acc.bufferView];
    if (view.buffer < 0 || view.buffer >= int(model_.buffers.size()))
      fail("bufferViews[" + std::to_string(acc.bufferView) + "]", "buffer out of range");
    const tinygltf::Buffer& buffer = model_.buffers[view.buffer];
    size_t elementSize = size_t(tinygltf::GetComponentSizeInBytes(acc.componentType)) *
                         size_t(tinygltf::GetNumComponentsInType(acc.type));
    *stride = view.byteStride ? view.byteStride : elementSize;
    if (*stride < elementSize) fail(el, "byteStride smaller than an element");
    if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
      fail("bufferViews[" + std::to_string(acc.bufferView) + "]",
           "range [" + std::to_string(view.byteOffset) + ", +" + std::to_string(view.byteLength) +
               ") exceeds buffer " + std::to_string(view.buffer) + " of " + std::to_string(buffer.data.size()) +
               " bytes");
    if (acc.count == 0) {
      *base = buffer.data.data();
      return true;
    }
    // Last byte needed: byteOffset + (count−1)·stride + elementSize, computed without overflow.
    size_t avail = view.byteLength;
    if (acc.byteOffset > avail || (acc.count - 1) > (avail - acc.byteOffset) / *stride ||
        acc.byteOffset + (acc.count - 1) * *stride + elementSize > avail)
      fail(el, "count " + std::to_string(acc.count) + " exceeds its bufferView (" + std::to_string(avail) + " bytes)");
    *base = buffer.data.data() + view.byteOffset + acc.byteOffset;
    return true;
  }

  // ---------- materials ----------
  static bool getNumber(const tinygltf::Value& obj, const char* key, double* out) {
    if (!obj.IsObject() || !obj.Has(key) || !obj.Get(key).IsNumber()) return false;
    *out = obj.Get(key).GetNumberAsDouble();
    return true;
  }
  static const tinygltf::Value* extension(const tinygltf::ExtensionMap& ext, const char* name) {
    auto it = ext.find(name);
    return it == ext.end() ? nullptr : &it->second;
  }
  const tinygltf::Value* photonlabExtras(const tinygltf::Value& extras) {
    if (extras.IsObject() && extras.Has("photonlab")) return &extras.Get("photonlab");
    return nullptr;
  }
  Spectrum spectrumValue(const tinygltf::Value& v, const std::string& el) {
    if (v.IsNumber()) return Spectrum(float(v.GetNumberAsDouble()));
    if (v.IsArray() && v.ArrayLen() == 3) {
      Spectrum s;
      for (int i = 0; i < 3; ++i) {
        if (!v.Get(i).IsNumber()) fail(el, "must be a number or an array of 3 numbers");
        s[i] = float(v.Get(i).GetNumberAsDouble());
      }
      return s;
    }
    fail(el, "must be a number or an array of 3 numbers");
  }
  void checkRange(const std::string& el, const Spectrum& s, float lo, float hi) {
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(s[i]) || s[i] < lo || s[i] > hi)
        fail(el, "value " + std::to_string(s[i]) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }

  // A textureInfo's KHR_texture_transform (identity without one). Its texCoord, like the
  // textureInfo's own, can only name TEXCOORD_0.
  template <typename Info>
  UvTransform textureTransform(int material, const Info& info, const std::string& el) {
    UvTransform t;
    const tinygltf::Value* ext = extension(info.extensions, "KHR_texture_transform");
    if (!ext || info.index < 0) return t;
    const std::string e = el + ".extensions.KHR_texture_transform";
    if (!ext->IsObject()) fail(e, "must be an object");
    auto pair = [&](const char* key, Vec2* out) {
      if (!ext->Has(key)) return;
      const tinygltf::Value& v = ext->Get(key);
      if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber())
        fail(e + "." + key, "must be an array of 2 numbers");
      *out = Vec2(float(v.Get(0).GetNumberAsDouble()), float(v.Get(1).GetNumberAsDouble()));
      if (!isFinite(Vec3(*out, 0.0f))) fail(e + "." + key, "must be finite");
    };
    pair("offset", &t.offset);
    pair("scale", &t.scale);
    double rotation = 0;
    if (ext->Has("rotation") && !(getNumber(*ext, "rotation", &rotation) && std::isfinite(rotation)))
      fail(e + ".rotation", "must be a finite number of radians");
    t.setRotation(float(rotation));
    double texCoord = 0;
    if (ext->Has("texCoord") && getNumber(*ext, "texCoord", &texCoord) && texCoord != 0)
      ignoredInMaterial(material, "KHR_texture_transform.texCoord " + std::to_string(int(texCoord)) + " is ignored; TEXCOORD_0 is used");
    return t;
  }

  // A textureInfo inside a material extension (tinygltf leaves those as JSON values), in the
  // shape textureTransform() reads; index −1 when the extension has no `key`.
  struct ExtensionTexture {
    int index = -1;
    tinygltf::ExtensionMap extensions;
  };
  ExtensionTexture extensionTexture(int material, const tinygltf::Value& ext, const char* key, const std::string& el) {
    ExtensionTexture t;
    if (!ext.Has(key)) return t;
    const tinygltf::Value& info = ext.Get(key);
    double number = -1;
    if (!getNumber(info, "index", &number)) fail(el + "." + key + ".index", "must be a texture index");
    t.index = int(number);
    if (getNumber(info, "texCoord", &number) && number != 0)
      ignoredInMaterial(material, std::string(key) + " uses TEXCOORD_" + std::to_string(int(number)) + "; TEXCOORD_0 is used");
    if (info.Has("extensions") && info.Get("extensions").IsObject())
      for (const std::string& name : info.Get("extensions").Keys()) t.extensions[name] = info.Get("extensions").Get(name);
    return t;
  }
  // A factor in [0, 1], left as it is when absent.
  void unitInterval(const tinygltf::Value& ext, const char* key, const std::string& el, double* value) {
    if (ext.Has(key) && !getNumber(ext, key, value)) fail(el + "." + key, "must be a number");
    if (!(*value >= 0 && *value <= 1)) fail(el + "." + key, "must be in [0, 1]");
  }

  // Colour textures (base colour, emission) are sRGB-encoded; data textures (metallic-roughness)
  // are linear, so they are decoded with `srgb` false.
  std::shared_ptr<const Image> textureImage(int textureIndex, const std::string& el, bool srgb = true) {
    if (textureIndex < 0) return nullptr;
    if (textureIndex >= int(model_.textures.size())) fail(el, "texture index out of range");
    int src = model_.textures[textureIndex].source;
    if (src < 0 || src >= int(model_.images.size())) fail(el, "texture has no valid image source");
    auto& cache = srgb ? images_ : linearImages_;
    auto cached = cache.find(src);
    if (cached != cache.end()) return cached->second;
    const tinygltf::Image& im = model_.images[src];
    // tinygltf hands over 8- or 16-bit samples (16-bit PNGs keep their depth), 1 to 4 per texel
    // (it expands to RGBA unless asked not to); grey, with or without alpha, is every channel.
    const int channels = im.component, bytes = im.bits / 8;
    if (im.width <= 0 || im.height <= 0 || channels < 1 || channels > 4 || (im.bits != 8 && im.bits != 16) ||
        im.image.size() < size_t(im.width) * im.height * channels * bytes)
      fail("images[" + std::to_string(src) + "]", "unsupported or undecoded image (need 8- or 16-bit grey, RGB or RGBA)");
    auto sample = [&](size_t texel, int c) {
      const size_t k = (texel * channels + c) * bytes;
      if (bytes == 1) return im.image[k] / 255.0f;
      uint16_t v;  // in the machine's byte order, as stb_image returns it
      std::memcpy(&v, &im.image[k], 2);
      return v / 65535.0f;
    };
    auto image = std::make_shared<Image>();
    image->width = im.width;
    image->height = im.height;
    image->texels.resize(size_t(im.width) * im.height);
    for (size_t i = 0; i < image->texels.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        float v = sample(i, channels >= 3 ? c : 0);
        image->texels[i][c] = srgb ? srgbDecode(v) : v;
      }
    if (channels == 2 || channels == 4) {  // grey + alpha, RGBA: coverage is linear
      image->alpha.resize(image->texels.size());
      for (size_t i = 0; i < image->texels.size(); ++i) image->alpha[i] = sample(i, channels - 1);
    }
    cache[src] = image;
    return image;
  }

  // What the file uses that photonlab does not render, each feature in one line: an extension
  // with the first material using it (and how many more do), any other unimplemented
  // extension, skins, animations and morph targets.
  void warnIgnored() {
    const auto& supported = supportedGltfExtensions();
    auto implemented = [&](const std::string& name) { return std::find(supported.begin(), supported.end(), name) != supported.end(); };
    std::set<std::string> byMaterial;
    for (size_t i = 0; i < model_.materials.size(); ++i)
      for (const auto& ext : model_.materials[i].extensions)
        if (!implemented(ext.first)) {
          ignoredInMaterial(i, ext.first + " is not implemented: ignored");
          byMaterial.insert(ext.first);
        }
    for (const std::string& name : model_.extensionsUsed)
      if (!implemented(name) && !byMaterial.count(name)) warn("extensionsUsed: " + name + " is not implemented: ignored");
    if (!model_.skins.empty())
      warn("skins: " + std::to_string(model_.skins.size()) + " ignored (meshes render as their vertices are stored)");
    if (!model_.animations.empty())
      warn("animations: " + std::to_string(model_.animations.size()) + " ignored (the scene renders as its nodes are posed)");
    for (size_t i = 0; i < model_.materials.size(); ++i)
      if (model_.materials[i].occlusionTexture.index >= 0)
        ignoredInMaterial(i, "occlusionTexture is ignored (global illumination computes occlusion)");
    size_t morphed = 0;
    for (const auto& mesh : model_.meshes)
      for (const auto& prim : mesh.primitives) morphed += !prim.targets.empty();
    if (morphed) warn("morph targets: " + std::to_string(morphed) + " primitive(s) with targets; the base shape is rendered");
  }

  // A feature material `index` uses and photonlab ignores or approximates: collected, then said
  // once per feature (the first material, and how many more), so that a file with a hundred
  // materials gives one line, not a hundred.
  void ignoredInMaterial(size_t index, const std::string& what) {
    auto it = ignored_.find(what);
    if (it == ignored_.end()) {
      std::string label = index == size_t(-1) ? std::string("default material") : "materials[" + std::to_string(index) + "]";
      if (index != size_t(-1) && !model_.materials[index].name.empty()) label += " '" + model_.materials[index].name + "'";
      ignoredOrder_.push_back(what);
      ignored_[what] = {label, 1};
    } else {
      ++it->second.second;
    }
  }

  void loadMaterials() {
    warnIgnored();
    for (size_t i = 0; i < model_.materials.size(); ++i) scene_->addMaterial(material(model_.materials[i], i));
    // glTF's default material, for primitives without one.
    tinygltf::Material fallback;
    fallback.name = "default";
    defaultMaterial_ = scene_->addMaterial(material(fallback, size_t(-1)));
    for (const std::string& what : ignoredOrder_) {
      const auto& [label, count] = ignored_[what];
      warn(label + (count > 1 ? " (and " + std::to_string(count - 1) + " more)" : "") + ": " + what);
    }
  }

  Material material(const tinygltf::Material& m, size_t index) {
    std::string el = index == size_t(-1) ? std::string("default material") : "materials[" + std::to_string(index) + "]";
    Material out;
    out.name = m.name.empty() ? el : m.name;
    out.twoSided = m.doubleSided;

    const auto& pbr = m.pbrMetallicRoughness;
    Spectrum baseColor(1.0f);
    if (pbr.baseColorFactor.size() >= 3)
      baseColor = Spectrum(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]), float(pbr.baseColorFactor[2]));
    checkRange(el + ".baseColorFactor", baseColor, 0.0f, 1.0f);
    if (pbr.baseColorTexture.index >= 0 && pbr.baseColorTexture.texCoord != 0)
      ignoredInMaterial(index, "baseColorTexture uses TEXCOORD_" + std::to_string(pbr.baseColorTexture.texCoord) + "; TEXCOORD_0 is used");
    ColorTexture base(baseColor, textureImage(pbr.baseColorTexture.index, el + ".baseColorTexture"),
                      textureTransform(index, pbr.baseColorTexture, el + ".baseColorTexture"));
    if (m.normalTexture.index >= 0) {
      if (m.normalTexture.texCoord != 0)
        ignoredInMaterial(index, "normalTexture uses TEXCOORD_" + std::to_string(m.normalTexture.texCoord) + "; TEXCOORD_0 is used");
      if (!std::isfinite(m.normalTexture.scale)) fail(el + ".normalTexture.scale", "not finite");
      auto map = std::make_shared<NormalMap>();
      map->image = textureImage(m.normalTexture.index, el + ".normalTexture", false);
      map->transform = textureTransform(index, m.normalTexture, el + ".normalTexture");
      map->scale = float(m.normalTexture.scale);
      out.normalMap = map;
    }
    // alphaMode: coverage = baseColorFactor's alpha × the base-colour texture's alpha.
    float alphaFactor = pbr.baseColorFactor.size() == 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
    if (!(alphaFactor >= 0 && alphaFactor <= 1)) fail(el + ".baseColorFactor[3]", "alpha must be in [0, 1]");
    if (m.alphaMode == "MASK" || m.alphaMode == "BLEND") {
      if (!(m.alphaCutoff >= 0 && m.alphaCutoff <= 1)) fail(el + ".alphaCutoff", "must be in [0, 1]");
      out.alphaMode = m.alphaMode == "MASK" ? AlphaMode::Mask : AlphaMode::Blend;
      out.alphaCutoff = float(m.alphaCutoff);
      out.alpha = std::make_shared<AlphaTexture>(alphaFactor, textureImage(pbr.baseColorTexture.index, el + ".baseColorTexture"),
                                                 textureTransform(index, pbr.baseColorTexture, el + ".baseColorTexture"));
      // Fully opaque everywhere (no alpha channel, factor 1): nothing to test per hit, unless a
      // mesh's COLOR_0 brings an alpha of its own (Scene tests only those meshes).
      if (out.alpha->isConstant() && (out.alphaMode == AlphaMode::Mask ? alphaFactor >= out.alphaCutoff : alphaFactor == 1.0f))
        out.alpha = nullptr;
    } else if (m.alphaMode != "OPAQUE" && !m.alphaMode.empty()) {
      fail(el + ".alphaMode", "must be OPAQUE, MASK or BLEND, got \"" + m.alphaMode + "\"");
    }
    float metallic = float(pbr.metallicFactor), roughness = float(pbr.roughnessFactor);
    if (!(metallic >= 0 && metallic <= 1)) fail(el + ".metallicFactor", "must be in [0, 1]");
    if (!(roughness >= 0 && roughness <= 1)) fail(el + ".roughnessFactor", "must be in [0, 1]");
    if (pbr.metallicRoughnessTexture.index >= 0 && pbr.metallicRoughnessTexture.texCoord != 0)
      ignoredInMaterial(index, "metallicRoughnessTexture uses TEXCOORD_" + std::to_string(pbr.metallicRoughnessTexture.texCoord) + "; TEXCOORD_0 is used");
    const bool mrTextured = pbr.metallicRoughnessTexture.index >= 0;

    // Emission: emissiveFactor × KHR_materials_emissive_strength, radiance in W/(m²·sr).
    Spectrum emissive(0.0f);
    if (m.emissiveFactor.size() >= 3)
      emissive = Spectrum(float(m.emissiveFactor[0]), float(m.emissiveFactor[1]), float(m.emissiveFactor[2]));
    double strength = 1.0;
    if (auto* ext = extension(m.extensions, "KHR_materials_emissive_strength")) getNumber(*ext, "emissiveStrength", &strength);
    out.emission = emissive * float(strength) * lightScale_;  // nits → W/(m²·sr) if photometric
    checkRange(el + ".emission", out.emission, 0.0f, 1e30f);
    if (m.emissiveTexture.index >= 0) {
      if (m.emissiveTexture.texCoord != 0)
        ignoredInMaterial(index, "emissiveTexture uses TEXCOORD_" + std::to_string(m.emissiveTexture.texCoord) + "; TEXCOORD_0 is used");
      out.emissionTexture = std::make_shared<ColorTexture>(out.emission, textureImage(m.emissiveTexture.index, el + ".emissiveTexture"),
                                                           textureTransform(index, m.emissiveTexture, el + ".emissiveTexture"));
    }

    // KHR_materials_unlit, approximated: the base colour is emitted, in the file's units (so an
    // unlit white shows as bright as the default sky, as viewers show it), and the surface
    // reflects nothing. Unlike a viewer's unlit surface it also lights what it faces.
    const bool unlit = extension(m.extensions, "KHR_materials_unlit") != nullptr;
    if (unlit) {
      out.emission = baseColor * lightScale_;
      out.emissionTexture = pbr.baseColorTexture.index >= 0
                                ? std::make_shared<ColorTexture>(out.emission, textureImage(pbr.baseColorTexture.index, el + ".baseColorTexture"),
                                                                 textureTransform(index, pbr.baseColorTexture, el + ".baseColorTexture"))
                                : nullptr;
    }

    double transmission = 0.0, thickness = 0.0, ior = 1.5;
    int transmissionTexture = -1;
    if (auto* ext = extension(m.extensions, "KHR_materials_transmission")) {
      const std::string te = el + ".KHR_materials_transmission";
      if (ext->Has("transmissionFactor") && !getNumber(*ext, "transmissionFactor", &transmission))
        fail(te + ".transmissionFactor", "must be a number");
      if (!(transmission >= 0 && transmission <= 1)) fail(te + ".transmissionFactor", "must be in [0, 1]");
      if (ext->Has("transmissionTexture")) {
        const tinygltf::Value& info = ext->Get("transmissionTexture");
        double number = -1;
        if (!getNumber(info, "index", &number)) fail(te + ".transmissionTexture.index", "must be a texture index");
        transmissionTexture = int(number);
        if (getNumber(info, "texCoord", &number) && number != 0)
          ignoredInMaterial(index, "transmissionTexture uses TEXCOORD_" + std::to_string(int(number)) + "; TEXCOORD_0 is used");
        if (info.Has("extensions")) ignoredInMaterial(index, "transmissionTexture's KHR_texture_transform is ignored");
      }
    }
    double attenuationDistance = INFINITY;
    Spectrum attenuationColor(1.0f);
    if (auto* ext = extension(m.extensions, "KHR_materials_volume")) {
      const std::string ve = el + ".KHR_materials_volume";
      getNumber(*ext, "thicknessFactor", &thickness);
      if (ext->Has("attenuationDistance") && !(getNumber(*ext, "attenuationDistance", &attenuationDistance) && attenuationDistance > 0))
        fail(ve + ".attenuationDistance", "must be a distance > 0 (metres)");
      if (ext->Has("attenuationColor")) {
        attenuationColor = spectrumValue(ext->Get("attenuationColor"), ve + ".attenuationColor");
        checkRange(ve + ".attenuationColor", attenuationColor, 0.0f, 1.0f);
      }
      if (ext->Has("thicknessTexture")) ignoredInMaterial(index, "KHR_materials_volume.thicknessTexture is ignored (the volume is the closed mesh itself)");
    }
    if (auto* ext = extension(m.extensions, "KHR_materials_ior")) getNumber(*ext, "ior", &ior);
    if (!(ior >= 1.0 && ior < 10.0) && ior != 0.0) fail(el + ".KHR_materials_ior.ior", "must be in [1, 10)");
    if (ior == 0.0) ior = 1.5;  // the extension allows 0 as "unset"
    double dispersion = 0.0;  // KHR_materials_dispersion: 20/V_d (Abbe number); 0 = none
    if (auto* ext = extension(m.extensions, "KHR_materials_dispersion")) {
      if (ext->Has("dispersion") && !getNumber(*ext, "dispersion", &dispersion))
        fail(el + ".KHR_materials_dispersion.dispersion", "must be a number");
      if (!(dispersion >= 0.0 && dispersion <= 20.0)) fail(el + ".KHR_materials_dispersion.dispersion", "must be in [0, 20]");
    }

    // KHR_materials_clearcoat and KHR_materials_sheen: layers over the material (bsdfs/layered.h).
    double clearcoat = 0.0, clearcoatRoughness = 0.0, sheenRoughness = 0.0;
    Spectrum sheenColor(0.0f);
    ExtensionTexture clearcoatTexture, clearcoatRoughnessTexture, sheenColorTexture, sheenRoughnessTexture;
    if (auto* ext = extension(m.extensions, "KHR_materials_clearcoat")) {
      const std::string ce = el + ".KHR_materials_clearcoat";
      unitInterval(*ext, "clearcoatFactor", ce, &clearcoat);
      unitInterval(*ext, "clearcoatRoughnessFactor", ce, &clearcoatRoughness);
      clearcoatTexture = extensionTexture(index, *ext, "clearcoatTexture", ce);
      clearcoatRoughnessTexture = extensionTexture(index, *ext, "clearcoatRoughnessTexture", ce);
      if (ext->Has("clearcoatNormalTexture"))
        ignoredInMaterial(index, "KHR_materials_clearcoat.clearcoatNormalTexture is ignored (the coat takes the material's shading normal)");
    }
    if (auto* ext = extension(m.extensions, "KHR_materials_sheen")) {
      const std::string se = el + ".KHR_materials_sheen";
      if (ext->Has("sheenColorFactor")) {
        sheenColor = spectrumValue(ext->Get("sheenColorFactor"), se + ".sheenColorFactor");
        checkRange(se + ".sheenColorFactor", sheenColor, 0.0f, 1.0f);
      }
      unitInterval(*ext, "sheenRoughnessFactor", se, &sheenRoughness);
      sheenColorTexture = extensionTexture(index, *ext, "sheenColorTexture", se);
      sheenRoughnessTexture = extensionTexture(index, *ext, "sheenRoughnessTexture", se);
    }

    const tinygltf::Value* extras = photonlabExtras(m.extras);
    // extras.photonlab.bsdf = "lambertian": f = baseColor/π, without the specification's 4 %
    // specular layer (what photonlab's own scenes and closed-form tests mean by a diffuse wall).
    bool lambertian = false;
    if (extras && extras->IsObject() && extras->Has("bsdf")) {
      const tinygltf::Value& b = extras->Get("bsdf");
      if (!b.IsString() || b.Get<std::string>() != "lambertian") fail(el + ".extras.photonlab.bsdf", "must be \"lambertian\"");
      if (metallic != 0 || mrTextured) fail(el + ".extras.photonlab.bsdf", "\"lambertian\" needs metallicFactor 0 and no metallicRoughnessTexture");
      lambertian = true;
    }
    GltfMaterial desc;
    desc.element = el;
    desc.base = base;
    desc.metallic = metallic, desc.roughness = roughness;
    desc.mrTextured = mrTextured;
    desc.metallicRoughness = [&] {
      return ColorTexture(Spectrum(1.0f, roughness, metallic),
                          textureImage(pbr.metallicRoughnessTexture.index, el + ".metallicRoughnessTexture", false),
                          textureTransform(index, pbr.metallicRoughnessTexture, el + ".metallicRoughnessTexture"));
    };
    desc.transmission = transmission, desc.thickness = thickness, desc.ior = ior, desc.dispersion = dispersion;
    desc.transmissionTexture = transmissionTexture;
    // Thin-walled transmission (no volume): factor × the linear texture's R.
    desc.transmissionColor = [&] {
      return ColorTexture(Spectrum(float(transmission)),
                          textureImage(transmissionTexture, el + ".KHR_materials_transmission.transmissionTexture", false));
    };
    desc.attenuationColor = attenuationColor, desc.attenuationDistance = attenuationDistance;
    desc.clearcoat = float(clearcoat);
    desc.clearcoatWeight = [&] {
      return ColorTexture(Spectrum(float(clearcoat)), textureImage(clearcoatTexture.index, el + ".KHR_materials_clearcoat.clearcoatTexture", false),
                          textureTransform(index, clearcoatTexture, el + ".KHR_materials_clearcoat.clearcoatTexture"));
    };
    desc.clearcoatRoughness = [&] {
      const std::string te = el + ".KHR_materials_clearcoat.clearcoatRoughnessTexture";
      return ColorTexture(Spectrum(1.0f, float(clearcoatRoughness), 1.0f), textureImage(clearcoatRoughnessTexture.index, te, false),
                          textureTransform(index, clearcoatRoughnessTexture, te));
    };
    desc.sheen = std::max({sheenColor.r, sheenColor.g, sheenColor.b});
    desc.sheenColor = [&] {
      const std::string te = el + ".KHR_materials_sheen.sheenColorTexture";
      return ColorTexture(sheenColor, textureImage(sheenColorTexture.index, te), textureTransform(index, sheenColorTexture, te));
    };
    desc.sheenRoughness = [&] {
      const std::string te = el + ".KHR_materials_sheen.sheenRoughnessTexture";
      return AlphaTexture(float(sheenRoughness), textureImage(sheenRoughnessTexture.index, te, false),
                          textureTransform(index, sheenRoughnessTexture, te));
    };
    desc.lambertian = lambertian;
    if (unlit) desc.lambertian = true, desc.base = ColorTexture(Spectrum(0.0f)), desc.transmission = 0, desc.clearcoat = desc.sheen = 0;
    desc.extras = extras;
    Reader reader(*this, index);
    for (const BSDFFactory& factory : bsdfFactories())
      if (factory.applies(desc)) {
        out.bsdf = factory.make(desc, reader, out);
        break;
      }
    for (const BSDFLayerFactory& layer : bsdfLayerFactories()) {
      if (!layer.applies(desc)) continue;
      if (out.bsdf->isSpecular()) {
        ignoredInMaterial(index, std::string(layer.name) + " over a smooth glass or mirror is ignored (a layer needs a rough base)");
        continue;
      }
      out.bsdf = std::make_unique<Layered>(std::move(out.bsdf), layer.make(desc, reader));
    }
    return out;
  }

  // ---------- nodes ----------
  Mat4 localTransform(const tinygltf::Node& n, const std::string& el) {
    for (double v : n.matrix)
      if (!std::isfinite(v)) fail(el + ".matrix", "not finite");
    if (n.matrix.size() == 16) {
      Mat4 m;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = float(n.matrix[c * 4 + r]);  // column-major
      return m;
    }
    Mat4 m(1.0f);
    auto finite = [&](const std::vector<double>& v, const char* what) {
      for (double x : v)
        if (!std::isfinite(x)) fail(el + "." + what, "not finite");
    };
    finite(n.translation, "translation");
    finite(n.rotation, "rotation");
    finite(n.scale, "scale");
    if (n.translation.size() == 3) m = glm::translate(m, Vec3(n.translation[0], n.translation[1], n.translation[2]));
    if (n.rotation.size() == 4) {
      glm::quat q(float(n.rotation[3]), float(n.rotation[0]), float(n.rotation[1]), float(n.rotation[2]));  // w, x, y, z
      if (glm::length(q) == 0) fail(el + ".rotation", "zero quaternion");
      m = m * glm::mat4_cast(glm::normalize(q));
    }
    if (n.scale.size() == 3) m = glm::scale(m, Vec3(n.scale[0], n.scale[1], n.scale[2]));
    return m;
  }

  void visit(int index, const Mat4& parent, int depth) {
    if (index < 0 || index >= int(model_.nodes.size())) fail("nodes", "node index " + std::to_string(index) + " out of range");
    if (depth > 256) fail("nodes[" + std::to_string(index) + "]", "hierarchy deeper than 256 (a cycle?)");
    const tinygltf::Node& node = model_.nodes[index];
    std::string el = "nodes[" + std::to_string(index) + "]";
    Mat4 world = parent * localTransform(node, el);
    for (int c = 0; c < 4; ++c)
      if (!isFinite(Vec3(world[c])) || !std::isfinite(world[c][3])) fail(el, "transform is not finite (overflow)");
    if (!withinScene(Vec3(world[3])))
      fail(el, "transform places it beyond 1e7 m from the origin (coordinates are in metres)");
    if (auto* ext = extension(node.extensions, "EXT_mesh_gpu_instancing"); ext && node.mesh >= 0) {
      for (const Mat4& local : gpuInstances(*ext, el + ".extensions.EXT_mesh_gpu_instancing")) placeMesh(node.mesh, world * local, el);
    } else if (node.mesh >= 0) {
      placeMesh(node.mesh, world, el);
    }
    if (node.camera >= 0) addCamera(node.camera, index, world, el);
    if (auto* ext = extension(node.extensions, "KHR_lights_punctual")) {
      double light;
      if (!getNumber(*ext, "light", &light)) fail(el + ".KHR_lights_punctual", "missing light index");
      addLight(int(light), world);
    }
    for (int child : node.children) visit(child, world, depth + 1);
  }

  void addCamera(int index, int nodeIndex, const Mat4& world, const std::string& el) {
    if (index >= int(model_.cameras.size())) fail(el + ".camera", "index out of range");
    const tinygltf::Camera& cam = model_.cameras[index];
    std::string cel = "cameras[" + std::to_string(index) + "]";
    if (cam.type != "perspective") {
      warn(el + ": " + cel + " is " + (cam.type.empty() ? "untyped" : cam.type) + ", not perspective: ignored");
      return;
    }
    Camera c;
    c.yfov = float(cam.perspective.yfov);
    c.aspectRatio = float(cam.perspective.aspectRatio);
    if (!(c.yfov > 0 && c.yfov < kPi)) fail(cel + ".yfov", "must be in (0, π)");
    if (!(c.aspectRatio >= 0 && std::isfinite(c.aspectRatio))) fail(cel + ".aspectRatio", "must be positive");
    c.position = Vec3(world * glm::vec4(0, 0, 0, 1));
    c.forward = glm::normalize(Vec3(world * glm::vec4(0, 0, -1, 0)));
    Vec3 up = Vec3(world * glm::vec4(0, 1, 0, 0));
    c.right = glm::normalize(glm::cross(c.forward, up));
    c.up = glm::cross(c.right, c.forward);
    if (!isFinite(c.position) || !isFinite(c.forward) || !isFinite(c.right)) fail(el, "degenerate camera transform");
    const std::string& nodeName = model_.nodes[size_t(nodeIndex)].name;
    const std::string& cameraName = cam.name;
    std::string name = el + (nodeName.empty() ? "" : " '" + nodeName + "'") + ", " + cel + (cameraName.empty() ? "" : " '" + cameraName + "'");
    scene_->addFileCamera({name, c});
  }

  void addLight(int index, const Mat4& world) {
    std::string el = "KHR_lights_punctual.lights[" + std::to_string(index) + "]";
    if (index < 0 || index >= int(model_.lights.size())) fail(el, "index out of range");
    const tinygltf::Light& l = model_.lights[index];
    Spectrum color(1.0f);
    if (l.color.size() >= 3) color = Spectrum(float(l.color[0]), float(l.color[1]), float(l.color[2]));
    checkRange(el + ".color", color, 0.0f, 1e30f);
    float intensity = float(l.intensity);
    if (!(intensity >= 0 && std::isfinite(intensity))) fail(el + ".intensity", "must be finite and ≥ 0");
    intensity *= lightScale_;  // cd → W/sr, lx → W/m² if photometric
    Spectrum I = color * intensity;  // W/sr (directional: W/m²)

    double power = -1, warn = -1, temperature = 0;
    bool equalEnergy = false;
    if (const tinygltf::Value* ex = photonlabExtras(l.extras)) {
      if (ex->Has("illuminant")) {
        const tinygltf::Value& il = ex->Get("illuminant");
        if (!il.IsString() || (il.Get<std::string>() != "D65" && il.Get<std::string>() != "E"))
          fail(el + ".extras.photonlab.illuminant", "must be \"D65\" (the default) or \"E\" (equal energy)");
        equalEnergy = il.Get<std::string>() == "E";
      }
      if (ex->Has("temperature") && !(getNumber(*ex, "temperature", &temperature) && temperature >= 100 && temperature <= 1e5))
        fail(el + ".extras.photonlab.temperature", "must be a temperature in kelvin, from 100 to 100000");
      if (ex->Has("power") && !getNumber(*ex, "power", &power)) fail(el + ".extras.photonlab.power", "must be a number");
      if (ex->Has("warn_exponent") && !getNumber(*ex, "warn_exponent", &warn))
        fail(el + ".extras.photonlab.warn_exponent", "must be a number");
      if (ex->Has("power") && !(power >= 0 && std::isfinite(power))) fail(el + ".extras.photonlab.power", "must be ≥ 0");
      if (ex->Has("warn_exponent") && !(warn >= 0 && warn < 1e6)) fail(el + ".extras.photonlab.warn_exponent", "must be in [0, 1e6)");
    }
    if (temperature > 0) {
      // A blackbody's colour at luminance 1, like white (1, 1, 1): intensity and power keep
      // their meaning. It replaces `color`.
      if (l.color.size() >= 3 && color != Spectrum(1.0f)) this->warn(el + ": color is replaced by the blackbody colour of extras.photonlab.temperature");
      color = blackbodyRGB(temperature);
      I = color * intensity;
    }
    if (equalEnergy) {
      if (temperature > 0) fail(el + ".extras.photonlab", "give temperature or illuminant, not both");
      // Like a temperature, the illuminant fixes the spectrum: its colour replaces `color`.
      if (l.color.size() >= 3 && color != Spectrum(1.0f)) this->warn(el + ": color is replaced by the equal-energy illuminant's");
      color = equalEnergyRGB();
      I = color * intensity;
    }
    GltfLight desc;
    desc.element = el, desc.type = l.type;
    desc.position = Vec3(world * glm::vec4(0, 0, 0, 1));
    desc.direction = glm::normalize(Vec3(world * glm::vec4(0, 0, -1, 0)));
    if (!isFinite(desc.position) || !isFinite(desc.direction)) fail(el, "degenerate light transform");
    desc.color = color, desc.I = I;
    desc.power = power, desc.warnExponent = warn;
    desc.innerCone = float(l.spot.innerConeAngle), desc.outerCone = float(l.spot.outerConeAngle);
    Reader reader(*this, size_t(-1));
    for (const LightFactory& factory : lightFactories())
      if (factory.applies(desc)) {
        std::unique_ptr<Light> light = factory.make(desc, reader);
        light->temperature = float(temperature);
        light->equalEnergy = equalEnergy;
        scene_->addLight(std::move(light));
        return;
      }
    fail(el + ".type", "unknown light type '" + l.type + "'");
  }

  // A primitive photonlab renders (triangles, strips, fans), with its POSITION: nullptr for
  // points and lines (warned once per primitive, by the caller).
  static bool isTriangles(const tinygltf::Primitive& prim) {
    return prim.mode == TINYGLTF_MODE_TRIANGLES || prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
           prim.mode == TINYGLTF_MODE_TRIANGLE_FAN || prim.mode == -1;
  }
  static size_t triangleCount(int mode, size_t indices) {
    if (mode == TINYGLTF_MODE_TRIANGLES || mode == -1) return indices / 3;
    return indices >= 2 ? indices - 2 : 0;
  }

  // Vertices and triangles a mesh will store (accessors checked, nothing read), so that the
  // scene makes room for all of a prototype's meshes at once.
  void meshTotals(int meshIndex, size_t* vertices, size_t* triangles, MeshAttributes* attributes) {
    if (meshIndex < 0 || meshIndex >= int(model_.meshes.size())) return;  // reported when it is placed
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = mesh.primitives[p];
      auto pos = prim.attributes.find("POSITION");
      if (!isTriangles(prim) || pos == prim.attributes.end()) continue;
      std::string el = "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(p) + "]";
      size_t n = attributeView(pos->second, 3, Attribute::Position, el + ".POSITION").count;
      size_t m = prim.indices >= 0 ? indexView(prim.indices).count : n;
      *vertices += n;
      *triangles += triangleCount(prim.mode, m);
      attributes->normals |= prim.attributes.count("NORMAL") > 0;
      attributes->uvs |= prim.attributes.count("TEXCOORD_0") > 0;
      attributes->tangents |= prim.attributes.count("TANGENT") > 0;
      attributes->colors |= prim.attributes.count("COLOR_0") > 0;
    }
  }

  // EXT_mesh_gpu_instancing: the node's mesh placed once per element of its attributes, each
  // T·R·S (TRANSLATION, ROTATION as a quaternion x, y, z, w, SCALE; any of them may be absent),
  // under the node's own transform.
  std::vector<Mat4> gpuInstances(const tinygltf::Value& ext, const std::string& el) {
    if (!ext.IsObject() || !ext.Has("attributes") || !ext.Get("attributes").IsObject()) fail(el, "needs attributes");
    const tinygltf::Value& attributes = ext.Get("attributes");
    size_t count = 0;
    bool first = true;
    auto view = [&](const char* name, int components, Attribute a) {
      double index;
      if (!getNumber(attributes, name, &index)) return ElementView{};
      ElementView v = attributeView(int(index), components, a, el + ".attributes." + name);
      if (!first && v.count != count) fail(el + ".attributes." + name, "count differs from the other attributes'");
      count = v.count, first = false;
      return v;
    };
    const ElementView T = view("TRANSLATION", 3, Attribute::Position), R = view("ROTATION", 4, Attribute::Rotation),
                      S = view("SCALE", 3, Attribute::Position);
    if (first) fail(el, "no TRANSLATION, ROTATION or SCALE");
    std::vector<Vec3> t(count, Vec3(0.0f)), s(count, Vec3(1.0f));
    std::vector<glm::quat> r(count, glm::quat(1, 0, 0, 0));
    if (T.count) readElements<3>(T, [&](size_t i, const float* v) { t[i] = Vec3(v[0], v[1], v[2]); });
    if (S.count) readElements<3>(S, [&](size_t i, const float* v) { s[i] = Vec3(v[0], v[1], v[2]); });
    if (R.count)
      readElements<4>(R, [&](size_t i, const float* v) {
        glm::quat q(v[3], v[0], v[1], v[2]);  // w, x, y, z
        if (glm::length(q) == 0) fail(el + ".attributes.ROTATION", "element " + std::to_string(i) + " is a zero quaternion");
        r[i] = glm::normalize(q);
      });
    std::vector<Mat4> out(count);
    for (size_t i = 0; i < count; ++i) out[i] = glm::scale(glm::translate(Mat4(1.0f), t[i]) * glm::mat4_cast(r[i]), s[i]);
    return out;
  }

  // How many times the scene places each mesh: a mesh placed more than once is instanced (and
  // so is any mesh placed through EXT_mesh_gpu_instancing).
  void countMeshUses(int index, int depth) {
    if (index < 0 || index >= int(model_.nodes.size()) || depth > 256) return;  // reported by visit()
    const tinygltf::Node& node = model_.nodes[size_t(index)];
    if (node.mesh >= 0 && node.mesh < int(model_.meshes.size()))
      meshUses_[size_t(node.mesh)] += node.extensions.count("EXT_mesh_gpu_instancing") ? 2 : 1;
    for (int child : node.children) countMeshUses(child, depth + 1);
  }

  // Places mesh `meshIndex` with the node's transform: stored in world space when the scene
  // places it once; otherwise stored once in its own space (at its first placement) and placed
  // as an instance.
  void placeMesh(int meshIndex, const Mat4& world, const std::string& nodeElement) {
    if (meshIndex >= int(model_.meshes.size())) fail("mesh", "index " + std::to_string(meshIndex) + " out of range");
    if (meshUses_[size_t(meshIndex)] <= 1) {
      addMesh(meshIndex, world, 0);
      return;
    }
    auto found = prototypes_.find(meshIndex);
    if (found == prototypes_.end()) {
      uint32_t prototype = scene_->addPrototype();
      size_t vertices = 0, triangles = 0;
      MeshAttributes attributes;
      meshTotals(meshIndex, &vertices, &triangles, &attributes);
      scene_->reserve(prototype, vertices, triangles, attributes);
      Bounds bounds = addMesh(meshIndex, Mat4(1.0f), prototype);
      found = prototypes_.emplace(meshIndex, std::make_pair(prototype, bounds)).first;
    }
    const Bounds& b = found->second.second;
    for (int c = 0; c < 8 && !b.empty(); ++c) {
      Vec3 corner(Vec3(world * glm::vec4((c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z, 1.0f)));
      if (!isFinite(corner) || !withinScene(corner))
        fail(nodeElement, "places meshes[" + std::to_string(meshIndex) + "] beyond 1e7 m from the origin (coordinates are in metres)");
    }
    scene_->addInstance(found->second.first, world);
  }

  // Appends the mesh's primitives to `prototype` (0: the world, transformed by `world`;
  // otherwise in the mesh's own space, `world` the identity). Accessors are read straight into
  // the scene's storage. Returns the bounds of what it stored.
  Bounds addMesh(int meshIndex, const Mat4& world, uint32_t prototype) {
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    const bool transform = prototype == 0;
    glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(world)));
    bool flipWinding = glm::determinant(glm::mat3(world)) < 0;  // mirroring turns CCW into CW
    Bounds bounds;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = mesh.primitives[p];
      std::string el = "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(p) + "]";
      if (!isTriangles(prim)) {
        warn(el + ": points and lines are not rendered");
        continue;
      }
      auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end()) fail(el, "no POSITION attribute");
      const ElementView P = attributeView(pos->second, 3, Attribute::Position, el + ".POSITION");
      const size_t n = P.count;
      ElementView N, T, TG;
      MeshAttributes attributes;
      if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
        N = attributeView(it->second, 3, Attribute::Normal, el + ".NORMAL");
        if (N.count != n) fail(el + ".NORMAL", "count differs from POSITION");
        attributes.normals = true;
      }
      if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
        T = attributeView(it->second, 2, Attribute::TexCoord, el + ".TEXCOORD_0");
        if (T.count != n) fail(el + ".TEXCOORD_0", "count differs from POSITION");
        attributes.uvs = true;
      }
      if (auto it = prim.attributes.find("TANGENT"); it != prim.attributes.end()) {
        TG = attributeView(it->second, 4, Attribute::Tangent, el + ".TANGENT");
        if (TG.count != n) fail(el + ".TANGENT", "count differs from POSITION");
        attributes.tangents = true;
      }
      // COLOR_0: RGB or RGBA, linear, multiplying the base colour (and its alpha the coverage).
      ElementView C;
      int colorComponents = 0;
      if (auto it = prim.attributes.find("COLOR_0"); it != prim.attributes.end()) {
        colorComponents = tinygltf::GetNumComponentsInType(accessor(it->second, el + ".COLOR_0").type) == 3 ? 3 : 4;
        C = attributeView(it->second, colorComponents, Attribute::Color, el + ".COLOR_0");
        if (C.count != n) fail(el + ".COLOR_0", "count differs from POSITION");
        attributes.colors = true;
      }
      ElementView I;
      if (prim.indices >= 0) I = indexView(prim.indices);
      const size_t m = prim.indices >= 0 ? I.count : n;
      const bool list = prim.mode == TINYGLTF_MODE_TRIANGLES || prim.mode == -1;
      if (list && m % 3) fail(el, "triangle list of " + std::to_string(m) + " indices (not a multiple of 3)");
      int material = prim.material;
      if (material >= int(model_.materials.size())) fail(el + ".material", "index out of range");

      MeshSlot slot = scene_->appendMesh(prototype, n, triangleCount(prim.mode, m),
                                         material < 0 ? defaultMaterial_ : uint32_t(material), attributes);
      readElements<3>(P, [&](size_t i, const float* v) {
        Vec3 x(v[0], v[1], v[2]);
        if (transform) x = Vec3(world * glm::vec4(x, 1.0f));
        if (!isFinite(x)) fail(el + ".POSITION", "not finite after the node transform");
        if (!withinScene(x))
          fail(el + ".POSITION", "vertex " + std::to_string(i) + " lies beyond 1e7 m from the origin (coordinates are in metres)");
        slot.positions[i] = x;
        bounds.extend(x);
      });
      if (slot.normals)
        readElements<3>(N, [&](size_t i, const float* v) {
          Vec3 nn = normalMatrix * Vec3(v[0], v[1], v[2]);
          float len = glm::length(nn);
          slot.normals[i] = len > 0 ? nn / len : Vec3(0, 1, 0);
        });
      if (slot.uvs) readElements<2>(T, [&](size_t i, const float* v) { slot.uvs[i] = Vec2(v[0], v[1]); });
      // Tangents are directions on the surface: they take the node's linear part (normals its
      // inverse transpose), and a mirroring transform flips the bitangent's handedness.
      if (slot.tangents)
        readElements<4>(TG, [&](size_t i, const float* v) {
          Vec3 t = glm::mat3(world) * Vec3(v[0], v[1], v[2]);
          float w = v[3] < 0 ? -1.0f : 1.0f;
          if (!isFinite(t)) fail(el + ".TANGENT", "not finite");
          slot.tangents[i] = glm::vec4(t, flipWinding ? -w : w);
        });

      // Colours as reflectances: clamped to [0, 1] (a float colour above 1 would create energy).
      auto unit = [](float x) { return std::clamp(x, 0.0f, 1.0f); };
      if (slot.colors && colorComponents == 3)
        readElements<3>(C, [&](size_t i, const float* v) { slot.colors[i] = glm::vec4(unit(v[0]), unit(v[1]), unit(v[2]), 1.0f); });
      else if (slot.colors)
        readElements<4>(C, [&](size_t i, const float* v) { slot.colors[i] = glm::vec4(unit(v[0]), unit(v[1]), unit(v[2]), unit(v[3])); });

      // Indices: a list straight into the scene; strips and fans through their triangles, every
      // other strip triangle reversed to keep counter-clockwise winding.
      std::vector<uint32_t> idx;
      uint32_t* out = slot.indices;
      if (!list) {
        idx.resize(m);
        out = idx.data();
      }
      if (prim.indices >= 0) {
        readIndices(I, out);
        for (size_t i = 0; i < m; ++i)
          if (out[i] >= n) fail(el + ".indices", "index " + std::to_string(out[i]) + " ≥ vertex count " + std::to_string(n));
      } else {
        for (size_t i = 0; i < m; ++i) out[i] = uint32_t(i);
      }
      if (!list) {
        uint32_t* t = slot.indices;
        for (size_t i = 2; i < m; ++i, t += 3) {
          if (prim.mode == TINYGLTF_MODE_TRIANGLE_FAN) t[0] = idx[0], t[1] = idx[i - 1], t[2] = idx[i];
          else if (i % 2 == 0) t[0] = idx[i - 2], t[1] = idx[i - 1], t[2] = idx[i];
          else t[0] = idx[i - 1], t[1] = idx[i - 2], t[2] = idx[i];
        }
      }
      if (flipWinding)
        for (size_t i = 0; i < 3 * slot.triangles; i += 3) std::swap(slot.indices[i + 1], slot.indices[i + 2]);
      scene_->finishMesh();
    }
    return bounds;
  }

  // The file's buffers and decoded images once the scene holds what it needs of them (meshes
  // read, textures converted): a large file's geometry is not kept twice.
  void releaseFileData() {
    for (tinygltf::Buffer& b : model_.buffers) std::vector<unsigned char>().swap(b.data);
    for (tinygltf::Image& im : model_.images) std::vector<unsigned char>().swap(im.image);
  }

  std::string path_;
  std::vector<std::string>* warnings_;
  GltfLoadOptions options_;
  float lightScale_ = 1.0f;  // radiometric per unit of the file's light values
  bool quantized_ = false;   // the file uses KHR_mesh_quantization: integer attributes allowed
  std::map<std::string, std::pair<std::string, size_t>> ignored_;  // feature: first material, count
  std::vector<std::string> ignoredOrder_;
  const unsigned char* bytes_ = nullptr;
  size_t size_ = 0;
  tinygltf::Model model_;
  std::unique_ptr<Scene> scene_;
  uint32_t defaultMaterial_ = 0;
  std::map<int, std::shared_ptr<const Image>> images_;
  std::map<int, std::shared_ptr<const Image>> linearImages_;  // the same images undecoded (data textures)
  std::vector<uint32_t> meshUses_;  // per mesh, how many nodes place it
  std::map<int, std::pair<uint32_t, Bounds>> prototypes_;  // instanced mesh: its prototype and bounds
};

}  // namespace

void checkCameraView(const CameraView& view) {
  if (view.fov != 0 && !(view.fov > 0 && view.fov < 180))
    throw Error("--fov: the vertical field of view must be between 0 and 180 degrees, got " + formatNumber(view.fov));
  if (view.kind == CameraView::Kind::Orbit && !(std::abs(view.elevation) < 90 && std::isfinite(view.azimuth)))
    throw Error("--orbit: the elevation must be strictly between -90 and 90 degrees, got " + formatNumber(view.elevation));
  if (view.kind != CameraView::Kind::LookAt) return;
  const Vec3 d = view.at - view.from;
  if (!(glm::length(d) > 0) || !std::isfinite(glm::length(d)))
    throw Error("--look-at: must differ from --look-from (both at " + formatNumber(view.from.x) + "," +
                formatNumber(view.from.y) + "," + formatNumber(view.from.z) + ")");
  const Vec3 side = glm::cross(glm::normalize(d), view.up);
  if (!(glm::length(side) > 1e-4f * glm::length(view.up)))
    throw Error("--up: must not point along the view direction (from --look-from to --look-at)");
}

std::unique_ptr<Scene> loadGltf(const std::string& path, std::vector<std::string>* warnings, const GltfLoadOptions& options) {
  return Loader(path, warnings, options).load();
}

std::unique_ptr<Scene> loadGltfFromMemory(const std::string& name, const void* bytes, size_t size,
                                          std::vector<std::string>* warnings) {
  return Loader(name, static_cast<const unsigned char*>(bytes), size, warnings).load();
}

}  // namespace pl
