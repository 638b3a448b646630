// Mass properties of convex primitives: each face fanned into triangles, each triangle with a
// reference point (the primitive's centroid) a tetrahedron; volume, first moment and covariance
// summed (Blow & Binstock, "How to find the inertia tensor (or other mass properties) of a 3D
// solid body represented by a triangle mesh", 2004), then moved to the centre of mass.
#include <cmath>

#include "core/dynamics/dynamics.h"

namespace hapticd::dynamics {

MassProperties computeMassProperties(std::span<const scene::Primitive> primitives, double density) {
  // covariance of the canonical tetrahedron (0, e1, e2, e3)
  const Mat3 canonical = Mat3{2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0} * (1.0 / 120.0);
  double volume = 0.0;
  Vec3 moment{0.0};  // integral of x dV
  Mat3 cov{0.0};     // integral of x x^T dV
  for (const scene::Primitive& prim : primitives) {
    if (!prim.shape)
      continue;
    const geom::Polytope& shape = *prim.shape;
    const geom::Transform X = prim.X_BP.toTransform();
    const Vec3 o = X.apply(shape.centroid());
    for (std::uint32_t f = 0; f < shape.faces().size(); ++f) {
      const auto fe = shape.faceEdges(f);
      if (fe.size() < 3)
        continue;
      const Vec3 p0 = X.apply(shape.vertices()[fe[0].vertex].p);
      for (std::size_t k = 1; k + 1 < fe.size(); ++k) {
        const Vec3 p1 = X.apply(shape.vertices()[fe[k].vertex].p);
        const Vec3 p2 = X.apply(shape.vertices()[fe[k + 1].vertex].p);
        // tetrahedron o, p0, p1, p2 (outward faces: positive volume); covariance about the
        // origin = covariance of the tetra at o translated
        const Mat3 A{p0 - o, p1 - o, p2 - o};  // columns
        const double det = glm::determinant(A);
        const double v = det / 6.0;
        const Vec3 c = o + (p0 + p1 + p2 - 3.0 * o) * 0.25;
        const Mat3 cov_o = det * (A * canonical * glm::transpose(A));  // about o
        // shift from o to the origin: int (x)(x)^T = cov_o + v (o c'^T + c' o^T) + v o o^T
        // with c' = c - o
        const Vec3 cr = c - o;
        cov += cov_o + v * (glm::outerProduct(o, cr) + glm::outerProduct(cr, o)) +
               v * glm::outerProduct(o, o);
        volume += v;
        moment += v * c;
      }
    }
  }
  MassProperties out;
  if (!(volume > 0.0) || !std::isfinite(volume))
    return out;
  out.mass = density * volume;
  out.com_B = moment / volume;
  const Mat3 cov_c = density * (cov - volume * glm::outerProduct(out.com_B, out.com_B));
  const double tr = cov_c[0][0] + cov_c[1][1] + cov_c[2][2];
  out.inertia_B = tr * Mat3{1.0} - cov_c;
  return out;
}

}  // namespace hapticd::dynamics
