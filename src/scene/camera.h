// Pinhole camera as glTF defines it: looks down its local −Z with +Y up; yfov is the full
// vertical field of view in radians.
#pragma once
#include "core/common.h"

namespace pl {

struct Camera {
  Vec3 position{0.0f};
  Vec3 right{1, 0, 0}, up{0, 1, 0}, forward{0, 0, -1};  // orthonormal, world space
  float yfov = 0.8f;
  float aspectRatio = 0.0f;  // width/height from the file; 0 when the file does not say

  // Ray through film position (x, y) in pixels, (0, 0) the top-left corner of the image.
  Ray generateRay(float x, float y, int width, int height) const {
    float tanHalf = std::tan(0.5f * yfov);
    float aspect = float(width) / float(height);
    float sx = (2.0f * x / width - 1.0f) * tanHalf * aspect;
    float sy = (1.0f - 2.0f * y / height) * tanHalf;  // row 0 at the top
    Vec3 d = glm::normalize(forward + sx * right + sy * up);
    return Ray{position, d};
  }
};

}  // namespace pl
