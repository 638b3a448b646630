#include "core/response/shading.h"

#include <algorithm>
#include <cmath>

#include "core/response/face_contact.h"

namespace hapticd::response {

using geom::Vec3;

ShadingTable::ShadingTable(const Polytope& shape, double crease_angle_rad) {
  const double cos_crease = std::cos(crease_angle_rad);
  const auto faces = shape.faces();
  first_.resize(faces.size());
  any_smooth_.assign(faces.size(), 0);
  edge_smooth_.assign(shape.edges().size(), 0);
  for (std::size_t e = 0; e < shape.edges().size(); ++e) {
    const auto& edge = shape.edges()[e];
    edge_smooth_[e] =
        glm::dot(faces[edge.face[0]].normal, faces[edge.face[1]].normal) > cos_crease ? 1 : 0;
  }
  for (std::uint32_t f = 0; f < faces.size(); ++f) {
    first_[f] = static_cast<std::uint32_t>(face_edges_.size());
    Vec3 centroid{0.0};
    const auto fes = shape.faceEdges(f);
    for (const auto& fe : fes)
      centroid += shape.vertices()[fe.vertex].p;
    centroid /= static_cast<double>(fes.size());
    for (const auto& fe : fes) {
      const auto& e = shape.edges()[fe.edge];
      EdgeInfo info;
      info.neighbour = e.face[0] == f ? e.face[1] : e.face[0];
      info.inset = glm::dot(centroid - shape.vertices()[fe.vertex].p, fe.side);
      info.smooth =
          info.inset > 0.0 && glm::dot(faces[f].normal, faces[info.neighbour].normal) > cos_crease;
      if (info.smooth) {
        any_smooth_[f] = 1;
        ++smooth_edges_;
      }
      face_edges_.push_back(info);
    }
  }
  smooth_edges_ /= 2;  // each edge seen from both faces
}

Vec3 ShadingTable::shadedNormal(const Polytope& shape,
                                const Vec3& x_P,
                                const Vec3& n_P,
                                Feature feature) const {
  // on a crease, or a vertex of one, the contact's normal stays its own
  if (feature.type == geom::FeatureType::kEdge && !edge_smooth_[feature.index])
    return n_P;
  if (feature.type == geom::FeatureType::kVertex) {
    for (const auto& ve : shape.vertexEdges(feature.index)) {
      if (!edge_smooth_[ve.edge])
        return n_P;
    }
  }
  const std::uint32_t f = bestFace(shape, n_P, feature);
  if (!any_smooth_[f])
    return n_P;
  return shadedNormalOnFace(shape, f, x_P);
}

Vec3 ShadingTable::shadedNormalOnFace(const Polytope& shape,
                                      std::uint32_t f,
                                      const Vec3& x_P) const {
  if (!any_smooth_[f])
    return shape.faces()[f].normal;
  const auto faces = shape.faces();
  const Vec3 nf = faces[f].normal;
  Vec3 n = nf;
  const auto fes = shape.faceEdges(f);
  for (std::size_t k = 0; k < fes.size(); ++k) {
    const EdgeInfo& info = face_edges_[first_[f] + k];
    if (!info.smooth)
      continue;
    const double s = glm::dot(x_P - shape.vertices()[fes[k].vertex].p, fes[k].side);
    const double t = std::clamp(s / info.inset, 0.0, 1.0);
    n += 0.5 * (1.0 - t) * (faces[info.neighbour].normal - nf);
  }
  const double l = std::sqrt(glm::dot(n, n));
  return l > 0.0 ? n / l : nf;
}

}  // namespace hapticd::response
