// Reading scene files: a JSON value that knows where it sits, so every complaint names its field, and the
// parsers for values several scene sections share (transforms). Used by the scene parser (scene.cpp) and the
// many-object world parser (world.cpp); not part of the public scene API.
#pragma once

#include "bench/core/scene.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab::scene_json {

using json = nlohmann::json;

std::string number_text(double v);
std::string join(const std::vector<std::string>& items, std::string_view sep = ", ");

/// A JSON value and where it sits (a JSON pointer), so every complaint can name the field.
class Node {
 public:
  Node(const json& value, std::string pointer, const std::string& source)
      : value_(&value), pointer_(std::move(pointer)), source_(&source) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw SceneError(*source_ + ": " + (pointer_.empty() ? "/" : pointer_) + ": " + problem);
  }
  [[nodiscard]] const json& value() const { return *value_; }
  [[nodiscard]] const std::string& pointer() const { return pointer_; }

  [[nodiscard]] std::string got() const {
    const json& v = *value_;
    if (v.is_string()) return "got \"" + v.get<std::string>() + "\"";
    if (v.is_number() || v.is_boolean()) return "got " + v.dump();
    if (v.is_null()) return "got null";
    if (v.is_array()) return "got an array";
    return "got an object";
  }

  [[nodiscard]] bool has(const std::string& key) const { return value_->contains(key); }
  [[nodiscard]] Node child(const std::string& key) const {
    if (!value_->contains(key)) Node(*value_, pointer_ + "/" + key, *source_).fail("missing");
    return Node((*value_)[key], pointer_ + "/" + escape(key), *source_);
  }
  [[nodiscard]] Node child(std::size_t index) const {
    return Node((*value_)[index], pointer_ + "/" + std::to_string(index), *source_);
  }

  const Node& expect_object(const std::vector<std::string>& allowed) const {
    if (!value_->is_object()) fail("expected an object; " + got());
    for (const auto& [key, _] : value_->items())
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        Node((*value_)[key], pointer_ + "/" + escape(key), *source_)
            .fail("unknown field; expected one of " + join(allowed));
    return *this;
  }
  [[nodiscard]] std::size_t array_size(bool allow_empty = false) const {
    if (!value_->is_array()) fail("expected an array; " + got());
    if (!allow_empty && value_->empty()) fail("expected a non-empty array");
    return value_->size();
  }
  [[nodiscard]] std::string string() const {
    if (!value_->is_string()) fail("expected a string; " + got());
    return value_->get<std::string>();
  }
  [[nodiscard]] std::string choice(const std::vector<std::string>& choices) const {
    if (!value_->is_string() ||
        std::find(choices.begin(), choices.end(), value_->get<std::string>()) == choices.end())
      fail("expected one of " + join(choices) + "; " + got());
    return value_->get<std::string>();
  }
  [[nodiscard]] double number(double lo = -HUGE_VAL, double hi = HUGE_VAL) const {
    if (!value_->is_number()) fail("expected a number; " + got());
    const double v = value_->get<double>();
    if (!std::isfinite(v) || v < lo || v > hi)
      fail("expected a number in [" + number_text(lo) + ", " + number_text(hi) + "]; " + got());
    return v;
  }
  [[nodiscard]] long long integer(long long lo, long long hi) const {
    if (!value_->is_number_integer()) fail("expected an integer; " + got());
    const long long v = value_->get<long long>();
    if (v < lo || v > hi)
      fail("expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]; " + got());
    return v;
  }
  [[nodiscard]] bool boolean() const {
    if (!value_->is_boolean()) fail("expected true or false; " + got());
    return value_->get<bool>();
  }
  [[nodiscard]] std::vector<double> numbers(std::size_t count, double lo = -HUGE_VAL,
                                            double hi = HUGE_VAL) const {
    if (!value_->is_array() || (count && value_->size() != count))
      fail("expected an array of " + (count ? std::to_string(count) + " " : std::string()) + "numbers; " +
           got());
    std::vector<double> out;
    for (std::size_t i = 0; i < value_->size(); ++i) out.push_back(child(i).number(lo, hi));
    return out;
  }

 private:
  static std::string escape(const std::string& key) {  // RFC 6901
    std::string out;
    for (char c : key) out += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
    return out;
  }
  const json* value_;
  std::string pointer_;
  const std::string* source_;
};

/// Parses JSON text; a syntax error becomes a SceneError naming `source`, the line and the column.
json parse_json(std::string_view text, const std::string& source);
/// The whole file; a SceneError naming it (and `what` it should be) when it cannot be read.
std::string read_text(const std::filesystem::path& file, const std::string& what);
/// The rotation by `degrees` about `axis`; nullopt for an axis that is zero or not finite.
std::optional<Mat3> axis_angle_rotation(const Vec3& axis, double degrees);
/// {"translation": [x,y,z], "rotation": 3x3 rows or "axis_angle_deg": [ax,ay,az,deg]}; a matrix that is no
/// rotation is refused. `extra` names further fields the caller allows (and reads itself).
RigidTransform parse_transform(const Node& node, const std::vector<std::string>& extra = {"group"});

/// Fails at `at` unless `count` poses (made up as `how`, say "3 distances of 400000 poses") stay within
/// limits::kPoses: the bound every generated pose set of a scene shares.
void check_pose_count(const Node& at, double count, const std::string& how);

/// A non-empty list of {"bv_tests": N, "deadline_us": T} (either or both), each checked against limits.
std::vector<Budget> parse_budgets(const Node& budgets);

/// The "world" section (bench/world/scene.cpp): instances, their motion, broad phases and frame budgets.
void parse_world(const Node& root, const std::filesystem::path& base_dir, Scene& scene);

/// The "deform" section (bench/deform/scene.cpp): the deforming object, its frames, B's poses, the refit and
/// the density updates.
void parse_deform(const Node& root, const std::filesystem::path& base_dir, Scene& scene);

/// The "points" section (bench/points/scene.cpp): densities, sampling, the protocol, the series'
/// parameters. `fcl`: whether this build has FCL (its octree series).
void parse_points(const Node& root, Scene& scene, bool fcl);

/// The "timing" section (bench/core/scene_timing.cpp): warm repeats per (series, pose) and their statistic.
void parse_timing(const Node& root, Scene& scene);

/// The workload's "axis" (bench/core/scene_timing.cpp): "separation" (the default of random and pose-file
/// workloads) or "group" (a pose file's own groups); the protocol's axis is its distances.
void parse_axis(const Node& workload, WorkloadSpec& spec);

/// Refuses "report/quality_distances" that hold no pose of the workload (bench/core/scene_timing.cpp). A
/// separation axis is binned per mesh pair, so its band is checked when the run has the objects' sizes.
void check_quality_band(const Node& root, const Scene& scene);

}  // namespace bvhlab::scene_json
