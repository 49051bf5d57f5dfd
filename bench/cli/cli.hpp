// bvhlab's command line: one registration function per subcommand (each in its own file here), and the
// helpers the subcommands share.
#pragma once

#include "bench/core/scene.hpp"
#include "bench/run.hpp"
#include "engine/policies.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace bvhlab::cli {

/// Exit statuses (the help's footer lists them all): 1 for a failure, 2 for a bad command line.
inline constexpr int kFailed = 1;
inline constexpr int kBadCommandLine = 2;

/// A subcommand: its node in the app, and the work to do when it is the one given, returning the exit
/// status. The work throws CLI::Error for bad arguments (main reports it as CLI11 does a parse error) and
/// std::exception for anything else.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

/// Each adds its subcommand and its options to `app`; the options are bound to arguments the returned
/// command owns.
Command add_info_command(CLI::App& app);
Command add_build_command(CLI::App& app);
Command add_query_command(CLI::App& app);
Command add_policies_command(CLI::App& app);
Command add_run_command(CLI::App& app);
Command add_report_command(CLI::App& app);
Command add_demo_command(CLI::App& app);

/// "a, b, c".
std::string join(const std::vector<std::string>& items);
/// Where fetched meshes go: $BVHLAB_MESH_CACHE, else the build's default.
std::filesystem::path mesh_cache_dir();
/// A mesh argument: an existing file, else a name in the mesh catalog (bundled or fetched meshes).
std::filesystem::path resolve_mesh_argument(const std::string& argument);
/// The scene object a mesh argument names, in its file's units or normalised by the protocol.
SceneObject object_for(const std::string& argument, bool normalize);
/// Refuses an output file before any work: its folder missing or not writable, or the path a folder.
/// Throws CLI::ValidationError naming `option`.
void check_output_file(const std::string& option, const std::filesystem::path& file);
/// Makes an output folder (and its parents) before any work; throws CLI::ValidationError naming `option` when
/// it cannot be made or written, or names a file.
void make_output_dir(const std::string& option, const std::filesystem::path& dir);
/// The runner's options: the cache at `cache` (default below the build folder) or none, quiet or not.
RunOptions run_options(const std::string& cache, bool no_cache, bool quiet);

/// Command-line options for the parameters of the registered densities or strategies, one per parameter
/// name ("p_min" becomes --p-min), with help, range and default from the policies' tables. A value given
/// for a policy that does not take it is refused, not ignored.
class ParameterOptions {
 public:
  void add(CLI::App* app, const std::vector<ParamSpec>& specs, const std::string& owner);
  /// Appends to each option's help which policies take it; call once, after the last add().
  void finish_help();
  /// The values given on the command line for the parameters in `specs`.
  [[nodiscard]] ParamValues pick(const std::vector<ParamSpec>& specs) const;
  /// Whether parameter `name` was given on the command line.
  [[nodiscard]] bool given(std::string_view name) const;
  /// Throws CLI::ValidationError for a value given that none of `specs` takes: `what` says what is in use.
  void refuse_others(const std::vector<const std::vector<ParamSpec>*>& specs, const std::string& what) const;

 private:
  std::map<std::string, double> values_;
  std::map<std::string, CLI::Option*> options_;
  std::map<std::string, std::string> owners_;
};

/// The density `name` with the parameters given on the command line, checked.
DensitySpec density_from(const std::string& name, const ParameterOptions& options);

}  // namespace bvhlab::cli
