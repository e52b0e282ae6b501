// The CUDA backend against the CPU backend on the same inputs, stage by stage: range images, point
// indices, ground labels and BEV maps identical (the scan's, the model's and a saved map's rendering);
// normals within 1e-4; Gauss-Newton sums within 1e-6 (relative), and the GPU's the same bit for bit when
// linearised again; poses within 1e-4 m and 1e-4 rad at every frame. These tests skip, saying why, where
// no CUDA device is usable or the build has no CUDA backend. The factory tests run everywhere.
#include <gtest/gtest.h>

#include <filesystem>
#include <numeric>
#include <sstream>
#include <string>

#include "analytic_scene.hpp"
#include "elo/io/sequence.hpp"
#include "elo/localization/localizer.hpp"
#include "elo/map/point_map.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {
namespace {

#define ELO_REQUIRE_CUDA()                                                                          \
  do {                                                                                              \
    const std::string reason = cudaUnavailableReason();                                             \
    if (!reason.empty()) GTEST_SKIP() << "the CUDA backend cannot run here: " << reason;            \
  } while (false)

const std::string kRealScans = std::string(ELO_SHARED_DATA) + "/real/hdl64_drive_a";

// Within 1e-4 m and 1e-4 rad, at every frame.
constexpr double kPoseTolerance = 1e-4;
// Normals: largest component difference where both backends have one, which must be the same pixels.
// Built for a host with FMA (the default -march=native), the backends round alike and agree bit for bit
// (test_shared_math.cpp checks the GPU's normal estimator so on the CPU).
constexpr float kNormalTolerance = 1e-4f;

using test::pose;
struct Backends {
  std::unique_ptr<Backend> cpu;
  std::unique_ptr<Backend> cuda;

  explicit Backends(Config config) {
    config.runtime.threads = 2;
    config.runtime.backend = BackendKind::cpu;
    cpu = makeBackend(config);
    config.runtime.backend = BackendKind::cuda;
    cuda = makeBackend(config);
  }

  // Projects the cloud and extracts its features on both.
  void prepare(const PointCloud& cloud, float stamp) {
    for (Backend* backend : {cpu.get(), cuda.get()}) {
      backend->projectScan(cloud, stamp);
      backend->segmentGround();
      backend->estimateNormals();
      backend->buildGroundMap();
    }
  }
};

// Counts the elements where `same(i)` fails, describing the first.
template <typename Same>
size_t countDifferences(size_t count, const Same& same, std::string& first) {
  size_t differences = 0;
  for (size_t i = 0; i < count; ++i) {
    if (same(i)) continue;
    if (differences++ == 0) first = "first at element " + std::to_string(i);
  }
  return differences;
}

void expectSameProjection(const ScanImage& cpu, const ScanImage& cuda) {
  ASSERT_EQ(cpu.image.pixelCount(), cuda.image.pixelCount());
  std::string first;
  EXPECT_EQ(countDifferences(cpu.label.size(), [&](size_t p) { return cpu.point_index[p] == cuda.point_index[p]; }, first), 0u)
      << "point indices, " << first;
  EXPECT_EQ(countDifferences(cpu.label.size(), [&](size_t p) { return cpu.image.range[p] == cuda.image.range[p]; }, first), 0u)
      << "ranges, " << first;
  EXPECT_EQ(countDifferences(cpu.label.size(),
                             [&](size_t p) { return !cpu.image.occupied(p) || cpu.image.vertex[p] == cuda.image.vertex[p]; },
                             first),
            0u)
      << "vertices, " << first;
  EXPECT_EQ(countDifferences(cpu.label.size(), [&](size_t p) { return cpu.label[p] == cuda.label[p]; }, first), 0u)
      << "labels, " << first;
}

void expectAgreeingNormals(const SphericalImage& cpu, const SphericalImage& cuda) {
  size_t with_normal = 0;
  size_t presence_differs = 0;
  float largest_difference = 0.0f;
  for (size_t p = 0; p < cpu.pixelCount(); ++p) {
    const bool cpu_has = cpu.occupied(p) && cpu.hasNormal(p);
    const bool cuda_has = cuda.occupied(p) && cuda.hasNormal(p);
    with_normal += cpu_has;
    if (cpu_has != cuda_has) {
      ++presence_differs;
    } else if (cpu_has) {
      largest_difference = std::max(largest_difference, (cpu.normal[p] - cuda.normal[p]).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_GT(with_normal, 0u);
  EXPECT_EQ(presence_differs, 0u) << "of " << with_normal;
  EXPECT_LT(largest_difference, kNormalTolerance);
}

// The model image: the same points in the same pixels, with normals that agree.
void expectAgreeingModelImage(const SphericalImage& cpu, const SphericalImage& cuda) {
  std::string first;
  EXPECT_EQ(countDifferences(cpu.pixelCount(), [&](size_t p) { return cpu.range[p] == cuda.range[p]; }, first), 0u)
      << "ranges, " << first;
  EXPECT_EQ(countDifferences(cpu.pixelCount(),
                             [&](size_t p) {
                               return !cpu.occupied(p) ||
                                      (cpu.vertex[p] == cuda.vertex[p] && cpu.stamp[p] == cuda.stamp[p]);
                             },
                             first),
            0u)
      << "vertices and stamps, " << first;
  expectAgreeingNormals(cpu, cuda);
}

void expectSameGroundMap(const BevImage& cpu, const BevImage& cuda) {
  ASSERT_EQ(cpu.size(), cuda.size());
  EXPECT_EQ(cpu.cell, cuda.cell);
  EXPECT_EQ(cpu.vertex, cuda.vertex);
  EXPECT_EQ(cpu.range, cuda.range);
  EXPECT_EQ(cpu.stamp, cuda.stamp);
  EXPECT_TRUE(cpu.point_of_cell == cuda.point_of_cell);
}

void expectAgreeingSums(const TermSums& cpu, const TermSums& cuda) {
  EXPECT_EQ(cpu.candidates, cuda.candidates);
  EXPECT_EQ(cpu.inliers, cuda.inliers);
  constexpr double kRelative = 1e-6;
  EXPECT_LE((cpu.JtJ - cuda.JtJ).norm(), kRelative * cpu.JtJ.norm());
  EXPECT_LE((cpu.Jte - cuda.Jte).norm(), kRelative * cpu.Jte.norm());
  EXPECT_LE(std::abs(cpu.squared_error - cuda.squared_error), kRelative * cpu.squared_error);
}

// The same linearisation twice on one GPU: the same sums bit for bit, whichever block finished last.
void expectIdenticalSums(const TermSums& first, const TermSums& again) {
  EXPECT_EQ(first.candidates, again.candidates);
  EXPECT_EQ(first.inliers, again.inliers);
  EXPECT_EQ(first.JtJ, again.JtJ);
  EXPECT_EQ(first.Jte, again.Jte);
  EXPECT_EQ(first.squared_error, again.squared_error);
}

// One linearisation on both backends (`linearize` of each, against its model or its map): sums that
// agree, and the GPU's the same bit for bit when linearised again. Returns the CPU's.
template <typename Linearize>
NormalEquations expectAgreeingLinearizations(Backends& backends, const Linearize& linearize) {
  const NormalEquations cpu = linearize(*backends.cpu);
  const NormalEquations cuda = linearize(*backends.cuda);
  expectAgreeingSums(cpu.nonground, cuda.nonground);
  expectAgreeingSums(cpu.ground, cuda.ground);
  const NormalEquations again = linearize(*backends.cuda);
  expectIdenticalSums(cuda.nonground, again.nonground);
  expectIdenticalSums(cuda.ground, again.ground);
  return cpu;
}

void expectAgreeingPoses(const Eigen::Isometry3d& cpu, const Eigen::Isometry3d& cuda, size_t frame) {
  EXPECT_LT((cpu.translation() - cuda.translation()).norm(), kPoseTolerance) << "frame " << frame;
  EXPECT_LT(rotationAngle(cpu.inverse() * cuda), kPoseTolerance) << "frame " << frame;
}

PointCloud streetScan(const Config& config, const Eigen::Isometry3d& sensor_pose = Eigen::Isometry3d::Identity(),
                      double stamp = 0.0, double range_noise = 0.0) {
  return test::scanScene(test::streetScene(), config.sensor, sensor_pose, stamp, range_noise).cloud;
}

TEST(BackendAgreement, ProjectionFillsTheSamePixelsWithTheSamePoints) {
  ELO_REQUIRE_CUDA();
  Config kitti;
  kitti.sensor.elevation_correction_deg = 0.195;
  for (const bool ring : {false, true}) {
    for (const Config& config : {Config(), kitti}) {
      SCOPED_TRACE(std::string("ring ") + (ring ? "on" : "off") + ", elevation correction " +
                   std::to_string(config.sensor.elevation_correction_deg));
      PointCloud cloud = streetScan(config, Eigen::Isometry3d::Identity(), 0.0, 0.02);
      if (!ring) cloud.ring.clear();
      Backends backends(config);
      EXPECT_EQ(backends.cpu->projectScan(cloud, 0.5f), backends.cuda->projectScan(cloud, 0.5f));
      expectSameProjection(backends.cpu->scan(), backends.cuda->scan());
    }
  }
}

TEST(BackendAgreement, GroundLabelsAreIdentical) {
  ELO_REQUIRE_CUDA();
  Config all_points;
  all_points.registration.terms = CostTerms::spherical_all;
  Config near_road_out;
  near_road_out.ground.min_range = 8.0;
  for (const Config& config : {Config(), all_points, near_road_out}) {
    Backends backends(config);
    const PointCloud cloud = streetScan(config, Eigen::Isometry3d::Identity(), 0.0, 0.02);
    for (Backend* backend : {backends.cpu.get(), backends.cuda.get()}) {
      backend->projectScan(cloud, 0.0f);
      backend->segmentGround();
    }
    expectSameProjection(backends.cpu->scan(), backends.cuda->scan());
  }
}

TEST(BackendAgreement, NormalsAgreeForEveryMethod) {
  ELO_REQUIRE_CUDA();
  for (const NormalMethod method : {NormalMethod::range_adaptive, NormalMethod::eigen, NormalMethod::cross_product}) {
    for (const double noise : {0.0, 0.02}) {
      SCOPED_TRACE("method " + std::to_string(static_cast<int>(method)) + ", noise " + std::to_string(noise));
      Config config;
      config.normals.method = method;
      Backends backends(config);
      backends.prepare(streetScan(config, Eigen::Isometry3d::Identity(), 0.0, noise), 0.0f);
      expectAgreeingNormals(backends.cpu->scan().image, backends.cuda->scan().image);
    }
  }
}

// The GPU reads each window from its block's tile in shared memory: windows too large for a block's tile
// stop the CUDA backend with an error that names the parameters to change.
TEST(BackendAgreement, WindowsTooLargeForATileStopTheCudaBackendNamingTheParameters) {
  ELO_REQUIRE_CUDA();
  Config config;
  config.normals.max_window_width = 81;
  config.normals.max_window_height = 41;
  config.runtime.backend = BackendKind::cuda;
  const std::unique_ptr<Backend> backend = makeBackend(config);
  backend->projectScan(streetScan(config), 0.0f);
  backend->segmentGround();
  try {
    backend->estimateNormals();
    ADD_FAILURE() << "81 x 41 windows need 86,016 bytes of shared memory per block, and ran";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("normals.max_window_width x normals.max_window_height"),
              std::string::npos)
        << error.what();
  }
}

TEST(BackendAgreement, ScanGroundMapsAreIdenticalInTheSameOrder) {
  ELO_REQUIRE_CUDA();
  for (const double min_range : {0.0, 8.0}) {
    SCOPED_TRACE("ground.min_range " + std::to_string(min_range));
    Config config;
    config.ground.min_range = min_range;
    Backends backends(config);
    backends.prepare(streetScan(config, pose(-3, 0.5, 0, 0, 0, 10), 0.0, 0.02), 0.0f);
    EXPECT_GT(backends.cpu->scanGround().size(), 10000u);
    expectSameGroundMap(backends.cpu->scanGround(), backends.cuda->scanGround());
  }
}

// `cloud` projected by both backends deskewed under `prior` (each point turned by `gyro` when it is
// known), with field and then azimuth times, and deskewed again in place under `velocity`: the same
// pixels, points, times, normals and ground maps after each.
void expectDeskewedAlike(const Config& config, const PointCloud& cloud, const Vector6d& prior,
                         const Vector6d& velocity, const GyroSweep& gyro) {
  for (const TimeSource source : {TimeSource::field, TimeSource::azimuth}) {
    SCOPED_TRACE(source == TimeSource::field ? "field" : "azimuth");
    Backends backends(config);
    for (Backend* backend : {backends.cpu.get(), backends.cuda.get()}) {
      backend->projectScan(cloud, 0.0f, {source, prior, 0.0, gyro});
      backend->segmentGround();
      backend->estimateNormals();
    }
    expectSameProjection(backends.cpu->scan(), backends.cuda->scan());
    EXPECT_EQ(backends.cpu->scan().time, backends.cuda->scan().time);
    for (Backend* backend : {backends.cpu.get(), backends.cuda.get()}) {
      backend->deskewScan(velocity);
      backend->buildGroundMap();
    }
    expectSameProjection(backends.cpu->scan(), backends.cuda->scan());
    expectAgreeingNormals(backends.cpu->scan().image, backends.cuda->scan().image);
    expectSameGroundMap(backends.cpu->scanGround(), backends.cuda->scanGround());
  }
}

// A sweep taken at 10 m/s while turning, deskewed in the projection under a prior 30% off (the field
// times with a few broken ones, then the azimuth times), then again in place under the true motion.
TEST(BackendAgreement, DeskewMovesThePointsAlike) {
  ELO_REQUIRE_CUDA();
  Vector6d velocity;
  velocity << 10.0, 0.3, 0.05, 0.02, -0.03, 0.5;
  const Config config;
  PointCloud cloud =
      test::sweepScene(test::streetScene(), config.sensor, pose(-3, 0.5, 0, 0, 0, 10), velocity).cloud;
  for (size_t i = 0; i < cloud.size(); i += 101) cloud.time[i] = i % 2 ? NAN : 5.0f;
  expectDeskewedAlike(config, cloud, 0.7 * velocity, velocity, GyroSweep());
}

TEST(BackendAgreement, GaussNewtonSumsAgreeForEveryCostVariant) {
  ELO_REQUIRE_CUDA();
  for (const CostTerms terms :
       {CostTerms::fused, CostTerms::spherical_all, CostTerms::spherical_nonground, CostTerms::bev_ground}) {
    SCOPED_TRACE("terms " + std::to_string(static_cast<int>(terms)));
    Config config;
    config.registration.terms = terms;
    config.registration.near_weight_range = terms == CostTerms::fused ? 30.0 : 0.0;  // both ways of weighing
    Backends backends(config);
    backends.prepare(streetScan(config), 0.0f);
    backends.cpu->updateModel(Eigen::Isometry3d::Identity(), 0.0f);
    backends.cuda->updateModel(Eigen::Isometry3d::Identity(), 0.0f);
    const Eigen::Isometry3d truth = pose(0.6, 0.15, 0.03, 0.3, -0.4, 1.5);
    backends.prepare(streetScan(config, truth, 0.1, 0.02), 0.1f);
    for (const Eigen::Isometry3d& guess : {Eigen::Isometry3d::Identity(), truth, pose(0.5, 0.1, 0.0, 0.0, 0.0, 1.0)}) {
      for (const double kernel_scale : {0.0, 0.1, 0.4}) {
        expectAgreeingLinearizations(
            backends, [&](Backend& backend) { return backend.linearize(guess, kernel_scale); });
      }
    }
  }
}

TEST(BackendAgreement, ModelUpdatesAgree) {
  ELO_REQUIRE_CUDA();
  Config config;
  config.model.time_window = 0.35;  // points expire within the run
  Backends backends(config);
  Eigen::Isometry3d truth = pose(-20, 0, 0, 0, 0, 0);
  Eigen::Isometry3d previous = truth;
  for (int frame = 0; frame < 8; ++frame) {
    backends.prepare(streetScan(config, truth, 0.1 * frame, 0.02), 0.1f * frame);
    const Eigen::Isometry3d model_from_scan = previous.inverse() * truth;
    backends.cpu->updateModel(model_from_scan, 0.1f * frame);
    backends.cuda->updateModel(model_from_scan, 0.1f * frame);
    const Model& cpu = backends.cpu->model();
    const Model& cuda = backends.cuda->model();
    SCOPED_TRACE("frame " + std::to_string(frame));
    expectSameGroundMap(cpu.ground, cuda.ground);
    expectAgreeingModelImage(cpu.nonground, cuda.nonground);
    EXPECT_EQ(cpu.initialized, cuda.initialized);
    previous = truth;
    truth = truth * pose(0.9, 0.0, 0.0, 0.0, 0.0, 0.7);
  }
}

// The odometry in `mode` on each backend, the CPU's with 2 threads.
struct OdometryOnBothBackends {
  explicit OdometryOnBothBackends(RegistrationMode mode)
      : cpu(configFor(mode, BackendKind::cpu)), cuda(configFor(mode, BackendKind::cuda)) {}

  static Config configFor(RegistrationMode mode, BackendKind backend) {
    Config config;
    config.model.mode = mode;
    config.runtime.threads = 2;
    config.runtime.backend = backend;
    return config;
  }

  Odometry cpu;
  Odometry cuda;
};

// Drives down the street with turning, accelerating motion in `mode`, on both backends.
void expectAgreeingStreetDrive(RegistrationMode mode) {
  const Config config;
  OdometryOnBothBackends odometry(mode);
  Eigen::Isometry3d truth = pose(-20, 0, 0, 0, 0, 0);
  double speed = 8.0;
  for (int frame = 0; frame < 25; ++frame) {
    const PointCloud cloud = streetScan(config, truth, 0.1 * frame, 0.02);
    const FrameResult a = odometry.cpu.process(cloud);
    const FrameResult b = odometry.cuda.process(cloud);
    ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
    expectAgreeingPoses(a.pose, b.pose, frame);
    speed += 0.3;
    truth = truth * pose(speed * 0.1, 0.0, 0.0, 0.0, 0.0, std::sin(frame * 0.3) * 0.8);
  }
}

TEST(BackendAgreement, PosesAgreeAtEveryFrameOfASimulatedDrive) {
  ELO_REQUIRE_CUDA();
  expectAgreeingStreetDrive(RegistrationMode::frame_to_model);
  expectAgreeingStreetDrive(RegistrationMode::frame_to_frame);
}

TEST(BackendAgreement, PosesAgreeOnADriveOfDeskewedSweeps) {
  ELO_REQUIRE_CUDA();
  const Config config;
  OdometryOnBothBackends odometry(RegistrationMode::frame_to_model);
  Vector6d velocity;
  velocity << 10.0, 0.0, 0.0, 0.0, 0.0, 0.12;
  for (int frame = 0; frame < 8; ++frame) {
    const Eigen::Isometry3d truth = pose(-25, 0, 0, 0, 0, 0) * expSE3(0.1 * frame * velocity);
    const PointCloud cloud = test::sweepScene(test::streetScene(), config.sensor, truth, velocity, 0.1 * frame).cloud;
    const FrameResult a = odometry.cpu.process(cloud);
    const FrameResult b = odometry.cuda.process(cloud);
    ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
    EXPECT_EQ(a.deskew_rounds, b.deskew_rounds);
    expectAgreeingPoses(a.pose, b.pose, frame);
  }
}

// Started on a vehicle already driving 15 m/s (docs/start_in_motion.md): the start search runs on the
// second scan, through each backend's linearisation, and must pick the same motion on both; with sweeps,
// the first scan is then deskewed again and the model rebuilt from it, on both.
TEST(BackendAgreement, PosesAgreeStartedInMotion) {
  ELO_REQUIRE_CUDA();
  const Config config;
  Vector6d velocity;
  velocity << 15.0, 0.0, 0.0, 0.0, 0.0, 0.05;
  for (const bool sweeps : {false, true}) {
    for (const RegistrationMode mode : {RegistrationMode::frame_to_model, RegistrationMode::frame_to_frame}) {
      OdometryOnBothBackends odometry(mode);
      for (int frame = 0; frame < 8; ++frame) {
        const Eigen::Isometry3d truth = pose(-25, 0, 0, 0, 0, 0) * expSE3(0.1 * frame * velocity);
        const PointCloud cloud =
            sweeps ? test::sweepScene(test::streetScene(), config.sensor, truth, velocity, 0.1 * frame).cloud
                   : streetScan(config, truth, 0.1 * frame, 0.02);
        const FrameResult a = odometry.cpu.process(cloud);
        const FrameResult b = odometry.cuda.process(cloud);
        ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
        expectAgreeingPoses(a.pose, b.pose, frame);
      }
      EXPECT_EQ(odometry.cpu.startSearchCount(), 1u);
      EXPECT_EQ(odometry.cuda.startSearchCount(), odometry.cpu.startSearchCount());
      EXPECT_EQ(odometry.cuda.ambiguousStartCount(), odometry.cpu.ambiguousStartCount());
    }
  }
}

// The tracking guard (docs/robustness.md#a-lost-track) on both backends: a scan taken turned 60 deg from
// where the car can be (a turn beyond motion.max_turn_rate_deg) is refused alike, its pose held from the
// prior, and the next scans are searched and recovered alike.
TEST(BackendAgreement, RefusalsAndRecoveriesAgree) {
  ELO_REQUIRE_CUDA();
  const Config config;
  OdometryOnBothBackends odometry(RegistrationMode::frame_to_model);
  size_t refused = 0;
  for (int frame = 0; frame < 10; ++frame) {
    const double turned = frame == 5 ? 60.0 : 0.0;
    const PointCloud cloud = streetScan(config, pose(-20 + 0.8 * frame, 0, 0, 0, 0, turned), 0.1 * frame, 0.02);
    const FrameResult a = odometry.cpu.process(cloud);
    const FrameResult b = odometry.cuda.process(cloud);
    ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
    EXPECT_EQ(a.refusal, b.refusal) << "frame " << frame;
    EXPECT_EQ(a.recovered, b.recovered) << "frame " << frame;
    refused += !a.refusal.empty();
    expectAgreeingPoses(a.pose, b.pose, frame);
  }
  EXPECT_GE(refused, 1u);
  EXPECT_EQ(odometry.cuda.refusalCounts(), odometry.cpu.refusalCounts());
  EXPECT_EQ(odometry.cuda.recoveryCount(), odometry.cpu.recoveryCount());
}

// A gap (docs/robustness.md#faulty-input): the scans' clock jumps 2 s forward while the car drives on;
// both backends search the scan after it on the same two lines and track on alike.
TEST(BackendAgreement, GapsAreSearchedAlike) {
  ELO_REQUIRE_CUDA();
  const Config config;
  OdometryOnBothBackends odometry(RegistrationMode::frame_to_model);
  for (int frame = 0; frame < 10; ++frame) {
    const double stamp = 0.1 * frame + (frame >= 5 ? 2.0 : 0.0);
    const PointCloud cloud = streetScan(config, pose(-20 + 0.8 * frame, 0, 0, 0, 0, 0), stamp, 0.02);
    const FrameResult a = odometry.cpu.process(cloud);
    const FrameResult b = odometry.cuda.process(cloud);
    ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
    EXPECT_EQ(a.gap, b.gap) << "frame " << frame;
    EXPECT_EQ(a.start_search.candidates, b.start_search.candidates) << "frame " << frame;
    expectAgreeingPoses(a.pose, b.pose, frame);
  }
  EXPECT_EQ(odometry.cpu.gapCount(), 1u);
  EXPECT_EQ(odometry.cuda.gapCount(), odometry.cpu.gapCount());
  EXPECT_EQ(odometry.cuda.refusalCounts(), odometry.cpu.refusalCounts());
}

// With an IMU (docs/imu.md) the gyro turns the guess and the deskew and the accelerometers carry the
// guess's translation; the backends deskew and register under the same velocities and from the same
// guesses, so they agree as without it. The samples are those of the drive's own motion: a circle at
// 10 m/s and 0.3 rad/s, the specific force its 3 m/s^2 towards the centre and gravity.
TEST(BackendAgreement, PosesAgreeWithTheImu) {
  ELO_REQUIRE_CUDA();
  Config config;
  config.imu.enabled = true;
  config.model.mode = RegistrationMode::frame_to_model;
  config.runtime.threads = 2;
  Odometry cpu(config);
  config.runtime.backend = BackendKind::cuda;
  Odometry cuda(config);
  Vector6d velocity;
  velocity << 10.0, 0.0, 0.0, 0.0, 0.0, 0.3;
  for (int sample = -40; sample <= 200; ++sample) {
    ImuSample gyro;
    gyro.stamp = 0.005 * sample;
    gyro.angular_velocity = velocity.tail<3>();
    gyro.specific_force = Eigen::Vector3d(0.0, velocity(0) * velocity(5), 9.81);
    cpu.addImu(gyro);
    cuda.addImu(gyro);
  }
  for (int frame = 0; frame < 8; ++frame) {
    const Eigen::Isometry3d truth = pose(-25, 0, 0, 0, 0, 0) * expSE3(0.1 * frame * velocity);
    const PointCloud cloud = test::sweepScene(test::streetScene(), config.sensor, truth, velocity, 0.1 * frame).cloud;
    const FrameResult a = cpu.process(cloud);
    const FrameResult b = cuda.process(cloud);
    ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
    EXPECT_EQ(a.imu_fallback, "");
    EXPECT_EQ(b.imu_fallback, "");
    expectAgreeingPoses(a.pose, b.pose, frame);
  }
}

// A sensor swung about a tilted axis at 180 deg/s at mid-sweep, the rate rising by half of that within
// the sweep, while it slides at 1.4 m/s (test::Swing); the LiDAR's rotation through the sweep by a 200 Hz
// gyro, as the odometry deskews it (docs/imu.md).
double swingAngle(double time) { return M_PI * time + 0.25 * M_PI / 0.1 * time * time; }

GyroSweep gyroOfSwing(const Eigen::Vector3d& axis) {
  ImuTrack track{ImuConfig()};
  for (int i = -40; i <= 40; ++i) {
    ImuSample sample;
    sample.stamp = 0.005 * i;
    sample.angular_velocity = axis * (M_PI + 0.5 * M_PI / 0.1 * sample.stamp);
    track.add(sample);
  }
  GyroSweep sweep;
  EXPECT_EQ(track.sweepRotation(0.0, -0.05, 0.05, sweep), "");
  return sweep;
}

// Each point turned by the gyro's rotation at its own time (the shared SweepRotation), in the projection
// and again in place under a new translation, with field and azimuth times.
TEST(BackendAgreement, DeskewWithTheGyroMovesThePointsAlike) {
  ELO_REQUIRE_CUDA();
  const Config config;
  const test::Swing<double (*)(double)> swing{Eigen::Vector3d(0.1, -0.2, 1.0).normalized(), &swingAngle,
                                              Eigen::Vector3d(1.4, 0.2, 0.0)};
  PointCloud cloud = test::swungSweepScene(test::streetScene(), config.sensor, pose(-3, 0.5, 0, 0, 0, 10), swing).cloud;
  for (size_t i = 0; i < cloud.size(); i += 101) cloud.time[i] = i % 2 ? NAN : 5.0f;
  const GyroSweep gyro = gyroOfSwing(swing.axis);
  ASSERT_TRUE(gyro.known());
  Vector6d velocity = Vector6d::Zero();
  velocity.head<3>() = swing.linear;
  velocity.tail<3>() = M_PI * swing.axis;
  expectDeskewedAlike(config, cloud, 0.5 * velocity, velocity, gyro);
}

// A drive of sweeps taken while the sensor yaws at 1.5 rad/s and 1 rad/s more or less, the rate swinging
// within every sweep (a period of 0.4 s), while it slides along the street at 8 m/s: the gyro turns
// each point by its own rotation on both backends, frame-to-model and frame-to-frame.
TEST(BackendAgreement, PosesAgreeWithTheGyroTurningWithinEachSweep) {
  ELO_REQUIRE_CUDA();
  constexpr double kSwingPeriod = 0.4;
  const auto angle = [](double t) {
    return 1.5 * t - kSwingPeriod / (2.0 * M_PI) * std::cos(2.0 * M_PI * t / kSwingPeriod);
  };
  const auto rate = [](double t) { return 1.5 + std::sin(2.0 * M_PI * t / kSwingPeriod); };
  for (const RegistrationMode mode : {RegistrationMode::frame_to_model, RegistrationMode::frame_to_frame}) {
    SCOPED_TRACE(mode == RegistrationMode::frame_to_model ? "frame-to-model" : "frame-to-frame");
    Config config;
    config.imu.enabled = true;
    config.model.mode = mode;
    config.runtime.threads = 2;
    Odometry cpu(config);
    config.runtime.backend = BackendKind::cuda;
    Odometry cuda(config);
    for (int sample = -40; sample <= 200; ++sample) {
      ImuSample gyro;
      gyro.stamp = 0.005 * sample;
      gyro.angular_velocity = Eigen::Vector3d(0.0, 0.0, rate(gyro.stamp));
      cpu.addImu(gyro);
      cuda.addImu(gyro);
    }
    for (int frame = 0; frame < 8; ++frame) {
      const double stamp = 0.1 * frame;
      const auto turned = [&](double t) { return angle(stamp + t) - angle(stamp); };
      const test::Swing<decltype(turned)> swing{Eigen::Vector3d::UnitZ(), turned,
                                                Eigen::AngleAxisd(-angle(stamp), Eigen::Vector3d::UnitZ()) *
                                                    Eigen::Vector3d(8.0, 0.0, 0.0)};
      const Eigen::Isometry3d reference = pose(-25.0 + 8.0 * stamp, 0, 0, 0, 0, angle(stamp) * 180.0 / M_PI);
      const PointCloud cloud =
          test::swungSweepScene(test::streetScene(), config.sensor, reference, swing, stamp).cloud;
      const FrameResult a = cpu.process(cloud);
      const FrameResult b = cuda.process(cloud);
      ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
      EXPECT_EQ(a.imu_fallback, "");
      EXPECT_EQ(b.imu_fallback, "");
      EXPECT_EQ(a.deskew_rounds, b.deskew_rounds);
      expectAgreeingPoses(a.pose, b.pose, frame);
    }
  }
}

TEST(BackendAgreement, RealScansAgreeStageByStageAndInPose) {
  ELO_REQUIRE_CUDA();
  if (!std::filesystem::is_directory(kRealScans)) {
    GTEST_SKIP() << "real scans not found at " << kRealScans << " (shared data absent)";
  }
  const Sequence sequence(kRealScans);
  {
    Backends backends{Config()};
    backends.prepare(sequence.load(0), 0.0f);
    expectSameProjection(backends.cpu->scan(), backends.cuda->scan());
    expectAgreeingNormals(backends.cpu->scan().image, backends.cuda->scan().image);
    expectSameGroundMap(backends.cpu->scanGround(), backends.cuda->scanGround());
  }
  for (const RegistrationMode mode : {RegistrationMode::frame_to_model, RegistrationMode::frame_to_frame}) {
    OdometryOnBothBackends odometry(mode);
    for (size_t i = 0; i < sequence.size(); ++i) {
      const PointCloud cloud = sequence.load(i);
      expectAgreeingPoses(odometry.cpu.process(cloud).pose, odometry.cuda.process(cloud).pose, i);
    }
  }
}

TEST(BackendAgreement, GpuRunsAreReproducible) {
  ELO_REQUIRE_CUDA();
  Config config;
  config.runtime.backend = BackendKind::cuda;
  Odometry first(config);
  Odometry second(config);
  Eigen::Isometry3d truth = pose(-15, 0, 0, 0, 0, 0);
  for (int frame = 0; frame < 6; ++frame) {
    const PointCloud cloud = streetScan(config, truth, 0.1 * frame, 0.02);
    EXPECT_EQ(first.process(cloud).pose.matrix(), second.process(cloud).pose.matrix()) << "frame " << frame;
    truth = truth * pose(1.0, 0.0, 0.0, 0.0, 0.0, 0.5);
  }
}

// A saved map of the street: two scans' points placed at their poses, normals estimated at load.
std::shared_ptr<MapCloud> streetMap(const Config& config) {
  auto map = std::make_shared<MapCloud>();
  for (const Eigen::Isometry3d& at : {pose(-20, 0, 0, 0, 0, 0), pose(-5, 0.5, 0, 0, 0, 4)}) {
    for (const Vec3f& point : streetScan(config, at, 0.0, 0.02).points) {
      map->points.push_back((at * point.cast<double>()).cast<float>());
    }
  }
  prepareMap(*map, config.localization.normal_radius);
  return map;
}

std::vector<int32_t> everyNth(size_t count, size_t step) {
  std::vector<int32_t> points;
  for (size_t i = 0; i < count; i += step) points.push_back(static_cast<int32_t>(i));
  return points;
}

// `points` of the map rendered from `at` on both backends: the same images and ground maps.
void expectSameRenderings(Backends& backends, const std::vector<int32_t>& points, const Eigen::Isometry3d& at,
                          size_t least_ground) {
  backends.cpu->renderMap(points, at);
  backends.cuda->renderMap(points, at);
  const Model& cpu = backends.cpu->mapModel();
  const Model& cuda = backends.cuda->mapModel();
  EXPECT_GT(cpu.ground.size(), least_ground);
  expectSameGroundMap(cpu.ground, cuda.ground);
  expectAgreeingModelImage(cpu.nonground, cuda.nonground);
}

// The map rendered from the same pose on both backends: the same pixels, vertices and ranges, and the
// same ground map in the same order; with and without the discs, from all points or a list of some, and
// from none.
TEST(BackendAgreement, MapRenderingsAreIdentical) {
  ELO_REQUIRE_CUDA();
  for (const double splat_radius : {0.0, Config().localization.splat_radius}) {
    Config config;
    config.localization.splat_radius = splat_radius;
    const std::shared_ptr<MapCloud> map = streetMap(config);
    Backends backends(config);
    backends.cpu->setMap(map);
    backends.cuda->setMap(map);
    for (const size_t step : {1, 3}) {
      for (const Eigen::Isometry3d& at : {pose(-12, 0.3, 0, 0, 0, 2), pose(-8, -0.5, 0.1, 1, -1, 12)}) {
        SCOPED_TRACE("splat " + std::to_string(splat_radius) + ", every " + std::to_string(step) + " point");
        expectSameRenderings(backends, everyNth(map->size(), step), at, 1000);
      }
    }
    backends.cpu->renderMap({}, pose(-12, 0, 0, 0, 0, 0));
    backends.cuda->renderMap({}, pose(-12, 0, 0, 0, 0, 0));
    const Model& cuda = backends.cuda->mapModel();
    EXPECT_EQ(cuda.ground.size(), 0u);
    const std::vector<float>& ranges = cuda.nonground.range;
    EXPECT_EQ(std::count_if(ranges.begin(), ranges.end(), [](float range) { return range > 0.0f; }), 0);
  }
}

// Renders down the street within 10 m of the sensor, with 4 m tiles: the GPU holds a few tiles of the map
// at a time and takes others up as the renders move on (MapResidency), then all of it for one render of
// every point, then few again. The same images and ground maps as the CPU's, which reads the whole map.
TEST(BackendAgreement, MapRenderingsAgreeWhileTheTilesHeldChange) {
  ELO_REQUIRE_CUDA();
  Config config;
  config.localization.tile_size = 4.0;
  const std::shared_ptr<MapCloud> map = streetMap(config);
  const MapTiles tiles(*map, config.localization.tile_size);
  Backends backends(config);
  backends.cpu->setMap(map);
  backends.cuda->setMap(map);
  std::vector<int32_t> all(map->size());
  std::iota(all.begin(), all.end(), 0);
  for (const double x : {-22.0, -18.0, -13.0, -8.0, -4.0, 0.0, -30.0, -10.0}) {
    SCOPED_TRACE("at x " + std::to_string(x));
    const Eigen::Isometry3d at = pose(x, 0.2, 0.0, 0.0, 0.0, 3.0);
    std::vector<int32_t> near;
    tiles.pointsNear(at.translation(), 10.0, near);
    expectSameRenderings(backends, x == -30.0 ? all : near, at, 100);
  }
}

// A scan registered against the rendered map: the same sums on both backends, and on the GPU the same
// bit for bit again.
TEST(BackendAgreement, MapMatchSumsAgree) {
  ELO_REQUIRE_CUDA();
  const Config config;
  const std::shared_ptr<MapCloud> map = streetMap(config);
  Backends backends(config);
  const Eigen::Isometry3d truth = pose(-11, 0.4, 0.02, 0.3, -0.2, 3);
  const Eigen::Isometry3d rendered_at = truth * pose(0.5, -0.2, 0.0, 0.0, 0.0, -1.5);
  backends.prepare(streetScan(config, truth, 0.0, 0.02), 0.0f);
  std::vector<int32_t> all(map->size());
  std::iota(all.begin(), all.end(), 0);
  for (Backend* backend : {backends.cpu.get(), backends.cuda.get()}) {
    backend->setMap(map);
    backend->renderMap(all, rendered_at);
  }
  for (const Eigen::Isometry3d& guess : {Eigen::Isometry3d::Identity(), rendered_at.inverse() * truth}) {
    for (const double kernel_scale : {0.0, 0.2}) {
      const NormalEquations cpu = expectAgreeingLinearizations(
          backends, [&](Backend& backend) { return backend.linearizeMap(guess, kernel_scale); });
      EXPECT_GT(cpu.nonground.inliers, 1000);
      EXPECT_GT(cpu.ground.inliers, 1000);
    }
  }
}

// One backend's localization of a scan, for a failure's message: a pose that differs after a search can
// come from two candidates of nearly equal health ranked apart by the sums' last bits.
std::string described(const LocalizationResult& result) {
  std::ostringstream text;
  text << (result.searched ? "searched" : "tracked") << ", inlier share " << result.health.inlier_share << ", rms "
       << result.health.rms << ", " << result.health.inliers << " inliers, " << result.health.iterations
       << " iterations" << (result.refusal.empty() ? "" : ", refused: " + result.refusal);
  return text.str();
}

// Localization down the street on both backends, from a hint 1.5 m and 6 degrees off: the same states,
// and poses within the odometry's tolerance at every scan.
TEST(BackendAgreement, LocalizedPosesAgree) {
  ELO_REQUIRE_CUDA();
  const std::shared_ptr<MapCloud> map = streetMap(Config());
  OdometryOnBothBackends odometry(RegistrationMode::frame_to_model);
  Localizer cpu(odometry.cpu, map);
  Localizer cuda(odometry.cuda, map);
  Eigen::Isometry3d truth = pose(-18, 0, 0, 0, 0, 0);
  const Eigen::Isometry3d hint = truth * pose(1.2, 0.9, 0.0, 0.0, 0.0, 6.0);
  cpu.setInitialPose(hint);
  cuda.setInitialPose(hint);
  LocalizationState state = LocalizationState::waiting_for_pose;
  for (int frame = 0; frame < 12; ++frame) {
    const PointCloud cloud = streetScan(Config(), truth, 0.1 * frame, 0.02);
    const LocalizationResult a = cpu.update(odometry.cpu.process(cloud));
    const LocalizationResult b = cuda.update(odometry.cuda.process(cloud));
    state = a.state;
    SCOPED_TRACE("CPU: " + described(a) + "; CUDA: " + described(b));
    ASSERT_EQ(a.state, b.state) << "frame " << frame;
    EXPECT_EQ(a.matched, b.matched) << "frame " << frame;
    EXPECT_EQ(a.map_points_rendered, b.map_points_rendered) << "frame " << frame;
    expectAgreeingPoses(a.pose, b.pose, static_cast<size_t>(frame));
    truth = truth * pose(1.0, 0.0, 0.0, 0.0, 0.0, 0.6);
  }
  EXPECT_EQ(state, LocalizationState::tracking);
}

// Sweeps down the street at 10 m/s while turning: points with rings and per-point times.
PointCloud streetSweep(const Config& config, int frame) {
  Vector6d velocity;
  velocity << 10.0, 0.0, 0.0, 0.0, 0.0, 0.12;
  const Eigen::Isometry3d truth = pose(-25, 0, 0, 0, 0, 0) * expSE3(0.1 * frame * velocity);
  return test::sweepScene(test::streetScene(), config.sensor, truth, velocity, 0.1 * frame).cloud;
}

// A prefetched upload (Backend::prefetch()) is taken for its own cloud only, and projects as the same
// cloud uploaded by the projection: another cloud projected in between, clouds prefetched one, two and
// three ahead (the first two then dropped), the same cloud twice, a cloud prefetched without the times
// its projection deskews by (deskew.time_source azimuth), and a scan with fewer points than the last.
TEST(BackendAgreement, ProjectionTakesAPrefetchedUploadOnlyForItsCloud) {
  ELO_REQUIRE_CUDA();
  for (const TimeSource prefetched_times : {TimeSource::field, TimeSource::azimuth}) {
    SCOPED_TRACE(prefetched_times == TimeSource::field ? "times prefetched" : "times not prefetched");
    Config config;
    config.runtime.backend = BackendKind::cuda;
    config.deskew.time_source = prefetched_times;
    std::vector<PointCloud> clouds;
    for (int frame = 0; frame < 4; ++frame) clouds.push_back(streetSweep(config, frame));
    clouds[3].points.resize(clouds[3].size() / 2);
    clouds[3].ring.resize(clouds[3].size());
    clouds[3].time.resize(clouds[3].size());
    Vector6d velocity;
    velocity << 9.0, 0.0, 0.0, 0.0, 0.0, 0.1;
    const std::unique_ptr<Backend> plain = makeBackend(config);
    const std::unique_ptr<Backend> prefetching = makeBackend(config);
    const auto expectSameScan = [&](const PointCloud& cloud, const std::string& what) {
      SCOPED_TRACE(what);
      const SweepMotion motion{TimeSource::field, velocity, 0.0};
      const float stamp = static_cast<float>(cloud.stamp);
      EXPECT_EQ(plain->projectScan(cloud, stamp, motion), prefetching->projectScan(cloud, stamp, motion));
      expectSameProjection(plain->scan(), prefetching->scan());
      EXPECT_EQ(plain->scan().time, prefetching->scan().time);
      EXPECT_EQ(plain->scan().measured, prefetching->scan().measured);
    };
    prefetching->prefetch(clouds[0]);
    expectSameScan(clouds[1], "another cloud than the one prefetched");
    expectSameScan(clouds[0], "the cloud prefetched before another was projected");
    for (int ahead = 1; ahead < 4; ++ahead) prefetching->prefetch(clouds[ahead]);
    for (int ahead = 1; ahead < 4; ++ahead) expectSameScan(clouds[ahead], "prefetched " + std::to_string(ahead) + " ahead");
    prefetching->prefetch(clouds[2]);
    prefetching->prefetch(clouds[2]);
    expectSameScan(clouds[2], "prefetched twice");
    expectSameScan(clouds[2], "projected again, from its second prefetched upload");
    prefetching->finishPrefetch();
  }
}

// elo_run's order: each scan prefetched before the scan before it is processed, then moved to where it
// is processed from; and a prefetched scan the odometry skips (a repeated stamp).
TEST(BackendAgreement, PrefetchedScansGiveTheSamePosesBitForBit) {
  ELO_REQUIRE_CUDA();
  Config config;
  config.runtime.backend = BackendKind::cuda;
  Odometry plain(config);
  Odometry prefetching(config);
  constexpr int kFrames = 8;
  PointCloud next = streetSweep(config, 0);
  prefetching.prefetch(next);
  for (int frame = 0; frame < kFrames; ++frame) {
    const PointCloud current = std::move(next);
    if (frame + 1 < kFrames) {
      next = streetSweep(config, frame + 1);
      prefetching.prefetch(next);
    }
    const FrameResult a = plain.process(current);
    const FrameResult b = prefetching.process(current);
    ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
    EXPECT_EQ(a.deskew_rounds, b.deskew_rounds) << "frame " << frame;
    EXPECT_EQ(a.pose.matrix(), b.pose.matrix()) << "frame " << frame;
    const PointCloud repeated = current;
    prefetching.prefetch(repeated);
    EXPECT_EQ(prefetching.process(repeated).skip_reason, "duplicate stamp") << "frame " << frame;
    if (frame + 1 < kFrames) prefetching.prefetch(next);
  }
}

TEST(BackendFactory, CudaWithoutAUsableGpuFailsSayingWhy) {
  const std::string reason = cudaUnavailableReason();
  if (reason.empty()) GTEST_SKIP() << "a CUDA device is usable here";
  Config config;
  config.runtime.backend = BackendKind::cuda;
  try {
    makeBackend(config);
    FAIL() << "made a CUDA backend without a usable GPU";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(reason), std::string::npos) << message;
    EXPECT_NE(message.find("runtime.backend_fallback"), std::string::npos) << message;
  }
}

TEST(BackendFactory, CudaFallsBackToTheCpuWithAWarningWhenAllowed) {
  const std::string reason = cudaUnavailableReason();
  if (reason.empty()) GTEST_SKIP() << "a CUDA device is usable here";
  Config config;
  config.runtime.backend = BackendKind::cuda;
  config.runtime.backend_fallback = true;
  std::string warning;
  EXPECT_STREQ(makeBackend(config, &warning)->name(), "cpu");
  EXPECT_NE(warning.find(reason), std::string::npos) << warning;
  const Odometry odometry(config);
  EXPECT_EQ(odometry.backendWarning(), warning);
}

TEST(BackendFactory, CudaWithAUsableGpuGivesTheCudaBackend) {
  ELO_REQUIRE_CUDA();
  Config config;
  config.runtime.backend = BackendKind::cuda;
  config.runtime.backend_fallback = true;
  std::string warning;
  EXPECT_STREQ(makeBackend(config, &warning)->name(), "cuda");
  EXPECT_TRUE(warning.empty()) << warning;
}

}  // namespace
}  // namespace elo
