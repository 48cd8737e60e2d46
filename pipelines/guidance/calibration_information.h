// What a set of target views tells about the unknowns, kept in the form
// that mrcal's "mean-frames" projection uncertainty needs: the information
// on the unknowns with every view's pose marginalised out, and sums over
// the views of their poses' covariance blocks and of how each pose estimate
// moves with the unknowns. Everything is a sum over views, so the
// information of two sets of views is the sum of theirs (a candidate view
// is scored as kept + candidate).
//
// Why the sums suffice: mrcal maps a camera point p into every view's
// target frame with the solved pose, back with the perturbed pose, and
// averages the results. To first order that compensation is
// (1/N) sum_i D_i(p) dpose_i, with D_i = [-2 [p - t_i]x, I] in the tangent
// of portcal's pose block (Eigen's quaternion manifold, whose step delta
// turns by 2 |delta|, then the translation), t_i the view's translation.
// Each pose estimate is dpose_i = -K_i du + e_i, with K_i = B_i^-1 C_i^T
// (B_i the pose's information, C_i the unknowns-pose block) and e_i of
// covariance B_i^-1, independent of the unknowns' estimate. D_i is affine
// in t_i, so the sums below over i of K_i, [t_i]x K_i, B_i^-1 and their
// products with [t_i]x give the compensation at any p in O(1).
#pragma once

#include <Eigen/Core>

namespace portcal {

struct CalibrationInformation {
  // Gauss-Newton information (J'J, unit pixel variance) on the unknowns,
  // every view's pose marginalised out (sum of A_i - C_i B_i^-1 C_i^T).
  Eigen::MatrixXd reduced;
  int num_views = 0;  // views whose pose the points fix
  // Sums over views; K = B^-1 C^T split into its rotation (r) and
  // translation (t) rows, T_i = 2 [t_i]x, P = B^-1 in 3x3 blocks.
  Eigen::MatrixXd k_rotation;                          // 3 x p: sum K_r
  Eigen::MatrixXd k_offset;                            // 3 x p: sum (T_i K_r + K_t)
  Eigen::Matrix3d p_rr = Eigen::Matrix3d::Zero();      // sum P_rr
  Eigen::Matrix3d p_rr_t = Eigen::Matrix3d::Zero();    // sum P_rr T_i^T
  Eigen::Matrix3d t_p_rr_t = Eigen::Matrix3d::Zero();  // sum T_i P_rr T_i^T
  Eigen::Matrix3d p_rt = Eigen::Matrix3d::Zero();      // sum P_rt
  Eigen::Matrix3d t_p_rt = Eigen::Matrix3d::Zero();    // sum T_i P_rt
  Eigen::Matrix3d p_tt = Eigen::Matrix3d::Zero();      // sum P_tt

  // No views, `num_unknowns` unknowns.
  static CalibrationInformation Zero(int num_unknowns);
  // One view from its pose-pose (6 x 6, tangent: rotation, translation),
  // unknowns-unknowns (p x p) and unknowns-pose (p x 6) information blocks
  // and its target-to-camera translation. An empty result (no views) when
  // the pose block is singular: the points do not fix the pose.
  static CalibrationInformation OfView(const Eigen::MatrixXd& pose_pose,
                                       const Eigen::MatrixXd& unknowns_unknowns,
                                       const Eigen::MatrixXd& unknowns_pose,
                                       const Eigen::Vector3d& translation);

  int NumUnknowns() const { return static_cast<int>(reduced.rows()); }
  CalibrationInformation& operator+=(const CalibrationInformation& other);
  CalibrationInformation operator+(const CalibrationInformation& other) const;

  // (1/N) sum_i D_i(p) K_i (3 x p) and (1/N^2) sum_i D_i(p) B_i^-1 D_i(p)^T
  // (3 x 3) at camera point `p`: the frames' compensation of the unknowns'
  // error and the frames' own noise, both as motions of the point.
  Eigen::MatrixXd MeanFrameGain(const Eigen::Vector3d& p) const;
  Eigen::Matrix3d MeanFrameNoise(const Eigen::Vector3d& p) const;
};

}  // namespace portcal
