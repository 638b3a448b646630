#pragma once
/// \file
/// The demo scenes of the paper's §6.2 (Gregory et al. 2000), generated reproducibly as glTF 2.0
/// binaries with KHR_physics_rigid_bodies and KHR_implicit_shapes (docs/demo-scenes.md):
/// "gears", "peg_in_hole", "dynamic", "stress" and "decomposed". docs/demo-scenes.md describes each
/// one. The same call gives the same bytes on every run and build; scenes/*.glb are its output
/// (written by the `make_scenes` tool). Any thread; allocates.

#include <cstdint>
#include <string_view>
#include <vector>

#include "scenes/meshes.h"

namespace hapticd::scenes {

/// The demo scene names, in a fixed order.
std::vector<std::string_view> demoSceneNames();

/// The .glb bytes of the named demo scene; empty when `name` is not a demo scene.
std::vector<std::uint8_t> makeDemoScene(std::string_view name);

/// The position of `name` in demoSceneNames(), -1 when it is not a demo scene.
int demoSceneIndex(std::string_view name);

/// Not a demo scene: `boxes` dynamic boxes of kBoxFieldSide_m (10 g each) resting on a static
/// floor, their bottoms at y = 0, in a square grid of kBoxFieldPitch_m centred on the origin; no
/// probe body (the simulation adds its probe sphere at the device); gravity -9.81 m/s^2 along Y.
/// The scene swap's test and benchmark load it into a running servo loop (issue 18: "200 boxes
/// of 2 cm resting on a floor"). The same bytes on every run; boxes < 1 gives the floor alone.
std::vector<std::uint8_t> makeBoxField(int boxes);
inline constexpr double kBoxFieldSide_m = 0.020;
inline constexpr double kBoxFieldPitch_m = 0.040;

/// Dimensions of the scenes, shared by the generator, the pose streams, tests and docs (metres,
/// kilograms). Y is up in every scene.
namespace gears {
/// Both gears: 19 teeth, module 5 mm, 20° pressure angle, 1 mm backlash, 15 mm face width.
SpurGear gear();
/// Gear A turns about +Z through (-kCentreDistance_m / 2, 0, 0), gear B through (+.../2, 0, 0).
inline constexpr double kCentreDistance_m = 0.095;  // 2 * pitch radius
inline constexpr double kMass_kg = 0.15;            // each gear (declared)
inline constexpr double kRodRadius_m = 0.003;       // the held handle: a rod along Z
inline constexpr double kRodLength_m = 0.036;
inline constexpr int kRodSides = 16;
}  // namespace gears

namespace peg {
inline constexpr double kPegSide_m = 0.020;     // square section, along X and Z
inline constexpr double kPegLength_m = 0.060;   // along Y
inline constexpr double kClearance_m = 0.0005;  // each side, between peg and wall
inline constexpr double kWallThickness_m = 0.010;
inline constexpr double kHoleDepth_m = 0.040;  // hole floor at y = 0, wall tops at y = depth
inline constexpr double kBaseSide_m = 0.100;   // the floor slab under the walls, 10 mm thick
inline constexpr double kBaseThickness_m = 0.010;
inline constexpr double kHoleStiffness_n_per_m = 600.0;  // extras.haptic.stiffness of the hole
}  // namespace peg

namespace dynamic {
inline constexpr double kCubeSide_m = 0.040;
inline constexpr double kCubeMass_kg = 0.050;
inline constexpr double kSphereRadius_m = 0.025;
inline constexpr double kSphereMass_kg = 0.065;
inline constexpr double kEllipsoidRadii_m[3] = {0.040, 0.020, 0.025};  // mass not declared
inline constexpr double kStickSize_m[3] = {0.020, 0.150, 0.020};
inline constexpr double kDropGap_m = 0.001;  // bodies start this far above the floor
inline constexpr double kRowX_m[4] = {-0.15, -0.05, 0.05, 0.15};
inline constexpr double kCubeZ_m = -0.10, kSphereZ_m = 0.0, kEllipsoidZ_m = 0.10;
}  // namespace dynamic

namespace stress {
inline constexpr int kGrid = 32;  // kGrid x kGrid static pillars
inline constexpr double kPitch_m = 0.030;
inline constexpr double kPillarSize_m[3] = {0.012, 0.040, 0.012};
inline constexpr int kBlocksPerSide = 4;  // 16 dynamic blocks on the pillar tops
inline constexpr double kBlockSide_m = 0.040;
inline constexpr double kBlockMass_kg = 0.050;
inline constexpr double kSweeperRadius_m = 0.015;
/// Centre of pillar (i, j) on X (Z alike).
inline constexpr double pillarCoordinate(int i) {
  return (i - 0.5 * (kGrid - 1)) * kPitch_m;
}
/// Centre of block (i, j) on X (Z alike): over the middle of a 2 x 2 group of pillars.
inline constexpr double blockCoordinate(int i) {
  return (8 * i + 4 - 0.5 * kGrid) * kPitch_m;
}
}  // namespace stress

/// A held plate of pins sliding in the grooves of a static plate; both plates are non-convex
/// meshes the generator builds cell by cell and decomposes into convex pieces
/// (core/decomp/decompose.h): ~500 pieces static, ~100 held.
namespace decomposed {
inline constexpr double kCell_m = 0.008;  // both plates' cell pitch, X and Z
/// The grooved plate: kGrooveCells x kGrooveCells ridge cells centred on the origin, ridge tops
/// at y = 0, grooves along Z centred at x = (k + 1/2) * kCell_m.
inline constexpr int kGrooveCells = 13;
inline constexpr double kRidgeWidth_m = 0.004;  // the grooves are kCell_m - this wide: 4 mm
inline constexpr double kGrooveDepth_m = 0.0035;
inline constexpr double kBaseThickness_m = 0.003;
/// The pin plate (held): kPinCellsX x kPinCellsZ pin cells; in its own frame cell (i, j) is
/// centred at x = i * kCell_m, z = (j - (kPinCellsZ - 1) / 2) * kCell_m; pins hang from y = 0.
inline constexpr int kPinCellsX = 10;
inline constexpr int kPinCellsZ = 5;
inline constexpr double kTileThickness_m = 0.002;
inline constexpr double kPinSide_m = 0.0024;
inline constexpr double kPinLength_m = 0.004;
/// The stream holds the plate turned by this about +Z (its +X side up), so that only its first
/// column of pins (x = 0) reaches into a groove.
inline constexpr double kTilt_rad = 20.0 * 3.14159265358979323846 / 180.0;
/// The groove the first column of pins runs in (its centre on X).
inline constexpr double kGrooveX_m = -0.028;
/// Where the stream runs the plate's origin (its first pin's root centre): the first pins' part
/// below the ridge tops centred in that groove (0.42 mm to each wall), their lowest corner 2.5 mm
/// below the ridge tops, the tiles' lower edge 0.3 mm above a ridge.
inline constexpr double kRunX_m = -0.0289;
inline constexpr double kRunY_m = 0.00167;
inline constexpr double kStartY_m = 0.030;             // the first and last rows: 30 mm up
inline constexpr double kRunZ_m[2] = {-0.030, 0.030};  // the run from one to the other along Z
/// Ridge cell (i, j) centre on X (Z alike).
inline constexpr double grooveCellCoordinate(int i) {
  return (i - 0.5 * (kGrooveCells - 1)) * kCell_m;
}
}  // namespace decomposed

}  // namespace hapticd::scenes
