// Mass properties of a body's primitives: the one routine (core/geometry/mass_properties.h)
// summed over them.
#include "core/geometry/mass_properties.h"

#include "core/dynamics/dynamics.h"

namespace hapticd::dynamics {

MassProperties computeMassProperties(std::span<const scene::Primitive> primitives, double density) {
  geom::VolumeIntegrals sum;
  for (const scene::Primitive& prim : primitives) {
    if (prim.shape)
      sum.add(geom::polytopeIntegrals(*prim.shape, prim.X_BP.toTransform()));
  }
  return geom::massFromIntegrals(sum, density);
}

}  // namespace hapticd::dynamics
