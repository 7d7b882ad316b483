// Builds small glTF files for loader and CLI tests: a valid scene (floor quad, camera, point
// light) that each test then breaks in one way.
#pragma once
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace pl::test {

using nlohmann::json;

inline std::string base64(const std::vector<uint8_t>& data) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    uint32_t v = data[i] << 16 | (i + 1 < data.size() ? data[i + 1] << 8 : 0) | (i + 2 < data.size() ? data[i + 2] : 0);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < data.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < data.size() ? t[v & 63] : '=';
  }
  return out;
}

struct GltfFixture {
  json doc;
  std::vector<uint8_t> bin;  // positions (4 × vec3) then indices (6 × uint32): 72 bytes

  GltfFixture() {
    float positions[12] = {-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1};
    uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    bin.resize(72);
    std::memcpy(bin.data(), positions, 48);
    std::memcpy(bin.data() + 48, indices, 24);
    doc = json::parse(R"({
      "asset": {"version": "2.0", "extras": {"photonlab": {"units": "radiometric"}}},
      "scene": 0,
      "scenes": [{"nodes": [0, 1, 2]}],
      "nodes": [
        {"mesh": 0},
        {"camera": 0, "translation": [0, 2, 0], "rotation": [-0.7071068, 0, 0, 0.7071068]},
        {"translation": [0, 1, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}
      ],
      "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.0, "znear": 0.01}}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
      "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0},
                     "extras": {"photonlab": {"bsdf": "lambertian"}}}],
      "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]},
        {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}
      ],
      "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 24}
      ],
      "buffers": [{"byteLength": 72}],
      "extensionsUsed": ["KHR_lights_punctual"],
      "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 2.0}]}}
    })");
  }

  // This process's scratch folder, removed when the process exits (ctest runs every test case
  // as a process of its own: without the removal each left a folder behind).
  static std::string dir() {
    struct Scratch {
      std::filesystem::path path =
          std::filesystem::temp_directory_path() / ("photonlab-tests-" + std::to_string(::getpid()));
      ~Scratch() {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
      }
    };
    static const Scratch scratch;
    std::filesystem::create_directories(scratch.path);
    return scratch.path.string();
  }

  // .gltf with the buffer as a data URI.
  std::string write(const std::string& name) {
    json d = doc;
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bin);
    return writeText(name, d.dump());
  }
  // .gltf with the buffer in a .bin file beside it.
  std::string writeWithExternalBuffer(const std::string& name) {
    json d = doc;
    d["buffers"][0]["uri"] = name + ".bin";
    std::ofstream(dir() + "/" + name + ".bin", std::ios::binary).write((const char*)bin.data(), bin.size());
    return writeText(name, d.dump());
  }
  // .glb: JSON chunk and BIN chunk, both padded to 4 bytes.
  std::string writeGlb(const std::string& name) {
    std::string j = doc.dump();
    while (j.size() % 4) j += ' ';
    std::vector<uint8_t> b = bin;
    while (b.size() % 4) b.push_back(0);
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t v) { for (int i = 0; i < 4; ++i) out.push_back((v >> (8 * i)) & 255); };
    u32(0x46546C67);
    u32(2);
    u32(uint32_t(12 + 8 + j.size() + 8 + b.size()));
    u32(uint32_t(j.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), j.begin(), j.end());
    u32(uint32_t(b.size()));
    u32(0x004E4942);
    out.insert(out.end(), b.begin(), b.end());
    std::string path = dir() + "/" + name;
    std::ofstream(path, std::ios::binary).write((const char*)out.data(), out.size());
    return path;
  }
  static std::string writeText(const std::string& name, const std::string& text) {
    std::string path = dir() + "/" + name;
    std::ofstream(path) << text;
    return path;
  }
};

}  // namespace pl::test
