#include "core/response/face_contact.h"

#include <cmath>

namespace hapticd::response {

std::uint32_t bestFace(const Polytope& shape, const Vec3& n_P, Feature feature) {
  const auto faces = shape.faces();
  std::uint32_t best = 0;
  double best_dot = -2.0;
  auto consider = [&](std::uint32_t f) {
    const double d = glm::dot(faces[f].normal, n_P);
    if (d > best_dot)
      best_dot = d, best = f;
  };
  auto aroundVertex = [&](std::uint32_t v) {
    for (const auto& ve : shape.vertexEdges(v)) {
      consider(shape.edges()[ve.edge].face[0]);
      consider(shape.edges()[ve.edge].face[1]);
    }
  };
  switch (feature.type) {
    case geom::FeatureType::kFace:
      return feature.index;
    case geom::FeatureType::kEdge:
      consider(shape.edges()[feature.index].face[0]);
      consider(shape.edges()[feature.index].face[1]);
      return best;
    case geom::FeatureType::kVertex:
      aroundVertex(feature.index);
      return best;
    case geom::FeatureType::kNone:
      aroundVertex(shape.support(n_P, shape.lookup(n_P)));
      return best;
  }
  return best;
}

bool faceContact(const Polytope& env,
                 const Transform& X_WE,
                 Feature env_feature,
                 const Polytope& held,
                 const Transform& X_WH,
                 Feature held_feature,
                 const Vec3& n_out_W,
                 double cos_tolerance,
                 FaceContact* out) {
  const Vec3 n_E = glm::transpose(X_WE.R) * n_out_W;
  const Vec3 n_H = glm::transpose(X_WH.R) * (-n_out_W);
  const std::uint32_t fe = bestFace(env, n_E, env_feature);
  const std::uint32_t fh = bestFace(held, n_H, held_feature);
  const auto& face_e = env.faces()[fe];
  const auto& face_h = held.faces()[fh];
  if (glm::dot(face_e.normal, n_E) < cos_tolerance)
    return false;
  if (glm::dot(face_h.normal, n_H) < cos_tolerance)
    return false;
  const auto edges_h = held.faceEdges(fh);
  if (edges_h.size() > FaceContact::kMaxPoints / 2)
    return false;
  // the held face in the environment primitive's frame
  const Transform X_EH = X_WE.inverse() * X_WH;
  std::array<Vec3, FaceContact::kMaxPoints> a{}, b{};
  std::size_t na = 0;
  for (const auto& fe_h : edges_h)
    a[na++] = X_EH.apply(held.vertices()[fe_h.vertex].p);
  // clip against each side plane of the environment's face: (x - v) . side >= 0 inside
  for (const auto& side : env.faceEdges(fe)) {
    const Vec3 v = env.vertices()[side.vertex].p;
    std::size_t nb = 0;
    for (std::size_t i = 0; i < na; ++i) {
      const Vec3& p = a[i];
      const Vec3& q = a[(i + 1) % na];
      const double dp = glm::dot(p - v, side.side), dq = glm::dot(q - v, side.side);
      if (dp >= 0.0 && nb < b.size())
        b[nb++] = p;
      if ((dp >= 0.0) != (dq >= 0.0) && nb < b.size())
        b[nb++] = p + (q - p) * (dp / (dp - dq));
    }
    if (nb == 0)
      return false;
    if (nb >= b.size())
      return false;  // would not fit: keep the manifold
    a = b;
    na = nb;
  }
  out->count = 0;
  for (std::size_t i = 0; i < na; ++i) {
    out->p_W[out->count] = X_WE.apply(a[i]);
    out->gap[out->count] = glm::dot(face_e.normal, a[i]) - face_e.offset;
    ++out->count;
  }
  out->n_W = X_WE.rotate(face_e.normal);
  out->env_face = fe;
  return out->count > 0;
}

}  // namespace hapticd::response
