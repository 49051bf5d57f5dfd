#include "bench/experiment.hpp"

#include "bench/deform/deform.hpp"
#include "bench/pairs/report.hpp"
#include "bench/pairs/write.hpp"
#include "bench/points/points.hpp"
#include "bench/world/world.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <optional>
#include <stdexcept>

namespace bvhlab {

std::optional<std::string> Experiment::refused_option(const RunOptions& options, bool snippet) const {
  if (options.per_pose != PerPose::none && !keeps_per_pose_rows()) return "per_pose";
  if (snippet && !writes_snippet()) return "snippet";
  return std::nullopt;
}

std::string Experiment::snippet(const std::filesystem::path&) const {
  throw std::logic_error(std::string(kind()) + " experiments write no snippet");
}

namespace {

/// Writes the report folder without figures: what `bvhlab run` leaves for the kinds whose results are
/// read in their README.
std::filesystem::path results_as_folder(const Experiment& experiment, const std::filesystem::path& dir) {
  ReportOptions options;
  options.figures = false;
  return write_report_folder(dir, experiment.report_folder(), options).readme;
}

/// Pairs of objects on the paper's protocol, or on poses (bench/run.hpp).
class PairsExperiment final : public Experiment {
 public:
  explicit PairsExperiment(const Scene& scene) : scene_(scene) {}
  [[nodiscard]] std::string_view kind() const override { return "pairs"; }
  [[nodiscard]] bool keeps_per_pose_rows() const override { return true; }
  [[nodiscard]] bool writes_snippet() const override { return true; }
  void run(const RunOptions& options) override { output_ = run_scene(scene_, options); }
  [[nodiscard]] std::filesystem::path write_results(const std::filesystem::path& dir) const override {
    write_results_csv(*output_, dir / "results.csv");
    write_results_json(*output_, dir / "results.json");
    write_calibration_csv(*output_, dir / "calibration.csv");
    if (output_->per_pose != PerPose::none) write_poses_csv(*output_, dir / "poses.csv");
    return dir / "results.csv";
  }
  [[nodiscard]] ReportFolder report_folder() const override { return bvhlab::report_folder(*output_); }
  [[nodiscard]] std::string summary() const override {
    const RunStats& s = output_->stats;
    return fmt::format(
        "{} queries in {:.1f} s (preprocessing {:.1f} s, ground truth {:.1f} s); trees built {}, annotated "
        "{}, "
        "from cache {}, rejected {}; FCL models {}; CGAL cross-check {} poses, {} disagreements\n",
        s.queries, s.wall_seconds, s.preprocess_seconds, s.truth_seconds, s.trees_built, s.trees_annotated,
        s.tree_cache_hits, s.tree_cache_rejected, s.fcl_models_built, s.cgal_checked, s.cgal_mismatches);
  }
  [[nodiscard]] nlohmann::json document() const override {
    nlohmann::json out = results_document(*output_);
    if (output_->per_pose != PerPose::none) out["poses"] = poses_document(*output_);
    return out;
  }
  [[nodiscard]] std::pair<int, std::string> status() const override {
    if (!output_->stats.cgal_mismatches) return {0, {}};
    return {3, fmt::format("the ground truth disagrees with CGAL on {} poses; the error rates are suspect",
                           output_->stats.cgal_mismatches)};
  }
  [[nodiscard]] std::string snippet(const std::filesystem::path& report_dir) const override {
    return report_snippet(*output_, report_dir);
  }

 private:
  const Scene& scene_;
  std::optional<RunOutput> output_;
};

/// Many moving objects, the broad phase and one budget per frame (bench/world/world.hpp).
class WorldExperiment final : public Experiment {
 public:
  explicit WorldExperiment(const Scene& scene) : scene_(scene) {}
  [[nodiscard]] std::string_view kind() const override { return "world"; }
  [[nodiscard]] bool keeps_per_pose_rows() const override { return true; }
  void run(const RunOptions& options) override { output_ = run_world(scene_, options); }
  [[nodiscard]] std::filesystem::path write_results(const std::filesystem::path& dir) const override {
    return results_as_folder(*this, dir);
  }
  [[nodiscard]] ReportFolder report_folder() const override { return world_report_folder(*output_); }
  [[nodiscard]] std::string summary() const override { return world_readme(*output_); }
  [[nodiscard]] nlohmann::json document() const override { return world_document(*output_); }

 private:
  const Scene& scene_;
  std::optional<WorldOutput> output_;
};

/// A deforming object, refitted or rebuilt frame by frame (bench/deform/deform.hpp).
class DeformExperiment final : public Experiment {
 public:
  explicit DeformExperiment(const Scene& scene) : scene_(scene) {}
  [[nodiscard]] std::string_view kind() const override { return "deform"; }
  [[nodiscard]] bool keeps_per_pose_rows() const override { return false; }
  void run(const RunOptions& options) override { output_ = run_deform(scene_, options); }
  [[nodiscard]] std::filesystem::path write_results(const std::filesystem::path& dir) const override {
    return results_as_folder(*this, dir);
  }
  [[nodiscard]] ReportFolder report_folder() const override { return deform_report_folder(*output_); }
  [[nodiscard]] std::string summary() const override { return deform_readme(*output_); }
  [[nodiscard]] nlohmann::json document() const override { return deform_document(*output_); }

 private:
  const Scene& scene_;
  std::optional<DeformOutput> output_;
};

/// Point clouds sampled from meshes on the tumbling protocol (bench/points/points.hpp).
class PointsExperiment final : public Experiment {
 public:
  explicit PointsExperiment(const Scene& scene) : scene_(scene) {}
  [[nodiscard]] std::string_view kind() const override { return "points"; }
  [[nodiscard]] bool keeps_per_pose_rows() const override { return false; }
  void run(const RunOptions& options) override { output_ = run_points(scene_, !options.progress); }
  [[nodiscard]] std::filesystem::path write_results(const std::filesystem::path& dir) const override {
    return results_as_folder(*this, dir);
  }
  [[nodiscard]] ReportFolder report_folder() const override { return points_report_folder(*output_); }
  [[nodiscard]] std::string summary() const override { return points_text(*output_); }
  [[nodiscard]] nlohmann::json document() const override { return points_document(*output_); }
  [[nodiscard]] std::pair<int, std::string> status() const override {
    if (!output_->cgal_mismatches) return {0, {}};
    return {3, fmt::format("the mesh truth disagrees with CGAL on {} poses; the error rates are suspect",
                           output_->cgal_mismatches)};
  }

 private:
  const Scene& scene_;
  std::optional<PointsOutput> output_;
};

/// The kinds with a section of their own, by that section; a scene with none of them is a pairs scene.
struct SectionKind {
  bool (*has_section)(const Scene&);
  std::unique_ptr<Experiment> (*make)(const Scene&);
};

template <class E>
std::unique_ptr<Experiment> make_kind(const Scene& scene) {
  return std::make_unique<E>(scene);
}

constexpr SectionKind kSectionKinds[] = {
    {[](const Scene& s) { return s.world.has_value(); }, &make_kind<WorldExperiment>},
    {[](const Scene& s) { return s.deform.has_value(); }, &make_kind<DeformExperiment>},
    {[](const Scene& s) { return s.points.has_value(); }, &make_kind<PointsExperiment>},
};

}  // namespace

std::unique_ptr<Experiment> make_experiment(const Scene& scene) {
  for (const SectionKind& kind : kSectionKinds)
    if (kind.has_section(scene)) return kind.make(scene);
  return make_kind<PairsExperiment>(scene);
}

}  // namespace bvhlab
