// Loading meshes (bvh/mesh_io.hpp): the input read, checked (bvh/io/format_checks.cpp, bvh/gltf_reduce.hpp)
// and handed to assimp (bvh/io/assimp_import.cpp); and the protocol normalisation.
#include "bvh/mesh_io.hpp"

#include "bvh/gltf_reduce.hpp"
#include "bvh/io/mesh_load_internal.hpp"
#include "bvh/io/text_internal.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

namespace bvhlab {
namespace {

// glTF is reduced to what the loader reads before assimp sees it (bvh/gltf_reduce.hpp). `asset_directory`
// as for detail::reduce_gltf.
LoadedMesh load_gltf(std::string_view bytes, const std::string& format, const std::string& source,
                     std::string name, const std::optional<std::string>& asset_directory) {
  std::optional<detail::ReducedGltf> gltf;
  try {
    gltf = detail::reduce_gltf(bytes, format, asset_directory);
  } catch (const detail::GltfRefused& e) {
    throw MeshError(source + ": " + e.what());
  }
  if (!gltf) throw MeshError(source + ": not glTF: glTF is JSON text that starts with '{'");
  LoadedMesh loaded =
      io::import_with_assimp(source, std::move(name), format, {gltf->bytes, gltf->format, {}});
  loaded.report.ignored_lines += gltf->dropped_line_segments;
  for (auto& warning : gltf->warnings) loaded.report.warnings.push_back("glTF: " + std::move(warning));
  return loaded;
}

// The checks every input gets, then assimp's read. `file` is the input's path when `bytes` are that file's
// content (assimp then reads the file itself when its name gives the format, so that side files such as
// OBJ's .mtl resolve), empty for input from memory. `asset_directory` as for detail::reduce_gltf.
LoadedMesh load_checked(std::string_view bytes, const std::string& hint, const std::string& source,
                        std::string name, const std::string& file,
                        const std::optional<std::string>& asset_directory) {
  if (io::ply_header_unterminated(bytes))
    throw MeshError(source + ": PLY header has no end_header line (truncated file?)");
  const std::string format = io::read_format(bytes, hint);
  if (format.empty())
    throw MeshError(source + ": unknown or unsupported file format" +
                    (hint.empty() ? "" : " ('" + hint + "')") + "; the loader reads " + io::kReadFormatList);
  if (const std::string problem = io::input_problem(bytes, format); !problem.empty())
    throw MeshError(source + ": " + problem);
  if (format == "gltf" || format == "glb")
    return load_gltf(bytes, format, source, std::move(name), asset_directory);
  return io::import_with_assimp(source, std::move(name), format,
                                {bytes, format, !file.empty() && hint == format ? file : std::string()});
}

// Where assimp looks for a file's side files: the path up to its last separator.
std::string asset_directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

}  // namespace

LoadedMesh load_mesh(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw MeshError(source + ": file not found");
  if (std::filesystem::is_directory(status)) throw MeshError(source + ": is a directory, not a mesh file");
  std::ifstream in(path, std::ios::binary);
  if (!in.is_open()) throw MeshError(source + ": cannot be opened for reading");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw MeshError(source + ": reading failed");
  if (bytes.empty()) throw MeshError(source + ": file is empty");
  const std::string extension = io::lower_case(path.extension().string());
  return load_checked(bytes, extension.empty() ? extension : extension.substr(1), source,
                      path.stem().string(), source, asset_directory_of(source));
}

LoadedMesh load_mesh_from_memory(std::span<const std::byte> buffer, std::string_view format_hint,
                                 std::string_view name) {
  const std::string source(name);
  if (buffer.empty()) throw MeshError(source + ": buffer is empty");
  std::string hint(format_hint);
  if (!hint.empty() && hint.front() == '.') hint.erase(0, 1);
  return load_checked(std::string_view(reinterpret_cast<const char*>(buffer.data()), buffer.size()),
                      io::lower_case(hint), source, std::filesystem::path(source).stem().string(),
                      std::string(), std::nullopt);
}

double normalize_to_unit_cube(Mesh& mesh) {
  const Box b = mesh.bounds();
  if (b.empty()) throw MeshError(mesh.name + ": cannot normalise an empty mesh");
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite())
      throw MeshError(mesh.name + ": cannot normalise: NaN or infinite coordinate at vertex " +
                      std::to_string(i));
  const double longest = b.extent().maxCoeff();
  if (!(longest > 0)) throw MeshError(mesh.name + ": cannot normalise: all vertices coincide");
  const double scale = 2.0 / longest;
  const Vec3 centre = b.center();
  for (auto& v : mesh.vertices) v = (v - centre) * scale;
  return scale;
}

}  // namespace bvhlab
