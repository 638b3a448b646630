#include "client/pose_stream.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <istream>
#include <sstream>

namespace hapticd::client {
namespace {

constexpr const char* kColumns[] = {"t", "px", "py", "pz", "qx", "qy", "qz", "qw", "buttons"};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos)
    return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(trim(cur));
  return out;
}

std::string fmt(double v) {
  std::ostringstream o;
  o.precision(17);
  o << v;
  return o.str();
}

double dot4(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
}

std::array<double, 4> normalised(std::array<double, 4> q) {
  const double n = std::sqrt(dot4(q, q));
  for (double& c : q)
    c /= n;
  return q;
}

// Hamilton product a*b, (x, y, z, w) order.
std::array<double, 4> mul(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  return {a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
          a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
          a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
          a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2]};
}

// Angular velocity (scene frame) that takes q0 to q1 in dt: q1 = exp(w dt / 2) q0.
std::array<double, 3> angularVelocity(const std::array<double, 4>& q0,
                                      const std::array<double, 4>& q1,
                                      double dt) {
  std::array<double, 4> d = mul(q1, {-q0[0], -q0[1], -q0[2], q0[3]});
  if (d[3] < 0.0)
    for (double& c : d)
      c = -c;  // the shorter way round
  const double s = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (s < 1e-300)
    return {0.0, 0.0, 0.0};
  const double angle = 2.0 * std::atan2(s, d[3]);
  const double k = angle / (s * dt);
  return {d[0] * k, d[1] * k, d[2] * k};
}

}  // namespace

Result<std::vector<PoseSample>> parsePoseStream(std::istream& in, const std::string& name) {
  std::vector<PoseSample> rows;
  std::string line;
  std::size_t line_no = 0;
  auto fail = [&](const std::string& what) {
    return Error{name + ":" + std::to_string(line_no) + ": " + what};
  };
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#')
      continue;
    const auto f = split(t);
    if (f[0] == "t") {  // a header
      const bool ok =
          (f.size() == 8 || f.size() == 9) && std::equal(f.begin(), f.end(), std::begin(kColumns));
      if (!ok || !rows.empty())
        return fail(rows.empty() ? "header must be t,px,py,pz,qx,qy,qz,qw,buttons"
                                 : "a header after the first row");
      continue;
    }
    if (f.size() != 8 && f.size() != 9)
      return fail(
          "expected 9 columns t,px,py,pz,qx,qy,qz,qw,buttons (buttons may be left out), "
          "got " +
          std::to_string(f.size()));
    double v[8];
    for (std::size_t i = 0; i < 8; ++i) {
      const char* s = f[i].c_str();
      char* end = nullptr;
      errno = 0;
      v[i] = std::strtod(s, &end);
      if (f[i].empty() || end != s + f[i].size())
        return fail("column " + std::to_string(i + 1) + " (" + kColumns[i] + "): '" + f[i] +
                    "' is not a number");
      if (!std::isfinite(v[i]))
        return fail("column " + std::to_string(i + 1) + " (" + kColumns[i] + "): '" + f[i] +
                    "' is not finite");
    }
    PoseSample r;
    r.t_s = v[0];
    r.p_W = {v[1], v[2], v[3]};
    const std::array<double, 4> q{v[4], v[5], v[6], v[7]};
    const double n = std::sqrt(dot4(q, q));
    if (!(std::fabs(n - 1.0) <= kPoseStreamQuatTolerance))
      return fail("quaternion (" + f[4] + ", " + f[5] + ", " + f[6] + ", " + f[7] + ") has norm " +
                  fmt(n) + ", not 1 (within " + fmt(kPoseStreamQuatTolerance) + ")");
    r.q_W = normalised(q);
    if (f.size() == 9 && !f[8].empty()) {
      const char* s = f[8].c_str();
      char* end = nullptr;
      errno = 0;
      const unsigned long long b = std::strtoull(s, &end, 10);
      if (f[8][0] == '-' || end != s + f[8].size() || errno == ERANGE || b > 0xffffffffull)
        return fail("column 9 (buttons): '" + f[8] + "' is not an unsigned 32-bit integer");
      r.buttons = static_cast<std::uint32_t>(b);
    }
    if (!rows.empty() && !(r.t_s > rows.back().t_s))
      return fail("t " + f[0] + " is not after the previous row's t " + fmt(rows.back().t_s) +
                  " (t must increase)");
    rows.push_back(r);
  }
  if (rows.empty())
    return Error{name + ": no rows"};
  return rows;
}

std::array<double, 4> slerp(const std::array<double, 4>& q0,
                            const std::array<double, 4>& q1,
                            double u) {
  std::array<double, 4> b = q1;
  double c = dot4(q0, q1);
  if (c < 0.0) {  // q and -q are the same rotation: take the shorter arc
    for (double& x : b)
      x = -x;
    c = -c;
  }
  std::array<double, 4> out;
  if (c > 1.0 - 1e-12) {
    for (std::size_t i = 0; i < 4; ++i)
      out[i] = q0[i] + u * (b[i] - q0[i]);
    return normalised(out);
  }
  const double theta = std::acos(std::min(c, 1.0));
  const double s = std::sin(theta);
  const double w0 = std::sin((1.0 - u) * theta) / s;
  const double w1 = std::sin(u * theta) / s;
  for (std::size_t i = 0; i < 4; ++i)
    out[i] = w0 * q0[i] + w1 * b[i];
  return normalised(out);
}

PoseSample samplePoseStream(std::span<const PoseSample> rows, double t_s, std::size_t* hint) {
  if (t_s <= rows.front().t_s || rows.size() == 1) {
    PoseSample s = rows.front();
    s.v_W = s.w_W = {0.0, 0.0, 0.0};
    if (rows.size() > 1 && t_s == rows.front().t_s) {
      // exactly at the first row: the velocities of the first segment
      const PoseSample& b = rows[1];
      const double dt = b.t_s - s.t_s;
      for (std::size_t k = 0; k < 3; ++k)
        s.v_W[k] = (b.p_W[k] - s.p_W[k]) / dt;
      s.w_W = angularVelocity(s.q_W, b.q_W, dt);
    }
    s.t_s = t_s;
    return s;
  }
  if (t_s >= rows.back().t_s) {
    PoseSample s = rows.back();
    s.v_W = s.w_W = {0.0, 0.0, 0.0};
    s.t_s = t_s;
    return s;
  }
  // the segment [i, i+1] with t_i <= t < t_{i+1}
  std::size_t i = 0;
  if (hint != nullptr && *hint + 1 < rows.size() && rows[*hint].t_s <= t_s) {
    i = *hint;
  } else {
    const auto it = std::upper_bound(rows.begin(), rows.end(), t_s,
                                     [](double t, const PoseSample& r) { return t < r.t_s; });
    i = static_cast<std::size_t>(it - rows.begin()) - 1;
  }
  while (i + 2 < rows.size() && rows[i + 1].t_s <= t_s)
    ++i;
  if (hint != nullptr)
    *hint = i;
  const PoseSample& a = rows[i];
  const PoseSample& b = rows[i + 1];
  const double dt = b.t_s - a.t_s;
  PoseSample s;
  s.t_s = t_s;
  s.buttons = a.buttons;
  if (t_s == a.t_s) {
    s.p_W = a.p_W;
    s.q_W = a.q_W;
  } else {
    const double u = (t_s - a.t_s) / dt;
    for (std::size_t k = 0; k < 3; ++k)
      s.p_W[k] = a.p_W[k] + u * (b.p_W[k] - a.p_W[k]);
    s.q_W = slerp(a.q_W, b.q_W, u);
  }
  for (std::size_t k = 0; k < 3; ++k)
    s.v_W[k] = (b.p_W[k] - a.p_W[k]) / dt;
  s.w_W = angularVelocity(a.q_W, b.q_W, dt);
  return s;
}

}  // namespace hapticd::client
