// A failed `build` writes nothing: no tree, no temporary left behind, and an older tree stays intact. Apart
// from test_bad_input.cpp because it runs the runner's tree store (bench/run.hpp), which the ASan stage does
// not build: the atomic write itself is sanitized with the saved trees (tests/adb/test_saved_tree.cpp).
#include "bench/run.hpp"
#include "bvh/mesh_io.hpp"
#include "support/file_bytes.hpp"
#include "support/meshes.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

namespace fs = std::filesystem;

using testing::read_bytes;

class FailedBuild : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("bvhlab-failed-build-" + std::to_string(getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::vector<std::string> files() const {
    std::vector<std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir_))
      out.push_back(e.path().lexically_relative(dir_));
    std::sort(out.begin(), out.end());
    return out;
  }
  static SceneObject object(const fs::path& mesh) {
    SceneObject o;
    o.name = mesh.stem().string();
    o.mesh = mesh.string();
    o.path = mesh;
    return o;
  }
  static HierarchySpec aabb() {
    HierarchySpec h;
    h.name = h.bv = "aabb";
    return h;
  }
  fs::path dir_;
};

TEST_F(FailedBuild, CorruptMeshLeavesNoFile) {
  const fs::path mesh = dir_ / "broken.obj";
  std::ofstream(mesh) << "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n";
  const fs::path output = dir_ / "out.tree";
  EXPECT_THROW(build_tree_file(object(mesh), aabb(), {}, output, 1), MeshError);
  EXPECT_EQ(files(), std::vector<std::string>{"broken.obj"});
}

TEST_F(FailedBuild, OlderTreeSurvivesAFailedRebuild) {
  const fs::path good = testing::bundled_mesh("pinion.off");
  const fs::path output = dir_ / "pinion.tree";
  build_tree_file(object(good), aabb(), {}, output, 1);
  const auto before = read_bytes(output);
  ASSERT_FALSE(before.empty());
  const fs::path broken = dir_ / "broken.obj";
  std::ofstream(broken) << "v 0 0 0\nf 1 1 1\n";
  EXPECT_THROW(build_tree_file(object(broken), aabb(), {}, output, 1), MeshError);
  EXPECT_EQ(read_bytes(output), before);
  EXPECT_EQ(files(), (std::vector<std::string>{"broken.obj", "pinion.tree"}));
}

TEST_F(FailedBuild, UnwritableDestinationLeavesNoTemporary) {
  const fs::path good = testing::bundled_mesh("pinion.off");
  // The destination is an existing, non-empty directory: the final rename must fail.
  const fs::path output = dir_ / "taken.tree";
  fs::create_directories(output / "inside");
  EXPECT_ANY_THROW(build_tree_file(object(good), aabb(), {}, output, 1));
  EXPECT_EQ(files(), (std::vector<std::string>{"taken.tree", "taken.tree/inside"}));
  // The destination's parent is a regular file.
  const fs::path blocker = dir_ / "file";
  std::ofstream(blocker) << "x";
  EXPECT_ANY_THROW(build_tree_file(object(good), aabb(), {}, blocker / "out.tree", 1));
  EXPECT_EQ(files(), (std::vector<std::string>{"file", "taken.tree", "taken.tree/inside"}));
}

}  // namespace
}  // namespace bvhlab
