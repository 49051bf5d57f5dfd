#include "adb/adb_density.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <map>
#include <mutex>

namespace bvhlab {

namespace {

constexpr ParamSpec kAdbParameters[] = {
    {.name = "grid",
     .description = "cells per axis of the grid laid on each node's bounding box",
     .min = 2,
     .max = 4,
     .default_value = 2,
     .integer = true},
    {.name = "tau",
     .description = "area threshold of a possible collision cell, as a fraction of the cell's mean face area",
     .min = 0,
     .max = 1,
     .default_value = kDefaultAdbTau},
};

// Saved bytes, version 1: grid (u32 LE), tau (IEEE double bits, u64 LE), then one pc byte per node.
constexpr std::size_t kParamsBytes = 12;

void put_le(std::vector<std::byte>& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::byte>((value >> (8 * i)) & 0xff));
}
std::uint64_t get_le(const std::byte* at, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value |= std::uint64_t(std::to_integer<std::uint8_t>(at[i])) << (8 * i);
  return value;
}

}  // namespace

std::shared_ptr<const AdbModel> shared_adb_model(int grid, double tau) {
  if (grid < 1 || grid > 6) throw std::invalid_argument("adb model: grid must lie in [1, 6]");
  static std::mutex mutex;
  static std::map<std::pair<int, std::uint64_t>, std::shared_ptr<const AdbModel>> models;
  const std::lock_guard lock(mutex);
  auto& slot = models[{grid, std::bit_cast<std::uint64_t>(tau)}];
  if (!slot) slot = std::make_shared<const AdbModel>(grid, tau);
  return slot;
}

namespace adb_storage {

std::span<const ParamSpec> parameters() {
  return kAdbParameters;
}

AdbParams make_params(const ParamValues& values, std::string_view name) {
  AdbParams params{static_cast<int>(parameter(values, "grid")), parameter(values, "tau")};
  try {
    (void)lb_for_tau(params.tau);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(name) + ": no LB value for tau = " + parameter_text(params.tau) +
                                " (" + e.what() + ")");
  }
  return params;
}

AdbStorage make(const AdbParams& params, std::vector<std::uint8_t> counts, std::string_view name) {
  const AdbParams checked =
      make_params(resolve_parameters(parameters(), {{"grid", params.grid}, {"tau", params.tau}}, name), name);
  const int cells = checked.grid * checked.grid * checked.grid;
  if (std::any_of(counts.begin(), counts.end(), [&](std::uint8_t c) { return c > cells; }))
    throw std::invalid_argument(std::string(name) + ": a possible-collision-cell count exceeds the grid's " +
                                std::to_string(cells) + " cells");
  return {checked, std::move(counts), shared_adb_model(checked.grid, checked.tau)};
}

std::string describe(const AdbParams& params, std::string_view name) {
  return std::string(name) + " grid=" + std::to_string(params.grid) + " tau=" + parameter_text(params.tau);
}

std::vector<std::byte> encode(const AdbStorage& storage) {
  std::vector<std::byte> out;
  out.reserve(kParamsBytes + storage.possible_collision_cells.size());
  put_le(out, static_cast<std::uint32_t>(storage.params.grid), 4);
  put_le(out, std::bit_cast<std::uint64_t>(storage.params.tau), 8);
  const auto pc = std::as_bytes(std::span(storage.possible_collision_cells));
  out.insert(out.end(), pc.begin(), pc.end());
  return out;
}

AdbStorage decode(std::span<const std::byte> bytes, std::size_t node_count, std::string_view name) {
  if (bytes.size() != kParamsBytes + node_count)
    throw std::invalid_argument(std::string(name) + ": " + std::to_string(bytes.size()) +
                                " bytes of annotation for " + std::to_string(node_count) +
                                " nodes (expected " + std::to_string(kParamsBytes + node_count) + ")");
  const auto grid = get_le(bytes.data(), 4);
  const double tau = std::bit_cast<double>(get_le(bytes.data() + 4, 8));
  std::vector<std::uint8_t> counts(node_count);
  if (node_count) std::memcpy(counts.data(), bytes.data() + kParamsBytes, node_count);
  const ParamValues values{{"grid", grid > 1000 ? 1000.0 : double(grid)}, {"tau", tau}};
  return make(make_params(resolve_parameters(parameters(), values, name), name), std::move(counts), name);
}

void check_combinable(const AdbStorage& a, const AdbStorage& b, std::string_view name) {
  if (!a.model || !b.model)
    throw std::invalid_argument(std::string(name) + ": a tree carries no ADB annotation");
  if (!(a.params == b.params))
    throw std::invalid_argument(std::string(name) + ": the trees were annotated with other parameters (" +
                                describe(a.params, name) + " and " + describe(b.params, name) + ")");
}

}  // namespace adb_storage

}  // namespace bvhlab
