// A 64-bit content hash for cache keys and payload checksums. Not cryptographic: it guards against stale and
// damaged cache files, not against an adversary, and a 64-bit value makes accidental collisions negligible
// for a cache of thousands of entries.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// Streaming hash: eight bytes per step, each word mixed by the splitmix64 finaliser, so every input bit
/// reaches every output bit. Feeding the same bytes in any split gives the same value.
class ContentHash {
 public:
  explicit ContentHash(std::uint64_t seed = 0x62766c61622d6331ull) : state_(seed) {}

  ContentHash& update(std::span<const std::byte> bytes) {
    for (std::byte b : bytes) {
      buffer_ |= static_cast<std::uint64_t>(b) << (8 * filled_);
      if (++filled_ == 8) absorb();
    }
    length_ += bytes.size();
    return *this;
  }
  ContentHash& update(std::string_view text) {
    return update(std::as_bytes(std::span(text.data(), text.size())));
  }

  [[nodiscard]] std::uint64_t digest() const {
    ContentHash copy = *this;
    copy.buffer_ ^= copy.length_ << 8;  // the length separates "ab" + "" from "a" + "b" padded alike
    copy.absorb();
    return mix(copy.state_);
  }
  [[nodiscard]] std::string hex() const { return to_hex(digest()); }

  static std::string to_hex(std::uint64_t value) {
    static constexpr char digits[] = "0123456789abcdef";
    std::string out(16, '0');
    for (int i = 15; i >= 0; --i, value >>= 4) out[static_cast<std::size_t>(i)] = digits[value & 15];
    return out;
  }

 private:
  static std::uint64_t mix(std::uint64_t x) {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return x;
  }
  void absorb() {
    state_ = mix(state_ ^ mix(buffer_ + 0x9e3779b97f4a7c15ull));
    buffer_ = 0;
    filled_ = 0;
  }

  std::uint64_t state_;
  std::uint64_t buffer_ = 0;
  unsigned filled_ = 0;
  std::uint64_t length_ = 0;
};

inline std::uint64_t hash_bytes(std::span<const std::byte> bytes) {
  return ContentHash().update(bytes).digest();
}

/// Hash of a file's bytes; throws std::runtime_error if it cannot be read.
inline std::uint64_t hash_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open for reading");
  ContentHash hash;
  std::vector<char> chunk(1 << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    hash.update(std::as_bytes(std::span(chunk.data(), got)));
  }
  if (in.bad()) throw std::runtime_error(path.string() + ": read error");
  return hash.digest();
}

}  // namespace bvhlab
