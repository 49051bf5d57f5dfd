// Whole-file reads and atomic whole-file writes: saved trees, and the tree and ground-truth caches above
// them.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab::file_io {

/// What went wrong with which file; what() is "<path>: <problem>".
class FileError : public std::runtime_error {
 public:
  FileError(const std::filesystem::path& path, const std::string& problem)
      : std::runtime_error(path.string() + ": " + problem), path_(path), problem_(problem) {}
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] const std::string& problem() const { return problem_; }

 private:
  std::filesystem::path path_;
  std::string problem_;
};

/// The file's bytes. Throws FileError when it cannot be opened, sized or read whole.
std::vector<std::byte> read_all(const std::filesystem::path& path);

/// Writes `bytes` to a fresh hidden file beside `path` (mode 0644), syncs it and renames it onto `path`:
/// a reader sees the old file or the new one, never part of one, and of two concurrent writers the last
/// rename wins, whole. On failure nothing is left behind and an existing `path` is untouched.
/// The folder must exist. Throws FileError naming `path` and the problem.
void write_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes);

}  // namespace bvhlab::file_io
