// Pictures of a calibration's geometry, to scale: is the housing plausible,
// is the rig or the reconstruction sane.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/housing/housing.h"

namespace portcal {

// The housing to scale, from above (x right, z forward) and from the side
// (z forward, y down): the camera's centre, its axis, and the dome's
// spheres and offset, or the flat port's glass and normal.
cv::Mat HousingPicture(const Housing& housing);

// A stereo rig from above: both cameras (centres, axes, fields of view) and
// where the target was in each frame.
cv::Mat RigFromAbovePicture(const Camera& camera1, const Rigid3d& cam2_from_cam1,
                            const std::vector<Rigid3d>& cam1_from_target);

// A reconstruction from above (its two widest axes): points and cameras.
cv::Mat SceneFromAbovePicture(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Rigid3d>& cam_from_world, const std::string& title);

}  // namespace portcal
