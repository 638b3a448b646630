#include "client/replay_stream.h"

#include "core/geometry/rotation.h"

namespace hapticd::client {

Result<std::vector<proto::PoseStreamRow>> parseReplayStream(const std::string& text,
                                                            const std::string& name) {
  return proto::parsePoseStream(text, name, kPoseStreamQuatTolerance,
                                proto::PoseStreamDialect::kLenient);
}

ReplaySample sampleReplayStream(std::span<const proto::PoseStreamRow> rows,
                                double t_s,
                                std::size_t* hint) {
  std::size_t search = 0;
  std::size_t& i = hint != nullptr ? *hint : search;
  const proto::PoseStreamRow r = proto::samplePoseStream(rows, t_s, i);
  ReplaySample s;
  s.t_s = t_s;
  s.X_WD = r.X_WD;
  s.buttons = r.buttons;
  if (rows.size() > 1 && t_s >= rows.front().t_s && t_s < rows.back().t_s) {
    // inside segment i (at the first row: the first segment)
    const proto::PoseStreamRow& a = rows[i];
    const proto::PoseStreamRow& b = rows[i + 1];
    const double dt = b.t_s - a.t_s;
    s.v_W = (b.X_WD.translation - a.X_WD.translation) / dt;
    s.w_W = geom::rotationVector(b.X_WD.rotation * glm::conjugate(a.X_WD.rotation)) / dt;
  }
  return s;
}

}  // namespace hapticd::client
