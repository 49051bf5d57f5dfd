#include "bvh/mesh_io.hpp"

#include "bvh/gltf_reduce.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <assimp/BaseImporter.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

namespace bvhlab {
namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
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
      const auto& a = mesh_.vertices[t[0]];
      const auto& b = mesh_.vertices[t[1]];
      const auto& c = mesh_.vertices[t[2]];
      if (CGAL::collinear(Epick::Point_3(a.x(), a.y(), a.z()), Epick::Point_3(b.x(), b.y(), b.z()),
                          Epick::Point_3(c.x(), c.y(), c.z())))
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

// The formats the loader reads: those whose input it checks before assimp does (below and in
// bvh/gltf_reduce.hpp) and that tests/fuzz covers.
constexpr std::string_view kReadFormats[] = {"obj", "ply", "stl", "off", "ms3d", "gltf", "glb"};
constexpr const char* kReadFormatList = "OBJ, PLY, STL, OFF, MS3D, glTF 2 and GLB";

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

template <class ReadFn>
LoadedMesh import_with(const std::string& source, std::string name, std::string_view format, ReadFn read) {
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
    scene = read(importer);
    if (scene != nullptr) {
      problem = prepare_for_triangulation(*const_cast<aiScene*>(scene));  // the importer's own scene
      if (problem.empty()) scene = importer.ApplyPostProcessing(aiProcess_Triangulate);
    }
  } catch (const std::exception& e) {  // assimp reports through GetErrorString; this is for bad_alloc & co.
    throw MeshError(source + ": reading failed: " + e.what());
  }

  std::vector<std::string> log;
  for (auto& m : capture.messages) {
    std::string message = strip_log_prefix(std::move(m));
    // The merger keeps only vertices that triangles use, so this validation remark is no news to the caller.
    if (message.find("There are unreferenced vertices") == std::string::npos)
      log.push_back(std::move(message));
  }
  if (scene == nullptr) {
    const std::string error = importer.GetErrorString();
    if (error.find("No suitable reader") != std::string::npos)
      throw MeshError(source + ": not a readable " + std::string(format) + " file (assimp: " + error + ")");
    if (error.find("Validation failed") != std::string::npos &&
        error.find("out of range") != std::string::npos)
      throw MeshError(source + ": index out of range (assimp: " + error + ")");
    throw MeshError(source + ": assimp could not read it: " + (error.empty() ? "unknown error" : error));
  }
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

// ASCII lower case, for format keywords and file extensions.
std::string lower_case(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// A count as assimp reads it: the text's leading digits ("12abc" is 12), saturating far above any real file
// so that an overflowing count is still caught as huge.
std::uint64_t leading_count(std::string_view text) {
  std::uint64_t value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') break;
    value = std::min<std::uint64_t>(value * 10 + static_cast<unsigned>(c - '0'), 1ull << 62);
  }
  return value;
}

// Whether `text` starts with the PLY magic (either case), where every PLY check here starts reading.
bool has_ply_magic(std::string_view text) {
  return lower_case(text.substr(0, 3)) == "ply";
}

// assimp 5.2's PLY reader never returns when the header ends without an `end_header` line (any truncated
// header; found by tests/fuzz), so such input is refused before assimp sees it.
bool ply_header_unterminated(std::string_view text) {
  if (!has_ply_magic(text)) return false;
  for (std::size_t position = 0; position < text.size();) {
    const std::size_t end = std::min(text.find('\n', position), text.size());
    const std::string_view line = text.substr(position, end - position);
    position = end + 1;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line.compare(first, 10, "end_header") != 0) continue;
    // assimp's token match takes only these after the keyword (a vertical tab, say, still hangs it).
    if (first + 10 == line.size() ||
        std::string_view(" \t\r\f\0", 5).find(line[first + 10]) != std::string_view::npos)
      return false;
  }
  return true;
}

constexpr const char* kUnterminatedPly = ": PLY header has no end_header line (truncated file?)";

// Whether a lower-case first token starts with the OFF keyword and its optional prefixes (ST, C, N, 4, n).
bool starts_with_off_keyword(std::string_view token) {
  const std::size_t at = token.find("off");
  return at != std::string_view::npos && at <= 3 &&
         token.find_first_not_of("abcdefghijklmnopqrstuvwxyz") >= at;
}

constexpr std::size_t kHeaderBytes = 1 << 16;  // a PLY header fits in it

// The vertex and face counts assimp 5.2's OFF reader takes from `text`, found by walking the header as it
// does: optional ST, C, N, 4, n prefixes and the keyword, then numbers, where a '#' after a number starts a
// comment to the end of the line ("8### 12 0" is 8 and then the next line's number), and a count wraps
// around at 2^32 as its strtoul10 does. Tokenising the header differently let a 275-byte file ask for 64 GB
// (found by tests/fuzz).
std::array<std::uint32_t, 2> off_header_counts(std::string_view text) {
  text = text.substr(0, text.find('\0'));                          // assimp's copy ends at the first NUL
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // and has no UTF-8 byte-order mark
  std::size_t car = 0;
  auto skip_blanks = [&] {
    while (car < text.size() && std::string_view(" \t\r\n").find(text[car]) != std::string_view::npos) ++car;
  };
  auto next_token = [&] {
    skip_blanks();
    while (car < text.size() && (text[car] == '#' || text[car] == '\n' || text[car] == '\r')) {
      while (car < text.size() && text[car] != '\r' && text[car] != '\n') ++car;
      skip_blanks();
    }
  };
  auto take = [&](std::string_view prefix) {
    const bool match = text.substr(car, prefix.size()) == prefix;
    if (match) car += prefix.size();
    return match;
  };
  auto number = [&] {
    std::uint32_t value = 0;
    for (; car < text.size() && text[car] >= '0' && text[car] <= '9'; ++car)
      value = value * 10 + static_cast<std::uint32_t>(text[car] - '0');
    return value;
  };
  next_token();
  take("ST");
  take("C");
  take("N");
  take("4");
  const bool dimension = take("n");
  take("OFF");
  next_token();
  if (dimension) {
    number();
    next_token();
  }
  next_token();
  const std::uint32_t vertices = number();
  next_token();
  return {vertices, number()};
}

// OFF and PLY headers declare element counts, and assimp allocates for them before reading a single element:
// a 60-byte OFF file declaring 14294967295 faces asked for 22 GB (found by tests/fuzz). Every element takes
// at least one byte of the file, so a count above the file's size is refused up front. `format` is the
// format the input is read as. Returns the problem, or "" when none is seen.
std::string oversized_header_count(std::string_view text, std::string_view format) {
  const std::uint64_t size = text.size();
  auto too_many = [&](std::uint64_t count, const std::string& what) {
    return count > size
               ? "header declares " + std::to_string(count) + " " + what + " but the file has only " +
                     std::to_string(size) + " bytes (corrupt or truncated?)"
               : std::string();
  };
  if (format == "off") {
    const auto [vertices, faces] = off_header_counts(text);
    if (auto problem = too_many(vertices, "vertices"); !problem.empty()) return problem;
    return too_many(faces, "faces");
  }
  std::istringstream in{std::string(text.substr(0, kHeaderBytes))};
  std::string token;
  if (!(in >> token)) return {};
  const std::string magic = lower_case(token);
  if (magic == "ply") {
    // A header that declares an element or the format twice makes assimp size its arrays from one
    // declaration and fill them from the other: a heap overflow inside assimp (found by tests/fuzz under
    // valgrind). Such a header is refused.
    std::vector<std::string> seen;
    for (std::string line; std::getline(in, line);) {
      std::istringstream words(line);
      std::string keyword, name, digits;
      if (!(words >> keyword)) continue;
      if (keyword == "end_header") break;
      if (keyword == "format") name = "format";
      if (keyword == "element" && !(words >> name >> digits)) continue;
      if (keyword != "element" && keyword != "format") continue;
      if (std::find(seen.begin(), seen.end(), name) != seen.end())
        return "PLY header declares " +
               (keyword == "format" ? std::string("the format") : "element '" + name + "'") + " twice";
      seen.push_back(name);
      if (keyword == "format") continue;
      if (auto problem = too_many(leading_count(digits), "'" + name + "' elements"); !problem.empty())
        return problem;
    }
  }
  return {};
}

// assimp 5.2's PLY reader trusts every list's own count: one face whose ASCII count read 6.6e25 made it
// allocate until it ran out of memory (found by tests/fuzz). So a PLY body is walked once, element by element
// as the header declares them, before assimp reads it: every value must be there and every list must fit in
// what is left of the file. Linear in the file, allocates nothing per element. A header this walk does not
// understand is refused too (an unknown property type let the same huge count through). Returns the
// problem, or "" for a PLY file whose body matches its header (and for input that is not PLY).
std::string ply_body_problem(std::string_view text) {
  if (!has_ply_magic(text)) return {};
  // Byte size of a PLY scalar type, 0 when unknown.
  auto size_of = [](const std::string& type) -> std::size_t {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
        type == "float32")
      return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
  };
  struct Property {
    std::size_t value_size = 0;
    std::size_t count_size = 0;  // lists only
  };
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
  };
  std::vector<Element> elements;
  std::string format;
  std::size_t position = 0, body = std::string_view::npos;
  while (position < text.size()) {
    const std::size_t end = std::min(text.find('\n', position), text.size());
    std::istringstream words{std::string(text.substr(position, end - position))};
    position = end + 1;
    std::string keyword;
    if (!(words >> keyword)) continue;
    if (keyword == "end_header") {
      body = std::min(position, text.size());
      break;
    }
    if (keyword == "format") {
      words >> format;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        return "PLY header: unknown format '" + format + "'";
    } else if (keyword == "element") {
      Element element;
      std::string digits;
      if (!(words >> element.name >> digits) || digits.find_first_not_of("0123456789") != std::string::npos)
        return "PLY header: element line without a name and a count";
      element.count = leading_count(digits);
      elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (elements.empty()) return "PLY header: property before any element";
      std::string type, count_type, value_type;
      words >> type;
      Property property;
      if (type == "list") {
        words >> count_type >> value_type;
        property.count_size = size_of(count_type);
        property.value_size = size_of(value_type);
        if (property.count_size == 0 || property.value_size == 0)
          return "PLY header: list property of unknown types '" + count_type + "' '" + value_type + "'";
      } else if ((property.value_size = size_of(type)) == 0) {
        return "PLY header: unknown property type '" + type + "'";
      }
      elements.back().properties.push_back(property);
    } else if (keyword != "comment" && keyword != "obj_info" && lower_case(keyword) != "ply") {
      return "PLY header: unknown line '" + keyword + "'";
    }
  }
  if (body == std::string_view::npos) return {};  // refused before (no end_header)
  if (format.empty()) return "PLY header has no format line";
  const std::string_view data = text.substr(body);
  auto ends_early = [&](const Element& element, std::uint64_t i) {
    return "PLY data ends inside element '" + element.name + "' " + std::to_string(i) + " of " +
           std::to_string(element.count) + " (corrupt or truncated?)";
  };
  auto too_few = [&](const Element& element, std::uint64_t i) {
    return "PLY element '" + element.name + "' " + std::to_string(i) + " has fewer values on its line than " +
           "the header declares (corrupt?)";
  };
  auto list_too_long = [&](const Element& element, std::uint64_t i, std::uint64_t count) {
    return "PLY element '" + element.name + "' " + std::to_string(i) + " holds a list of " +
           std::to_string(count) + " values, more than its data has (corrupt?)";
  };
  if (format == "ascii") {
    // assimp reads one element per line (whatever follows its properties on the line is ignored), so every
    // value of an element, a list's included, must be on that element's line. Lines end at LF, CR LF, CR or
    // NUL.
    std::size_t at = 0, line_end = 0;
    auto ends_line = [](char c) { return c == '\n' || c == '\r' || c == '\0'; };
    auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; };
    // The next element's line. assimp does not skip blank lines (it reads one as an element), so they are
    // refused here rather than guessed at: 0 = a line, 1 = the data ended, 2 = a blank line.
    auto next_line = [&] {
      if (at >= data.size()) return 1;
      line_end = at;
      while (line_end < data.size() && !ends_line(data[line_end])) ++line_end;
      while (at < line_end && is_space(data[at])) ++at;
      return at < line_end ? 0 : 2;
    };
    auto skip_line_end = [&] {
      at = line_end;
      if (at < data.size()) at += data[at] == '\r' && at + 1 < data.size() && data[at + 1] == '\n' ? 2 : 1;
    };
    auto next_token = [&](std::string_view& token) {
      while (at < line_end && is_space(data[at])) ++at;
      const std::size_t start = at;
      while (at < line_end && !is_space(data[at])) ++at;
      token = data.substr(start, at - start);
      return !token.empty();
    };
    std::string_view token;
    for (const Element& element : elements) {
      if (element.properties.empty()) continue;
      for (std::uint64_t i = 0; i < element.count; ++i) {
        if (const int line = next_line(); line == 1)
          return ends_early(element, i);
        else if (line == 2)
          return "PLY element '" + element.name + "' " + std::to_string(i) + " is a blank line (corrupt?)";
        for (const Property& property : element.properties) {
          if (!next_token(token)) return too_few(element, i);
          if (property.count_size == 0) continue;
          const std::uint64_t count = leading_count(token);
          // Each value needs at least one character and a separator on this line.
          if (count > (line_end - at) / 2 + 1) return list_too_long(element, i, count);
          for (std::uint64_t k = 0; k < count; ++k)
            if (!next_token(token)) return list_too_long(element, i, count);
        }
        skip_line_end();
      }
    }
    return {};
  }
  const bool big_endian = format == "binary_big_endian";
  std::size_t at = 0;
  for (const Element& element : elements) {
    if (element.properties.empty()) continue;
    for (std::uint64_t i = 0; i < element.count; ++i)
      for (const Property& property : element.properties) {
        if (property.count_size == 0) {
          if (data.size() - at < property.value_size) return ends_early(element, i);
          at += property.value_size;
          continue;
        }
        if (data.size() - at < property.count_size) return ends_early(element, i);
        std::uint64_t count = 0;  // read as unsigned: a negative count is as impossible as a huge one
        for (std::size_t b = 0; b < property.count_size; ++b) {
          const std::size_t byte = big_endian ? b : property.count_size - 1 - b;
          count = (count << 8) | static_cast<unsigned char>(data[at + byte]);
        }
        at += property.count_size;
        if (count > (data.size() - at) / property.value_size) return list_too_long(element, i, count);
        at += count * property.value_size;
      }
  }
  return {};
}

// OBJ is a text format. assimp 5.2's OBJ reader, given from memory an `mtllib` line whose name holds NUL
// bytes, writes through a wild pointer (a SEGV, found by tests/fuzz; valgrind shows an invalid write). A NUL
// byte has no business in an OBJ file, so one is refused up front.
std::string binary_data_in_obj(std::string_view text, std::string_view format) {
  if (format != "obj") return {};
  const std::size_t nul = text.find('\0');
  return nul == std::string_view::npos
             ? std::string()
             : "OBJ is a text format, but byte " + std::to_string(nul) + " is NUL (binary data?)";
}

// assimp 5.2's MS3D reader checks a group's triangle indices and a triangle's vertex indices with > where it
// needs >=: index n of n is read past the end of its list, or through null when the list is empty (a group
// naming triangle 0 of none; found by tests/fuzz). It also builds the joint tree recursively. So the indices,
// the groups' materials and the joint count are checked first, walking the file as assimp reads it. Where
// the file ends early assimp stops with an error of its own, and so does this walk, silently.
constexpr std::size_t kMaxMs3dJoints = 1024;  // MilkShape itself allows 128

std::string ms3d_problem(std::string_view bytes) {
  std::size_t at = 14;  // magic and version, which assimp checks
  bool whole = true;
  auto skip = [&](std::uint64_t n) {
    whole = whole && n <= bytes.size() - std::min(at, bytes.size());
    at = whole ? at + n : bytes.size();
  };
  auto unsigned_le = [&](std::size_t n) {
    std::uint32_t value = 0;
    const std::size_t start = at;
    skip(n);
    for (std::size_t i = 0; whole && i < n; ++i)
      value |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[start + i])) << (8 * i);
    return value;
  };
  const std::uint32_t vertices = unsigned_le(2);
  skip(15ull * vertices);  // flags, position, bone, reference count
  const std::uint32_t triangles = unsigned_le(2);
  for (std::uint32_t t = 0; whole && t < triangles; ++t) {
    skip(2);
    for (int k = 0; k < 3; ++k)
      if (const std::uint32_t v = unsigned_le(2); whole && v >= vertices)
        return "MS3D triangle " + std::to_string(t) + " refers to vertex " + std::to_string(v) + " of " +
               std::to_string(vertices);
    skip(36 + 24 + 2);  // normals, uv, smoothing group, group
  }
  const std::uint32_t groups = unsigned_le(2);
  std::vector<std::uint32_t> group_materials;
  for (std::uint32_t g = 0; whole && g < groups; ++g) {
    skip(33);  // flags, name
    const std::uint32_t count = unsigned_le(2);
    for (std::uint32_t j = 0; whole && j < count; ++j)
      if (const std::uint32_t t = unsigned_le(2); whole && t >= triangles)
        return "MS3D group " + std::to_string(g) + " refers to triangle " + std::to_string(t) + " of " +
               std::to_string(triangles);
    group_materials.push_back(unsigned_le(1));
  }
  const std::uint32_t materials = unsigned_le(2);
  for (std::size_t g = 0; whole && materials > 0 && g < group_materials.size(); ++g)
    if (group_materials[g] != 0xFF && group_materials[g] >= materials)
      return "MS3D group " + std::to_string(g) + " uses material " + std::to_string(group_materials[g]) +
             " of " + std::to_string(materials);
  skip(361ull * materials + 12);  // materials; fps, current time, frame count
  const std::uint32_t joints = unsigned_le(2);
  if (whole && joints > kMaxMs3dJoints)
    return "MS3D file has " + std::to_string(joints) + " joints; more than " +
           std::to_string(kMaxMs3dJoints) + " are not read";
  return {};
}

// Binary STL, as assimp recognises it: an 80-byte header, a triangle count, 50 bytes per triangle.
bool is_binary_stl(std::string_view bytes) {
  if (bytes.size() < 84) return false;
  std::uint64_t count = 0;
  for (int i = 3; i >= 0; --i) count = (count << 8) | static_cast<unsigned char>(bytes[80 + i]);
  return 84 + 50 * count == bytes.size();
}

// assimp converts text that starts with a UTF-16 or UTF-32 byte-order mark in ways it does not check (its
// UTF-32 path reads past its buffer), and the checks here read text formats as single bytes: such text is
// refused.
std::string wide_text_problem(std::string_view bytes, std::string_view format) {
  const bool text_format = format == "obj" || format == "off" || (format == "stl" && !is_binary_stl(bytes));
  const auto byte = [&](std::size_t i) {
    return i < bytes.size() ? static_cast<unsigned char>(bytes[i]) : 0u;
  };
  const bool wide = (byte(0) == 0xFE && byte(1) == 0xFF) || (byte(0) == 0xFF && byte(1) == 0xFE);
  return text_format && wide ? "text in UTF-16 or UTF-32 is not read (save it as ASCII or UTF-8)" : "";
}

// The format the input is read as. A hint naming a read format decides (assimp then picks that importer by
// name alone); otherwise the content does, much as assimp would guess it. "" when it is none of them.
std::string read_format(std::string_view bytes, const std::string& hint) {
  if (std::find(std::begin(kReadFormats), std::end(kReadFormats), hint) != std::end(kReadFormats))
    return hint;
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  const std::string_view start = first == std::string_view::npos ? std::string_view() : bytes.substr(first);
  const std::string token =
      lower_case(start.substr(0, std::min<std::size_t>(start.find_first_of(" \t\r\n"), 64)));
  if (bytes.substr(0, 4) == "glTF") return "glb";
  if (start.substr(0, 1) == "{") return "gltf";
  if (has_ply_magic(bytes)) return "ply";
  if (bytes.substr(0, 10) == "MS3D000000") return "ms3d";
  if (starts_with_off_keyword(token)) return "off";
  if (token.rfind("solid", 0) == 0) return "stl";
  if (is_binary_stl(bytes)) return "stl";
  // OBJ: a line with one of its statements among the first lines.
  const std::string_view head = bytes.substr(0, 4096);
  for (std::size_t position = 0; position < head.size();) {
    const std::size_t end = std::min(head.find('\n', position), head.size());
    std::string_view line = head.substr(position, end - position);
    position = end + 1;
    line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
    for (const char* statement : {"v ", "vt ", "vn ", "f ", "o ", "g ", "s ", "mtllib ", "usemtl "})
      if (line.rfind(statement, 0) == 0) return "obj";
  }
  return {};
}

// The checks every input gets, then assimp's read. `file` is the input's path when `bytes` are that file's
// content (assimp then reads the file itself when its name gives the format, so that side files such as
// OBJ's .mtl resolve), empty for input from memory. `asset_directory` as for detail::reduce_gltf.
LoadedMesh load_checked(std::string_view bytes, const std::string& hint, const std::string& source,
                        std::string name, const std::string& file,
                        const std::optional<std::string>& asset_directory) {
  if (ply_header_unterminated(bytes)) throw MeshError(source + kUnterminatedPly);
  const std::string format = read_format(bytes, hint);
  if (format.empty())
    throw MeshError(source + ": unknown or unsupported file format" +
                    (hint.empty() ? "" : " ('" + hint + "')") + "; the loader reads " + kReadFormatList);
  // The PLY checks start at the magic; assimp's reader skips what precedes it (NUL bytes let a header without
  // end_header through to its endless loop; found by tests/fuzz). The PLY rules put the magic first.
  if (format == "ply" && !has_ply_magic(bytes))
    throw MeshError(source + ": not a PLY file: it must start with 'ply'");
  for (const std::string& problem :
       {wide_text_problem(bytes, format), oversized_header_count(bytes, format), ply_body_problem(bytes),
        binary_data_in_obj(bytes, format), format == "ms3d" ? ms3d_problem(bytes) : std::string()})
    if (!problem.empty()) throw MeshError(source + ": " + problem);
  if (format == "gltf" || format == "glb") {
    std::optional<detail::ReducedGltf> gltf;
    try {
      gltf = detail::reduce_gltf(bytes, format, asset_directory);
    } catch (const detail::GltfRefused& e) {
      throw MeshError(source + ": " + e.what());
    }
    if (!gltf) throw MeshError(source + ": not glTF: glTF is JSON text that starts with '{'");
    LoadedMesh loaded = import_with(source, std::move(name), format, [&](Assimp::Importer& importer) {
      return importer.ReadFileFromMemory(gltf->bytes.data(), gltf->bytes.size(), kPostProcess,
                                         gltf->format.c_str());
    });
    loaded.report.ignored_lines += gltf->dropped_line_segments;
    for (auto& warning : gltf->warnings) loaded.report.warnings.push_back("glTF: " + std::move(warning));
    return loaded;
  }
  return import_with(source, std::move(name), format, [&](Assimp::Importer& importer) {
    return !file.empty() && hint == format
               ? importer.ReadFile(file, kPostProcess)
               : importer.ReadFileFromMemory(bytes.data(), bytes.size(), kPostProcess, format.c_str());
  });
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
  const std::string extension = lower_case(path.extension().string());
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
                      lower_case(hint), source, std::filesystem::path(source).stem().string(), std::string(),
                      std::nullopt);
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
