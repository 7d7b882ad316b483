#include "scene/gltf_schema.h"

#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>

namespace pl {
namespace {

using nlohmann::json;

struct TypeError {
  std::string message;
};

const char* typeName(const json& j) {
  switch (j.type()) {
    case json::value_t::object: return "an object";
    case json::value_t::array: return "an array";
    case json::value_t::string: return "a string";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::null: return "null";
    default: return "a number";
  }
}

[[noreturn]] void wrong(const std::string& at, const std::string& expected, const json& j) {
  std::string got = j.is_array() ? "an array of " + std::to_string(j.size()) : typeName(j);
  throw TypeError{(at.empty() ? "document" : at) + ": must be " + expected + ", got " + got +
                  (j.is_number() || j.is_boolean() || j.is_null() || (j.is_string() && j.get<std::string>().size() < 40)
                       ? " (" + j.dump() + ")"
                       : "")};
}

// One JSON object's members, each checked if present.
class Members {
 public:
  Members(const json& j, std::string at) : j_(j), at_(std::move(at)) {
    if (!j_.is_object()) wrong(at_, "an object", j_);
  }
  const json* get(const char* key) const {
    auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  std::string at(const char* key) const { return at_.empty() ? key : at_ + "." + key; }

  void number(const char* key) const {
    if (auto* v = get(key)) checkNumber(*v, at(key));
  }
  // A JSON Schema integer (1.0 counts), at least `min` (0 for indices).
  void integer(const char* key, double min = 0) const {
    if (auto* v = get(key)) checkInteger(*v, at(key), min);
  }
  void string(const char* key) const {
    if (auto* v = get(key); v && !v->is_string()) wrong(at(key), "a string", *v);
  }
  void boolean(const char* key) const {
    if (auto* v = get(key); v && !v->is_boolean()) wrong(at(key), "true or false", *v);
  }
  // An array of numbers: exactly `n` of them, or any count with n = 0.
  void numbers(const char* key, size_t n = 0) const {
    auto* v = get(key);
    if (!v) return;
    std::string expected = n ? "an array of " + std::to_string(n) + " numbers" : "an array of numbers";
    if (!v->is_array() || (n && v->size() != n)) wrong(at(key), expected, *v);
    for (size_t i = 0; i < v->size(); ++i) checkNumber((*v)[i], at(key) + "[" + std::to_string(i) + "]");
  }
  void indices(const char* key) const {
    auto* v = get(key);
    if (!v) return;
    if (!v->is_array()) wrong(at(key), "an array of indices", *v);
    for (size_t i = 0; i < v->size(); ++i) checkInteger((*v)[i], at(key) + "[" + std::to_string(i) + "]", 0);
  }
  void strings(const char* key) const {
    auto* v = get(key);
    if (!v) return;
    if (!v->is_array()) wrong(at(key), "an array of strings", *v);
    for (size_t i = 0; i < v->size(); ++i)
      if (!(*v)[i].is_string()) wrong(at(key) + "[" + std::to_string(i) + "]", "a string", (*v)[i]);
  }
  // Every member is an index (a primitive's attributes).
  void allIndices() const {
    for (auto it = j_.begin(); it != j_.end(); ++it) checkInteger(it.value(), at_ + "." + it.key(), 0);
  }
  // A member object, checked by fn.
  void object(const char* key, const std::function<void(const Members&)>& fn) const {
    if (auto* v = get(key)) fn(Members(*v, at(key)));
  }
  // An array of objects, each checked by fn.
  void objects(const char* key, const std::function<void(const Members&)>& fn) const {
    auto* v = get(key);
    if (!v) return;
    if (!v->is_array()) wrong(at(key), "an array of objects", *v);
    for (size_t i = 0; i < v->size(); ++i) fn(Members((*v)[i], at(key) + "[" + std::to_string(i) + "]"));
  }
  // extensions.NAME, if present, checked by fn.
  void extension(const char* name, const std::function<void(const Members&)>& fn) const {
    object("extensions", [&](const Members& e) { e.object(name, fn); });
  }

 private:
  static void checkNumber(const json& v, const std::string& at) {
    if (!v.is_number()) wrong(at, "a number", v);
  }
  static void checkInteger(const json& v, const std::string& at, double min) {
    bool integral = v.is_number_integer() || (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>());
    if (!integral) wrong(at, min == 0 ? "an index (an integer, 0 or more)" : "an integer", v);
    if (v.get<double>() < min) wrong(at, min == 0 ? "an index (an integer, 0 or more)" : "an integer ≥ " + std::to_string(int(min)), v);
  }

  const json& j_;
  std::string at_;
};

// Each top-level array's elements, "name[i]" relative to the document.
void topLevel(const json& doc, const char* key, const std::function<void(const Members&)>& fn) {
  auto it = doc.find(key);
  if (it == doc.end()) return;
  if (!it->is_array()) wrong(key, "an array of objects", *it);
  for (size_t i = 0; i < it->size(); ++i) fn(Members((*it)[i], std::string(key) + "[" + std::to_string(i) + "]"));
}

void textureInfo(const Members& t) {
  t.integer("index");
  t.integer("texCoord");
  t.number("scale");
  t.number("strength");
}

// extras.photonlab on a material or a light (docs: reference/gltf.md): its known keys' types.
void photonlabExtras(const Members& owner) {
  owner.object("extras", [](const Members& extras) {
    extras.object("photonlab", [](const Members& p) {
      p.number("power");
      p.number("temperature");
      p.string("illuminant");
      p.number("warn_exponent");
      p.object("phong", [](const Members& ph) { ph.number("exponent"); });  // kd, ks: a number or 3 (the loader checks)
    });
  });
}

void checkDocument(const json& doc) {
  Members root(doc, "");
  root.object("asset", [](const Members& a) {
    a.string("version");
    a.string("generator");
    a.string("minVersion");
  });
  root.integer("scene");
  root.strings("extensionsUsed");
  root.strings("extensionsRequired");
  topLevel(doc, "scenes", [](const Members& s) {
    s.indices("nodes");
    s.string("name");
  });
  topLevel(doc, "nodes", [](const Members& n) {
    n.integer("camera");
    n.integer("mesh");
    n.integer("skin");
    n.indices("children");
    n.numbers("matrix", 16);
    n.numbers("rotation", 4);
    n.numbers("scale", 3);
    n.numbers("translation", 3);
    n.numbers("weights");
    n.string("name");
    n.extension("KHR_lights_punctual", [](const Members& l) { l.integer("light"); });
    n.extension("EXT_mesh_gpu_instancing", [](const Members& e) {
      e.object("attributes", [](const Members& a) {
        a.integer("TRANSLATION");
        a.integer("ROTATION");
        a.integer("SCALE");
      });
    });
  });
  topLevel(doc, "meshes", [](const Members& m) {
    m.string("name");
    m.numbers("weights");
    m.objects("primitives", [](const Members& p) {
      p.object("attributes", [](const Members& a) { a.allIndices(); });  // every attribute is an accessor index
      p.integer("indices");
      p.integer("material");
      p.integer("mode");
    });
  });
  topLevel(doc, "materials", [](const Members& m) {
    m.string("name");
    m.object("pbrMetallicRoughness", [](const Members& pbr) {
      pbr.numbers("baseColorFactor", 4);
      pbr.number("metallicFactor");
      pbr.number("roughnessFactor");
      pbr.object("baseColorTexture", textureInfo);
      pbr.object("metallicRoughnessTexture", textureInfo);
    });
    m.object("normalTexture", textureInfo);
    m.object("occlusionTexture", textureInfo);
    m.object("emissiveTexture", textureInfo);
    m.numbers("emissiveFactor", 3);
    m.string("alphaMode");
    m.number("alphaCutoff");
    m.boolean("doubleSided");
    m.extension("KHR_materials_emissive_strength", [](const Members& e) { e.number("emissiveStrength"); });
    m.extension("KHR_materials_transmission", [](const Members& e) {
      e.number("transmissionFactor");
      e.object("transmissionTexture", textureInfo);
    });
    m.extension("KHR_materials_volume", [](const Members& e) {
      e.number("thicknessFactor");
      e.number("attenuationDistance");
      e.numbers("attenuationColor", 3);
    });
    m.extension("KHR_materials_ior", [](const Members& e) { e.number("ior"); });
    m.extension("KHR_materials_dispersion", [](const Members& e) { e.number("dispersion"); });
    m.extension("KHR_materials_clearcoat", [](const Members& e) {
      e.number("clearcoatFactor");
      e.object("clearcoatTexture", textureInfo);
      e.number("clearcoatRoughnessFactor");
      e.object("clearcoatRoughnessTexture", textureInfo);
      e.object("clearcoatNormalTexture", textureInfo);
    });
    m.extension("KHR_materials_sheen", [](const Members& e) {
      e.numbers("sheenColorFactor", 3);
      e.object("sheenColorTexture", textureInfo);
      e.number("sheenRoughnessFactor");
      e.object("sheenRoughnessTexture", textureInfo);
    });
    photonlabExtras(m);
  });
  topLevel(doc, "accessors", [](const Members& a) {
    a.integer("bufferView");
    a.integer("byteOffset");
    a.integer("componentType");
    a.boolean("normalized");
    a.integer("count");
    a.string("type");
    a.numbers("max");
    a.numbers("min");
  });
  topLevel(doc, "bufferViews", [](const Members& v) {
    v.integer("buffer");
    v.integer("byteOffset");
    v.integer("byteLength");
    v.integer("byteStride");
    v.integer("target");
  });
  topLevel(doc, "buffers", [](const Members& b) {
    b.string("uri");
    b.integer("byteLength");
  });
  topLevel(doc, "cameras", [](const Members& c) {
    c.string("type");
    c.object("perspective", [](const Members& p) {
      p.number("yfov");
      p.number("aspectRatio");
      p.number("znear");
      p.number("zfar");
    });
    c.object("orthographic", [](const Members& o) {
      o.number("xmag");
      o.number("ymag");
      o.number("znear");
      o.number("zfar");
    });
  });
  topLevel(doc, "images", [](const Members& i) {
    i.string("uri");
    i.string("mimeType");
    i.integer("bufferView");
  });
  topLevel(doc, "textures", [](const Members& t) {
    t.integer("sampler");
    t.integer("source");
  });
  topLevel(doc, "samplers", [](const Members& s) {
    s.integer("magFilter");
    s.integer("minFilter");
    s.integer("wrapS");
    s.integer("wrapT");
  });
  root.extension("KHR_lights_punctual", [](const Members& e) {
    e.objects("lights", [](const Members& l) {
      l.string("type");
      l.numbers("color", 3);
      l.number("intensity");
      l.number("range");
      l.object("spot", [](const Members& s) {
        s.number("innerConeAngle");
        s.number("outerConeAngle");
      });
      photonlabExtras(l);
    });
  });
}

}  // namespace


const std::vector<std::string>& supportedGltfExtensions() {
  static const std::vector<std::string> names = {"KHR_lights_punctual",       "KHR_materials_emissive_strength",
                                                 "KHR_materials_transmission", "KHR_materials_volume",
                                                 "KHR_materials_ior",          "KHR_materials_dispersion",
                                                 "KHR_texture_transform",      "KHR_mesh_quantization",
                                                 "EXT_mesh_gpu_instancing",    "KHR_materials_unlit",
                                                 "KHR_materials_clearcoat",    "KHR_materials_sheen"};
  return names;
}

namespace {

// RFC 3986 percent-decoding ("my%20model.bin" names "my model.bin"); a malformed escape stays.
std::string percentDecoded(const std::string& uri) {
  std::string out;
  auto hex = [](char c) { return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1; };
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

std::string checkRequirements(const json& doc, const std::string& directory) {
  if (!doc.is_object()) return "";  // the glTF parser reports it
  const auto& supported = supportedGltfExtensions();
  if (doc.contains("extensionsRequired") && doc["extensionsRequired"].is_array())
    for (size_t i = 0; i < doc["extensionsRequired"].size(); ++i) {
      const json& name = doc["extensionsRequired"][i];
      if (!name.is_string()) continue;
      const std::string n = name.get<std::string>();
      if (std::find(supported.begin(), supported.end(), n) != supported.end()) continue;
      std::string list;
      for (const auto& s : supported) list += (list.empty() ? "" : ", ") + s;
      return "extensionsRequired[" + std::to_string(i) + "]: " + n +
             " is required by the file and photonlab does not implement it (it reads " + list + ")";
    }
  if (directory.empty()) return "";
  for (const char* kind : {"buffers", "images"}) {
    if (!doc.contains(kind) || !doc[kind].is_array()) continue;
    for (size_t i = 0; i < doc[kind].size(); ++i) {
      const json& item = doc[kind][i];
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue;
      const std::filesystem::path file = std::filesystem::path(directory) / percentDecoded(uri);
      std::error_code ec;
      if (!std::filesystem::is_regular_file(file, ec))
        return std::string(kind) + "[" + std::to_string(i) + "].uri: file not found: " + file.string();
    }
  }
  return "";
}

}  // namespace

std::string checkGltfDocument(const std::string& text, const std::string& directory) {
  json doc = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return "";  // not JSON: the glTF parser says so, with its own message
  try {
    checkDocument(doc);
  } catch (const TypeError& e) {
    return e.message;
  }
  return checkRequirements(doc, directory);
}

}  // namespace pl
