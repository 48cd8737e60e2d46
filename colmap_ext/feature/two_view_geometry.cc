#include "colmap_ext/feature/two_view_geometry.h"

#include <utility>

namespace portcal {

TwoViewGeometry TwoViewGeometry::Inverse() const {
  TwoViewGeometry inverse = *this;
  inverse.F = F.transpose();
  inverse.E = E.transpose();
  if (H.determinant() != 0) inverse.H = H.inverse();
  inverse.cam2_from_cam1 = cam2_from_cam1.Inverse();
  for (FeatureMatch& match : inverse.inlier_matches) {
    std::swap(match.point2D_idx1, match.point2D_idx2);
  }
  return inverse;
}

}  // namespace portcal
