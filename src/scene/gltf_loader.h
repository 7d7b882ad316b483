// glTF 2.0 (.gltf with external or data-URI buffers, or .glb) into a Scene.
// See docs/pages/reference/gltf.md for the material and light mapping and the radiometric units.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace pl {

struct GltfLoadOptions {
  // Which of the file's cameras renders: the index in Scene::fileCameras() (the nodes with a
  // perspective camera, in scene order, as `photonlab info` lists them); -1: the first. A file
  // with none is rendered from automaticCamera() (scene/camera.h), with a warning.
  int camera = -1;
  // A view from the command line instead (--look-from/--look-at, --orbit, --fov): checked by
  // checkCameraView before loading.
  CameraView view;
  float aspect = 1.0f;         // width/height of the image, for the automatic camera's framing
  // The sky (lights/environment_light.h): when enabled, it replaces the file's
  // extras.photonlab.environment. A scene with no light at all gets defaultEnvironment(), with a
  // warning.
  EnvironmentSpec environment;
  // Reads an environment map's file (the io layer's readEnvironmentMap; without one a map is an
  // error).
  ImageReader readImage;
  // "radiometric" or "photometric" (--units), or empty: the file's asset.extras.photonlab.units,
  // and photometric for a file without it (the glTF specification's units; docs: reference/gltf.md).
  std::string units;
  // Embree's BVH: fast, compact (about half the memory, slower rays), or compact only for
  // scenes of Scene::kCompactTriangles stored triangles and more (--bvh).
  Scene::BvhLayout bvh = Scene::BvhLayout::Auto;
};

// Photometric light values (cd, lx, nits) in radiometric units (W/sr, W/m², W/(m²·sr)): divided
// by the luminous efficacy of 555 nm light, 683 lm/W.
constexpr float kLumensPerWatt = 683.0f;

// Throws Error("--FLAG: what is wrong") for a view that makes no camera: --look-from at --look-at,
// --up along the view direction, an elevation of ±90° or more, a field of view outside (0°, 180°).
void checkCameraView(const CameraView& view);

// Throws Error("FILE: ELEMENT: what is wrong") on any bad input. Warnings (things ignored or
// approximated) are appended to `warnings`.
std::unique_ptr<Scene> loadGltf(const std::string& path, std::vector<std::string>* warnings = nullptr,
                                const GltfLoadOptions& options = {});

// The same from the bytes of a .gltf or .glb (`name` only names it in messages). External files
// are not read: buffers and images must be embedded (data URIs or the GLB's BIN chunk).
std::unique_ptr<Scene> loadGltfFromMemory(const std::string& name, const void* bytes, size_t size,
                                          std::vector<std::string>* warnings = nullptr);

}  // namespace pl
