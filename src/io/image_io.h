// Image files through OpenImageIO. Writes go to a temporary file in the same folder, renamed
// over the target when complete: an interrupted run never leaves a broken image.
#pragma once
#include <map>
#include <string>

#include "io/tonemap.h"
#include "render/image.h"

namespace pl {

// .exr: linear float RGB with `metadata` as string attributes. .png: 8-bit display values made
// by `display` (io/tonemap.h: exposure, tone curve, sRGB transfer curve; by default clamped to
// [0, 1]), recorded in its metadata too. Throws Error on failure.
void writeImage(const std::string& path, const ImageRGB& image, const std::map<std::string, std::string>& metadata = {},
                const Display& display = {});
ImageRGB readImage(const std::string& path);
// True for images holding display values (PNG, JPEG, ...), false for linear ones (EXR, HDR, PFM).
bool isDisplayReferred(const std::string& path);
// Metadata attributes of an image file (for tests and `photonlab info IMAGE.exr`).
std::map<std::string, std::string> readImageMetadata(const std::string& path);

}  // namespace pl
