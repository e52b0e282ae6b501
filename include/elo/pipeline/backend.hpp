// The per-frame stages of the pipeline behind one interface, so that the threaded CPU kernels and the
// CUDA kernels are interchangeable. A backend owns the current scan and the model; the Gauss-Newton loop
// (registration.hpp) and the motion prior live above it and are shared.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "elo/config.hpp"
#include "elo/imu/gyro_sweep.hpp"
#include "elo/se3.hpp"
#include "elo/types.hpp"

namespace elo {

struct MapCloud;

// The reductions of one Gauss-Newton step, per cost term, before fusion (Eq. 1-2). Sums over the
// correspondences that passed the gates; `candidates` counts the points that were tried.
struct TermSums {
  Matrix6d JtJ = Matrix6d::Zero();
  Vector6d Jte = Vector6d::Zero();
  double squared_error = 0.0;
  int candidates = 0;
  int inliers = 0;

  double inlierRatio() const { return candidates > 0 ? static_cast<double>(inliers) / candidates : 0.0; }
  TermSums& operator+=(const TermSums& other);
};

struct NormalEquations {
  TermSums nonground;  // E_S: scan SRI against the model SRI
  TermSums ground;     // E_G: scan BEV against the model BEV
};

// How the projection deskews a scan (docs/deskew.md): where its points' times come from (deskew.time_source,
// or `none` for a cloud without usable times: instantaneous) and the sensor's velocity over the sweep, a
// twist per second (translation, rotation) in the scan's frame at its reference instant, and that instant
// in the cloud's per-point times (`field`: CloudTimes::reference, the middle of the sweep). With a gyro
// (docs/imu.md), `gyro` turns each point by the rotation at its own time instead of the velocity's rate,
// in the projection and in every deskew after it (deskewScan()), which change only the translation.
struct SweepMotion {
  TimeSource times = TimeSource::none;
  Vector6d velocity = Vector6d::Zero();
  double reference = 0.0;
  GyroSweep gyro = {};
};

// A device backend queues the work of a stage call and returns; a call whose result the host needs (the
// occupied count, the sums, the host views) waits for it. The CPU backend finishes every call at once.
class Backend {
 public:
  virtual ~Backend() = default;
  virtual const char* name() const = 0;

  // Sec. III-B.1: spherical projection of the cloud (closest point per pixel), every point deskewed by
  // `motion` first. `stamp` is the scan's time in seconds since the first scan; it becomes the
  // observation time of every vertex. Returns the number of occupied pixels. A point whose own time
  // (`field`) lies outside the sweep (SweepTiming::withinSweep()) is dropped. A `field` source with a
  // cloud whose times are missing or not one per point is taken as `none`.
  virtual size_t projectScan(const PointCloud& cloud, float stamp, const SweepMotion& motion = {}) = 0;
  // Deskews the projected scan again under `velocity` (as SweepMotion::velocity): every vertex from its
  // measured point and time, every normal turned with it (under the projection's gyro, SweepMotion::gyro,
  // the turn stays and so do the normals). Pixels, labels and the registration pixels stay; the ground
  // map must be built again (buildGroundMap()). Nothing to do for an instantaneous scan.
  virtual void deskewScan(const Vector6d& velocity) = 0;
  // Sec. III-C.1: labels every occupied pixel ground or non-ground.
  virtual void segmentGround() = 0;
  // Sec. III-B.3-4: normals and curvature gating of the non-ground pixels.
  virtual void estimateNormals() = 0;
  // Sec. III-C.2: the BEV map of the ground pixels.
  virtual void buildGroundMap() = 0;
  // Sec. III-A: the sums of one Gauss-Newton step with the scan moved by `model_from_scan` (T^{t-1}_t),
  // residuals weighted by a Geman-McClure kernel of scale `kernel_scale` (0: unweighted).
  virtual NormalEquations linearize(const Eigen::Isometry3d& model_from_scan, double kernel_scale) = 0;
  // Sec. III-D: moves the model into the scan's frame and fuses the scan into it (frame-to-model), or
  // makes the scan the model (frame-to-frame).
  virtual void updateModel(const Eigen::Isometry3d& model_from_scan, float stamp) = 0;
  virtual void resetModel() = 0;

  // Host views of the buffers, for tests, visualisation and backend comparison. A device backend
  // copies its buffers to the host on these calls.
  virtual const ScanImage& scan() = 0;
  virtual const BevImage& scanGround() = 0;
  virtual const Model& model() = 0;

  // Waits until every stage called so far has finished, so that its time can be taken.
  virtual void synchronize() {}

  // Starts moving `cloud`, a scan to project after the current one, to the device while the current
  // scan's stages run (docs/cuda.md); nothing to do on the host. projectScan() takes that upload only for
  // the same cloud (CloudIdentity: the same arrays' memory, lengths and stamp), and its results are the
  // same, bit for bit, with or without it. The cloud's arrays are read until finishPrefetch() returns, and
  // must not change until the cloud is projected.
  virtual void prefetch(const PointCloud& /*cloud*/) {}
  // Waits until the backend no longer reads the arrays of the cloud last prefetched. Never throws: a
  // failed upload is reported by the projectScan() of its cloud.
  virtual void finishPrefetch() noexcept {}
  // Of the last scan, the time (ms) its processing waited for scans to reach the device: in projectScan(),
  // for its own upload (all of it unless prefetched), and in finishPrefetch(), for the next scan's
  // arrays to be read; 0 on the host.
  virtual double lastUploadMilliseconds() const { return 0.0; }

  // Localization on a saved map (localization/localizer.hpp): a second model, rendered from map points
  // instead of fused from scans, that the current scan's features register against with the same cost.
  // Hands over the map (kept until the next call); `map` must have normals (prepareMap()).
  virtual void setMap(std::shared_ptr<const MapCloud> map) = 0;
  // Renders map points `points` (indices into the map) seen from the sensor at `map_from_sensor` into
  // the map model: the non-ground range image (points with a normal, each covering a disc of
  // localization.splat_radius) and the ground BEV (points whose height lies in the ground segmentation's
  // band), in the sensor's frame, as the model of a scan taken there would hold them.
  virtual void renderMap(const std::vector<int32_t>& points, const Eigen::Isometry3d& map_from_sensor) = 0;
  // linearize() against the rendered map model: `rendered_from_scan` moves the scan's features into the
  // frame the map was rendered in.
  virtual NormalEquations linearizeMap(const Eigen::Isometry3d& rendered_from_scan, double kernel_scale) = 0;
  virtual const Model& mapModel() = 0;
};

// Makes the backend `config.runtime.backend` names. When that is the CUDA backend and it cannot run here
// (no usable GPU, or a build without CUDA), throws std::runtime_error saying why, or with
// runtime.backend_fallback returns the CPU backend and puts the reason into `*warning` (when given) for
// the caller to show.
std::unique_ptr<Backend> makeBackend(const Config& config, std::string* warning = nullptr);

// Why the CUDA backend cannot run here, or empty when it can.
std::string cudaUnavailableReason();

}  // namespace elo
