// The per-pixel render loop of camera-side integrators (PixelIntegrator): samples are taken one
// pass (one sample per pixel) at a time, so every pixel has the same sample count except after a
// pass the time budget cut short.
#pragma once
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "render/integrator.h"
#include "image/image.h"
#include "render/render_options.h"

namespace pl {

// Pixel value = average radiance over the pixel's area (box filter): sample s of pixel (x, y)
// uses the random stream keyed by (seed, pixel index, s), never by thread.
// Calls integrator.preprocess() first (its time is part of the render time). Hands the
// integrator Scene::kPacket neighbouring pixels of a row at a time (PixelIntegrator::LiPacket).
// Checks the time limit and interrupts before each such group; a pass they cut short leaves
// some pixels with one sample more.
ImageRGB renderPixels(const Scene& scene, PixelIntegrator& integrator, RenderOptions options, RenderInfo* info);

// Any integrator: integrator.render(), which owns its loop.
inline ImageRGB render(const Scene& scene, Integrator& integrator, const RenderOptions& options, RenderInfo* info) {
  return integrator.render(scene, options, info);
}

}  // namespace pl
