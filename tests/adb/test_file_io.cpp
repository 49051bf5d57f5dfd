// The one whole-file reader and atomic writer (adb/file_io.hpp) that saved trees and the bench caches use.
#include "adb/file_io.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstddef>
#include <filesystem>
#include <iterator>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

namespace fs = std::filesystem;
using file_io::FileError;

class FileIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("bvhlab_file_io_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  [[nodiscard]] std::size_t entries() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), {}));
  }
  fs::path dir_;
};

std::vector<std::byte> bytes_of(const std::string& text) {
  std::vector<std::byte> out;
  for (const char c : text) out.push_back(static_cast<std::byte>(c));
  return out;
}

/// Calls f, expects a FileError naming `path` and containing `problem`.
template <class F>
void expect_file_error(F&& f, const fs::path& path, const std::string& problem) {
  try {
    f();
    ADD_FAILURE() << "no FileError for " << path;
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), path);
    EXPECT_NE(e.problem().find(problem), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

TEST_F(FileIo, RoundTripsAndReplacesWhole) {
  const fs::path file = dir_ / "data.bin";
  std::vector<std::byte> first = bytes_of(std::string("a\0b\nc", 5));
  file_io::write_atomically(file, first);
  EXPECT_EQ(file_io::read_all(file), first);
  const std::vector<std::byte> shorter = bytes_of("x");
  file_io::write_atomically(file, shorter);
  EXPECT_EQ(file_io::read_all(file), shorter);
  file_io::write_atomically(file, {});
  EXPECT_TRUE(file_io::read_all(file).empty());
  EXPECT_EQ(entries(), 1u);  // no temporary left beside it
  EXPECT_EQ(fs::status(file).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
}

TEST_F(FileIo, MissingFileIsNamed) {
  const fs::path file = dir_ / "absent.bin";
  expect_file_error([&] { file_io::read_all(file); }, file, "cannot open for reading");
}

TEST_F(FileIo, FailedWriteLeavesNothingAndKeepsTheTarget) {
  // An occupied directory as the target: the data is written, then the rename fails.
  const fs::path occupied = dir_ / "occupied";
  fs::create_directories(occupied / "inside");
  expect_file_error([&] { file_io::write_atomically(occupied, bytes_of("data")); }, occupied,
                    "cannot move the written file into place");
  EXPECT_TRUE(fs::is_directory(occupied / "inside"));
  EXPECT_EQ(entries(), 1u);
  // A folder that does not exist: the writer does not create it.
  const fs::path nowhere = dir_ / "no" / "such" / "file.bin";
  expect_file_error([&] { file_io::write_atomically(nowhere, bytes_of("data")); }, nowhere,
                    "cannot create a temporary file");
  EXPECT_EQ(entries(), 1u);
}

}  // namespace
}  // namespace bvhlab
