#include "core/response/coupling.h"

namespace hapticd::response {

Wrench VirtualCoupling::step(const Vec3& h_dev_W,
                             const Quat& q_dev,
                             const Vec3& h_prx_W,
                             const Quat& q_prx) {
  Vec3 v_rel{0.0}, w_rel{0.0};
  if (have_prev_) {
    const Vec3 v_dev = (h_dev_W - prev_h_dev_) / p_.tick_s;
    const Vec3 v_prx = (h_prx_W - prev_h_prx_) / p_.tick_s;
    const Vec3 w_dev = geom::rotationVector(q_dev * glm::conjugate(prev_q_dev_)) / p_.tick_s;
    const Vec3 w_prx = geom::rotationVector(q_prx * glm::conjugate(prev_q_prx_)) / p_.tick_s;
    v_rel = v_prx - v_dev;
    w_rel = w_prx - w_dev;
  }
  have_prev_ = true;
  prev_h_dev_ = h_dev_W;
  prev_h_prx_ = h_prx_W;
  prev_q_dev_ = q_dev;
  prev_q_prx_ = q_prx;
  Wrench w;
  w.force_n = p_.stiffness_n_per_m * (h_prx_W - h_dev_W) + p_.damping_n_s_per_m * v_rel;
  w.torque_nm = p_.rot_stiffness_nm_per_rad * geom::rotationVector(q_prx * glm::conjugate(q_dev)) +
                p_.rot_damping_nm_s_per_rad * w_rel;
  return w;
}

void VirtualCoupling::writeState(StateWriter& w) const {
  for (const double v : {p_.stiffness_n_per_m, p_.damping_n_s_per_m, p_.rot_stiffness_nm_per_rad,
                         p_.rot_damping_nm_s_per_rad, p_.tick_s})
    w.f64(v);
  w.flag(have_prev_);
  w.glm(prev_h_dev_);
  w.glm(prev_h_prx_);
  w.glm(prev_q_dev_);
  w.glm(prev_q_prx_);
}

}  // namespace hapticd::response
