// glTF 2.0 (.gltf with external or data-URI buffers, or .glb) into a Scene.
// See README "Scenes" for the material and light mapping and the radiometric units.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace pl {

// Throws Error("FILE: ELEMENT: what is wrong") on any bad input. Warnings (things ignored or
// approximated) are appended to `warnings`.
std::unique_ptr<Scene> loadGltf(const std::string& path, std::vector<std::string>* warnings = nullptr);

// The same from the bytes of a .gltf or .glb (`name` only names it in messages). External files
// are not read: buffers and images must be embedded (data URIs or the GLB's BIN chunk).
std::unique_ptr<Scene> loadGltfFromMemory(const std::string& name, const void* bytes, size_t size,
                                          std::vector<std::string>* warnings = nullptr);

}  // namespace pl
