// The one report-folder writer every kind of experiment uses (`bvhlab report`): its data files, then its
// figures (stale ones removed first, so a folder never shows a figure of another run), then its README,
// which names the figures that were drawn and why the others were not.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace bvhlab {

struct ReportOptions;

/// What one kind of experiment puts into its report folder.
struct ReportFolder {
  std::vector<std::string> figures;  ///< the PNG names its plot script draws
  std::string plot_script;           ///< in bench/: "plot_world.py"
  std::string plot_arguments;        ///< after the folder, already quoted
  /// Every figure must be drawn when the script succeeds (else some apply only to some data).
  bool every_figure = true;
  std::function<void(const std::filesystem::path& dir)> write_data;  ///< CSV and JSON files
  /// The README: `drawn` the figures that exist, `plot_error` why the others do not ("" when all do).
  std::function<std::string(const std::vector<std::string>& drawn, const std::string& plot_error)> readme;
};

struct ReportFolderFiles {
  std::filesystem::path dir, readme;           ///< absolute
  std::vector<std::filesystem::path> figures;  ///< the PNGs that exist after plotting
  std::string plot_error;                      ///< why figures are missing, if they are
};

/// Writes `folder` into `dir` (created if needed). Plotting problems are returned in plot_error and given to
/// the README, never thrown: the numbers stay usable without matplotlib. Throws std::runtime_error when a
/// file cannot be written.
ReportFolderFiles write_report_folder(const std::filesystem::path& dir, const ReportFolder& folder,
                                      const ReportOptions& options);

}  // namespace bvhlab
