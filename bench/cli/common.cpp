// What the bvhlab subcommands share: mesh arguments, the cache, the policies' parameter options.
#include "bench/cli/cli.hpp"
#include "engine/mesh_catalog.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include <unistd.h>

namespace bvhlab::cli {

namespace fs = std::filesystem;

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

namespace {

/// Where trees and ground truth are cached: --cache, else $BVHLAB_CACHE_DIR, else <build dir>/cache.
fs::path default_cache_dir() {
  if (const char* env = std::getenv("BVHLAB_CACHE_DIR"); env && *env) return env;
  return fs::path(BVHLAB_BINARY_DIR) / "cache";
}

}  // namespace

void check_output_file(const std::string& option, const fs::path& file) {
  std::error_code error;
  if (fs::is_directory(file, error))
    throw CLI::ValidationError(option, file.string() + " is a folder, not a file");
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  if (!fs::is_directory(folder, error))
    throw CLI::ValidationError(
        option, "cannot write " + file.string() + ": folder " + folder.string() + " does not exist");
  if (::access(folder.c_str(), W_OK) != 0)
    throw CLI::ValidationError(
        option, "cannot write " + file.string() + ": folder " + folder.string() + " is not writable");
}

void make_output_dir(const std::string& option, const fs::path& dir) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir))
    throw CLI::ValidationError(option, "cannot make folder " + dir.string() +
                                           (error ? ": " + error.message() : ": a file of that name exists"));
  if (::access(dir.c_str(), W_OK) != 0)
    throw CLI::ValidationError(option, "folder " + dir.string() + " is not writable");
}

fs::path mesh_cache_dir() {
  if (const char* env = std::getenv("BVHLAB_MESH_CACHE"); env && *env) return env;
  return BVHLAB_DEFAULT_MESH_CACHE;
}

fs::path resolve_mesh_argument(const std::string& argument) {
  if (fs::is_regular_file(argument)) return fs::absolute(argument);
  if (auto found = find_mesh(fs::path(argument).filename().string())) return *found;
  throw std::runtime_error("mesh '" + argument +
                           "' is neither a file nor in the mesh catalog (bundled meshes/ or " +
                           mesh_cache_dir().string() + "; fetch larger meshes with meshes/fetch.sh)");
}

SceneObject object_for(const std::string& argument, bool normalize) {
  SceneObject object;
  object.mesh = argument;
  object.path = resolve_mesh_argument(argument);
  object.name = object.path.stem().string();
  object.normalize = normalize;
  return object;
}

RunOptions run_options(const std::string& cache, bool no_cache, bool quiet) {
  RunOptions options;
  options.cache_dir = no_cache ? fs::path() : cache.empty() ? default_cache_dir() : fs::path(cache);
  options.progress = !quiet;
  if (quiet) options.log = [](const std::string&) {};
  return options;
}

void ParameterOptions::add(CLI::App* app, const std::vector<ParamSpec>& specs, const std::string& owner) {
  for (const ParamSpec& p : specs) {
    const std::string name(p.name);
    if (options_.count(name)) {
      owners_[name] += ", " + owner;
      continue;
    }
    std::string flag = "--" + name;
    std::replace(flag.begin(), flag.end(), '_', '-');
    std::string help = std::string(p.description) + "; " + p.range_text();
    if (!p.required()) help += ", default " + parameter_text(p.default_value);
    owners_[name] = owner;
    options_[name] = app->add_option(flag, values_[name], help);
  }
}

void ParameterOptions::finish_help() {
  for (auto& [name, option] : options_)
    option->description(option->get_description() + " (" + owners_[name] + ")");
}

ParamValues ParameterOptions::pick(const std::vector<ParamSpec>& specs) const {
  ParamValues out;
  for (const ParamSpec& p : specs)
    if (const auto it = options_.find(std::string(p.name)); it != options_.end() && it->second->count())
      out[std::string(p.name)] = values_.at(std::string(p.name));
  return out;
}

bool ParameterOptions::given(std::string_view name) const {
  const auto it = options_.find(std::string(name));
  return it != options_.end() && it->second->count() > 0;
}

void ParameterOptions::refuse_others(const std::vector<const std::vector<ParamSpec>*>& specs,
                                     const std::string& what) const {
  for (const auto& [name, option] : options_) {
    if (option->count() == 0) continue;
    const bool taken = std::any_of(specs.begin(), specs.end(), [&, n = name](const auto* list) {
      return std::any_of(list->begin(), list->end(), [&](const ParamSpec& p) { return p.name == n; });
    });
    if (!taken) throw CLI::ValidationError(option->get_name(), "does not apply to " + what);
  }
}

DensitySpec density_from(const std::string& name, const ParameterOptions& options) {
  const DensityInfo& info = density_info(name);
  return density_spec(name, options.pick(info.parameters));
}

}  // namespace bvhlab::cli
