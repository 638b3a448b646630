#include "scenes/pose_streams.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "scenes/demo_scenes.h"

namespace hapticd::scenes {
namespace {

constexpr double kPi = std::numbers::pi;

/// One keyframe: where the held body is at time t. Between two keys the channels move with a
/// smoothstep (zero velocity at both keys); buttons hold from a key until the next one.
struct Key {
  double t;
  Vec3 a;         // position, or scene-specific coordinates (the gears use polar ones)
  Vec3 rot{0.0};  // rotation vector (axis * angle, rad)
  std::uint32_t buttons = 0;
};

struct Sample {
  Vec3 a;
  Vec3 rot;
  std::uint32_t buttons;
};

double smoothstep(double u) {
  return u * u * (3.0 - 2.0 * u);
}

Sample sampleKeys(const std::vector<Key>& keys, double t) {
  if (t <= keys.front().t)
    return {keys.front().a, keys.front().rot, keys.front().buttons};
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (t <= keys[i].t) {
      const Key& k0 = keys[i - 1];
      const Key& k1 = keys[i];
      const double s = smoothstep((t - k0.t) / (k1.t - k0.t));
      return {k0.a + s * (k1.a - k0.a), k0.rot + s * (k1.rot - k0.rot), k0.buttons};
    }
  }
  return {keys.back().a, keys.back().rot, keys.back().buttons};
}

/// Appends x in fixed notation with `digits` decimals; never "-0.000".
void appendFixed(std::string& out, double x, int digits) {
  if (!std::isfinite(x))
    throw std::invalid_argument("pose stream: non-finite value");
  if (std::fabs(x) < 0.5 * std::pow(10.0, -digits))
    x = 0.0;
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::fixed, digits);
  out.append(buf, r.ptr);
}

struct Pose {
  Vec3 p;
  Vec3 rot;
  std::uint32_t buttons;
};

/// Samples pose(t) at kPoseStreamRate_hz from 0 to `duration_s` (inclusive) as CSV.
std::string writeStream(double duration_s, const std::function<Pose(double)>& pose) {
  std::string out = "t,px,py,pz,qx,qy,qz,qw,buttons\n";
  const auto rows = static_cast<int>(std::lround(duration_s * kPoseStreamRate_hz));
  for (int i = 0; i <= rows; ++i) {
    const double t = static_cast<double>(i) / kPoseStreamRate_hz;
    const Pose x = pose(t);
    // quaternion of the rotation vector, continuous in t (no sign flips)
    const double angle = glm::length(x.rot);
    Vec3 axis{0.0, 1.0, 0.0};
    if (angle > 0.0)
      axis = x.rot / angle;
    double q[4] = {axis.x * std::sin(0.5 * angle), axis.y * std::sin(0.5 * angle),
                   axis.z * std::sin(0.5 * angle), std::cos(0.5 * angle)};
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    appendFixed(out, t, 3);
    for (int k = 0; k < 3; ++k) {
      out.push_back(',');
      appendFixed(out, x.p[k], 7);
    }
    for (double c : q) {
      out.push_back(',');
      appendFixed(out, c / n, 9);
    }
    out.push_back(',');
    out += std::to_string(x.buttons);
    out.push_back('\n');
  }
  return out;
}

/// The peg: approach over the hole, insert with a wobble, jam (tilted and pushed), push to the
/// floor, pull out.
std::string pegStream() {
  using namespace peg;
  const double h = 0.5 * kPegLength_m;  // peg origin above its lower end
  const double top = kHoleDepth_m;
  const std::vector<Key> keys = {
      {0.0, {0.030, top + h + 0.040, 0.020}},
      {1.0, {0.030, top + h + 0.040, 0.020}},
      {3.0, {0.0, top + h + 0.005, 0.0}},                             // over the hole
      {6.0, {0.0, h + 0.015, 0.0}},                                   // 25 mm in (wobble added)
      {7.5, {0.001, h + 0.012, 0.0}, {0.0, 0.0, 4.0 * kPi / 180.0}},  // tilt 4 degrees: jam
      {8.5, {0.001, h + 0.012, 0.0}, {0.0, 0.0, 4.0 * kPi / 180.0}},
      {10.0, {0.0, h - 0.002, 0.0}},  // straight, 2 mm into floor
      {11.0, {0.0, h - 0.002, 0.0}},
      {13.5, {0.0003, top + h + 0.040, 0.0}},  // out, rubbing one wall
      {14.5, {0.030, top + h + 0.040, 0.020}},
      {15.0, {0.030, top + h + 0.040, 0.020}},
  };
  return writeStream(15.0, [&](double t) {
    Sample s = sampleKeys(keys, t);
    if (t > 3.0 && t < 6.0) {
      // wobble while inserting: +-1.5 degrees about X and Z, +-0.3 mm sideways, faded in and out
      const double u = (t - 3.0) / 3.0;
      const double env = std::sin(kPi * u);
      const double deg = kPi / 180.0;
      s.rot += env * Vec3{1.5 * deg * std::sin(2.0 * kPi * 1.0 * (t - 3.0)), 0.0,
                          1.5 * deg * std::sin(2.0 * kPi * 0.7 * (t - 3.0) + 1.0)};
      s.a += env * Vec3{0.0003 * std::sin(2.0 * kPi * 1.3 * (t - 3.0)), 0.0,
                        0.0003 * std::cos(2.0 * kPi * 0.9 * (t - 3.0))};
    }
    return Pose{s.a, s.rot, s.buttons};
  });
}

/// The rod: into gear A's top gap, push the tooth ahead of it clockwise by 30 degrees, then back
/// through the backlash to push the other tooth 60 degrees the other way, then out.
std::string gearsStream() {
  using namespace gears;
  const SpurGear g = gear();
  const double pitch = 2.0 * kPi / g.teeth;
  const double gap = 4.5 * pitch;  // the gap of gear A nearest the top
  const double in = 0.5 * (g.pitchRadius() + g.rootRadius()) + 0.002;  // 46.4 mm from the axis
  const double out = 0.075;
  const double turn = 30.0 * kPi / 180.0;
  // channels: (polar angle about gear A's axis, distance from the axis, z)
  const std::vector<Key> keys = {
      {0.0, {gap, out, 0.0}},         {1.0, {gap, out, 0.0}},        {3.0, {gap, in, 0.0}},
      {4.0, {gap, in, 0.0}},          {7.0, {gap - turn, in, 0.0}},  {8.0, {gap - turn, in, 0.0}},
      {13.0, {gap + turn, in, 0.0}},  {14.0, {gap + turn, in, 0.0}}, {15.5, {gap + turn, out, 0.0}},
      {16.0, {gap + turn, out, 0.0}},
  };
  const Vec3 centre{-0.5 * kCentreDistance_m, 0.0, 0.0};
  return writeStream(16.0, [&](double t) {
    const Sample s = sampleKeys(keys, t);
    const Vec3 p = centre + Vec3{s.a.y * std::cos(s.a.x), s.a.y * std::sin(s.a.x), s.a.z};
    return Pose{p, s.rot, s.buttons};
  });
}

/// The stick: push a cube along the floor, strike a sphere, press an ellipsoid with a tilted
/// stick, then hold button 1 (grab) to lift a cube, carry it and drop it.
std::string dynamicStream() {
  using namespace dynamic;
  const double tilt = 15.0 * kPi / 180.0;
  const std::vector<Key> keys = {
      {0.0, {0.0, 0.20, 0.25}},
      {1.0, {0.0, 0.20, 0.25}},
      {1.8, {-0.21, 0.17, kCubeZ_m}},    // high over the spheres and ellipsoids, then
      {2.5, {-0.21, 0.090, kCubeZ_m}},   // down left of Cube0, lower end 15 mm up
      {4.5, {-0.125, 0.090, kCubeZ_m}},  // push it 55 mm along +X
      {5.0, {-0.125, 0.090, kCubeZ_m}},
      {5.8, {-0.125, 0.17, kCubeZ_m}},
      {6.5, {0.21, 0.17, kSphereZ_m}},  // over to the right of Sphere3, high above it
      {7.0, {0.21, 0.10, kSphereZ_m}},  // down beside it, the lower end at its equator
      {7.5, {0.21, 0.10, kSphereZ_m}},
      {7.8, {0.14, 0.10, kSphereZ_m}},  // strike: 70 mm in 0.3 s
      {8.3, {0.14, 0.10, kSphereZ_m}},
      {8.8, {0.21, 0.10, kSphereZ_m}},
      {9.5, {0.21, 0.17, kSphereZ_m}},
      {10.5, {-0.05, 0.14, kEllipsoidZ_m}, {tilt, 0.0, 0.0}},   // over Ellipsoid1, tilted
      {12.0, {-0.05, 0.110, kEllipsoidZ_m}, {tilt, 0.0, 0.0}},  // press into its top
      {12.5, {-0.05, 0.110, kEllipsoidZ_m}, {tilt, 0.0, 0.0}},
      {13.0, {-0.05, 0.17, kEllipsoidZ_m}},
      {14.0, {0.05, 0.17, kCubeZ_m}},  // over Cube2
      // on its top as it rests on the floor (it started kDropGap_m higher); button 1 held
      {15.0, {0.05, 0.5 * kStickSize_m[1] + kCubeSide_m, kCubeZ_m}, Vec3{0.0}, 1},
      {16.5, {0.05, 0.20, kCubeZ_m}, Vec3{0.0}, 1},  // lift
      {17.5, {0.05, 0.20, 0.20}, Vec3{0.0}, 1},      // carry
      {18.0, {0.05, 0.14, 0.20}},                    // lower, release: it drops
      {19.0, {0.05, 0.22, 0.20}},
      {19.5, {0.05, 0.22, 0.20}},
  };
  return writeStream(19.5, [&](double t) {
    const Sample s = sampleKeys(keys, t);
    return Pose{s.a, s.rot, s.buttons};
  });
}

/// The sweeper: a lawn-mower path over the pillar field, pressing 1 mm into the pillar tops of
/// every fourth row and pushing the blocks on four of the rows, turning slowly about Y.
std::string stressStream() {
  using namespace stress;
  const double y = kPillarSize_m[1] + kSweeperRadius_m - 0.001;
  const double x_end = 0.52;
  std::vector<Key> keys;
  const double z0 = pillarCoordinate(4);
  keys.push_back({0.0, {-x_end, 0.10, z0}});
  keys.push_back({1.0, {-x_end, 0.10, z0}});
  double t = 2.0;
  keys.push_back({t, {-x_end, y, z0}});
  double x = -x_end;
  for (int line = 0; line < 7; ++line) {
    const double z = pillarCoordinate(4 + 4 * line);
    if (line > 0) {
      t += 0.4;
      keys.push_back({t, {x, y, z}});
    }
    x = -x;
    t += 2.0;
    keys.push_back({t, {x, y, z}});
  }
  const Vec3 last = keys.back().a;
  t += 1.0;
  keys.push_back({t, {last.x, 0.10, last.z}});
  t += 0.5;
  keys.push_back({t, {last.x, 0.10, last.z}});
  const double duration = t;
  return writeStream(duration, [&](double time) {
    const Sample s = sampleKeys(keys, time);
    return Pose{s.a, Vec3{0.0, 0.3 * time, 0.0}, s.buttons};
  });
}

/// The pin plate, tilted 20 degrees about Z throughout: down until its first column of pins is in
/// a groove and its tiles' edge presses a ridge (0.3 mm), along the groove 60 mm, 1 mm sideways
/// against the groove's wall, back along it so pressed, back to the middle, up.
std::string decomposedStream() {
  using namespace decomposed;
  const double x = kRunX_m, up = kStartY_m, y = kRunY_m - 0.0006;
  const double z0 = kRunZ_m[0], z1 = kRunZ_m[1];
  const Vec3 tilt{0.0, 0.0, kTilt_rad};
  const std::vector<Key> keys = {
      {0.0, {x, up, z0}, tilt}, {1.0, {x, up, z0}, tilt},        {2.5, {x, y, z0}, tilt},
      {6.5, {x, y, z1}, tilt},  {7.0, {x + 0.001, y, z1}, tilt}, {10.0, {x + 0.001, y, z0}, tilt},
      {10.5, {x, y, z0}, tilt}, {12.0, {x, up, z0}, tilt},       {12.5, {x, up, z0}, tilt},
  };
  return writeStream(12.5, [&](double t) {
    const Sample s = sampleKeys(keys, t);
    return Pose{s.a, s.rot, s.buttons};
  });
}

}  // namespace

std::string makePoseStream(std::string_view scene) {
  // in demoSceneNames() order
  static constexpr std::string (*kStreams[])() = {&gearsStream, &pegStream, &dynamicStream,
                                                  &stressStream, &decomposedStream};
  const int i = demoSceneIndex(scene);
  return i < 0 ? std::string{} : kStreams[static_cast<std::size_t>(i)]();
}

}  // namespace hapticd::scenes
