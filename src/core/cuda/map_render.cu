// Localization on the GPU: the map points near the vehicle rendered into the images of a model, as the
// CPU backend's renderMapModel() (cpu/map_render.cpp) renders them, with the per-point rules of
// common/map_render.hpp. Three steps on the stream:
//  1. offerMapPoints: each listed point moved into the sensor's frame (kept per source), and each
//     non-ground one with a normal offered to every pixel of its disc (atomicMin of the closest-wins key,
//     source = its position in the list, as on the CPU);
//  2. the ground points into the BEV map by the cell compaction (bev_compaction.cuh), their height
//     standing in for an age;
//  3. takeRenderedPixels: each pixel takes its winner, or is emptied, and clears its key.
#include "core/common/map_render.hpp"
#include "core/common/normals.hpp"
#include "core/cuda/bev_compaction.cuh"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

__global__ void offerMapPoints(DeviceMap map, MapRenderSources sources, Rigid3f sensor_from_map,
                               SphericalProjection projection, MapRendering rendering, ClosestKey* closest_keys) {
  const int source = globalThread();
  if (source >= sources.count) return;
  const int32_t index = sources.indices[source];
  const Float3 vertex = sensor_from_map.apply(map.points[index]);
  const Float3 normal = sensor_from_map.rotate(map.normals[index]);
  sources.vertices[source] = vertex;
  sources.normals[source] = towardsSensor(normal, vertex);
  if (isMapGround(vertex, normal, rendering) || isZero(normal)) return;
  int row = 0;
  int col = 0;
  if (!projection.pixelOf(vertex, row, col)) return;
  const ClosestKey key = closestWinsKey(norm(vertex), static_cast<uint32_t>(source));
  forEachSplatPixel(projection, row, col, norm(vertex), rendering.splat_radius,
                    [&](int pixel) { atomicMin(&closest_keys[pixel], key); });
}

// The ground map's sources: the rendered points in the ground band (isMapGround()), in list order.
struct MapGroundSources {
  const Float3* vertices;
  const Float3* normals;
  int points;
  MapRendering rendering;

  __device__ MapGroundSources counted() const { return *this; }
  __device__ int count() const { return points; }
  __device__ Float3 vertex(uint32_t source) const { return vertices[source]; }
  __device__ float stamp(uint32_t source) const { return mapGroundAge(vertices[source], rendering); }
  __device__ int offer(int source, const BevProjection& projection, float& range) const {
    int row = 0;
    int col = 0;
    const Float3 vertex = vertices[source];
    if (!isMapGround(vertex, normals[source], rendering) || !projection.cellOf(vertex, row, col)) return -1;
    range = norm(vertex);
    return row * projection.cols + col;
  }
};

// Every offer is in: each pixel's key is read here by its own thread alone, which clears it.
__global__ void takeRenderedPixels(ClosestKey* closest_keys, MapRenderSources sources, DeviceModelImage image) {
  const int pixel = globalThread();
  if (pixel >= image.pixels()) return;
  const ClosestKey key = closest_keys[pixel];
  if (key == kNoClosestKey) {
    image.ranges[pixel] = 0.0f;
    image.normals[pixel] = Float3{0.0f, 0.0f, 0.0f};
    return;
  }
  closest_keys[pixel] = kNoClosestKey;
  const uint32_t source = closestWinsSource(key);
  image.vertices[pixel] = sources.vertices[source];
  image.normals[pixel] = sources.normals[source];
  image.ranges[pixel] = closestWinsRange(key);
  image.stamps[pixel] = 0.0f;
}

}  // namespace

void renderMapModel(const DeviceMap& map, const MapRenderSources& sources, const Rigid3f& sensor_from_map,
                    const SphericalProjection& spherical, const BevProjection& bev, const MapRendering& rendering,
                    ClosestKey* closest_keys, const DeviceModelImage& image, const DeviceBev& ground,
                    const CellCompaction& compaction, cudaStream_t stream) {
  if (sources.count > 0) {
    offerMapPoints<<<blocksFor(sources.count), kThreads, 0, stream>>>(map, sources, sensor_from_map, spherical,
                                                                      rendering, closest_keys);
    checkLaunch("offerMapPoints");
    const MapGroundSources ground_sources{sources.vertices, sources.normals, sources.count, rendering};
    cell_compaction::compact(ground_sources, blocksFor(sources.count), bev, rendering.same_surface_distance,
                             compaction, ground, stream);
  } else {
    clearGroundMap(ground, stream);
  }
  takeRenderedPixels<<<blocksFor(image.pixels()), kThreads, 0, stream>>>(closest_keys, sources, image);
  checkLaunch("takeRenderedPixels");
}

}  // namespace elo::cuda
