#include "core/response/proxy.h"

#include <algorithm>
#include <cmath>

namespace hapticd::response {
namespace {

using Mat6 = std::array<std::array<double, 6>, 6>;
using Vec6 = std::array<double, 6>;
constexpr std::size_t kMaxDofs = 6 + ProxyProblem::kMaxDriven;
using MatN = std::array<std::array<double, kMaxDofs>, kMaxDofs>;
using VecN = std::array<double, kMaxDofs>;

constexpr std::size_t kMaxPasses = 16;

Vec6 rowJacobian(const ContactRow& r, const Vec3& c_W) {
  const Vec3 t = glm::cross(r.p_W - c_W, r.n_W);
  return {r.n_W.x, r.n_W.y, r.n_W.z, t.x, t.y, t.z};
}

double dot6(const Vec6& a, const Vec6& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < 6; ++i)
    s += a[i] * b[i];
  return s;
}

// Solves A x = b for the leading n x n block of a symmetric positive definite A (Cholesky).
// Returns false (x untouched) if A is not positive definite.
bool choleskySolve(MatN A, VecN b, std::size_t n, VecN* x) {
  for (std::size_t j = 0; j < n; ++j) {
    double d = A[j][j];
    for (std::size_t k = 0; k < j; ++k)
      d -= A[j][k] * A[j][k];
    if (!(d > 0.0))
      return false;
    const double l = std::sqrt(d);
    A[j][j] = l;
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = A[i][j];
      for (std::size_t k = 0; k < j; ++k)
        s -= A[i][k] * A[j][k];
      A[i][j] = s / l;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    double s = b[i];
    for (std::size_t k = 0; k < i; ++k)
      s -= A[i][k] * b[k];
    b[i] = s / A[i][i];
  }
  for (std::size_t ii = n; ii-- > 0;) {
    double s = b[ii];
    for (std::size_t k = ii + 1; k < n; ++k)
      s -= A[k][ii] * b[k];
    b[ii] = s / A[ii][ii];
  }
  for (std::size_t i = 0; i < n; ++i)
    (*x)[i] = b[i];
  return true;
}

Vec3 clampLength(const Vec3& v, double max_length) {
  const double l = std::sqrt(glm::dot(v, v));
  return l > max_length ? v * (max_length / l) : v;
}

// the coupling's stretch that pulls the proxy, clamped (see couplingReach in proxy.h)
Vec3 linearPull(const ProxyProblem& pb, const ProxyParams& params) {
  return clampLength(pb.h_target_W - pb.h_W, couplingReach(params, pb.radius).linear);
}

Vec3 angularPull(const ProxyProblem& pb, const ProxyParams& params) {
  return clampLength(geom::rotationVector(pb.q_target * glm::conjugate(pb.q_handle)),
                     couplingReach(params, pb.radius).angular);
}

}  // namespace

ProxyBasis ProxyBasis::free() {
  ProxyBasis b;
  b.dofs = 6;
  for (std::size_t i = 0; i < 6; ++i)
    b.column[i][i] = 1.0;
  return b;
}

ProxyBasis ProxyBasis::hinge(const Vec3& o_W, const Vec3& a_W, const Vec3& c_W) {
  ProxyBasis b;
  b.dofs = 1;
  const Vec3 v = glm::cross(a_W, c_W - o_W);  // velocity of c per unit angular rate
  b.column[0] = {v.x, v.y, v.z, a_W.x, a_W.y, a_W.z};
  return b;
}

CouplingReach couplingReach(const ProxyParams& params, double radius) {
  CouplingReach r;
  const double kc = params.coupling_stiffness, kr = params.rot_coupling_stiffness;
  r.linear = std::max(params.max_force_n / kc, 2.0 * params.max_travel);
  r.angular = params.max_torque_nm / kr;
  if (radius > 0.0)
    r.angular = std::max(r.angular, 2.0 * params.max_travel / radius);
  return r;
}

void ContactRows::writeState(StateWriter& w) const {
  w.integer(rows_.size());
  for (const ContactRow& r : rows_) {
    w.glm(r.p_W);
    w.glm(r.n_W);
    w.f64(r.gap);
    w.f64(r.stiffness);
    w.integer(r.first);
    w.integer(r.second);
    w.f64(r.mu_s);
    w.f64(r.mu_d);
  }
  w.integer(capacity_);
  w.flag(full_);
}

Wrench penaltyWrench(std::span<const ContactRow> rows, const Vec3& c_W, double delta) {
  Wrench w;
  for (const ContactRow& r : rows) {
    if (r.gap >= delta || r.first >= 0)
      continue;
    const Vec3 f = r.stiffness * (delta - r.gap) * r.n_W;
    w.force_n += f;
    w.torque_nm += glm::cross(r.p_W - c_W, f);
  }
  return w;
}

namespace {

// the rows the solver holds, with each row's generalised Jacobian (how its gap changes with
// every coordinate) and whether it is in the active set
struct RowSystem {
  std::size_t nr = 0;
  std::array<VecN, kMaxRows> g;
  std::array<std::uint8_t, kMaxRows> active{};
};

// the coupling part of the 6 x 6 system about c: a linear spring at the handle h and a
// rotational spring; its force is clamped to the device limits
void couplingSystem(const ProxyProblem& pb, const ProxyParams& params, Mat6& A0, Vec6& b0) {
  const double kc = params.coupling_stiffness, kr = params.rot_coupling_stiffness;
  const Vec3 e_lin = linearPull(pb, params);
  const Vec3 e_rot = angularPull(pb, params);
  {
    // handle displacement = dc + dtheta x r = dc - [r]x dtheta, r = h - c
    Vec6 jx[3];
    const Vec3 r = pb.h_W - pb.c_W;
    for (int k = 0; k < 3; ++k) {
      Vec3 ek{0.0};
      ek[k] = 1.0;
      const Vec3 t = glm::cross(r, ek);  // row k of -[r]x is (r x e_k)
      jx[k] = pb.handle_fixed ? Vec6{} : Vec6{ek.x, ek.y, ek.z, t.x, t.y, t.z};
    }
    for (std::size_t i = 0; i < 6; ++i) {
      for (std::size_t j = 0; j < 6; ++j) {
        double s = 0.0;
        for (int k = 0; k < 3; ++k)
          s += jx[k][i] * jx[k][j];
        A0[i][j] = kc * s;
      }
      for (int k = 0; k < 3; ++k)
        b0[i] += kc * jx[k][i] * e_lin[k];
    }
    for (std::size_t i = 0; i < 3; ++i) {
      A0[3 + i][3 + i] += kr;
      b0[3 + i] += kr * e_rot[static_cast<int>(i)];
    }
  }
}

// the system in the free coordinates: (S^T A0 S), S^T b0, then each driven hinge's drag
void freeSystem(const ProxyProblem& pb,
                const Mat6& A0,
                const Vec6& b0,
                std::size_t nd,
                MatN& Ac,
                VecN& bc) {
  const ProxyBasis& S = pb.basis;
  const std::size_t nh = S.dofs;
  for (std::size_t p = 0; p < nh; ++p) {
    for (std::size_t q = 0; q < nh; ++q) {
      double s = 0.0;
      for (std::size_t a = 0; a < 6; ++a) {
        double t = 0.0;
        for (std::size_t c = 0; c < 6; ++c)
          t += A0[a][c] * S.column[q][c];
        s += S.column[p][a] * t;
      }
      Ac[p][q] = s;
    }
    bc[p] = dot6(S.column[p], b0);
  }
  for (std::size_t d = 0; d < nd; ++d)
    Ac[nh + d][nh + d] += pb.driven[d].drag;
}

// each row's generalised Jacobian; active: the rows within delta now
void rowSystem(const ProxyProblem& pb,
               std::span<const ContactRow> rows,
               const ProxyParams& params,
               std::size_t nd,
               RowSystem& rs) {
  const ProxyBasis& S = pb.basis;
  const std::size_t nh = S.dofs;
  const std::size_t nr = rs.nr;
  auto& g = rs.g;
  auto& active = rs.active;
  for (std::size_t i = 0; i < nr; ++i) {
    const ContactRow& row = rows[i];
    g[i] = VecN{};
    // the first side moving along n opens the gap; the second side moving along n closes it
    auto hingeRate = [&](std::int32_t d) {
      const DrivenHinge& h = pb.driven[static_cast<std::size_t>(d)];
      return glm::dot(glm::cross(h.a_W, row.p_W - h.o_W), row.n_W);
    };
    if (row.first < 0) {
      const Vec6 J = rowJacobian(row, pb.c_W);
      for (std::size_t q = 0; q < nh; ++q)
        g[i][q] = dot6(J, S.column[q]);
    } else if (static_cast<std::size_t>(row.first) < nd) {
      g[i][nh + static_cast<std::size_t>(row.first)] += hingeRate(row.first);
    }
    if (row.second >= 0 && static_cast<std::size_t>(row.second) < nd) {
      g[i][nh + static_cast<std::size_t>(row.second)] -= hingeRate(row.second);
    }
    active[i] = rows[i].gap < params.delta ? 1 : 0;
  }
}

// the active set: rows within delta now; passes add rows that would come within delta and drop
// rows that would pull. Returns the step in the coordinates.
VecN solveActiveSet(std::span<const ContactRow> rows,
                    const ProxyParams& params,
                    const MatN& Ac,
                    const VecN& bc,
                    std::size_t n,
                    RowSystem& rs,
                    ProxyStep& out) {
  const std::size_t nr = rs.nr;
  const auto& g = rs.g;
  auto& active = rs.active;
  VecN x{};
  const std::size_t passes =
      std::min<std::size_t>(std::max<std::uint32_t>(params.max_passes, 1), kMaxPasses);
  for (std::size_t pass = 0; pass < passes; ++pass) {
    ++out.passes;
    MatN A = Ac;
    VecN b = bc;
    for (std::size_t i = 0; i < nr; ++i) {
      if (!active[i])
        continue;
      const double k = rows[i].stiffness;
      const double f = k * (params.delta - rows[i].gap);
      for (std::size_t p = 0; p < n; ++p) {
        if (g[i][p] == 0.0)
          continue;
        for (std::size_t q = 0; q < n; ++q)
          A[p][q] += k * g[i][p] * g[i][q];
        b[p] += f * g[i][p];
      }
    }
    VecN xs{};
    if (!choleskySolve(A, b, n, &xs))
      xs = VecN{};
    x = xs;
    bool changed = false;
    for (std::size_t i = 0; i < nr; ++i) {
      double gp = rows[i].gap;
      for (std::size_t p = 0; p < n; ++p)
        gp += g[i][p] * x[p];
      const bool want = gp < params.delta;
      if (want != static_cast<bool>(active[i])) {
        active[i] = want ? 1 : 0;
        changed = true;
      }
    }
    if (!changed)
      break;
  }
  for (std::size_t i = 0; i < nr; ++i)
    out.active += active[i];
  return x;
}

// Coulomb friction on the translation of a freely held set (see the file comment of proxy.h):
// stick inside the cone, slide on its edge
void applyFriction(const ProxyProblem& pb,
                   std::span<const ContactRow> rows,
                   const ProxyParams& params,
                   const RowSystem& rs,
                   std::size_t n,
                   VecN& x,
                   ProxyStep& out) {
  if (pb.basis.dofs != 6)
    return;
  Vec3 n_sum{0.0};
  double f_sum = 0.0, mus = 0.0, mud = 0.0;
  for (std::size_t i = 0; i < rs.nr; ++i) {
    const ContactRow& r = rows[i];
    if (!rs.active[i] || r.first >= 0)
      continue;
    double gp = r.gap;
    for (std::size_t p = 0; p < n; ++p)
      gp += rs.g[i][p] * x[p];
    const double f = r.stiffness * (params.delta - gp);
    if (!(f > 0.0))
      continue;
    n_sum += f * r.n_W;
    f_sum += f;
    mus += f * r.mu_s;
    mud += f * r.mu_d;
  }
  const double N = std::sqrt(glm::dot(n_sum, n_sum));
  if (!(f_sum > 0.0 && N > 0.0) || !(mus > 0.0 || mud > 0.0))
    return;
  mus /= f_sum;
  mud /= f_sum;
  const Vec3 nb = n_sum / N;
  const double kc = params.coupling_stiffness;
  const Vec3 e = linearPull(pb, params);
  const Vec3 e_t = e - glm::dot(e, nb) * nb;
  const double pull = kc * std::sqrt(glm::dot(e_t, e_t));  // tangential, were it not to slide
  const Vec3 dc{x[0], x[1], x[2]};
  const Vec3 dc_n = glm::dot(dc, nb) * nb;
  const Vec3 dc_t = dc - dc_n;
  out.normal_force_n = N;
  const double limit = (pb.sliding ? mud : mus) * N;
  Vec3 moved = dc_n;
  if (pull <= limit) {
    out.stuck = true;
    out.friction_force_n = pull;
  } else {
    out.sliding = true;
    out.friction_force_n = mud * N;
    moved += dc_t * (1.0 - mud * N / pull);
  }
  x[0] = moved.x;
  x[1] = moved.y;
  x[2] = moved.z;
}

// the step's motion, scaled so that no point of the held set, nor of a driven body, moves
// farther than max_travel (the safe distance)
void finishStep(const ProxyProblem& pb,
                const ProxyParams& params,
                const VecN& x,
                std::size_t nd,
                ProxyStep& out) {
  const ProxyBasis& S = pb.basis;
  const std::size_t nh = S.dofs;
  Vec6 twist{};
  for (std::size_t q = 0; q < nh; ++q) {
    for (std::size_t a = 0; a < 6; ++a)
      twist[a] += S.column[q][a] * x[q];
  }
  Vec3 dc{twist[0], twist[1], twist[2]}, dth{twist[3], twist[4], twist[5]};
  double travel = std::sqrt(glm::dot(dc, dc)) + std::sqrt(glm::dot(dth, dth)) * pb.radius;
  for (std::size_t d = 0; d < nd; ++d)
    travel = std::max(travel, std::abs(x[nh + d]) * pb.driven[d].radius);
  double scale = 1.0;
  if (travel > params.max_travel) {
    scale = params.max_travel / travel;
    out.travel_limited = true;
  }
  out.dc_W = dc * scale;
  out.dtheta_W = dth * scale;
  for (std::size_t q = 0; q < nh; ++q)
    out.x[q] = x[q] * scale;
  for (std::size_t d = 0; d < nd; ++d)
    out.driven_angle[d] = x[nh + d] * scale;
}

}  // namespace

ProxyStep solveProxyStep(const ProxyProblem& pb,
                         std::span<const ContactRow> rows,
                         const ProxyParams& params) {
  ProxyStep out;
  const std::size_t nh = pb.basis.dofs;
  const std::size_t nd = std::min<std::size_t>(pb.driven_count, ProxyProblem::kMaxDriven);
  const std::size_t n = nh + nd;
  Mat6 A0{};
  Vec6 b0{};
  couplingSystem(pb, params, A0, b0);
  MatN Ac{};
  VecN bc{};
  freeSystem(pb, A0, b0, nd, Ac, bc);
  RowSystem rs;
  rs.nr = std::min(rows.size(), kMaxRows);
  out.rows_dropped = rows.size() > kMaxRows;
  rowSystem(pb, rows, params, nd, rs);
  VecN x = solveActiveSet(rows, params, Ac, bc, n, rs, out);
  applyFriction(pb, rows, params, rs, n, x, out);
  finishStep(pb, params, x, nd, out);
  return out;
}

}  // namespace hapticd::response
