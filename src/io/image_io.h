// Image files through OpenImageIO. Writes go to a temporary file in the same folder, renamed
// over the target when complete: an interrupted run never leaves a broken image.
#pragma once
#include <map>
#include <string>

#include "render/image.h"

namespace pl {

// .exr: linear float RGB with `metadata` as string attributes. .png: tone-mapped to sRGB
// (clamp to [0, 1], sRGB transfer curve, 8 bits). Throws Error on failure.
void writeImage(const std::string& path, const ImageRGB& image, const std::map<std::string, std::string>& metadata = {});
ImageRGB readImage(const std::string& path);
// Metadata attributes of an image file (for tests and `photonlab info IMAGE.exr`).
std::map<std::string, std::string> readImageMetadata(const std::string& path);

}  // namespace pl
