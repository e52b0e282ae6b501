#include "elo/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "elo/sim/rng.hpp"
#include "worlds/recipe.hpp"
#include "worlds/roadside.hpp"
#include "worlds/shapes.hpp"

namespace elo::sim {
namespace {

constexpr double kPathSpacing = 2.0;     // m between the road's polyline points
constexpr double kAnchorSpacing = 5.0;   // m between the route points the ground is sampled around
constexpr double kTrafficLane = 3.0;     // m from the route to the lanes moving cars use
// Independent random streams of one world.
constexpr uint64_t kTerrainStream = 1;
constexpr uint64_t kRoadsideStream = 2;
constexpr uint64_t kTrafficStream = 3;

const std::map<std::string, WorldFamily>& familyTable() {
  static const std::map<std::string, WorldFamily> table = {{"urban", WorldFamily::urban},
                                                           {"highway", WorldFamily::highway},
                                                           {"country", WorldFamily::country},
                                                           {"parking", WorldFamily::parking},
                                                           {"tunnel", WorldFamily::tunnel},
                                                           {"indoor", WorldFamily::indoor}};
  return table;
}

WorldRecipe recipeFor(WorldFamily family) {
  switch (family) {
    case WorldFamily::urban:
      return urbanRecipe();
    case WorldFamily::highway:
      return highwayRecipe();
    case WorldFamily::country:
      return countryRecipe();
    case WorldFamily::parking:
      return parkingRecipe();
    case WorldFamily::tunnel:
      return tunnelRecipe();
    case WorldFamily::indoor:
      return indoorRecipe();
  }
  throw std::invalid_argument("unknown world family");
}

struct Wave {
  Eigen::Vector2d direction;
  double wavenumber;
  double amplitude;
  double phase;
};

std::vector<Wave> drawWaves(const std::vector<WaveBand>& bands, uint64_t seed) {
  Rng rng(seed);
  std::vector<Wave> waves;
  for (const WaveBand& band : bands) {
    for (int i = 0; i < band.count; ++i) {
      const double angle = rng.uniform(0.0, 2.0 * M_PI);
      const double wavelength = rng.uniform(band.min_wavelength, band.max_wavelength);
      // A sine of amplitude A and wavelength L is steepest at 2 pi A / L.
      const double amplitude = band.slope * wavelength / (2.0 * M_PI);
      waves.push_back({Eigen::Vector2d(std::cos(angle), std::sin(angle)), 2.0 * M_PI / wavelength, amplitude,
                       rng.uniform(0.0, 2.0 * M_PI)});
    }
  }
  return waves;
}

// Road points added before the route's start and after its end to continue it for `length`.
int extensionPoints(double length) { return static_cast<int>(std::ceil(length / kPathSpacing)); }

// The route's path continued straight for `length` before its start and after its end, so that the
// street is furnished behind the first scan and ahead of the last as it is everywhere else.
std::vector<Eigen::Vector2d> roadAlong(const Route& route, double length) {
  const std::vector<Eigen::Vector2d> path = route.path(kPathSpacing);
  const auto direction = [](const Pose2& pose) { return Eigen::Vector2d(std::cos(pose.heading), std::sin(pose.heading)); };
  const Eigen::Vector2d backward = -direction(route.at(route.startTime()));
  const Eigen::Vector2d forward = direction(route.at(route.endTime()));
  const int extra = extensionPoints(length);
  std::vector<Eigen::Vector2d> road;
  for (int i = extra; i > 0; --i) road.push_back(path.front() + i * kPathSpacing * backward);
  road.insert(road.end(), path.begin(), path.end());
  for (int i = 1; i <= extra; ++i) road.push_back(path.back() + i * kPathSpacing * forward);
  return road;
}

std::shared_ptr<const HeightField> makeGround(const WorldRecipe& recipe, const Route& route, const Centerline& road,
                                              const WorldOptions& options) {
  const std::vector<Wave> waves = drawWaves(recipe.terrain, mixSeed(options.seed, kTerrainStream));
  const std::vector<Hill> hills = route.hills();
  const auto cross_section = recipe.cross_section;
  const bool shaped_by_road = recipe.cross_section_reach > 0.0;
  auto surface = [waves, hills, cross_section, shaped_by_road, &road](double x, double y) {
    const Eigen::Vector2d point(x, y);
    double height = cross_section(shaped_by_road ? road.distance(point) : 0.0);
    for (const Wave& wave : waves) height += wave.amplitude * std::sin(wave.wavenumber * wave.direction.dot(point) + wave.phase);
    for (const Hill& hill : hills) height += hill.heightAt(point);
    return height;
  };
  return std::make_shared<HeightField>(surface, route.path(kAnchorSpacing), options.reach);
}

std::vector<Primitive> furnish(const WorldRecipe& recipe, const Centerline& road, const GroundSurface& ground,
                               const WorldOptions& options) {
  const double route_start = extensionPoints(options.reach) * kPathSpacing;  // the road's straight lead-in
  Roadside roadside(road, ground, mixSeed(options.seed, kRoadsideStream), route_start);
  recipe.furnish(roadside);
  return roadside.takePrimitives();
}

// The static scene and the cars moving through it at one instant.
class WorldSnapshot : public RayCaster {
 public:
  WorldSnapshot(const Scene& scene, std::vector<Primitive> cars) : scene_(scene), cars_(std::move(cars)) {}

  std::optional<Hit> cast(const Ray& ray, double max_distance) const override {
    std::optional<Hit> best = scene_.cast(ray, max_distance);
    if (auto car = castEach(ray, cars_, best ? best->distance : max_distance, SurfaceKind::moving_object)) best = car;
    return best;
  }

 private:
  const Scene& scene_;
  std::vector<Primitive> cars_;
};

}  // namespace

std::optional<WorldFamily> worldFamilyFromName(const std::string& name) {
  const auto found = familyTable().find(name);
  if (found == familyTable().end()) return std::nullopt;
  return found->second;
}

std::string worldName(WorldFamily family) {
  for (const auto& [name, value] : familyTable()) {
    if (value == family) return name;
  }
  throw std::invalid_argument("unknown world family");
}

std::vector<std::string> worldNames() { return {"urban", "highway", "country", "parking", "tunnel", "indoor"}; }

double cruiseSpeed(WorldFamily family) { return recipeFor(family).cruise_speed; }

Traffic::Traffic(const Centerline& road, const GroundSurface& ground, int count, double speed, uint64_t seed)
    : road_(road), ground_(ground) {
  Rng rng(seed);
  for (int i = 0; i < count; ++i) {
    const bool oncoming = i % 2 == 0;
    Car car;
    car.start = rng.uniform(0.0, road.length());
    car.speed = (oncoming ? -1.0 : 1.0) * speed * rng.uniform(0.6, 1.1);
    car.lateral = oncoming ? kTrafficLane : -kTrafficLane;
    car.body_seed = mixSeed(seed, static_cast<uint64_t>(i));
    cars_.push_back(car);
  }
}

std::vector<Primitive> Traffic::carsNear(double time, const Eigen::Vector2d& position, double radius) const {
  std::vector<Primitive> shapes;
  for (const Car& car : cars_) {
    // A car that has driven off either end of the road is gone.
    const double arc_length = car.start + car.speed * time;
    if (arc_length < 0.0 || arc_length > road_.length()) continue;
    const Centerline::Frame frame = road_.frameAt(arc_length);
    const Eigen::Vector2d center = frame.point + car.lateral * frame.left;
    if ((center - position).norm() > radius) continue;
    Rng rng(car.body_seed);
    const double heading = frame.heading + (car.speed < 0.0 ? M_PI : 0.0);
    addCar(shapes, center, heading, ground_.height(center.x(), center.y()), CarBody::random(rng));
  }
  return shapes;
}

World::World(WorldFamily family, const Route& route, const WorldOptions& options)
    : World(family, recipeFor(family), route, options) {}

World::World(WorldFamily family, const WorldRecipe& recipe, const Route& route, const WorldOptions& options)
    : family_(family),
      road_(roadAlong(route, options.reach), std::max(recipe.cross_section_reach, recipe.clearance_reach)),
      ground_(makeGround(recipe, route, road_, options)),
      scene_(ground_, furnish(recipe, road_, *ground_, options), recipe.ground_reflectivity),
      traffic_(road_, *ground_, options.moving_cars, recipe.cruise_speed, mixSeed(options.seed, kTrafficStream)) {}

std::unique_ptr<RayCaster> World::snapshot(double time, const Eigen::Vector3d& position, double radius) const {
  return std::make_unique<WorldSnapshot>(scene_, traffic_.carsNear(time, position.head<2>(), radius));
}

}  // namespace elo::sim
