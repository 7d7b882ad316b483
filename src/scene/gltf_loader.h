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

}  // namespace pl
