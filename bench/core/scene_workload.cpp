// Scene poses: the "workload" section (the protocol, random poses in a box, or a pose file), the held-out
// "calibration" training poses, and the pose files and pose lists the CLI reads. Part of the scene parser
// (scene.cpp); messages name the field or the file's line.
#include "bench/core/scene_workload.hpp"

#include "engine/content_hash.hpp"
#include "engine/protocol.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace bvhlab {

using namespace scene_json;

namespace {

/// A pose file's poses (a list, or {"poses": list}) in groups: each pose's "group", by default the length of
/// its translation; by rising group.
std::vector<PoseGroup> parse_poses(const json& document, const std::string& source) {
  const Node root(document, "", source);
  const Node list = document.is_array() ? root : root.expect_object({"poses"}).child("poses");
  const std::size_t n = list.array_size();
  std::vector<PoseGroup> groups;
  for (std::size_t i = 0; i < n; ++i) {
    const Node entry = list.child(i);
    const RigidTransform pose = parse_transform(entry);
    const double group = entry.has("group") ? entry.child("group").number() : pose.translation.norm();
    auto it =
        std::find_if(groups.begin(), groups.end(), [&](const PoseGroup& g) { return g.distance == group; });
    if (it == groups.end()) it = groups.insert(groups.end(), PoseGroup{group, {}});
    it->poses.push_back(pose);
  }
  std::sort(groups.begin(), groups.end(),
            [](const auto& x, const auto& y) { return x.distance < y.distance; });
  return groups;
}

/// The numbers of one pose-list line, separated by blanks or commas; throws std::invalid_argument.
std::vector<double> line_numbers(std::string_view line) {
  std::vector<double> out;
  std::size_t at = 0;
  const auto separator = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; };
  while (at < line.size()) {
    if (separator(line[at])) {
      ++at;
      continue;
    }
    std::size_t end = at;
    while (end < line.size() && !separator(line[end])) ++end;
    const std::string_view item = line.substr(at, end - at);
    double value = 0;
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (ec == std::errc::result_out_of_range)
      throw std::invalid_argument("'" + std::string(item) + "' is beyond the range of a double");
    if (ec != std::errc() || ptr != item.data() + item.size())
      throw std::invalid_argument("'" + std::string(item) + "' is not a number");
    out.push_back(value);
    at = end;
  }
  return out;
}

/// A "poses" workload: the pose file, read now, and its content as the workload's identity.
void parse_pose_file(const Node& w, const std::filesystem::path& base_dir, WorkloadSpec& workload) {
  w.expect_object({"type", "file", "axis"});
  workload.kind = WorkloadSpec::Kind::PoseFile;
  const Node f = w.child("file");
  std::filesystem::path file(f.string());
  if (!file.is_absolute()) file = base_dir / file;
  workload.pose_file = file;
  std::string text;
  try {
    text = read_text(file, "pose");
    workload.groups = parse_poses(parse_json(text, file.string()), file.string());
  } catch (const SceneError& e) {
    f.fail(e.what());
  }
  workload.identity = "poses:" + ContentHash().update(text).hex();
}

/// A "random" workload: seeded poses in a box, one group filed under distance 0.
void parse_random(const Node& w, WorkloadSpec& workload) {
  w.expect_object({"type", "count", "seed", "box", "axis"});
  workload.kind = WorkloadSpec::Kind::Random;
  workload.count = static_cast<int>(w.child("count").integer(1, static_cast<long long>(limits::kPoses.max)));
  workload.seed = static_cast<std::uint64_t>(w.has("seed") ? w.child("seed").integer(0, 1LL << 53) : 1);
  const Node box = w.child("box");
  if (!box.value().is_array() || box.value().size() != 2)
    box.fail("expected [[x, y, z], [x, y, z]]; " + box.got());
  const auto lo = box.child(0).numbers(3, -1e12, 1e12), hi = box.child(1).numbers(3, -1e12, 1e12);
  workload.box_min = Vec3(lo[0], lo[1], lo[2]);
  workload.box_max = Vec3(hi[0], hi[1], hi[2]);
  if (!(workload.box_min.array() <= workload.box_max.array()).all())
    box.fail("expected the box's lower corner first (each coordinate <= the upper corner's)");
  workload.groups.push_back(
      {0, random_poses(workload.seed, workload.count, workload.box_min, workload.box_max)});
  char identity[256];
  std::snprintf(identity, sizeof identity,
                "random:count=%d:seed=%llu:box=%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", workload.count,
                static_cast<unsigned long long>(workload.seed), lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  workload.identity = identity;
}

/// The pose's twelve numbers, bit for bit.
std::array<std::uint64_t, 12> pose_bits(const RigidTransform& p) {
  std::array<std::uint64_t, 12> out;
  std::memcpy(out.data(), p.rotation.data(), 9 * sizeof(double));
  std::memcpy(out.data() + 9, p.translation.data(), 3 * sizeof(double));
  return out;
}

std::uint64_t pose_hash(const RigidTransform& p) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (std::uint64_t word : pose_bits(p)) h = (h ^ word) * 0xff51afd7ed558ccdull + (h >> 29);
  return h;
}

/// Fails unless no training pose equals (bit for bit) a pose of the workload. It sorts 64-bit hashes, not a
/// tree of 96-byte keys: a scene may hold a million poses.
void check_disjoint(const Node& at, const WorkloadSpec& training, const WorkloadSpec& test) {
  std::vector<std::pair<std::uint64_t, const RigidTransform*>> seen;
  for (const PoseGroup& g : test.groups)
    for (const RigidTransform& p : g.poses) seen.emplace_back(pose_hash(p), &p);
  auto by_hash = [](const auto& a, const auto& b) { return a.first < b.first; };
  std::sort(seen.begin(), seen.end(), by_hash);
  for (const PoseGroup& g : training.groups)
    for (const RigidTransform& p : g.poses) {
      const auto [first, last] =
          std::equal_range(seen.begin(), seen.end(), std::pair{pose_hash(p), &p}, by_hash);
      for (auto it = first; it != last; ++it)
        if (pose_bits(*it->second) == pose_bits(p))
          at.fail("a training pose at distance " + std::to_string(g.distance) +
                  " equals a test pose; choose another training_seed");
    }
}

}  // namespace

std::vector<PoseGroup> load_pose_file(const std::filesystem::path& file) {
  const std::string source = file.string();
  return parse_poses(parse_json(read_text(file, "pose"), source), source);
}

RigidTransform pose_from_numbers(std::span<const double> v) {
  if (v.size() != 3 && v.size() != 7 && v.size() != 12)
    throw std::invalid_argument(
        "expected 3 numbers (TX TY TZ), 7 (TX TY TZ AX AY AZ DEGREES) or 12 (the 3 x 4 "
        "matrix [R | t] row by row); got " +
        std::to_string(v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw std::invalid_argument("expected finite numbers; got " + number_text(x));
  if (v.size() == 12) {
    Mat3 rotation;
    Vec3 translation;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) rotation(i, j) = v[std::size_t(4 * i + j)];
      translation[i] = v[std::size_t(4 * i + 3)];
    }
    try {
      return RigidTransform::checked(rotation, translation, 1e-6);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("not a rotation: ") + e.what());
    }
  }
  RigidTransform pose;
  pose.translation = Vec3(v[0], v[1], v[2]);
  if (v.size() == 7) {
    const std::optional<Mat3> r = axis_angle_rotation(Vec3(v[3], v[4], v[5]), v[6]);
    if (!r) throw std::invalid_argument("the rotation axis must be finite and not zero");
    pose.rotation = *r;
  }
  return pose;
}

std::vector<ListedPose> parse_pose_list(std::string_view text, const std::string& source) {
  std::vector<ListedPose> out;
  std::size_t line_number = 0;
  for (std::size_t at = 0; at <= text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    ++line_number;
    at = end + 1;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#') continue;
    try {
      out.push_back({pose_from_numbers(line_numbers(line)), line_number});
    } catch (const std::invalid_argument& e) {
      throw SceneError(source + ":" + std::to_string(line_number) + ": " + e.what());
    }
  }
  if (out.empty())
    throw SceneError(source + ": no pose (one per line: TX TY TZ [AX AY AZ DEGREES], or 12 numbers)");
  return out;
}

std::vector<ListedPose> load_pose_list(const std::filesystem::path& file) {
  return parse_pose_list(read_text(file, "pose"), file.string());
}

namespace scene_json {

void parse_workload(const Node& root, const std::filesystem::path& base_dir, WorkloadSpec& workload) {
  if (root.has("workload")) {
    const Node w = root.child("workload");
    if (!w.value().is_object()) w.fail("expected an object; " + w.got());
    const std::string type =
        w.has("type") ? w.child("type").choice({"protocol", "poses", "random"}) : "protocol";
    if (type == "random") {
      parse_random(w, workload);
    } else if (type == "protocol") {
      w.expect_object({"type", "distances", "steps", "stride", "axis"});  // axis: refused by parse_axis
      if (w.has("distances")) {
        workload.distances = w.child("distances").numbers(0, limits::kDistance.min, limits::kDistance.max);
        if (workload.distances.empty()) w.child("distances").fail("expected at least one distance");
      }
      if (w.has("steps"))
        workload.steps = static_cast<int>(w.child("steps").integer(
            static_cast<long long>(limits::kSteps.min), static_cast<long long>(limits::kSteps.max)));
      if (w.has("stride")) workload.stride = static_cast<int>(w.child("stride").integer(1, workload.steps));
      const int per_distance = (workload.steps + workload.stride - 1) / workload.stride;
      check_pose_count(w, double(workload.distances.size()) * per_distance,
                       std::to_string(workload.distances.size()) + " distances of " +
                           std::to_string(per_distance) + " poses");
    } else {
      parse_pose_file(w, base_dir, workload);
    }
    parse_axis(w, workload);
  }
  if (workload.kind == WorkloadSpec::Kind::Protocol) {
    // A stride of 1 keeps the identity it had before strides: the ground-truth cache stays valid.
    std::string identity = "protocol:steps=" + std::to_string(workload.steps) +
                           (workload.stride != 1 ? ":stride=" + std::to_string(workload.stride) : "") + ":d=";
    for (double d : workload.distances) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.17g,", d);
      identity += buf;
      workload.groups.push_back({d, protocol_poses(d, workload.steps, workload.stride)});
    }
    workload.identity = identity;
  }
}

/// "calibration": the training pose set, drawn like the workload's poses from another seed.
void parse_calibration(const Node& root, Scene& scene) {
  if (!root.has("calibration")) return;
  const Node c = root.child("calibration");
  c.expect_object({"training_seed", "training_steps"});
  CalibrationSpec spec;
  spec.training_seed = static_cast<std::uint64_t>(c.child("training_seed").integer(0, 1LL << 53));
  spec.training_steps = static_cast<int>(
      c.child("training_steps")
          .integer(static_cast<long long>(limits::kSteps.min), static_cast<long long>(limits::kSteps.max)));
  const WorkloadSpec& test = scene.workload;
  const std::size_t groups = test.kind == WorkloadSpec::Kind::Protocol ? test.distances.size() : 1;
  std::size_t test_poses = 0;
  for (const PoseGroup& g : test.groups) test_poses += g.poses.size();
  check_pose_count(c.child("training_steps"), double(groups) * spec.training_steps + double(test_poses),
                   std::to_string(groups) + " training groups of " + std::to_string(spec.training_steps) +
                       " poses and the workload's " + std::to_string(test_poses));
  WorkloadSpec& training = spec.training;
  training.steps = training.count = spec.training_steps;
  training.seed = spec.training_seed;
  std::mt19937_64 rng(spec.training_seed);
  auto unit = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  if (test.kind == WorkloadSpec::Kind::Protocol) {
    training.distances = test.distances;
    for (double d : test.distances) {
      PoseGroup group{d, {}};
      group.poses.reserve(static_cast<std::size_t>(spec.training_steps));
      for (int k = 0; k < spec.training_steps; ++k) {
        const double theta = 2.0 * std::numbers::pi * unit();
        RigidTransform pose;
        pose.rotation =
            (Eigen::AngleAxisd(theta, Vec3::UnitZ()) * Eigen::AngleAxisd(theta, Vec3::UnitX())).matrix();
        pose.translation = Vec3(d, 0, 0);
        group.poses.push_back(pose);
      }
      training.groups.push_back(std::move(group));
    }
  } else if (test.kind == WorkloadSpec::Kind::Random) {
    if (spec.training_seed == test.seed)
      c.child("training_seed").fail("must differ from the workload's seed (the training poses are held out)");
    training.kind = WorkloadSpec::Kind::Random;
    training.box_min = test.box_min;
    training.box_max = test.box_max;
    training.groups.push_back(
        {0, random_poses(spec.training_seed, spec.training_steps, test.box_min, test.box_max)});
  } else {
    c.fail("needs a protocol or random workload to draw training poses from (a pose file has no seed)");
  }
  check_disjoint(c, training, test);
  training.identity = "calibration-training:seed=" + std::to_string(spec.training_seed) +
                      ":steps=" + std::to_string(spec.training_steps) + ":" + test.identity;
  scene.calibration = std::move(spec);
}

}  // namespace scene_json

}  // namespace bvhlab
