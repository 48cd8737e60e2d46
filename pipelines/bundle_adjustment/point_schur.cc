#include "pipelines/bundle_adjustment/point_schur.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cstdint>
#include <exception>
#include <thread>

#include "colmap_ext/util/error.h"

namespace portcal {

// One residual block at the solution: its residual (without the loss) and
// its Jacobians in tangent coordinates, the point's and each other block's.
struct PointSchurComplement::Linearised {
  Eigen::VectorXd residual;
  Eigen::Matrix<double, Eigen::Dynamic, 3> point;       // rows x 3; no rows without a point
  std::vector<std::pair<int, Eigen::MatrixXd>> others;  // (other block, rows x its tangent)
};

// One point's sums over its residual blocks: H_pp, H_pc by other block, and
// H_pp's pseudo-inverse.
struct PointSchurComplement::PointBlocks {
  Eigen::Matrix3d point_point = Eigen::Matrix3d::Zero();
  std::vector<std::pair<int, Eigen::Matrix<double, 3, Eigen::Dynamic>>> point_other;
  Eigen::Matrix3d pinv = Eigen::Matrix3d::Zero();
};

namespace {

// Pseudo-inverse of a point's 3x3 information: a direction the views do
// not fix (nearly parallel rays) adds nothing instead of infinity.
Eigen::Matrix3d PseudoInverse(const Eigen::Matrix3d& information) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(information);
  const Eigen::Vector3d values = eig.eigenvalues();
  Eigen::Vector3d inverse = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    if (values(k) > 1e-12 * values(2)) inverse(k) = 1.0 / values(k);
  }
  return eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

// Runs work(begin, end, thread) on `num_threads` threads over contiguous
// ranges of [0, count); the first exception is rethrown after all ended.
void ForEachRange(size_t count, int num_threads,
                  const std::function<void(size_t, size_t, int)>& work) {
  const size_t threads =
      std::max<size_t>(1, std::min<size_t>(static_cast<size_t>(num_threads), count));
  if (threads == 1) return work(0, count, 0);
  std::vector<std::exception_ptr> errors(threads);
  std::vector<std::thread> running;
  for (size_t t = 0; t < threads; ++t) {
    running.emplace_back([&, t] {
      try {
        work(count * t / threads, count * (t + 1) / threads, static_cast<int>(t));
      } catch (...) {
        errors[t] = std::current_exception();
      }
    });
  }
  for (std::thread& thread : running) thread.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

void AddPair(int a, int b, const Eigen::MatrixXd& value,
             std::unordered_map<uint64_t, Eigen::MatrixXd>* pairs) {
  if (a > b) return AddPair(b, a, value.transpose(), pairs);
  const uint64_t key = (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b);
  const auto [it, inserted] = pairs->try_emplace(key);
  if (inserted) {
    it->second = value;
  } else {
    it->second += value;
  }
}

}  // namespace

PointSchurComplement::PointSchurComplement(ceres::Problem* problem,
                                           const std::vector<double*>& points,
                                           const std::vector<double*>& others, int num_threads)
    : problem_(problem), num_threads_(std::max(1, num_threads)) {
  IndexBlocks(points, others);
  GroupByPoint(points.size());
  // Each thread sums its points' shares of S; the sums are added after.
  squared_norms_.assign(residual_blocks_.size(), 0.0);
  std::vector<PairBlocks> pairs(static_cast<size_t>(num_threads_));
  ForEachRange(points.size() + 1, num_threads_, [&](size_t begin, size_t end, int thread) {
    std::vector<Linearised> linearised;
    for (size_t p = begin; p < end; ++p)
      Reduce(p, &linearised, &pairs[static_cast<size_t>(thread)]);
  });
  for (size_t t = 1; t < pairs.size(); ++t) {
    for (const auto& [key, value] : pairs[t]) {
      const auto [it, inserted] = pairs[0].try_emplace(key, value);
      if (!inserted) it->second += value;
    }
    pairs[t] = {};
  }
  Assemble(pairs[0]);
}

void PointSchurComplement::IndexBlocks(const std::vector<double*>& points,
                                       const std::vector<double*>& others) {
  for (size_t p = 0; p < points.size(); ++p) {
    PORTCAL_CHECK_MSG(
        problem_->ParameterBlockTangentSize(points[p]) == 3 && !problem_->GetManifold(points[p]),
        "a marginalised point must be a plain 3-vector");
    point_index_[points[p]] = static_cast<int>(p);
  }
  for (double* block : others) {
    other_index_[block] = static_cast<int>(start_.size());
    const int tangent = problem_->ParameterBlockTangentSize(block);
    const int ambient = problem_->ParameterBlockSize(block);
    Eigen::MatrixXd plus;
    if (const ceres::Manifold* manifold = problem_->GetManifold(block)) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jacobian(ambient,
                                                                                      tangent);
      manifold->PlusJacobian(block, jacobian.data());
      plus = jacobian;
    }
    start_.push_back(num_columns_);
    size_.push_back(tangent);
    plus_.push_back(std::move(plus));
    offset_[block] = num_columns_;
    num_columns_ += tangent;
  }
  if (num_columns_ == 0) throw NumericalError("covariance: no free parameters");
}

// The residual blocks by point (a counting sort), those of no point last.
void PointSchurComplement::GroupByPoint(size_t num_points) {
  problem_->GetResidualBlocks(&residual_blocks_);
  std::vector<size_t> point_of(residual_blocks_.size(), num_points);
  std::vector<double*> blocks;
  first_.assign(num_points + 2, 0);
  for (size_t k = 0; k < residual_blocks_.size(); ++k) {
    problem_->GetParameterBlocksForResidualBlock(residual_blocks_[k], &blocks);
    for (double* block : blocks) {
      const auto it = point_index_.find(block);
      if (it == point_index_.end()) continue;
      PORTCAL_CHECK_MSG(point_of[k] == num_points, "a residual touches two marginalised points");
      point_of[k] = static_cast<size_t>(it->second);
    }
    ++first_[point_of[k] + 1];
  }
  for (size_t p = 0; p <= num_points; ++p) first_[p + 1] += first_[p];
  by_point_.resize(residual_blocks_.size());
  std::vector<size_t> next(first_.begin(), first_.end() - 1);
  for (size_t k = 0; k < residual_blocks_.size(); ++k) by_point_[next[point_of[k]]++] = k;
}

// S from its blocks, both triangles.
void PointSchurComplement::Assemble(const PairBlocks& pairs) {
  std::vector<Eigen::Triplet<double>> entries;
  for (const auto& [key, value] : pairs) {
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    for (Eigen::Index i = 0; i < value.rows(); ++i) {
      for (Eigen::Index j = 0; j < value.cols(); ++j) {
        entries.emplace_back(start_[a] + i, start_[b] + j, value(i, j));
        if (a != b) entries.emplace_back(start_[b] + j, start_[a] + i, value(i, j));
      }
    }
  }
  reduced_.resize(num_columns_, num_columns_);
  reduced_.setFromTriplets(entries.begin(), entries.end());
}

void PointSchurComplement::Linearise(size_t block, Linearised* out) const {
  const ceres::ResidualBlockId id = residual_blocks_[block];
  const ceres::CostFunction* cost = problem_->GetCostFunctionForResidualBlock(id);
  std::vector<double*> blocks;
  problem_->GetParameterBlocksForResidualBlock(id, &blocks);
  const int rows = cost->num_residuals();
  using Jacobian = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<Jacobian> ambient(blocks.size());
  std::vector<double*> jacobians(blocks.size(), nullptr);
  std::vector<int> other(blocks.size(), -1);  // other block index; -1 held or the point
  std::vector<bool> is_point(blocks.size(), false);
  for (size_t i = 0; i < blocks.size(); ++i) {
    if (const auto it = other_index_.find(blocks[i]); it != other_index_.end()) {
      other[i] = it->second;
    } else if (point_index_.count(blocks[i])) {
      is_point[i] = true;
    } else {
      continue;  // held: no columns
    }
    ambient[i].resize(rows, cost->parameter_block_sizes()[i]);
    jacobians[i] = ambient[i].data();
  }
  out->residual.resize(rows);
  out->point.resize(0, 3);
  out->others.clear();
  bool finite = cost->Evaluate(blocks.data(), out->residual.data(), jacobians.data()) &&
                out->residual.allFinite();
  for (size_t i = 0; i < blocks.size() && finite; ++i) {
    finite = ambient[i].allFinite();
    if (is_point[i]) out->point = ambient[i];
    if (other[i] < 0) continue;
    const Eigen::MatrixXd& plus = plus_[static_cast<size_t>(other[i])];
    out->others.emplace_back(
        other[i], plus.size() ? Eigen::MatrixXd(ambient[i] * plus) : Eigen::MatrixXd(ambient[i]));
  }
  if (!finite)
    throw NumericalError("covariance: the residuals cannot be evaluated at the solution");
}

// Linearises the residual blocks of `point` (num_points: those of no point)
// and sums the point's blocks of J'J.
void PointSchurComplement::AccumulatePoint(size_t point, std::vector<Linearised>* linearised,
                                           PointBlocks* local) const {
  const size_t begin = first_[point], end = first_[point + 1];
  linearised->resize(end - begin);
  *local = PointBlocks();
  for (size_t k = begin; k < end; ++k) {
    Linearised& block = (*linearised)[k - begin];
    Linearise(by_point_[k], &block);
    if (block.point.rows() == 0) continue;
    local->point_point += block.point.transpose() * block.point;
    for (const auto& [other, jacobian] : block.others) {
      auto it = std::find_if(local->point_other.begin(), local->point_other.end(),
                             [other = other](const auto& entry) { return entry.first == other; });
      if (it == local->point_other.end()) {
        local->point_other.emplace_back(
            other, Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, jacobian.cols()));
        it = local->point_other.end() - 1;
      }
      it->second += block.point.transpose() * jacobian;
    }
  }
  if (!local->point_other.empty()) local->pinv = PseudoInverse(local->point_point);
}

// Adds the point's share of S: its residuals' J_c'J_c, less H_cp H_pp^+ H_pc.
void PointSchurComplement::Reduce(size_t point, std::vector<Linearised>* linearised,
                                  PairBlocks* pairs) {
  PointBlocks local;
  AccumulatePoint(point, linearised, &local);
  const size_t begin = first_[point];
  for (size_t k = 0; k < linearised->size(); ++k) {
    const Linearised& block = (*linearised)[k];
    squared_norms_[by_point_[begin + k]] = block.residual.squaredNorm();
    for (size_t i = 0; i < block.others.size(); ++i) {
      for (size_t j = i; j < block.others.size(); ++j) {
        AddPair(block.others[i].first, block.others[j].first,
                block.others[i].second.transpose() * block.others[j].second, pairs);
      }
    }
  }
  std::vector<Eigen::MatrixXd> response;  // H_pp^+ H_pc, the point's response to each block
  for (const auto& [other, point_other] : local.point_other)
    response.emplace_back(local.pinv * point_other);
  for (size_t i = 0; i < local.point_other.size(); ++i) {
    for (size_t j = 0; j < local.point_other.size(); ++j) {
      if (local.point_other[j].first < local.point_other[i].first) continue;
      AddPair(local.point_other[i].first, local.point_other[j].first,
              -local.point_other[i].second.transpose() * response[j], pairs);
    }
  }
}

void PointSchurComplement::VisitReducedGradients(
    const Eigen::MatrixXd& gain, const std::vector<double>& weights,
    const std::function<void(size_t, const Eigen::VectorXd&)>& visit) const {
  // In batches of points: the threads' effects wait for the visit, and a
  // batch's are a few MB.
  constexpr size_t kBatch = 4096;
  const size_t count = first_.size() - 1;  // the points and the blocks of none
  std::vector<std::vector<std::pair<size_t, Eigen::VectorXd>>> effects(
      static_cast<size_t>(num_threads_));
  for (size_t batch = 0; batch < count; batch += kBatch) {
    const size_t size = std::min(kBatch, count - batch);
    ForEachRange(size, num_threads_, [&](size_t begin, size_t end, int thread) {
      std::vector<std::pair<size_t, Eigen::VectorXd>>& out = effects[static_cast<size_t>(thread)];
      out.clear();
      std::vector<Linearised> linearised;  // scratch, reused point after point
      for (size_t p = batch + begin; p < batch + end; ++p)
        ReducedGradientsOf(p, gain, weights, &linearised, &out);
    });
    for (auto& thread : effects) {
      for (const auto& [index, effect] : thread) visit(index, effect);
      thread.clear();
    }
  }
}

void PointSchurComplement::ReducedGradientsOf(
    size_t point, const Eigen::MatrixXd& gain, const std::vector<double>& weights,
    std::vector<Linearised>* linearised_scratch,
    std::vector<std::pair<size_t, Eigen::VectorXd>>* out) const {
  PointBlocks local;
  AccumulatePoint(point, linearised_scratch, &local);
  const std::vector<Linearised>& linearised = *linearised_scratch;
  const Eigen::Index rows = gain.rows();
  // gain H_cp H_pp^+: how the point's least-squares response carries a
  // residual's pull on the point into the other blocks.
  Eigen::MatrixXd point_gain = Eigen::MatrixXd::Zero(rows, 3);
  for (const auto& [other, point_other] : local.point_other) {
    point_gain +=
        gain.middleCols(start_[static_cast<size_t>(other)], size_[static_cast<size_t>(other)]) *
        point_other.transpose();
  }
  point_gain = point_gain * local.pinv;
  for (size_t k = 0; k < linearised.size(); ++k) {
    const size_t index = by_point_[first_[point] + k];
    const Linearised& block = linearised[k];
    const Eigen::VectorXd weighted = weights[index] * block.residual;
    Eigen::VectorXd effect = Eigen::VectorXd::Zero(rows);
    for (const auto& [other, jacobian] : block.others) {
      effect.noalias() +=
          gain.middleCols(start_[static_cast<size_t>(other)], size_[static_cast<size_t>(other)]) *
          (jacobian.transpose() * weighted);
    }
    if (block.point.rows() > 0)
      effect.noalias() -= point_gain * (block.point.transpose() * weighted);
    out->emplace_back(index, std::move(effect));
  }
}

}  // namespace portcal
