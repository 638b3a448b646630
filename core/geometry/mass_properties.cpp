#include "core/geometry/mass_properties.h"

namespace hapticd::geom {

VolumeIntegrals polytopeIntegrals(const Polytope& shape, const Transform& X_BP) {
  // tetrahedra from a reference point r inside the hull to every face's fan triangles, in
  // coordinates y = x - r (small numbers far from the origin), shifted back at the end
  const Vec3 r = X_BP.apply(shape.centroid());
  const auto vertices = shape.vertices();
  double volume = 0.0;
  Vec3 first{0.0};
  Mat3 second{0.0};
  for (std::uint32_t f = 0; f < shape.faces().size(); ++f) {
    const auto boundary = shape.faceEdges(f);
    if (boundary.size() < 3)
      continue;
    const Vec3 a = X_BP.rotate(vertices[boundary[0].vertex].p - shape.centroid());
    for (std::size_t i = 1; i + 1 < boundary.size(); ++i) {
      const Vec3 b = X_BP.rotate(vertices[boundary[i].vertex].p - shape.centroid());
      const Vec3 c = X_BP.rotate(vertices[boundary[i + 1].vertex].p - shape.centroid());
      const double v = glm::dot(a, glm::cross(b, c)) / 6.0;
      const Vec3 s = a + b + c;  // the fourth vertex is the origin of y
      volume += v;
      first += v * s / 4.0;
      const Mat3 sum = glm::outerProduct(a, a) + glm::outerProduct(b, b) + glm::outerProduct(c, c) +
                       glm::outerProduct(s, s);
      second += (v / 20.0) * sum;
    }
  }
  VolumeIntegrals out;
  out.volume = volume;
  out.first = first + volume * r;
  out.second = second + glm::outerProduct(first, r) + glm::outerProduct(r, first) +
               volume * glm::outerProduct(r, r);
  return out;
}

MassProperties massFromIntegrals(const VolumeIntegrals& v, double density) {
  MassProperties out;
  if (!(v.volume > 0.0))
    return out;
  out.mass = density * v.volume;
  out.com_B = v.first / v.volume;
  const Mat3 j = density * (v.second - v.volume * glm::outerProduct(out.com_B, out.com_B));
  const double trace = j[0][0] + j[1][1] + j[2][2];
  out.inertia_B = trace * Mat3(1.0) - j;
  // exact symmetry (the sums above are symmetric only up to rounding)
  for (int c = 0; c < 3; ++c) {
    for (int r = c + 1; r < 3; ++r) {
      const double m = 0.5 * (out.inertia_B[c][r] + out.inertia_B[r][c]);
      out.inertia_B[c][r] = m;
      out.inertia_B[r][c] = m;
    }
  }
  return out;
}

}  // namespace hapticd::geom
