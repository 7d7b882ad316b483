// Image files through OpenImageIO. Writes go to a temporary file in the same folder, renamed
// over the target when complete: an interrupted run never leaves a broken image.
#pragma once
#include <map>
#include <string>

#include "image/tonemap.h"
#include "image/image.h"
#include "render/render_options.h"

namespace pl {

// .exr: linear float RGB with `metadata` as string attributes. .png: 8-bit display values made
// by `display` (image/tonemap.h: exposure, tone curve, sRGB transfer curve; by default clamped to
// [0, 1]), recorded in its metadata too. Throws Error on failure.
void writeImage(const std::string& path, const ImageRGB& image, const std::map<std::string, std::string>& metadata = {},
                const Display& display = {});
ImageRGB readImage(const std::string& path);
// An environment map's texels as linear radiance: readImage, with display-referred files
// (PNG, JPEG) decoded from sRGB. What the CLI and experiments hand the loader (ImageReader).
ImageRGB readEnvironmentMap(const std::string& path);
// True for images holding display values (PNG, JPEG, ...), false for linear ones (EXR, HDR, PFM).
bool isDisplayReferred(const std::string& path);
// A slice of a render (`photonlab render --sample-range`, `--pass-range`) as an EXR: R, G, B
// hold the slice's own mean (viewable as any image), `count` each pixel's samples, and
// sum.<R|G|B>.<limb>.<lo|hi> the exact sums' 320-bit integers as 32-bit halves of their five
// 64-bit limbs, so that `photonlab merge` adds them without a rounding. The metadata says
// which slice it is (range_begin, range_end) besides everything a render records.
void writeSlice(const std::string& path, const RenderSlice& part, const std::map<std::string, std::string>& metadata);
// Throws Error naming the file when it is not a slice photonlab wrote.
RenderSlice readSlice(const std::string& path);
// Metadata attributes of an image file (for tests and `photonlab info IMAGE.exr`).
std::map<std::string, std::string> readImageMetadata(const std::string& path);

}  // namespace pl
