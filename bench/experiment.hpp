// The kinds of experiment a scene describes, behind one interface: "pairs" (the paper's protocol between
// pairs of objects), "world" (many moving objects, one budget per frame), "deform" (a deforming object) and
// "points" (point clouds). `bvhlab run`, `bvhlab report`, `bvhlab demo` and Python's run_scene go through
// it only; make_experiment is the one place that reads which kind a scene is.
#pragma once

#include "bench/core/scene.hpp"
#include "bench/report_folder.hpp"
#include "bench/run.hpp"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace bvhlab {

class Experiment {
 public:
  virtual ~Experiment() = default;
  /// "pairs", "world", "deform" or "points".
  [[nodiscard]] virtual std::string_view kind() const = 0;
  /// Whether it keeps per-pose rows (RunOptions::per_pose) and writes a README snippet: an option this
  /// kind cannot honour is refused before any work (refused_option), never ignored.
  [[nodiscard]] virtual bool keeps_per_pose_rows() const = 0;
  [[nodiscard]] virtual bool writes_snippet() const { return false; }
  /// The first option asked for that this kind cannot honour: "per_pose" or "snippet"; nothing when none.
  [[nodiscard]] std::optional<std::string> refused_option(const RunOptions& options, bool snippet) const;

  /// Runs the scene (once): everything else reads what it measured.
  virtual void run(const RunOptions& options) = 0;
  /// `bvhlab run`: the data files into `dir`; returns the file to name to the user.
  [[nodiscard]] virtual std::filesystem::path write_results(const std::filesystem::path& dir) const = 0;
  /// `bvhlab report`: what its report folder holds (write_report_folder writes it).
  [[nodiscard]] virtual ReportFolder report_folder() const = 0;
  /// What the run says on the terminal when it is not quiet.
  [[nodiscard]] virtual std::string summary() const = 0;
  /// Python's run_scene: the run as JSON, keyed like its CSV files' columns.
  [[nodiscard]] virtual nlohmann::json document() const = 0;
  /// 3 (with the reason) when the ground truth disagrees with CGAL, else 0 and "".
  [[nodiscard]] virtual std::pair<int, std::string> status() const { return {0, {}}; }
  /// The project README's short results section (writes_snippet only).
  [[nodiscard]] virtual std::string snippet(const std::filesystem::path& report_dir) const;
};

/// The experiment `scene` describes: the kind whose section it has ("world", "deform", "points"), else
/// pairs. The scene must outlive it.
std::unique_ptr<Experiment> make_experiment(const Scene& scene);

}  // namespace bvhlab
