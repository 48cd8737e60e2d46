#include "pipelines/stages/hierarchical_mapper.h"

#include <fstream>
#include <optional>
#include <set>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "pipelines/distributed/mpi_world.h"
#include "pipelines/distributed/shards.h"
#include "pipelines/sfm/global_adjustment.h"

namespace fs = std::filesystem;

namespace portcal {

void HierarchicalMapperOptions::Check() const {
  if (!mapper.image_list_path.empty()) {
    throw OptionError("--image_list_path", mapper.image_list_path,
                      "'' (the clusters are the stage's lists)");
  }
  mapper.Check();
  partition.Check();
  merge.Check();
}

namespace {

// Maps cluster `index` of `clusters` into OUTPUT/clusters/INDEX; returns
// nothing: its models are read back from there.
void MapCluster(const HierarchicalMapperOptions& options, const std::vector<image_t>& cluster,
                size_t index, const std::map<image_t, std::string>& names, ProgressSink& progress) {
  const fs::path folder = fs::path(options.mapper.output_path) / "clusters";
  const fs::path list = folder / (std::to_string(index) + ".txt");
  {
    std::ofstream out(list);
    for (image_t id : cluster) {
      const auto name = names.find(id);
      if (name == names.end()) {
        throw InputError(options.mapper.database_path + ": a verified pair names image " +
                         std::to_string(id) + ", which the images table does not hold");
      }
      out << name->second << "\n";
    }
    if (!(out << std::flush))
      throw InputError(list.string() + ": cannot write the cluster's image list");
  }
  RefractiveMapperOptions mapper = options.mapper;
  mapper.image_list_path = list.string();
  mapper.output_path = (folder / std::to_string(index)).string();
  RefractiveMapperSummary summary;
  try {
    summary = RunRefractiveMapper(mapper, progress);
  } catch (const NumericalError& e) {
    // A cluster whose images start no model (a stretch of poor overlap)
    // is left out, as one that shares too few points is at the merge: the
    // others still make the survey's model, and its images that other
    // clusters hold are registered there.
    LOG(WARNING) << "hierarchical_mapper: cluster " << index << " (" << cluster.size()
                 << " images) could not be mapped and is left out: " << e.what();
    return;
  }
  LOG(INFO) << "hierarchical_mapper: cluster " << index << " (rank " << MpiWorld::Rank()
            << "): " << summary.num_registered << " of " << cluster.size() << " images in "
            << summary.num_models << " model(s)";
}

// The merged model adjusted as a whole: scaled to the markers or aligned
// to the position priors (whichever gives the scale), adjusted, filtered,
// adjusted again.
void AdjustMerged(const IncrementalMapperOptions& mapper, Reconstruction* r) {
  BundleAdjustmentOptions ba =
      GlobalAdjustmentOptions(mapper, static_cast<int>(r->poses().size()), true);
  std::vector<MarkerCorner> markers;
  if (mapper.marker_scale.side_length_m > 0) {
    PrepareMarkerCorners(r, 4 * mapper.filter_max_reproj_error_px,
                         mapper.marker_scale.side_length_m, &markers);
  } else if (mapper.position_prior_sigma_m > 0 &&
             AlignToPositionPriors(r, 5 * mapper.position_prior_sigma_m)) {
    ba.position_prior_sigma_m = mapper.position_prior_sigma_m;
  }
  r->DeleteUnprojectableObservations();  // clusters merged by similarities: a point may lie inside
                                         // a port
  AdjustBundle(r, ba, BundleAdjustmentScope(), &markers, mapper.marker_scale);
  r->DeleteObservationsBeyond(mapper.filter_max_reproj_error_px);
  AdjustBundle(r, ba, BundleAdjustmentScope(), &markers, mapper.marker_scale);
}

// Rank 0's part: the clusters' models merged, adjusted and written.
void MergeClusters(const HierarchicalMapperOptions& options, size_t num_clusters,
                   HierarchicalMapperSummary* summary) {
  const fs::path folder = fs::path(options.mapper.output_path) / "clusters";
  std::vector<SparseModel> models;
  for (size_t c = 0; c < num_clusters; ++c) {
    // A cluster's mapper writes its models largest first: the first is the
    // cluster's (the others are pieces that would not join it). A cluster
    // that could not be mapped has none.
    const fs::path model = folder / std::to_string(c) / "0";
    if (fs::exists(model)) {
      models.push_back(ReadSparseModel(model));
    } else {
      ++summary->num_unmapped;
    }
  }
  const MergedModels merged = MergeModels(models, options.merge);
  for (const ModelAlignment& a : merged.alignments) {
    LOG(INFO) << "hierarchical_mapper: merged cluster " << a.model_index << ": "
              << a.num_shared_images << " shared images, " << a.num_inliers << " of "
              << a.num_shared_points << " shared points fit the similarity (scale "
              << a.merged_from_model.scale << ", RMS " << a.rms << ")";
  }
  if (!merged.left_out.empty()) {
    LOG(WARNING) << "hierarchical_mapper: " << merged.left_out.size()
                 << " cluster model(s) shared fewer than " << options.merge.min_shared_points
                 << " points with the rest and were left out";
  }
  if (merged.model.images.size() < 2) {
    throw NumericalError("hierarchical_mapper: no cluster of " + options.mapper.database_path +
                         " could be mapped (see the clusters' messages above)");
  }
  SfmInputs inputs;
  {
    Database database(options.mapper.database_path, Database::OpenMode::kReadOnly);
    inputs = SfmInputs::Read(&database);
  }
  Reconstruction r = Reconstruction::FromSparseModel(&inputs, merged.model);
  // The cameras and housings the clusters were mapped with (the first
  // cluster's estimate), not the database's.
  for (auto& [id, camera] : r.mutable_cameras()) {
    const auto intrinsics = merged.model.cameras.find(id);
    if (intrinsics != merged.model.cameras.end()) camera.camera = intrinsics->second;
    const auto housing = merged.model.housings.find(id);
    if (housing != merged.model.housings.end()) camera.housing = housing->second;
  }
  r.UpdateRays();
  AdjustMerged(options.mapper.mapper, &r);
  WriteSparseModel(r.ToSparseModel(), fs::path(options.mapper.output_path) / "0",
                   ModelFormat::kBinary);
  summary->alignments = merged.alignments;
  summary->num_left_out = static_cast<int>(merged.left_out.size());
  summary->num_registered = static_cast<int>(r.poses().size());
  summary->mean_reprojection_error_px = r.MeanReprojectionError();
  LOG(INFO) << "hierarchical_mapper: " << summary->num_registered
            << " images in the merged model from " << models.size() << " of " << num_clusters
            << " clusters (" << summary->num_unmapped << " unmapped, " << summary->num_left_out
            << " left out)";
}

}  // namespace

HierarchicalMapperSummary RunHierarchicalMapper(const HierarchicalMapperOptions& options,
                                                ProgressSink& progress) {
  options.Check();
  const fs::path output(options.mapper.output_path);
  // Rank 0 owns the output: a failed run on any rank leaves no folder it made.
  std::optional<NewPaths> new_output;
  if (MpiWorld::Rank() == 0)
    new_output.emplace(std::vector<fs::path>{output, output / "clusters", output / "0"});
  MpiWorld::Barrier();  // before any rank makes a folder
  // The partition needs only the pairs' inlier counts and the images'
  // names; the keypoints and correspondences stay in the database (each
  // cluster's mapper reads its own images', rank 0 all of them to merge).
  std::map<image_pair_t, int> pair_inliers;
  std::map<image_t, std::string> names;
  {
    Database database(options.mapper.database_path, Database::OpenMode::kReadOnly);
    for (const auto& [pair_id, inliers] : database.ReadTwoViewGeometryNumInliers())
      pair_inliers[pair_id] = inliers;
    for (const DatabaseImage& image : database.ReadAllImages()) names[image.image_id] = image.name;
  }
  if (pair_inliers.empty()) {
    throw InputError(options.mapper.database_path +
                     ": no verified image pairs; run a matcher first");
  }
  const std::vector<std::vector<image_t>> clusters =
      PartitionScene(pair_inliers, options.partition);
  HierarchicalMapperSummary summary;
  summary.num_clusters = static_cast<int>(clusters.size());
  std::set<image_t> clustered;
  for (const auto& cluster : clusters) clustered.insert(cluster.begin(), cluster.end());
  summary.num_images = static_cast<int>(clustered.size());
  LOG(INFO) << "hierarchical_mapper: " << clusters.size() << " clusters over " << MpiWorld::Size()
            << " rank(s)";
  const auto clean_up = [] {};
  RunOnEveryRank(
      "hierarchical_mapper",
      [&] {
        fs::create_directories(output / "clusters");
        for (size_t c = 0; c < clusters.size(); ++c) {
          if (static_cast<int>(c % static_cast<size_t>(MpiWorld::Size())) != MpiWorld::Rank())
            continue;
          MapCluster(options, clusters[c], c, names, progress);
        }
      },
      clean_up);
  RunOnEveryRank(
      "hierarchical_mapper",
      [&] {
        if (MpiWorld::Rank() == 0) MergeClusters(options, clusters.size(), &summary);
      },
      clean_up);
  if (new_output) new_output->Keep();
  return summary;
}

}  // namespace portcal
