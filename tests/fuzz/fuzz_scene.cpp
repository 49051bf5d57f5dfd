// libFuzzer target: the scene-file parser, the pose-file reader and the pose-list parser
// (bench/core/scene.hpp). Input: text, parsed once as a scene, once, written to a temporary file, as a pose
// file, and once as a pose list (`bvhlab query --poses`).
//
// A SceneError naming the source is the expected way to refuse. Anything else -- another exception, a crash,
// a sanitizer report, or an accepted scene that breaks the parser's promises (every transform rigid and
// finite, every name resolvable) -- is a finding.
#include "bench/core/scene.hpp"
#include "engine/policies.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <unistd.h>

namespace {

[[noreturn]] void broken_promise(const std::string& what) {
  std::fprintf(stderr, "fuzz_scene: accepted scene breaks a promise: %s\n", what.c_str());
  std::abort();
}

// Plain arithmetic on the raw coefficients: a scene may generate a million poses, and Eigen's expression
// templates, compiled at -O1 with coverage, cost ten times as much per pose (the input's time limit is 20 s).
void check_rigid(const bvhlab::RigidTransform& t, const char* where) {
  const double* r = t.rotation.data();  // column-major: r[3 * col + row]
  const double* x = t.translation.data();
  bool finite = std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
  for (int k = 0; k < 9; ++k) finite = finite && std::isfinite(r[k]);
  if (!finite) broken_promise(std::string(where) + ": non-finite");
  double orthogonality = 0;  // max |R^T R - I|: column i against column j
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double dot = r[3 * i] * r[3 * j] + r[3 * i + 1] * r[3 * j + 1] + r[3 * i + 2] * r[3 * j + 2];
      orthogonality = std::max(orthogonality, std::abs(dot - (i == j ? 1.0 : 0.0)));
    }
  const double determinant = r[0] * (r[4] * r[8] - r[7] * r[5]) - r[3] * (r[1] * r[8] - r[7] * r[2]) +
                             r[6] * (r[1] * r[5] - r[4] * r[2]);
  if (orthogonality > 1e-6 || determinant < 0)
    broken_promise(std::string(where) +
                   ": not a rotation (max |R^T R - I| = " + std::to_string(orthogonality) + ")");
}

void check_scene(const bvhlab::Scene& scene) {
  using namespace bvhlab;
  if (scene.objects.empty() || scene.hierarchies.empty()) broken_promise("empty objects or hierarchies");
  for (const auto& o : scene.objects) {
    check_rigid(o.placement, "placement");
    if (!(o.scale > 0) || !std::isfinite(o.scale)) broken_promise("scale");
  }
  for (const auto& p : scene.pairs)
    if (!scene.object(p.a) || !scene.object(p.b)) broken_promise("pair names an unknown object");
  for (const auto& s : scene.strategies) {
    for (const auto& name : s.hierarchies)
      if (!scene.hierarchy(name)) broken_promise("strategy names an unknown hierarchy");
    const StrategyInfo& info = strategy_info(s.name);
    for (const auto& v : expand(s)) {  // every accepted value lies in its parameter's range
      (void)v.label();
      for (const ParamSpec& p : info.parameters)
        if (!p.problem(v.value_or(p.name, std::nan(""))).empty()) broken_promise("parameter out of range");
    }
  }
  for (const auto& g : scene.workload.groups)
    for (const auto& pose : g.poses) check_rigid(pose, "pose");
}

// Relative paths resolve here: an empty directory, so only catalog names (meshes/) resolve.
const std::filesystem::path& base_dir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / "bvhlab-fuzz-scene-base";
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

void expect_named_refusal(const bvhlab::SceneError& e, std::string_view source) {
  if (std::string_view(e.what()).rfind(source, 0) != 0) {
    std::fprintf(stderr, "fuzz_scene: refusal does not start with the source %s: %s\n",
                 std::string(source).c_str(), e.what());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    check_scene(bvhlab::parse_scene(text, base_dir(), "fuzz.json"));
  } catch (const bvhlab::SceneError& e) {
    expect_named_refusal(e, "fuzz.json");
  }

  static const std::filesystem::path pose_file = base_dir() / ("poses-" + std::to_string(getpid()) + ".json");
  {
    std::ofstream out(pose_file, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  }
  try {
    for (const auto& group : bvhlab::load_pose_file(pose_file))
      for (const auto& pose : group.poses) check_rigid(pose, "pose file");
  } catch (const bvhlab::SceneError& e) {
    expect_named_refusal(e, pose_file.string());
  }
  try {
    for (const auto& listed : bvhlab::parse_pose_list(text, "fuzz.txt")) {
      check_rigid(listed.pose, "pose list");
      if (listed.line == 0) broken_promise("pose list: a pose without its line");
    }
  } catch (const bvhlab::SceneError& e) {
    expect_named_refusal(e, "fuzz.txt");
  }
  return 0;
}
