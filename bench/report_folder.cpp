#include "bench/report_folder.hpp"

#include "bench/pairs/report.hpp"

#include <fstream>
#include <stdexcept>

namespace bvhlab {

ReportFolderFiles write_report_folder(const std::filesystem::path& dir, const ReportFolder& folder,
                                      const ReportOptions& options) {
  ReportFolderFiles files;
  files.dir = std::filesystem::absolute(dir);
  std::filesystem::create_directories(files.dir);
  folder.write_data(files.dir);
  for (const std::string& name : folder.figures) std::filesystem::remove(files.dir / name);
  files.plot_error = options.figures
                         ? run_plot_script(options, folder.plot_script, files.dir, folder.plot_arguments)
                         : "figures were not requested";
  std::vector<std::string> drawn;
  for (const std::string& name : folder.figures)
    if (std::filesystem::is_regular_file(files.dir / name)) {
      drawn.push_back(name);
      files.figures.push_back(files.dir / name);
    }
  if (folder.every_figure && files.plot_error.empty() && drawn.size() != folder.figures.size())
    files.plot_error = folder.plot_script + " did not draw every figure";
  files.readme = files.dir / "README.md";
  std::ofstream readme(files.readme, std::ios::trunc);
  readme << folder.readme(drawn, files.plot_error);
  if (!readme) throw std::runtime_error(files.readme.string() + ": cannot write");
  return files;
}

}  // namespace bvhlab
