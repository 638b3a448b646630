#pragma once
/// \file
/// Methods that answer the tick's pair queries inside the closed loop in place of its own
/// (collision::PairQueryMethod), for hapticstudy's scene parts (docs/accuracy.md): the paper's
/// depth along the motion (§4.1), and the peer libraries. Only hapticstudy links these (the peers
/// need FCL, Bullet and libccd; hapticctl does not).

#include <vector>

#include "bench/study/scene_study.h"

namespace hapticd::study {

/// The depth along the motion, then the peer sets that answer both apart and overlapping pairs
/// (FCL with libccd, Bullet's btGjkPairDetector, Bullet's btGjkEpaSolver2).
std::vector<LoopMethod> loopMethods();

}  // namespace hapticd::study
