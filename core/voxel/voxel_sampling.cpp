#include "core/voxel/voxel_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/collision/segment.h"

namespace hapticd::voxel {
namespace {

using collision::detail::closestOnSegment;

constexpr double kInf = std::numeric_limits<double>::infinity();

struct ShapeDistance {
  double distance = kInf;
  Vec3 normal_P{0.0};
};

// The point of face f (a convex polygon) nearest to x, in the shape's frame.
Vec3 nearestOnFace(const Polytope& p, std::uint32_t f, const Vec3& x) {
  const auto& face = p.faces()[f];
  const auto fe = p.faceEdges(f);
  bool inside = true;
  for (const auto& e : fe) {
    if (glm::dot(x - p.vertices()[e.vertex].p, e.side) < 0.0) {
      inside = false;
      break;
    }
  }
  if (inside)
    return x - face.normal * (glm::dot(face.normal, x) - face.offset);
  double best2 = kInf;
  Vec3 nearest{0.0};
  for (std::size_t k = 0; k < fe.size(); ++k) {
    const Vec3& a = p.vertices()[fe[k].vertex].p;
    const Vec3& b = p.vertices()[fe[(k + 1) % fe.size()].vertex].p;
    const Vec3 c = a + (b - a) * closestOnSegment(x, a, b);
    const double d2 = glm::dot(x - c, x - c);
    if (d2 < best2)
      best2 = d2, nearest = c;
  }
  return nearest;
}

// Signed distance from x (in the shape's frame) to one convex polytope. Inside: minus the depth
// below the nearest face plane (exact). Outside: the distance to the nearest point, found on the
// faces whose planes x is above (the nearest point lies on one of them).
ShapeDistance shapeDistance(const Polytope& p, const Vec3& x) {
  ShapeDistance best;
  double s_max = -kInf;
  std::uint32_t f_max = 0;
  const auto faces = p.faces();
  for (std::uint32_t f = 0; f < faces.size(); ++f) {
    const double s = glm::dot(faces[f].normal, x) - faces[f].offset;
    if (s > s_max)
      s_max = s, f_max = f;
  }
  if (s_max <= 0.0) {
    best.distance = s_max;
    best.normal_P = faces[f_max].normal;
    return best;
  }
  double best2 = kInf;
  Vec3 nearest{0.0};
  for (std::uint32_t f = 0; f < faces.size(); ++f) {
    if (glm::dot(faces[f].normal, x) - faces[f].offset <= 0.0)
      continue;
    const Vec3 c = nearestOnFace(p, f, x);
    const double d2 = glm::dot(x - c, x - c);
    if (d2 < best2)
      best2 = d2, nearest = c;
  }
  best.distance = std::sqrt(best2);
  best.normal_P = best.distance > 0.0 ? (x - nearest) / best.distance : faces[f_max].normal;
  return best;
}

// The inputs of `what` ("voxel map", "point shell"): some shapes to `verb`, and a step
// (`step_name`, "the voxel size") positive and finite.
Result<bool> checkSampling(std::span<const PlacedShape> shapes,
                           double step,
                           const char* what,
                           const char* verb,
                           const char* step_name) {
  if (shapes.empty())
    return Error{std::string(what) + ": no shape to " + verb};
  if (!(step > 0.0) || !std::isfinite(step)) {
    return Error{std::string(what) + ": " + step_name + " must be positive and finite, not " +
                 std::to_string(step)};
  }
  return true;
}

}  // namespace

SignedDistance signedDistance(std::span<const PlacedShape> shapes, const Vec3& p_W) {
  SignedDistance out{kInf, Vec3{0.0}};
  for (const auto& s : shapes) {
    const Transform X_PW = s.X_WP.inverse();
    const ShapeDistance d = shapeDistance(*s.shape, X_PW.apply(p_W));
    if (d.distance < out.distance) {
      out.distance = d.distance;
      out.normal_W = s.X_WP.rotate(d.normal_P);
    }
  }
  return out;
}

Result<VoxelMap> VoxelMap::build(std::span<const PlacedShape> shapes,
                                 double voxel_size,
                                 std::uint64_t max_voxels) {
  if (auto ok = checkSampling(shapes, voxel_size, "voxel map", "voxelise", "the voxel size"); !ok)
    return ok.error();
  Vec3 lo(kInf), hi(-kInf);
  for (const auto& s : shapes) {
    for (const auto& v : s.shape->vertices()) {
      const Vec3 p = s.X_WP.apply(v.p);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  VoxelMap map;
  map.h_ = voxel_size;
  map.origin_ = lo - Vec3(voxel_size);
  const Vec3 n = glm::ceil((hi - map.origin_) / voxel_size) + 1.0;
  const double count = n.x * n.y * n.z;
  if (!(count <= static_cast<double>(max_voxels))) {
    return Error{"voxel map: " + std::to_string(static_cast<std::uint64_t>(count)) +
                 " voxels at size " + std::to_string(voxel_size) + " exceed the limit of " +
                 std::to_string(max_voxels)};
  }
  map.nx_ = static_cast<std::uint32_t>(n.x);
  map.ny_ = static_cast<std::uint32_t>(n.y);
  map.nz_ = static_cast<std::uint32_t>(n.z);
  map.cells_.assign(static_cast<std::size_t>(count), 0u);
  const double r = 0.5 * std::sqrt(3.0) * voxel_size;  // half a voxel diagonal
  std::vector<Transform> X_PW;
  for (const auto& s : shapes)
    X_PW.push_back(s.X_WP.inverse());
  // the shapes near each brick of 8 x 8 x 8 voxels: those whose box, grown by r, meets the brick
  // (a shape within r of a voxel centre, or holding a point within r of it, is one of them)
  constexpr std::uint32_t kBrick = 8;
  const std::uint32_t bx = (map.nx_ + kBrick - 1) / kBrick, by = (map.ny_ + kBrick - 1) / kBrick,
                      bz = (map.nz_ + kBrick - 1) / kBrick;
  std::vector<std::vector<std::uint32_t>> near(static_cast<std::size_t>(bx) * by * bz);
  const double brick = kBrick * voxel_size;
  for (std::uint32_t k = 0; k < shapes.size(); ++k) {
    Vec3 slo(kInf), shi(-kInf);
    for (const auto& v : shapes[k].shape->vertices()) {
      const Vec3 p = shapes[k].X_WP.apply(v.p);
      slo = glm::min(slo, p);
      shi = glm::max(shi, p);
    }
    const Vec3 a = glm::max((slo - r - map.origin_) / brick, Vec3(0.0));
    const Vec3 b = (shi + r - map.origin_) / brick;
    const auto to = [](double x, std::uint32_t count_) {
      return std::min(static_cast<std::uint32_t>(x), count_ - 1);
    };
    for (std::uint32_t z = to(a.z, bz); z <= to(b.z, bz); ++z) {
      for (std::uint32_t y = to(a.y, by); y <= to(b.y, by); ++y) {
        for (std::uint32_t x = to(a.x, bx); x <= to(b.x, bx); ++x) {
          near[(static_cast<std::size_t>(z) * by + y) * bx + x].push_back(k);
        }
      }
    }
  }
  const auto inside = [&](const Vec3& p_W, std::size_t skip,
                          const std::vector<std::uint32_t>& list) {
    for (const std::uint32_t k : list) {
      if (k == skip)
        continue;
      const Polytope& q = *shapes[k].shape;
      if (shapeDistance(q, X_PW[k].apply(p_W)).distance < -1e-9 * q.radius())
        return true;
    }
    return false;
  };
  std::size_t i = 0;
  for (std::uint32_t z = 0; z < map.nz_; ++z) {
    for (std::uint32_t y = 0; y < map.ny_; ++y) {
      for (std::uint32_t x = 0; x < map.nx_; ++x, ++i) {
        const auto& list =
            near[(static_cast<std::size_t>(z / kBrick) * by + y / kBrick) * bx + x / kBrick];
        if (list.empty())
          continue;  // nothing within r: free
        const Vec3 c = map.origin_ + (Vec3(x, y, z) + 0.5) * voxel_size;
        // the distance to the union is exact outside it: far from every shape, free
        double d_min = kInf;
        for (const std::uint32_t k : list) {
          d_min = std::min(d_min, shapeDistance(*shapes[k].shape, X_PW[k].apply(c)).distance);
        }
        if (d_min > r)
          continue;
        // a surface voxel when an exposed surface point (on a shape's face, not covered by
        // another shape) lies within r of the centre: seams between touching shapes are not
        // surfaces. Each face is represented by its point nearest the centre.
        Vec3 normal{0.0};
        double best = std::numeric_limits<double>::infinity();
        for (const std::uint32_t k : list) {
          const Polytope& q = *shapes[k].shape;
          const Vec3 c_P = X_PW[k].apply(c);
          for (std::uint32_t f = 0; f < q.faces().size(); ++f) {
            const double plane = glm::dot(q.faces()[f].normal, c_P) - q.faces()[f].offset;
            if (std::abs(plane) > r)
              continue;
            const Vec3 on_P = nearestOnFace(q, f, c_P);
            const double dist = glm::length(c_P - on_P);
            if (dist > r || dist >= best)
              continue;
            // covered when a step off the face along its normal is inside another shape
            const Vec3 n_W = shapes[k].X_WP.rotate(q.faces()[f].normal);
            if (inside(shapes[k].X_WP.apply(on_P) + n_W * (1e-4 * voxel_size), k, list))
              continue;
            best = dist;
            normal = n_W;
          }
        }
        if (best > r) {
          if (d_min < 0.0)
            map.cells_[i] = 1u;  // inside the union, no surface near
          continue;
        }
        map.cells_[i] = static_cast<std::uint32_t>(map.normals_.size()) + 2u;
        map.normals_.push_back(normal);
      }
    }
  }
  return map;
}

VoxelMap::Cell VoxelMap::lookup(const Vec3& p_W, Vec3* centre_W, Vec3* normal_W) const {
  const Vec3 g = (p_W - origin_) / h_;
  if (!(g.x >= 0.0 && g.y >= 0.0 && g.z >= 0.0 && g.x < nx_ && g.y < ny_ && g.z < nz_)) {
    return Cell::kFree;
  }
  const auto x = static_cast<std::uint32_t>(g.x), y = static_cast<std::uint32_t>(g.y),
             z = static_cast<std::uint32_t>(g.z);
  const std::uint32_t c = cells_[(static_cast<std::size_t>(z) * ny_ + y) * nx_ + x];
  if (c == 0u)
    return Cell::kFree;
  if (c == 1u)
    return Cell::kInterior;
  if (centre_W)
    *centre_W = origin_ + (Vec3(x, y, z) + 0.5) * h_;
  if (normal_W)
    *normal_W = normals_[c - 2u];
  return Cell::kSurface;
}

Result<PointShell> makePointShell(std::span<const PlacedShape> shapes,
                                  double spacing,
                                  std::size_t max_points) {
  if (auto ok = checkSampling(shapes, spacing, "point shell", "sample", "the spacing"); !ok)
    return ok.error();
  PointShell shell;
  // a point on one shape's surface inside another shape of the body is not on the body's surface
  const auto keep = [&](std::size_t self, const Vec3& p_B) {
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      if (k == self)
        continue;
      const Polytope& q = *shapes[k].shape;
      const double tol = 1e-9 * q.radius();
      if (shapeDistance(q, shapes[k].X_WP.inverse().apply(p_B)).distance < -tol)
        return false;
    }
    return true;
  };
  const auto add = [&](const Vec3& p_B, const Vec3& inward_B) -> bool {
    if (shell.p_B.size() >= max_points)
      return false;
    shell.p_B.push_back(p_B);
    shell.inward_B.push_back(inward_B);
    return true;
  };
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const Polytope& p = *shapes[s].shape;
    const Transform& X = shapes[s].X_WP;
    for (std::uint32_t f = 0; f < p.faces().size(); ++f) {
      const auto fe = p.faceEdges(f);
      const Vec3 n = p.faces()[f].normal;
      // an orthonormal frame (u, v) in the face plane, its extent over the face's vertices
      const Vec3 e0 = p.vertices()[fe[0].vertex].p;
      const Vec3 u = glm::normalize(p.vertices()[fe[1].vertex].p - e0);
      const Vec3 v = glm::cross(n, u);
      double u_lo = kInf, u_hi = -kInf, v_lo = kInf, v_hi = -kInf;
      for (const auto& e : fe) {
        const Vec3 d = p.vertices()[e.vertex].p - e0;
        u_lo = std::min(u_lo, glm::dot(d, u)), u_hi = std::max(u_hi, glm::dot(d, u));
        v_lo = std::min(v_lo, glm::dot(d, v)), v_hi = std::max(v_hi, glm::dot(d, v));
      }
      for (double a = u_lo + 0.5 * spacing; a < u_hi; a += spacing) {
        for (double b = v_lo + 0.5 * spacing; b < v_hi; b += spacing) {
          const Vec3 q = e0 + u * a + v * b;
          bool inside = true;
          for (const auto& e : fe) {
            if (glm::dot(q - p.vertices()[e.vertex].p, e.side) < 0.0) {
              inside = false;
              break;
            }
          }
          if (!inside)
            continue;
          const Vec3 q_B = X.apply(q);
          if (!keep(s, q_B))
            continue;
          if (!add(q_B, -X.rotate(n))) {
            return Error{"point shell: more than " + std::to_string(max_points) +
                         " points at spacing " + std::to_string(spacing)};
          }
        }
      }
    }
    // vertices, with the mean of their faces' inward normals
    for (std::uint32_t vi = 0; vi < p.vertices().size(); ++vi) {
      Vec3 inward{0.0};
      for (const auto& ve : p.vertexEdges(vi)) {
        const auto& e = p.edges()[ve.edge];
        inward -= p.faces()[e.face[0]].normal + p.faces()[e.face[1]].normal;
      }
      const Vec3 q_B = X.apply(p.vertices()[vi].p);
      if (!keep(s, q_B))
        continue;
      if (!add(q_B, X.rotate(glm::normalize(inward)))) {
        return Error{"point shell: more than " + std::to_string(max_points) +
                     " points at spacing " + std::to_string(spacing)};
      }
    }
  }
  return shell;
}

VoxelForce force(const VoxelMap& map,
                 const PointShell& shell,
                 const Transform& X_WB,
                 const Vec3& com_W,
                 double stiffness_per_point) {
  VoxelForce out;
  Vec3 centre{0.0}, normal{0.0};
  for (std::size_t i = 0; i < shell.p_B.size(); ++i) {
    const Vec3 p = X_WB.apply(shell.p_B[i]);
    const VoxelMap::Cell cell = map.lookup(p, &centre, &normal);
    if (cell == VoxelMap::Cell::kInterior) {
      ++out.points_interior;
      continue;
    }
    if (cell != VoxelMap::Cell::kSurface)
      continue;
    const double depth = glm::dot(centre - p, normal);  // below the voxel's tangent plane
    if (depth <= 0.0)
      continue;
    const Vec3 f = normal * (stiffness_per_point * depth);
    out.force_W += f;
    out.torque_W += glm::cross(p - com_W, f);
    ++out.points_in_contact;
    out.max_depth = std::max(out.max_depth, depth);
  }
  return out;
}

}  // namespace hapticd::voxel
