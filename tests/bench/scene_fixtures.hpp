// Helpers for the scene and runner tests: a private temporary folder and small generated mesh files.
#pragma once

#include "bench/core/scene.hpp"
#include "bvh/mesh.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace bvhlab::testing {

/// A fresh folder per test (ctest runs tests in parallel), removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / ("bvhlab-" + std::string(info->test_suite_name()) + "-" +
                                                      info->name() + "-" + std::to_string(getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  ASSERT_TRUE(out.good()) << file;
}

inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A test that parses scene texts in its own folder; `source` names the text in messages.
class SceneParsing : public ::testing::Test {
 protected:
  explicit SceneParsing(std::string source) : source_(std::move(source)) {}
  Scene parse(const std::string& text) { return parse_scene(text, dir.path(), source_); }

  /// Parses `text`, expects a SceneError, and returns its message.
  std::string error_of(const std::string& text) {
    try {
      parse(text);
    } catch (const SceneError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no SceneError for: " << text;
    return {};
  }

  TempDir dir;

 private:
  std::string source_;
};

/// Writes `mesh` as an OBJ file (1-based indices, full precision).
inline void write_obj(const Mesh& mesh, const std::filesystem::path& file) {
  std::ofstream out(file, std::ios::trunc);
  out.precision(17);
  for (const Vec3& v : mesh.vertices) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : mesh.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  ASSERT_TRUE(out.good()) << file;
}

/// Splits one CSV line, honouring double quotes.
inline std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

inline std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) rows.push_back(split_csv_line(line));
  return rows;
}

/// The scene object a scene entry {"mesh": file} gives (in its file's units, as scenes default to), named by
/// its stem.
inline SceneObject object_from(const std::filesystem::path& file) {
  SceneObject object;
  object.mesh = file.filename().string();
  object.name = file.stem().string();
  object.path = file;
  return object;
}

/// A bvhlab hierarchy of one BV, named after it, with the default build options.
inline HierarchySpec hierarchy_of(const std::string& bv) {
  HierarchySpec h;
  h.bv = h.name = bv;
  return h;
}

}  // namespace bvhlab::testing
