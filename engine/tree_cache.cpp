#include "engine/tree_cache.hpp"

#include "adb/file_io.hpp"

#include <nlohmann/json.hpp>

#include <iostream>
#include <sstream>

namespace bvhlab {

namespace tree_cache_detail {

std::vector<std::byte> read_file_bytes(const std::filesystem::path& file) {
  return file_io::read_all(file);
}

void write_file_bytes(const std::filesystem::path& file, std::span<const std::byte> bytes) {
  std::filesystem::create_directories(file.parent_path());
  file_io::write_atomically(file, bytes);
}

}  // namespace tree_cache_detail

TreeCache::TreeCache(std::filesystem::path dir, std::function<void(const std::string&)> log)
    : dir_(std::move(dir)), log_(std::move(log)) {}

std::optional<AnyTree> TreeCache::load(const std::string& key, std::string_view bv, const Mesh& mesh,
                                       CachedTreeTimes* times, std::string_view expected_density) {
  if (!enabled()) return std::nullopt;
  const auto file = tree_file(key, bv);
  if (!std::filesystem::exists(file) && !std::filesystem::exists(meta_file(file))) {
    ++counts_.misses;
    return std::nullopt;
  }
  try {
    const std::vector<std::byte> payload = read_checked_payload(key, file, times);
    AnyTree tree = AnyTree::from_bytes(payload, file.string(), &mesh);
    if (tree.info().bv != bv)
      throw std::runtime_error("a " + tree.info().bv + " tree, expected " + std::string(bv));
    if (tree.info().annotation != expected_density)
      throw std::runtime_error("annotated as '" + tree.info().annotation + "', expected '" +
                               std::string(expected_density) + "'");
    ++counts_.hits;
    return tree;
  } catch (const std::exception& e) {
    ++counts_.rejected;
    say("tree cache: rejected " + file.filename().string() + " (" + e.what() + "); rebuilding");
    return std::nullopt;
  }
}

void TreeCache::store(const std::string& key, const AnyTree& tree, const CachedTreeTimes& times) {
  if (!enabled()) return;
  const auto file = tree_file(key, tree.info().bv);
  try {
    write_entry(key, file, tree.save_bytes(file.string()), times);
    ++counts_.stored;
  } catch (const std::exception& e) {
    say("tree cache: could not store " + file.string() + " (" + e.what() + ")");
  }
}

std::filesystem::path TreeCache::tree_file(const std::string& key, std::string_view bv) const {
  return dir_ / (std::string(bv) + "-" + ContentHash().update(key).hex() + ".tree");
}

std::filesystem::path TreeCache::meta_file(const std::filesystem::path& tree_file) {
  auto meta = tree_file;
  meta += ".meta.json";
  return meta;
}

std::vector<std::byte> TreeCache::read_checked_payload(const std::string& key,
                                                       const std::filesystem::path& file,
                                                       CachedTreeTimes* times) const {
  nlohmann::json meta;
  try {
    const auto meta_bytes = tree_cache_detail::read_file_bytes(meta_file(file));
    meta = nlohmann::json::parse(reinterpret_cast<const char*>(meta_bytes.data()),
                                 reinterpret_cast<const char*>(meta_bytes.data()) + meta_bytes.size());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("unreadable meta file: ") + e.what());
  }
  if (!meta.is_object() || !meta.contains("key") || !meta["key"].is_string() || meta["key"] != key)
    throw std::runtime_error("stale: the entry was made for another key");
  if (!meta.contains("payload_bytes") || !meta.contains("payload_hash") ||
      !meta["payload_bytes"].is_number_unsigned() || !meta["payload_hash"].is_string())
    throw std::runtime_error("meta file lacks the payload's size or checksum");
  std::vector<std::byte> payload = tree_cache_detail::read_file_bytes(file);
  if (payload.size() != meta["payload_bytes"].get<std::size_t>())
    throw std::runtime_error("payload has " + std::to_string(payload.size()) + " bytes, the meta file says " +
                             std::to_string(meta["payload_bytes"].get<std::size_t>()));
  if (ContentHash::to_hex(hash_bytes(payload)) != meta["payload_hash"].get<std::string>())
    throw std::runtime_error("payload checksum mismatch");
  if (times) {
    times->build_seconds = meta.value("build_seconds", 0.0);
    times->annotate_seconds = meta.value("annotate_seconds", 0.0);
  }
  return payload;
}

void TreeCache::write_entry(const std::string& key, const std::filesystem::path& file,
                            std::span<const std::byte> payload, const CachedTreeTimes& times) const {
  nlohmann::json meta = {{"key", key},
                         {"payload_bytes", payload.size()},
                         {"payload_hash", ContentHash::to_hex(hash_bytes(payload))},
                         {"build_seconds", times.build_seconds},
                         {"annotate_seconds", times.annotate_seconds}};
  const std::string text = meta.dump(2) + "\n";
  // Payload first, meta last: a crash in between leaves a meta-less entry, which load() rejects.
  std::filesystem::remove(meta_file(file));
  tree_cache_detail::write_file_bytes(file, payload);
  tree_cache_detail::write_file_bytes(meta_file(file), std::as_bytes(std::span(text.data(), text.size())));
}

void TreeCache::say(const std::string& message) const {
  if (log_)
    log_(message);
  else
    std::cerr << message << '\n';
}

}  // namespace bvhlab
