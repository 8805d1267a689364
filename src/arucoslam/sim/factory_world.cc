#include "arucoslam/sim/factory_world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/dictionary.h"
#include "arucoslam/markers/marker_image.h"
#include "arucoslam/markers/sdf_export.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

constexpr double kPi = std::numbers::pi;
// Layout (metres). World x runs along the aisles, y across them, z up; the hall's inner
// corner is the origin.
constexpr double kCrossAisle = 3.5;  // free floor at both ends of the racks
constexpr double kCorridor = 3.0;    // the long low-texture corridor along the y = 0 wall
constexpr double kPartition = 0.2;   // wall between the corridor and the first aisle
constexpr double kPartitionHeight = 2.6;
constexpr double kAisle = 2.8;
constexpr double kRackDepth = 1.0;  // one rack; rows between aisles are back to back
constexpr double kRackGap = 0.1;
constexpr double kRackHeight = 4.0;
constexpr double kHallHeight = 6.0;
constexpr double kWallThickness = 0.3;
constexpr double kBoardThickness = 0.02;  // dock board on the wall
constexpr double kPillarGuardWidth = 0.44;  // the striped guard at a pillar's foot
// The corridor-end boards' distance from the end walls (the first and last wall board).
constexpr double kCorridorEndBoardInset = 1.8;
constexpr double kUTurnRadius = 0.9;      // the default route's tight turn
constexpr double kEndApproach = 1.75;     // route waypoints this far from the end walls

using Visual = FactoryVisual;

// RGB colours 0..1.
const cv::Scalar kWhite{1, 1, 1};
const cv::Scalar kRackBlue{0.12, 0.25, 0.55};
const cv::Scalar kBeamOrange{0.95, 0.45, 0.08};
const cv::Scalar kLaneYellow{0.95, 0.78, 0.1};
const cv::Scalar kDarkGrey{0.22, 0.23, 0.25};

Rigid3 Pose(double x, double y, double z, double yaw = 0.0) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())),
                Eigen::Vector3d(x, y, z));
}

Visual Box(std::string name, const Rigid3& pose, const Eigen::Vector3d& size,
           const cv::Scalar& colour, std::string texture = "") {
  Visual visual;
  visual.name = std::move(name);
  visual.model_from_visual = pose;
  visual.size = size;
  visual.colour = colour;
  visual.texture = texture.empty() ? "" : "textures/" + texture + ".png";
  return visual;
}

Visual Cylinder(std::string name, const Rigid3& pose, double radius, double length,
                const cv::Scalar& colour, std::string texture = "") {
  Visual visual = Box(std::move(name), pose, {2 * radius, 2 * radius, length}, colour, texture);
  visual.shape = Visual::Shape::kCylinder;
  return visual;
}

// Builds the world piece by piece; every random choice comes from one seeded stream per
// part so that changing one part does not reshuffle the others.
class FactoryBuilder {
 public:
  explicit FactoryBuilder(const FactoryOptions& options)
      : options_(options), detail_(TextureDetail(options.texture)) {
    world_.options = options;
    world_.hall_length_m = options.aisle_length_m + 2 * kCrossAisle;
    world_.hall_width_m = kCorridor + kPartition + options.aisles * kAisle +
                          (options.aisles - 1) * (2 * kRackDepth + kRackGap) + kRackDepth + 0.2;
    world_.markers.dictionary = options.dictionary;
  }

  FactoryWorld Build() {
    AddTextures();
    AddShell();
    AddFloor();
    AddPartition();
    AddRackRows();
    AddDocks();
    AddEndMachines();
    AddPosters();
    AddDefaultRoute();
    return std::move(world_);
  }

 private:
  double Length() const { return world_.hall_length_m; }
  double Width() const { return world_.hall_width_m; }
  double AisleStart(int aisle) const {
    return kCorridor + kPartition + aisle * (kAisle + 2 * kRackDepth + kRackGap);
  }
  double AisleCentre(int aisle) const { return AisleStart(aisle) + kAisle / 2; }
  // x of the pillars along both long walls, about 8 m apart.
  std::vector<double> PillarXs() const {
    const int count = std::max(2, static_cast<int>(std::round(Length() / 8.0)));
    std::vector<double> xs;
    for (int i = 1; i < count; ++i) xs.push_back(Length() * i / count);
    return xs;
  }
  std::uint64_t Stream(std::uint64_t part) const {
    return (static_cast<std::uint64_t>(options_.seed) << 24) ^ (part * 0x9E3779B97F4A7C15ull);
  }
  void AddTexture(const std::string& name, const cv::Mat& image) {
    world_.textures["textures/" + name + ".png"] = image;
  }
  FactoryModel& NewModel(const std::string& name, const Rigid3& pose) {
    world_.models.push_back(FactoryModel{name, pose, {}});
    return world_.models.back();
  }

  void AddTextures();
  void AddShell();
  void AddFloor();
  void AddPartition();
  void AddRackRows();
  void AddRackBay(const std::string& name, double x, double y_low, bool two_sided,
                  double bay_length, SeededRandom& random);
  void AddShelfContents(FactoryModel& model, const std::string& prefix, double bay_length,
                        double y_centre, double z, double headroom, SeededRandom& random);
  void AddMachine(const std::string& name, const Rigid3& pose, double length, double depth,
                  SeededRandom& random);
  void AddDocks();
  // Where the corridor's wall boards go (corridor_end_markers, wall_marker_spacing_m):
  // x along the y = 0 wall, ascending.
  std::vector<double> CorridorWallBoards() const;
  void AddDock(const std::string& name, double x_wall, double y, bool faces_plus_x, int first_id);
  // A board at camera height against a wall (`world_from_board`: +x out of the wall) carrying
  // markers_per_dock markers from `first_id`; their ids, or none without markers.
  std::vector<int> AddMarkerBoard(FactoryModel& model, const Rigid3& world_from_board,
                                  int first_id);
  // A marker's box side (black square and quiet zone, metres) and a board's width.
  double MarkerSide() const {
    MarkerImageOptions image;
    image.marker_size_px = options_.marker_image_px;
    return MarkerBoxSide(options_.marker_size_m, options_.dictionary, image);
  }
  double MarkerBoardWidth() const {
    return std::max(0.7, options_.markers_per_dock * (MarkerSide() + 0.08) + 0.15);
  }
  void AddEndMachines();
  void AddPosters();
  void AddDefaultRoute();

  FactoryOptions options_;
  double detail_;
  FactoryWorld world_;
};

void FactoryBuilder::AddTextures() {
  SeededRandom random(Stream(1));
  // Corridor and hall walls: off-white over a grey-green band, four stain patterns.
  for (int i = 0; i < 4; ++i) {
    AddTexture("wall_" + std::to_string(i),
               PaintedWallTexture(512, 768, cv::Scalar(214, 220, 222), cv::Scalar(150, 160, 140),
                                  0.2, detail_, random.Next()));
    AddTexture("partition_" + std::to_string(i),
               PaintedWallTexture(768, 512, cv::Scalar(200, 208, 212), cv::Scalar(120, 130, 136),
                                  0.38, detail_, random.Next()));
  }
  for (int i = 0; i < 4; ++i) {
    AddTexture("floor_" + std::to_string(i), ConcreteFloorTexture(1024, detail_, random.Next()));
  }
  AddTexture("ceiling", CeilingTexture(512, random.Next()));
  for (int i = 0; i < 4; ++i) {
    AddTexture("cardboard_" + std::to_string(i), CardboardTexture(256, detail_, random.Next()));
  }
  AddTexture("wood", WoodTexture(512, 128, random.Next()));
  AddTexture("hazard", HazardStripeTexture(512, 64));
  const cv::Scalar paints[] = {{90, 130, 60}, {140, 110, 70}, {60, 120, 200}};
  for (int i = 0; i < 3; ++i) {
    AddTexture("machine_" + std::to_string(i),
               MachinePanelTexture(768, 512, paints[i], random.Next()));
  }
  for (int i = 0; i < 8; ++i) {
    AddTexture("poster_" + std::to_string(i), PosterTexture(360, 512, random.Next()));
  }
}

// Walls as 4 m panels with varied stains, pillars, ceiling tiles and light strips.
void FactoryBuilder::AddShell() {
  SeededRandom random(Stream(2));
  const double length = Length(), width = Width(), h = kHallHeight, t = kWallThickness;
  struct WallLine {
    const char* name;
    double x0, y0, x1, y1, off_x, off_y;
  };
  const WallLine walls[] = {{"wall_south", 0, 0, length, 0, 0, -t / 2},
                            {"wall_north", 0, width, length, width, 0, t / 2},
                            {"wall_west", 0, 0, 0, width, -t / 2, 0},
                            {"wall_east", length, 0, length, width, t / 2, 0}};
  for (const WallLine& wall : walls) {
    FactoryModel& model = NewModel(wall.name, Rigid3());
    const double span = std::hypot(wall.x1 - wall.x0, wall.y1 - wall.y0);
    const int panels = std::max(1, static_cast<int>(std::round(span / 4.0)));
    const double yaw = std::atan2(wall.y1 - wall.y0, wall.x1 - wall.x0);
    for (int i = 0; i < panels; ++i) {
      const double u = (i + 0.5) / panels;
      model.visuals.push_back(Box("panel_" + std::to_string(i),
                                  Pose(wall.x0 + u * (wall.x1 - wall.x0) + wall.off_x,
                                       wall.y0 + u * (wall.y1 - wall.y0) + wall.off_y, h / 2, yaw),
                                  {span / panels, t, h}, kWhite,
                                  "wall_" + std::to_string(random.Int(0, 3))));
    }
  }
  // Pillars every ~8 m along the long walls, with a striped guard at the bottom.
  FactoryModel& pillars = NewModel("pillars", Rigid3());
  const std::vector<double> pillar_xs = PillarXs();
  for (std::size_t i = 1; i <= pillar_xs.size(); ++i) {
    const double x = pillar_xs[i - 1];
    for (const double y : {0.15, width - 0.15}) {
      const std::string name = "pillar_" + std::to_string(i) + (y < 1 ? "_s" : "_n");
      pillars.visuals.push_back(Box(name, Pose(x, y, h / 2), {0.4, 0.3, h}, {0.62, 0.63, 0.64}));
      pillars.visuals.push_back(
          Box(name + "_guard", Pose(x, y, 0.5), {kPillarGuardWidth, 0.34, 1.0}, kWhite, "hazard"));
    }
  }
  FactoryModel& ceiling = NewModel("ceiling", Rigid3());
  const int nx = static_cast<int>(std::ceil(length / 6.0)),
            ny = static_cast<int>(std::ceil(width / 6.0));
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      ceiling.visuals.push_back(Box("tile_" + std::to_string(i) + "_" + std::to_string(j),
                                    Pose((i + 0.5) * length / nx, (j + 0.5) * width / ny, h + 0.05),
                                    {length / nx, width / ny, 0.1}, kWhite, "ceiling"));
    }
  }
  for (double x = 3.0; x < length - 1.0; x += 6.0) {
    for (double y = 2.0; y < width - 1.0; y += 5.0) {
      ceiling.visuals.push_back(Box("lamp_" + std::to_string(ceiling.visuals.size()),
                                    Pose(x, y, h - 0.3), {1.5, 0.25, 0.08}, {1.0, 1.0, 0.97}));
    }
  }
}

// Concrete tiles (with a joint pattern), yellow lane lines along every lane and dock zones.
void FactoryBuilder::AddFloor() {
  SeededRandom random(Stream(3));
  const double length = Length(), width = Width();
  FactoryModel& floor = NewModel("floor", Rigid3());
  const int nx = static_cast<int>(std::ceil(length / 6.0)),
            ny = static_cast<int>(std::ceil(width / 6.0));
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      floor.visuals.push_back(Box("tile_" + std::to_string(i) + "_" + std::to_string(j),
                                  Pose((i + 0.5) * length / nx, (j + 0.5) * width / ny, -0.05,
                                       random.Chance(0.5) ? kPi : 0.0),
                                  {length / nx, width / ny, 0.1}, kWhite,
                                  "floor_" + std::to_string(random.Int(0, 3))));
    }
  }
  FactoryModel& lanes = NewModel("lane_markings", Rigid3());
  const double x0 = kCrossAisle, x1 = length - kCrossAisle;
  auto line = [&lanes](double xa, double ya, double xb, double yb) {
    const double len = std::hypot(xb - xa, yb - ya);
    lanes.visuals.push_back(
        Box("line_" + std::to_string(lanes.visuals.size()),
            Pose((xa + xb) / 2, (ya + yb) / 2, 0.002, std::atan2(yb - ya, xb - xa)),
            {len, 0.08, 0.004}, kLaneYellow));
  };
  line(x0, 0.35, x1, 0.35);
  line(x0, kCorridor - 0.15, x1, kCorridor - 0.15);
  for (int a = 0; a < options_.aisles; ++a) {
    line(x0, AisleStart(a) + 0.15, x1, AisleStart(a) + 0.15);
    line(x0, AisleStart(a) + kAisle - 0.15, x1, AisleStart(a) + kAisle - 0.15);
  }
  line(x0 - 0.25, 0.35, x0 - 0.25, width - 0.35);
  line(x1 + 0.25, 0.35, x1 + 0.25, width - 0.35);
}

// The partition between corridor and first aisle: painted block wall panels, low texture.
void FactoryBuilder::AddPartition() {
  SeededRandom random(Stream(4));
  FactoryModel& model = NewModel("partition", Rigid3());
  const double length = options_.aisle_length_m;
  const int panels = std::max(1, static_cast<int>(std::round(length / 4.0)));
  for (int i = 0; i < panels; ++i) {
    model.visuals.push_back(Box("panel_" + std::to_string(i),
                                Pose(kCrossAisle + (i + 0.5) * length / panels,
                                     kCorridor + kPartition / 2, kPartitionHeight / 2),
                                {length / panels, kPartition, kPartitionHeight}, kWhite,
                                "partition_" + std::to_string(random.Int(0, 3))));
  }
  model.visuals.push_back(Box(
      "cap", Pose(kCrossAisle + length / 2, kCorridor + kPartition / 2, kPartitionHeight + 0.03),
      {length, kPartition + 0.02, 0.06}, {0.45, 0.47, 0.5}));
}

void FactoryBuilder::AddRackRows() {
  SeededRandom random(Stream(5));
  const double length = options_.aisle_length_m;
  const int bays = std::max(1, static_cast<int>(std::round(length / 2.7)));
  const double bay_length = length / bays;
  for (int row = 0; row < options_.aisles; ++row) {
    const bool two_sided = row + 1 < options_.aisles;
    const double y_low = AisleStart(row) + kAisle;
    const double depth = two_sided ? 2 * kRackDepth + kRackGap : kRackDepth;
    // One or two bays of the row hold a machine instead of shelves.
    int machine_bay = bays >= 3 ? random.Int(1, bays - 2) : -1;
    int second_machine =
        options_.texture == TextureLevel::kHigh && bays >= 5 ? random.Int(1, bays - 2) : -1;
    for (int bay = 0; bay < bays; ++bay) {
      const double x = kCrossAisle + (bay + 0.5) * bay_length;
      const std::string name = "rack_" + std::to_string(row) + "_" + std::to_string(bay);
      if (bay == machine_bay || bay == second_machine) {
        AddMachine("machine_" + std::to_string(row) + "_" + std::to_string(bay),
                   Pose(x, y_low + depth / 2, 0), bay_length - 0.3, depth - 0.2, random);
      } else {
        AddRackBay(name, x, y_low, two_sided, bay_length, random);
      }
    }
  }
}

// One bay of pallet racking: blue uprights, orange beams, decks at three heights and
// whatever is stored on the floor level and the shelves.
void FactoryBuilder::AddRackBay(const std::string& name, double x, double y_low, bool two_sided,
                                double bay_length, SeededRandom& random) {
  const double depth = two_sided ? 2 * kRackDepth + kRackGap : kRackDepth;
  FactoryModel& model = NewModel(name, Pose(x, y_low + depth / 2, 0));
  std::vector<double> sides =
      two_sided ? std::vector<double>{-(kRackDepth + kRackGap) / 2, (kRackDepth + kRackGap) / 2}
                : std::vector<double>{0.0};
  const double levels[] = {0.0, 1.3, 2.5, 3.7};
  const double edge = kRackDepth / 2 - 0.04;
  for (std::size_t s = 0; s < sides.size(); ++s) {
    const double yc = sides[s];
    const std::string side = "s" + std::to_string(s) + "_";
    for (const double dx : {-bay_length / 2, bay_length / 2}) {
      for (const double dy : {-edge, edge}) {
        model.visuals.push_back(Box(side + "post_" + std::to_string(model.visuals.size()),
                                    Pose(dx, yc + dy, kRackHeight / 2), {0.08, 0.08, kRackHeight},
                                    kRackBlue));
      }
    }
    for (int level = 0; level < 4; ++level) {
      const double z = levels[level];
      const std::string prefix = side + "l" + std::to_string(level) + "_";
      if (level > 0) {
        for (const double dy : {-edge, edge}) {
          model.visuals.push_back(Box(prefix + "beam_" + std::to_string(dy > 0),
                                      Pose(0, yc + dy, z), {bay_length - 0.08, 0.05, 0.12},
                                      kBeamOrange));
        }
        model.visuals.push_back(Box(prefix + "deck", Pose(0, yc, z + 0.075),
                                    {bay_length - 0.1, kRackDepth - 0.1, 0.03},
                                    {0.55, 0.56, 0.58}));
      }
      const double floor_z = level > 0 ? z + 0.09 : 0.0;
      const double headroom = level < 3 ? 1.3 - 0.2 : kRackHeight - z - 0.3;
      AddShelfContents(model, prefix, bay_length, yc, floor_z, headroom, random);
    }
  }
}

void FactoryBuilder::AddShelfContents(FactoryModel& model, const std::string& prefix,
                                      double bay_length, double y_centre, double z, double headroom,
                                      SeededRandom& random) {
  const double fill = options_.texture == TextureLevel::kLow      ? 0.35
                      : options_.texture == TextureLevel::kMedium ? 0.7
                                                                  : 0.95;
  const int slots = bay_length > 2.4 ? 3 : 2;
  const double slot = (bay_length - 0.2) / slots;
  for (int i = 0; i < slots; ++i) {
    if (!random.Chance(fill) || headroom < 0.3) continue;
    const std::string item = prefix + "slot" + std::to_string(i) + "_";
    const double xs = -bay_length / 2 + 0.1 + (i + 0.5) * slot;
    const double kind = random.Uniform();
    if (kind < 0.15 && headroom > 1.0) {  // barrels
      const cv::Scalar colour =
          random.Chance(0.5) ? cv::Scalar(0.1, 0.3, 0.7) : cv::Scalar(0.7, 0.15, 0.1);
      for (const double dx : {-slot / 4, slot / 4}) {
        model.visuals.push_back(Cylinder(item + "barrel_" + std::to_string(dx > 0),
                                         Pose(xs + dx, y_centre, z + 0.45), 0.2, 0.9, colour));
      }
      continue;
    }
    double base = z;
    if (kind < 0.8) {  // a pallet under the boxes
      model.visuals.push_back(Box(item + "pallet", Pose(xs, y_centre, z + 0.07),
                                  {slot * 0.9, 0.8, 0.14}, kWhite, "wood"));
      base += 0.14;
    }
    const int boxes = random.Int(1, 3);
    for (int b = 0; b < boxes && base + 0.2 < z + headroom; ++b) {
      const double height = std::min(random.Uniform(0.2, 0.55), z + headroom - base);
      const double w = random.Uniform(0.35, slot * 0.85), d = random.Uniform(0.4, 0.8);
      model.visuals.push_back(
          Box(item + "box_" + std::to_string(b),
              Pose(xs + random.Uniform(-0.05, 0.05), y_centre + random.Uniform(-0.05, 0.05),
                   base + height / 2, random.Uniform(-0.08, 0.08)),
              {w, d, height}, kWhite, "cardboard_" + std::to_string(random.Int(0, 3))));
      base += height;
    }
  }
}

void FactoryBuilder::AddMachine(const std::string& name, const Rigid3& pose, double length,
                                double depth, SeededRandom& random) {
  FactoryModel& model = NewModel(name, pose);
  const std::string paint = "machine_" + std::to_string(random.Int(0, 2));
  const double height = random.Uniform(1.5, 2.1);
  model.visuals.push_back(
      Box("body", Pose(0, 0, height / 2), {length, depth, height}, kWhite, paint));
  model.visuals.push_back(Box("hood", Pose(-length * 0.15, 0, height + 0.3),
                              {length * 0.55, depth * 0.6, 0.6}, {0.6, 0.62, 0.6}));
  model.visuals.push_back(
      Cylinder("tank", Pose(length * 0.3, 0, height + 0.5), 0.3, 1.0, {0.75, 0.76, 0.78}));
  model.visuals.push_back(
      Box("cabinet", Pose(length / 2 + 0.2, 0, 0.9), {0.4, 0.6, 1.8}, {0.85, 0.85, 0.82}));
  model.visuals.push_back(
      Cylinder("beacon", Pose(length / 2 + 0.2, 0, 1.9), 0.05, 0.2, {0.95, 0.55, 0.05}));
}

void FactoryBuilder::AddDocks() {
  const int per_dock = options_.markers_per_dock;
  std::vector<double> lanes = {kCorridor / 2};
  for (int a = 0; a < options_.aisles; ++a) lanes.push_back(AisleCentre(a));
  const std::vector<double> wall_boards = CorridorWallBoards();
  const int needed =
      (static_cast<int>(lanes.size()) * 2 + static_cast<int>(wall_boards.size())) * per_dock;
  const int available = DictionaryFromName(options_.dictionary, "--dictionary")->bytesList.rows;
  if (options_.markers && needed > available) {
    throw InputError(options_.wall_marker_spacing_m > 0.0 ? "--wall-markers" : "--markers-per-dock",
                     std::to_string(needed) + " markers are needed but " + options_.dictionary +
                         " has only " + std::to_string(available) + " ids");
  }
  int next_id = 0;
  for (std::size_t lane = 0; lane < lanes.size(); ++lane) {
    const std::string lane_name = lane == 0 ? "corridor" : "aisle" + std::to_string(lane - 1);
    AddDock("dock_" + lane_name + "_west", 0.0, lanes[lane], true, next_id);
    next_id += per_dock;
    AddDock("dock_" + lane_name + "_east", Length(), lanes[lane], false, next_id);
    next_id += per_dock;
  }
  if (!options_.markers) return;
  int board = 0;
  for (const double x : wall_boards) {
    const Rigid3 world_from_board = Pose(x, 0.0, 0.0, kPi / 2);  // facing +y
    const bool end = std::abs(x - kCorridorEndBoardInset) < 1e-9 ||
                     std::abs(x - (Length() - kCorridorEndBoardInset)) < 1e-9;
    const std::string name = end && options_.corridor_end_markers
                                 ? (x < Length() / 2 ? "sign_corridor_west" : "sign_corridor_east")
                                 : "sign_corridor_" + std::to_string(board);
    AddMarkerBoard(NewModel(name, world_from_board), world_from_board, next_id);
    next_id += per_dock;
    ++board;
  }
}

std::vector<double> FactoryBuilder::CorridorWallBoards() const {
  const double first = kCorridorEndBoardInset, last = Length() - kCorridorEndBoardInset;
  std::vector<double> xs;
  if (options_.corridor_end_markers) xs = {first, last};
  const double spacing = options_.wall_marker_spacing_m;
  if (spacing > 0.0) {
    // A board's half width plus the pillar guard's, and 5 cm, keeps clear of a pillar.
    const std::vector<double> pillar_xs = PillarXs();
    const double clearance = MarkerBoardWidth() / 2 + kPillarGuardWidth / 2 + 0.05;
    for (double x = first; x <= last + 1e-9; x += spacing) {
      bool clear = true;
      for (const double pillar_x : pillar_xs) {
        if (std::abs(x - pillar_x) < clearance) clear = false;
      }
      for (const double taken : xs) {
        if (std::abs(x - taken) < 1e-6) clear = false;
      }
      if (clear) xs.push_back(x);
    }
  }
  std::sort(xs.begin(), xs.end());
  return xs;
}

std::vector<int> FactoryBuilder::AddMarkerBoard(FactoryModel& model, const Rigid3& world_from_board,
                                                int first_id) {
  const int k = options_.markers_per_dock;
  const double side = MarkerSide();
  const double spacing = side + 0.08;
  const double h = options_.camera_height_m;
  const double board_height = std::max(0.9, side + 0.3);
  model.visuals.push_back(Box("board", Pose(kBoardThickness / 2, 0, h),
                              {kBoardThickness, MarkerBoardWidth(), board_height},
                              {0.92, 0.92, 0.9}));
  std::vector<int> ids;
  if (!options_.markers) return ids;
  Eigen::Matrix3d board_from_marker_rotation;  // columns: marker x, y, z in the board frame
  board_from_marker_rotation << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  for (int j = 0; j < k; ++j) {
    MarkerInfo marker;
    marker.id = first_id + j;
    marker.size = options_.marker_size_m;
    // Marker j counted from the left as the robot sees it (board +y is the robot's left).
    const double offset = ((k - 1) / 2.0 - j) * spacing;
    marker.world_from_marker =
        world_from_board *
        Rigid3(board_from_marker_rotation, Eigen::Vector3d(kBoardThickness + 0.002, offset, h));
    world_.markers.markers[marker.id] = marker;
    ids.push_back(marker.id);
  }
  return ids;
}

// A charging station against an end wall: a base, a board at camera height carrying the
// markers (their +z out of the board, toward the approaching robot), a fire extinguisher.
void FactoryBuilder::AddDock(const std::string& name, double x_wall, double y, bool faces_plus_x,
                             int first_id) {
  const Rigid3 world_from_dock = Pose(x_wall, y, 0, faces_plus_x ? 0.0 : kPi);
  FactoryModel& model = NewModel(name, world_from_dock);
  const std::vector<int> ids = AddMarkerBoard(model, world_from_dock, first_id);
  const double board_width = MarkerBoardWidth();
  model.visuals.push_back(Box("base", Pose(0.25, 0, 0.125), {0.46, 0.7, 0.25}, kDarkGrey));
  model.visuals.push_back(Box("stripe", Pose(0.485, 0, 0.06), {0.01, 0.7, 0.08}, kWhite, "hazard"));
  for (const double dy : {-0.15, 0.15}) {
    model.visuals.push_back(Box("contact_" + std::to_string(dy > 0), Pose(0.49, dy, 0.17),
                                {0.02, 0.06, 0.04}, {0.8, 0.5, 0.2}));
  }
  model.visuals.push_back(Cylinder("extinguisher", Pose(0.12, board_width / 2 + 0.3, 0.3), 0.08,
                                   0.55, {0.8, 0.08, 0.05}));
  FactoryDock dock;
  dock.name = name;
  dock.front = (world_from_dock * Eigen::Vector3d(1.0 + kBoardThickness, 0, 0)).head<2>();
  dock.facing = (world_from_dock.rotation * Eigen::Vector3d::UnitX()).head<2>();
  dock.marker_ids = ids;
  world_.docks.push_back(dock);
}

// Big machines against the east wall and pallet stacks against the west wall, at the ends
// of the rack rows (between the docks); a parked forklift and bollards as landmarks.
void FactoryBuilder::AddEndMachines() {
  SeededRandom random(Stream(6));
  for (int row = 0; row < options_.aisles; ++row) {
    const bool two_sided = row + 1 < options_.aisles;
    const double depth = two_sided ? 2 * kRackDepth + kRackGap : kRackDepth;
    const double yc = AisleStart(row) + kAisle + depth / 2;
    AddMachine("press_" + std::to_string(row), Pose(Length() - 0.5, yc, 0, kPi / 2),
               std::max(0.6, depth - 0.5), 0.8, random);
    FactoryModel& stack = NewModel("stack_" + std::to_string(row), Pose(0.6, yc, 0));
    double z = 0.0;
    for (int level = random.Int(2, 5); level > 0; --level) {
      stack.visuals.push_back(Box("pallet_" + std::to_string(level), Pose(0, 0, z + 0.07),
                                  {0.8, 1.2, 0.14}, kWhite, "wood"));
      z += 0.14;
      if (random.Chance(0.6)) {
        stack.visuals.push_back(Box("load_" + std::to_string(level), Pose(0, 0, z + 0.3),
                                    {0.75, 1.1, 0.6}, kWhite,
                                    "cardboard_" + std::to_string(random.Int(0, 3))));
        z += 0.6;
      }
    }
  }
  FactoryModel& forklift =
      NewModel("forklift", Pose(1.6, Width() - 1.6, 0, random.Uniform(-0.4, 0.4)));
  forklift.visuals.push_back(Box("body", Pose(0, 0, 0.6), {1.6, 1.0, 0.9}, {0.95, 0.6, 0.05}));
  forklift.visuals.push_back(
      Box("cabin", Pose(-0.2, 0, 1.55), {0.9, 0.9, 1.0}, {0.15, 0.15, 0.15}));
  forklift.visuals.push_back(Box("mast", Pose(0.85, 0, 1.2), {0.1, 0.8, 2.2}, {0.2, 0.2, 0.2}));
  for (const double dy : {-0.25, 0.25}) {
    forklift.visuals.push_back(Box("fork_" + std::to_string(dy > 0), Pose(1.4, dy, 0.05),
                                   {1.0, 0.12, 0.05}, {0.25, 0.25, 0.25}));
  }
  FactoryModel& bollards = NewModel("bollards", Rigid3());
  for (const double y : {0.6, kCorridor - 0.6}) {
    bollards.visuals.push_back(Cylinder("bollard_" + std::to_string(y > 1),
                                        Pose(kCrossAisle - 0.3, y, 0.5), 0.08, 1.0,
                                        {0.95, 0.8, 0.1}));
  }
}

// Posters and signs on the walls, away from the docks and the pillars.
void FactoryBuilder::AddPosters() {
  SeededRandom random(Stream(7));
  const int count = options_.texture == TextureLevel::kLow      ? 3
                    : options_.texture == TextureLevel::kMedium ? 6
                                                                : 10;
  FactoryModel& model = NewModel("posters", Rigid3());
  const std::vector<double> pillar_xs = PillarXs();
  int placed = 0;
  for (int attempt = 0; attempt < 200 && placed < count; ++attempt) {
    const int wall = random.Int(0, 3);  // south, north, west, east
    const bool long_wall = wall < 2;
    const double along = random.Uniform(1.0, (long_wall ? Length() : Width()) - 1.0);
    if (long_wall && std::any_of(pillar_xs.begin(), pillar_xs.end(),
                                 [along](double x) { return std::abs(along - x) < 0.7; })) {
      continue;  // a pillar
    }
    bool near_dock = false;
    for (const FactoryDock& dock : world_.docks) {
      if (!long_wall && std::abs(dock.front.y() - along) < 1.0) near_dock = true;
    }
    if (near_dock) continue;
    const Eigen::Vector2d normal = wall == 0   ? Eigen::Vector2d(0, 1)
                                   : wall == 1 ? Eigen::Vector2d(0, -1)
                                   : wall == 2 ? Eigen::Vector2d(1, 0)
                                               : Eigen::Vector2d(-1, 0);
    const Eigen::Vector2d at = wall == 0   ? Eigen::Vector2d(along, 0)
                               : wall == 1 ? Eigen::Vector2d(along, Width())
                               : wall == 2 ? Eigen::Vector2d(0, along)
                                           : Eigen::Vector2d(Length(), along);
    const Eigen::Vector2d centre = at + 0.008 * normal;
    model.visuals.push_back(Box("poster_" + std::to_string(placed),
                                Pose(centre.x(), centre.y(), random.Uniform(1.4, 2.0),
                                     std::atan2(normal.y(), normal.x()) - kPi / 2),
                                {0.6, 0.012, 0.85}, kWhite,
                                "poster_" + std::to_string(placed % 8)));
    ++placed;
  }
}

// Start in the first aisle (textured racks on one side) facing along it; drive to its east
// dock, cross into the low-texture corridor, drive it back to its west dock, make the tight
// U-turn into the aisle and stop at the start: one loop, both docks approached head-on.
void FactoryBuilder::AddDefaultRoute() {
  const double y_corridor = kCorridor / 2, y_aisle = AisleCentre(0);
  const double x_west = kEndApproach, x_east = Length() - kEndApproach;
  const double x_start = x_west + kUTurnRadius + 1.0;
  PathSpec& route = world_.default_route;
  route.waypoints = {{x_start, y_aisle},
                     {x_east, y_aisle},
                     {x_east, y_corridor},
                     {x_west, y_corridor, kUTurnRadius},
                     {x_west, y_aisle, kUTurnRadius},
                     {x_start, y_aisle}};
  route.options.camera_height_m = options_.camera_height_m;
  route.options.seed = options_.seed;
  for (FactoryDock& dock : world_.docks) {
    dock.on_default_route = dock.name == "dock_aisle0_east" || dock.name == "dock_corridor_west";
  }
}

std::string Number(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string Rgba(const cv::Scalar& colour) {
  return Number(colour[0]) + " " + Number(colour[1]) + " " + Number(colour[2]) + " 1";
}

void AppendVisual(std::ostringstream& out, const FactoryVisual& visual) {
  std::ostringstream geometry;
  if (visual.shape == FactoryVisual::Shape::kBox) {
    geometry << "<box><size>" << Number(visual.size.x()) << " " << Number(visual.size.y()) << " "
             << Number(visual.size.z()) << "</size></box>";
  } else {
    geometry << "<cylinder><radius>" << Number(visual.size.x() / 2) << "</radius><length>"
             << Number(visual.size.z()) << "</length></cylinder>";
  }
  const std::string pose = SdfPoseText(visual.model_from_visual);
  out << "        <visual name=\"" << visual.name << "\">\n          <pose>" << pose
      << "</pose>\n          <geometry>" << geometry.str()
      << "</geometry>\n          <material><ambient>" << Rgba(visual.colour)
      << "</ambient><diffuse>" << Rgba(visual.colour) << "</diffuse>";
  if (!visual.texture.empty()) {
    out << "<pbr><metal><albedo_map>" << visual.texture << "</albedo_map></metal></pbr>";
  }
  out << "</material>\n        </visual>\n        <collision name=\"" << visual.name
      << "_collision\"><pose>" << pose << "</pose><geometry>" << geometry.str()
      << "</geometry></collision>\n";
}

MarkerModelSdfOptions MarkerSdfOptions(const FactoryOptions& options, int id) {
  MarkerModelSdfOptions sdf;
  sdf.dictionary = options.dictionary;
  sdf.image.marker_size_px = options.marker_image_px;
  sdf.albedo_map = "markers/" + std::to_string(id) + ".png";
  return sdf;
}

}  // namespace

bool FactoryOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.InRange("aisles", aisles, 1, 8, Interval::kClosed);
  check.InRange("aisle_length_m", aisle_length_m, 6.0, 60.0, Interval::kClosed);
  check.InRange("marker_size_m", marker_size_m, 0.05, 1.0, Interval::kOpenClosed);
  check.InRange("markers_per_dock", markers_per_dock, 1, 4, Interval::kClosed);
  check.InRange("marker_image_px", marker_image_px, 16, 2048, Interval::kClosed);
  check.InRange("camera_height_m", camera_height_m, 0.3, 1.0, Interval::kClosed);
  check.Rule(wall_marker_spacing_m == 0.0 ||
                 (wall_marker_spacing_m >= 1.0 && wall_marker_spacing_m <= 20.0),
             "wall_marker_spacing_m", wall_marker_spacing_m, "0 or in [1, 20]");
  return check.ok();
}

TextureLevel TextureLevelFromName(const std::string& name) {
  if (name == "low") return TextureLevel::kLow;
  if (name == "medium") return TextureLevel::kMedium;
  if (name == "high") return TextureLevel::kHigh;
  throw InputError("--texture", "unknown level '" + name + "' (expected low, medium or high)");
}

std::string TextureLevelName(TextureLevel level) {
  switch (level) {
    case TextureLevel::kLow:
      return "low";
    case TextureLevel::kMedium:
      return "medium";
    case TextureLevel::kHigh:
      return "high";
  }
  return "medium";
}

FactoryWorld BuildFactoryWorld(const FactoryOptions& options) {
  if (!options.Check()) {
    throw InputError(
        "world factory",
        "options out of range (aisles 1-8, aisle length 6-60 m, marker size 0.05-1 m, "
        "1-4 markers per dock, camera height 0.3-1 m, wall markers 0 or every 1-20 m)");
  }
  DictionaryFromName(options.dictionary, "--dictionary");
  return FactoryBuilder(options).Build();
}

std::string FactoryWorldSdf(const FactoryWorld& world) {
  std::ostringstream out;
  out << "  <world name=\"factory\">\n"
      << "    <scene><ambient>0.6 0.6 0.6 1</ambient><background>0.7 0.7 0.7 1</background>"
         "<shadows>false</shadows></scene>\n"
      << "    <light type=\"directional\" name=\"sun\"><cast_shadows>false</cast_shadows>"
         "<pose>0 0 10 0 0 0</pose><diffuse>0.8 0.8 0.8 1</diffuse><specular>0.1 0.1 0.1 "
         "1</specular>"
         "<direction>0.3 0.2 -0.93</direction></light>\n";
  for (const FactoryModel& model : world.models) {
    out << "    <model name=\"" << model.name << "\">\n      <static>true</static>\n      <pose>"
        << SdfPoseText(model.world_from_model) << "</pose>\n      <link name=\"link\">\n";
    for (const FactoryVisual& visual : model.visuals) AppendVisual(out, visual);
    out << "      </link>\n    </model>\n";
  }
  for (const auto& [id, marker] : world.markers.markers) {
    out << MarkerModelSdf(marker, MarkerSdfOptions(world.options, id));
  }
  out << "  </world>\n";
  return SdfDocument(out.str());
}

void WriteFactoryWorld(const FactoryWorld& world, const std::filesystem::path& dir) {
  RequireDirectory(dir, "factory output folder");
  std::filesystem::create_directories(dir / "textures");
  for (const auto& [name, image] : world.textures) {
    if (!cv::imwrite((dir / name).string(), image))
      throw InputError((dir / name).string(), "cannot write PNG");
  }
  std::filesystem::create_directories(dir / "markers");
  MarkerImageOptions image;
  image.marker_size_px = world.options.marker_image_px;
  for (const auto& [id, marker] : world.markers.markers) {
    const std::filesystem::path file = dir / MarkerSdfOptions(world.options, id).albedo_map;
    if (!cv::imwrite(file.string(), DrawMarkerImage(world.options.dictionary, id, image))) {
      throw InputError(file.string(), "cannot write PNG");
    }
  }
  WriteMarkerMapJson(world.markers, dir / "markers.json");
  WritePathJson(dir / "path.json", world.default_route);
  WriteTextFileAtomically(dir / "world.sdf", FactoryWorldSdf(world));
}

}  // namespace arucoslam
