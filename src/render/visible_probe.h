// A deterministic look at what the camera sees: a grid of rays through the image, each followed
// through mirrors and glass to its first diffuse or glossy point, the kind of point where
// photons are gathered. Used to choose defaults from the view (the progressive methods' initial
// radius) and to summarise what a render did there (the photon map's mean gather radius).
#pragma once
#include <vector>

#include "photon/photon_tracer.h"
#include "scene/scene.h"

namespace pl {

struct ProbePoint {
  SurfaceHit hit;
  Vec3 wo;           // towards the camera (along the last segment)
  float distance;    // along the whole path from the camera
};

// n×n rays through the centres of an n×n grid of cells over a width×height image. Specular
// bounces are sampled from a stream keyed by the ray's grid index, so the points are the same
// on every call. Rays that leave the scene, or bounce more than 16 times, give no point.
std::vector<ProbePoint> probeVisiblePoints(const Scene& scene, int width, int height, int n = 32);

// The default gather radius of the density estimators (the progressive methods, vcm and bpm):
// a few pixels' footprint at the median distance from the camera to the points it sees first
// through mirrors and glass, over a 32×32 grid of camera rays. (The distance to the scene's
// centre collapses when the camera sits at the centre, inside a furnace.)
struct DefaultRadius {
  static constexpr float kFootprints = 5.0f;
  float radius = 0;      // kFootprints · footprint (m)
  float distance = 0;    // median distance to a visible point (m)
  float footprint = 0;   // one pixel's footprint at that distance (m)
  size_t visiblePoints = 0;  // of the 1024 rays, how many found a diffuse or glossy point
};
DefaultRadius defaultRadius(const Scene& scene, int width, int height);

// --photon-target view's target: the sphere around what the camera sees, the bounding box
// of a 64×64 probe's points grown by `margin` (a gather radius: photons that far from a visible
// point still count) and by a tenth for what falls between the probe's rays. No target (radius
// 0) when nothing diffuse or glossy is in view, or when the sphere is nearly the scene's.
EmissionTarget visibleEmissionTarget(const Scene& scene, int width, int height, float margin);

}  // namespace pl
