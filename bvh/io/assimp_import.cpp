// The mesh loader's use of assimp (bvh/io/mesh_load_internal.hpp): its log read per load, its importers
// kept to the one format the input was checked as, the scene checked before it is triangulated, then merged
// into one welded Mesh.
#include "bvh/io/mesh_load_internal.hpp"
#include "bvh/triangle_intersection.hpp"

#include <assimp/BaseImporter.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <mutex>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace bvhlab::io {
namespace {

using Mat4 = Eigen::Matrix<double, 4, 4>;

// ---------------------------------------------------------------------------------------------------------
// assimp's log, per load. Some loaders only log a bad index and substitute another vertex (the OFF reader
// clamps it to the last vertex), so the log has to be read to avoid a silently wrong mesh. The logger is a
// process-wide singleton; each load collects the messages of its own thread.

struct LogCapture {
  std::vector<std::string> messages;  // Err and Warn, prefix stripped
};

thread_local LogCapture* current_capture = nullptr;

class ThreadCaptureStream : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    if (current_capture == nullptr || message == nullptr) return;
    // Bounded: a broken file can make a loader log once per face.
    if (current_capture->messages.size() < 1000) current_capture->messages.emplace_back(message);
  }
};

void install_assimp_logger() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (Assimp::DefaultLogger::isNullLogger())
      Assimp::DefaultLogger::create(nullptr, Assimp::Logger::NORMAL, /*defStreams=*/0u);
    Assimp::DefaultLogger::get()->attachStream(new ThreadCaptureStream,
                                               Assimp::Logger::Err | Assimp::Logger::Warn);
  });
}

class ScopedCapture {
 public:
  explicit ScopedCapture(LogCapture& capture) : previous_(current_capture) { current_capture = &capture; }
  ~ScopedCapture() { current_capture = previous_; }
  ScopedCapture(const ScopedCapture&) = delete;
  ScopedCapture& operator=(const ScopedCapture&) = delete;

 private:
  LogCapture* previous_;
};

std::string strip_log_prefix(std::string message) {
  static const std::regex prefix(R"(^\s*(Error|Warn|Info|Debug|Verbose)[^:]*:\s*)");
  message = std::regex_replace(message, prefix, "", std::regex_constants::format_first_only);
  while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
  return message;
}

// A loader message that says a vertex/face index was bad means geometry was dropped or replaced.
bool reports_bad_index(const std::string& message) {
  static const std::regex bad_index(
      R"((vertex|face|polygon|triangle)[a-z ]{0,20}(index|indices|reference)[a-z ]{0,30})"
      R"((out of range|out of bounds|outside|overflow))"
      R"(|(invalid|bad) (vertex|face|triangle) (index|ind|reference))"
      R"(|(vertex|face) has an invalid index)"
      R"(|index overflow in [a-z0-9 ]{0,20}vertex)"
      R"(|faces had out-of-range indices)",  // glTF: those faces were dropped
      std::regex::icase);
  return std::regex_search(message, bad_index);
}

// ---------------------------------------------------------------------------------------------------------
// Merging the scene into one welded Mesh.

Mat4 to_eigen(const aiMatrix4x4& m) {
  Mat4 out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return out;
}

// Exact position equality; -0.0 and +0.0 are the same point, so they must hash alike.
struct PositionKey {
  std::uint64_t x, y, z;
  bool operator==(const PositionKey&) const = default;
};
struct PositionKeyHash {
  std::size_t operator()(const PositionKey& k) const {
    std::uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
    h ^= k.y + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h ^= k.z + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    return static_cast<std::size_t>(h);
  }
};
PositionKey key_of(const Vec3& p) {
  return {std::bit_cast<std::uint64_t>(p.x() + 0.0), std::bit_cast<std::uint64_t>(p.y() + 0.0),
          std::bit_cast<std::uint64_t>(p.z() + 0.0)};
}

std::string format_number(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

std::string format_point(const Vec3& p) {
  std::ostringstream out;
  out.precision(17);
  out << '(' << p.x() << ", " << p.y() << ", " << p.z() << ')';
  return out.str();
}

std::string describe_submesh(unsigned index, const aiMesh& mesh) {
  std::string out = "sub-mesh " + std::to_string(index);
  if (mesh.mName.length > 0) out += " '" + std::string(mesh.mName.C_Str()) + "'";
  return out;
}

class SceneMerger {
 public:
  explicit SceneMerger(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& problem) const { throw MeshError(source_ + ": " + problem); }

  void add_instance(unsigned mesh_index, const aiMesh& mesh, const Mat4& transform) {
    if (mesh.mNumFaces > 0 && mesh.mFaces == nullptr)
      fail(describe_submesh(mesh_index, mesh) + " has no faces array");
    if (mesh.mNumVertices > 0 && mesh.mVertices == nullptr)
      fail(describe_submesh(mesh_index, mesh) + " has no positions");
    const Eigen::Matrix3d linear = transform.topLeftCorner<3, 3>();
    const Eigen::Vector3d offset = transform.topRightCorner<3, 1>();
    // A mirroring transform would turn the faces inside out; keep the winding outward.
    const bool mirrored = linear.determinant() < 0;
    std::vector<std::uint32_t> merged_index(mesh.mNumVertices, kUnset);
    bool contributed = false;

    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 1) {
        ++report_.ignored_points;
        continue;
      }
      if (face.mNumIndices == 2) {
        ++report_.ignored_lines;
        continue;
      }
      if (face.mNumIndices < 3 || face.mIndices == nullptr) continue;
      std::vector<std::uint32_t> corners(face.mNumIndices);
      for (unsigned c = 0; c < face.mNumIndices; ++c) {
        const unsigned v = face.mIndices[c];
        if (v >= mesh.mNumVertices)
          fail("index out of range: face " + std::to_string(f) + " of " + describe_submesh(mesh_index, mesh) +
               " refers to vertex " + std::to_string(v) + " but there are only " +
               std::to_string(mesh.mNumVertices) + " vertices");
        corners[c] = vertex(mesh_index, mesh, v, linear, offset, merged_index);
      }
      // aiProcess_Triangulate leaves no polygons; a fan keeps any leftover one instead of dropping it.
      for (std::size_t c = 1; c + 1 < corners.size(); ++c) {
        TriangleIndices t{corners[0], corners[c], corners[c + 1]};
        if (mirrored) std::swap(t[1], t[2]);
        if (mesh_.triangles.size() >= kMaxIndex) fail("more than 2^32-1 triangles");
        mesh_.triangles.push_back(t);
      }
      contributed = true;
    }
    if (contributed) ++report_.submeshes;
  }

  LoadedMesh finish(std::string name) {
    if (mesh_.triangles.empty()) {
      std::string problem = "no triangles";
      if (report_.ignored_points + report_.ignored_lines > 0)
        problem += " (only " + std::to_string(report_.ignored_points) + " point and " +
                   std::to_string(report_.ignored_lines) + " line primitives, which are ignored)";
      fail(problem);
    }
    const Box bounds = mesh_.bounds();
    const double max_abs = std::max(bounds.min.cwiseAbs().maxCoeff(), bounds.max.cwiseAbs().maxCoeff());
    const double diagonal = bounds.extent().norm();
    if (max_abs > MeshPrecisionLimits::max_abs_coordinate)
      fail("coordinates too large: max |coordinate| = " + format_number(max_abs) + " exceeds 1e15");
    if (!(diagonal >= MeshPrecisionLimits::min_diagonal))
      fail("model has zero size: all triangle vertices coincide (bounding-box diagonal " +
           format_number(diagonal) + ")");
    constexpr bool float_reader = sizeof(ai_real) == sizeof(float);
    constexpr double warn_ratio = float_reader ? MeshPrecisionLimits::warn_offset_ratio_float_reader
                                               : MeshPrecisionLimits::warn_offset_ratio_double_reader;
    if (max_abs / diagonal > warn_ratio) {
      std::ostringstream w;
      w << "coordinates are far from the origin relative to the model size (max |coordinate| / diagonal = "
        << max_abs / diagonal << " > " << warn_ratio << "): the file's coordinates were read with "
        << (float_reader ? "32-bit float" : "double") << " precision, so details below ~"
        << max_abs / diagonal * (float_reader ? 6e-8 : 1.1e-16) << " of the model size are lost";
      report_.warnings.push_back(w.str());
    }

    for (std::size_t i = 0; i < mesh_.triangles.size(); ++i) {
      const auto& t = mesh_.triangles[i];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
        ++report_.degenerate_triangles;
        continue;
      }
      if (exactly_collinear(mesh_.vertices[t[0]], mesh_.vertices[t[1]], mesh_.vertices[t[2]]))
        ++report_.degenerate_triangles;
    }

    report_.source = source_;
    report_.bounds = bounds;
    mesh_.name = std::move(name);
    return {std::move(mesh_), std::move(report_)};
  }

  LoadReport& report() { return report_; }

  static constexpr std::uint32_t kUnset = std::numeric_limits<std::uint32_t>::max();
  static constexpr std::size_t kMaxIndex = kUnset;  ///< triangles and vertices a Mesh holds

 private:
  std::uint32_t vertex(unsigned mesh_index, const aiMesh& mesh, unsigned v, const Eigen::Matrix3d& linear,
                       const Eigen::Vector3d& offset, std::vector<std::uint32_t>& merged_index) {
    if (merged_index[v] != kUnset) return merged_index[v];
    const aiVector3D& raw = mesh.mVertices[v];
    const Vec3 local(raw.x, raw.y, raw.z);
    if (!local.allFinite())
      fail("NaN or infinite coordinate " + format_point(local) + " at vertex " + std::to_string(v) + " of " +
           describe_submesh(mesh_index, mesh));
    const Vec3 p = linear * local + offset;
    if (!p.allFinite())
      fail("NaN or infinite coordinate after the node transform at vertex " + std::to_string(v) + " of " +
           describe_submesh(mesh_index, mesh));
    ++report_.input_vertices;
    const auto [it, inserted] =
        weld_.try_emplace(key_of(p), static_cast<std::uint32_t>(mesh_.vertices.size()));
    if (inserted) {
      if (mesh_.vertices.size() >= kMaxIndex) fail("more than 2^32-1 vertices");
      mesh_.vertices.push_back(p);
    }
    merged_index[v] = it->second;
    return it->second;
  }

  std::string source_;
  Mesh mesh_;
  LoadReport report_;
  std::unordered_map<PositionKey, std::uint32_t, PositionKeyHash> weld_;
};

LoadedMesh merge_scene(const aiScene& scene, const std::string& source, std::string name) {
  SceneMerger merger(source);
  std::vector<bool> referenced(scene.mNumMeshes, false);
  // Every (sub-mesh, global transform) the scene places, found first: instancing multiplies faces (a 1 MB
  // glTF file can place one mesh 10^5 times), so their total is checked before anything is merged.
  std::vector<std::pair<unsigned, Mat4>> instances;
  std::uint64_t instanced_faces = 0;
  auto place = [&](unsigned m, const Mat4& global) {
    instances.emplace_back(m, global);
    instanced_faces += scene.mMeshes[m]->mNumFaces;
  };
  // Iterative walk: a hostile file must not overflow the stack with a deep node chain.
  std::vector<std::pair<const aiNode*, Mat4>> pending;
  if (scene.mRootNode != nullptr) pending.emplace_back(scene.mRootNode, Mat4::Identity());
  while (!pending.empty()) {
    auto [node, parent] = pending.back();
    pending.pop_back();
    const Mat4 global = parent * to_eigen(node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const unsigned m = node->mMeshes[i];
      if (m >= scene.mNumMeshes || scene.mMeshes[m] == nullptr)
        merger.fail("scene node refers to sub-mesh " + std::to_string(m) + " which does not exist");
      referenced[m] = true;
      place(m, global);
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c)
      if (node->mChildren[c] != nullptr) pending.emplace_back(node->mChildren[c], global);
  }
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    if (referenced[m] || scene.mMeshes[m] == nullptr) continue;
    merger.report().warnings.push_back(describe_submesh(m, *scene.mMeshes[m]) +
                                       " is in no scene node; merged untransformed");
    place(m, Mat4::Identity());
  }
  if (instanced_faces > SceneMerger::kMaxIndex)
    merger.fail("the scene places " + std::to_string(instanced_faces) +
                " faces (instances counted), more than the 2^32-1 triangles a mesh holds");
  for (const auto& [m, global] : instances) merger.add_instance(m, *scene.mMeshes[m], global);
  return merger.finish(std::move(name));
}

// Debian's assimp keeps its ai_asserts, and TriangulateProcess aborts the whole process on a face without
// indices or on a mesh that claims polygons it does not have (truncated or corrupt OFF and PLY files; found
// by tests/fuzz). So a scene is read and validated first, then checked and its primitive types recomputed
// from its faces (prepare_for_triangulation), and only then triangulated.
constexpr unsigned kPostProcess = aiProcess_ValidateDataStructure;

/// Empty when `scene` is safe to triangulate, else the problem.
std::string prepare_for_triangulation(aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr) continue;
    if (mesh->mNumFaces > 0 && mesh->mFaces == nullptr)
      return describe_submesh(m, *mesh) + " has no faces array";
    unsigned types = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 0 || face.mIndices == nullptr)
        return "face " + std::to_string(f) + " of " + describe_submesh(m, *mesh) + " has no vertex indices";
      types |= face.mNumIndices == 1   ? aiPrimitiveType_POINT
               : face.mNumIndices == 2 ? aiPrimitiveType_LINE
               : face.mNumIndices == 3 ? aiPrimitiveType_TRIANGLE
                                       : aiPrimitiveType_POLYGON;
    }
    mesh->mPrimitiveTypes = types;
  }
  return {};
}

// assimp picks an importer by content as well as by name, so any of its ~40 importers could be handed a file
// checked as another format: Quick3D content behind a glTF hint allocated 4 TB, OBJ content behind a glTF
// hint reached the OBJ reader's NUL-byte crash (both found by tests/fuzz). Each import keeps only the
// importer(s) of the one format its input was checked as.
void keep_only_importers_of(Assimp::Importer& importer, std::string_view format) {
  for (std::size_t i = importer.GetImporterCount(); i-- > 0;) {
    const aiImporterDesc* info = importer.GetImporterInfo(i);
    std::istringstream extensions(info != nullptr && info->mFileExtensions != nullptr ? info->mFileExtensions
                                                                                      : "");
    bool keep = false;
    for (std::string extension; extensions >> extension;) keep = keep || extension == format;
    if (keep) continue;
    Assimp::BaseImporter* other = importer.GetImporter(i);
    if (importer.UnregisterLoader(other) == AI_SUCCESS) delete other;  // unregistering does not delete it
  }
}

/// The messages assimp logged during a load, prefixes stripped, without the ones that are no news.
std::vector<std::string> logged_messages(LogCapture& capture) {
  std::vector<std::string> log;
  for (auto& m : capture.messages) {
    std::string message = strip_log_prefix(std::move(m));
    // The merger keeps only vertices that triangles use, so this validation remark is no news to the caller.
    if (message.find("There are unreferenced vertices") == std::string::npos)
      log.push_back(std::move(message));
  }
  return log;
}

/// Why assimp returned no scene.
[[noreturn]] void throw_read_failure(const Assimp::Importer& importer, const std::string& source,
                                     std::string_view format) {
  const std::string error = importer.GetErrorString();
  if (error.find("No suitable reader") != std::string::npos)
    throw MeshError(source + ": not a readable " + std::string(format) + " file (assimp: " + error + ")");
  if (error.find("Validation failed") != std::string::npos && error.find("out of range") != std::string::npos)
    throw MeshError(source + ": index out of range (assimp: " + error + ")");
  throw MeshError(source + ": assimp could not read it: " + (error.empty() ? "unknown error" : error));
}

}  // namespace

LoadedMesh import_with_assimp(const std::string& source, std::string name, std::string_view format,
                              const AssimpInput& input) {
  install_assimp_logger();
  LogCapture capture;
  Assimp::Importer importer;
  const aiScene* scene = nullptr;
  std::string problem;
  try {
    // One import at a time: assimp's DefaultLogger formats every message in one buffer shared by all threads
    // (ThreadSanitizer: a data race in WriteToStreams), so concurrent loads could swap or garble the messages
    // this loader reads to detect bad indices. Loading is rarely the bottleneck; being right is not optional.
    static std::mutex import_mutex;
    const std::lock_guard lock(import_mutex);
    keep_only_importers_of(importer, format);  // logs through the same buffer
    ScopedCapture scoped(capture);
    scene = input.file.empty() ? importer.ReadFileFromMemory(input.bytes.data(), input.bytes.size(),
                                                             kPostProcess, input.hint.c_str())
                               : importer.ReadFile(input.file, kPostProcess);
    if (scene != nullptr) {
      problem = prepare_for_triangulation(*const_cast<aiScene*>(scene));  // the importer's own scene
      if (problem.empty()) scene = importer.ApplyPostProcessing(aiProcess_Triangulate);
    }
  } catch (const std::exception& e) {  // assimp reports through GetErrorString; this is for bad_alloc & co.
    throw MeshError(source + ": reading failed: " + e.what());
  }

  const std::vector<std::string> log = logged_messages(capture);
  if (scene == nullptr) throw_read_failure(importer, source, format);
  if (!problem.empty()) throw MeshError(source + ": " + problem);
  for (const auto& m : log)
    if (reports_bad_index(m)) throw MeshError(source + ": index out of range (assimp: " + m + ")");

  LoadedMesh loaded = merge_scene(*scene, source, std::move(name));
  constexpr std::size_t kMaxLogWarnings = 20;
  for (std::size_t i = 0; i < log.size() && i < kMaxLogWarnings; ++i)
    loaded.report.warnings.push_back("assimp: " + log[i]);
  if (log.size() > kMaxLogWarnings)
    loaded.report.warnings.push_back("assimp: " + std::to_string(log.size() - kMaxLogWarnings) +
                                     " more messages");
  return loaded;
}

}  // namespace bvhlab::io
