// libFuzzer target: mesh loading from a memory buffer (bvh/mesh_io.hpp), then everything a loaded mesh is
// promised to survive. Input: one selector byte (the format hint), then the file's bytes.
//
// A MeshError is the expected way to refuse. Anything else -- another exception, a crash, a sanitizer report,
// or a loaded mesh that breaks the loader's promises -- is a finding.
#include "bvh/bvh.hpp"
#include "bvh/mesh_io.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>

namespace {

// The formats the loader documents, plus "" (assimp guesses from the content).
constexpr const char* kFormats[] = {"obj", "ply", "stl", "off", "ms3d", "gltf", "glb", ""};

[[noreturn]] void broken_promise(const char* what) {
  std::fprintf(stderr, "fuzz_mesh_load: loaded mesh breaks a promise: %s\n", what);
  std::abort();
}

void check_loaded(const bvhlab::LoadedMesh& loaded) {
  using namespace bvhlab;
  const Mesh& mesh = loaded.mesh;
  if (mesh.triangles.empty()) broken_promise("no triangles");
  for (const auto& t : mesh.triangles)
    for (auto i : t)
      if (i >= mesh.vertices.size()) broken_promise("index out of range");
  for (const auto& v : mesh.vertices) {
    if (!v.allFinite()) broken_promise("non-finite vertex");
    if (v.cwiseAbs().maxCoeff() > MeshPrecisionLimits::max_abs_coordinate) broken_promise("huge coordinate");
  }
  if (loaded.report.degenerate_triangles > mesh.triangles.size()) broken_promise("degenerate count");

  // A mesh the loader accepted must normalise (it refuses zero-size models) ...
  Mesh normalised = mesh;
  normalize_to_unit_cube(normalised);
  for (const auto& v : normalised.vertices)
    if (!v.allFinite() || v.cwiseAbs().maxCoeff() > 1 + 1e-12) broken_promise("normalisation left [-1, 1]^3");
  // ... and build and answer a query: every triangle touches itself, so the mesh collides with itself.
  if (mesh.triangles.size() > 4096) return;  // keep each run fast
  const auto tree = Bvh<Aabb>::build(normalised, {.threads = 1});
  if (!query_exact(tree, tree, RigidTransform::identity()).collides) broken_promise("mesh misses itself");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const char* format = kFormats[data[0] % std::size(kFormats)];
  const auto bytes = std::as_bytes(std::span(data + 1, size - 1));
  try {
    check_loaded(bvhlab::load_mesh_from_memory(bytes, format, "fuzz-input"));
  } catch (const bvhlab::MeshError& e) {
    // Refused: the message must name the input.
    if (std::string_view(e.what()).find("fuzz-input") == std::string_view::npos) {
      std::fprintf(stderr, "fuzz_mesh_load: refusal does not name the input: %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}
