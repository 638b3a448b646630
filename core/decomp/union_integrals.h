#pragma once
/// \file
/// The mass integrals of a union of convex solids, each point of space counted once: what a body
/// made of overlapping convex pieces weighs. The pieces of a decomposition overlap where merged
/// hulls reach into their neighbours (docs/decomposition.md, "Merging"); summing the pieces'
/// own integrals counts those parts twice (the Stanford bunny's 21 pieces sum to 1.79 times the
/// model's volume). Each solid less the solids before it is cut into convex cells by their face
/// planes (splitCell) and integrated exactly. No I/O; any thread.

#include <span>

#include "core/decomp/cut.h"
#include "core/geometry/mass_properties.h"
#include "core/geometry/polytope.h"
#include "core/geometry/pose.h"

namespace hapticd::decomp {

/// What unionIntegrals found.
struct UnionIntegrals {
  geom::VolumeIntegrals integrals;  ///< of the union; the sum of the solids' when not `exact`
  std::size_t overlapping = 0;      ///< solids that overlap an earlier one (counted once each)
  std::size_t work = 0;             ///< vertices tested against a plane
  bool exact = true;  ///< false: the work passed the budget, and `integrals` is the plain sum
};

/// Work allowed by default (vertices tested against planes, a few ns each): a decomposition's
/// pieces take 1e4 to 1e6 (the shared CAD part's 53 at 0.02: 7e5, 7 ms); many solids each
/// overlapping many others (a molecule of overlapping atoms) can take billions (64 turned
/// 128-sided prisms in one place: 3.5e9, 12 s); at the budget, about 0.35 s on the 2-core VM, the
/// union is given up for the sum.
inline constexpr std::size_t kUnionWorkBudget = 100'000'000;

/// The exact volume integrals of the union of `solids` (convex polyhedra as their faces' loops,
/// any orientation, none empty). `own[i]`, when given (the same size as `solids`), are solid i's
/// own integrals, taken as they are for a solid that overlaps no earlier one: solids that only
/// touch give bitwise the sum of their own integrals. An overlap thinner than 1e-9 of the
/// solids' bounding-box diagonal is no overlap. More than `max_work`: the sum, not exact.
UnionIntegrals unionIntegrals(std::span<const Cell> solids,
                              std::span<const geom::VolumeIntegrals> own = {},
                              std::size_t max_work = kUnionWorkBudget);

/// The exact volume integrals of one convex cell (any orientation of its loops).
geom::VolumeIntegrals cellIntegrals(const Cell& cell);

/// A convex piece's cell: its triangles as loops.
Cell pieceCell(const ConvexPiece& piece);

/// A polytope's cell placed by X (its faces' loops).
Cell polytopeCell(const geom::Polytope& shape, const geom::Transform& X);

}  // namespace hapticd::decomp
