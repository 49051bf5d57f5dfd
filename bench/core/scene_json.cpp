#include "bench/core/scene_json.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

namespace bvhlab::scene_json {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void check_pose_count(const Node& at, double count, const std::string& how) {
  if (count > limits::kPoses.max)
    at.fail(how + " make " + std::to_string(static_cast<long long>(count)) +
            " poses; a scene generates at most " +
            std::to_string(static_cast<long long>(limits::kPoses.max)));
}

std::string join(const std::vector<std::string>& items, std::string_view sep) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? std::string(sep) : "") + items[i];
  return out;
}

json parse_json(std::string_view text, const std::string& source) {
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    // e.what() is "[json.exception.parse_error.101] parse error at line L, column C: ..."
    std::string what = e.what();
    const auto cut = what.find("] ");
    throw SceneError(source +
                     ": not valid JSON: " + (cut == std::string::npos ? what : what.substr(cut + 2)));
  } catch (const json::exception& e) {
    // Other parser refusals, e.g. a number beyond double's range ("1e999": out_of_range.406).
    std::string what = e.what();
    const auto cut = what.find("] ");
    throw SceneError(source +
                     ": not valid JSON: " + (cut == std::string::npos ? what : what.substr(cut + 2)));
  }
}

std::string read_text(const std::filesystem::path& file, const std::string& what) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SceneError(file.string() + ": cannot read the " + what + " file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::optional<Mat3> axis_angle_rotation(const Vec3& axis, double degrees) {
  // Scale by the largest component before normalising: the norm of [1e200, 1e200, 0] overflows and
  // that of [1e-200, 1e-200, 0] underflows, and either would silently give a matrix that is no rotation.
  const double largest = axis.cwiseAbs().maxCoeff();
  if (!(largest > 0) || !std::isfinite(largest)) return std::nullopt;
  return Eigen::AngleAxisd(degrees * M_PI / 180.0, (axis / largest).normalized()).toRotationMatrix();
}

RigidTransform parse_transform(const Node& node, const std::vector<std::string>& extra) {
  std::vector<std::string> fields{"translation", "rotation", "axis_angle_deg"};
  fields.insert(fields.end(), extra.begin(), extra.end());
  node.expect_object(fields);
  Vec3 translation = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
  if (node.has("translation")) {
    const auto t = node.child("translation").numbers(3);
    translation = Vec3(t[0], t[1], t[2]);
  }
  if (node.has("rotation") && node.has("axis_angle_deg"))
    node.child("axis_angle_deg").fail("give either \"rotation\" or \"axis_angle_deg\", not both");
  if (node.has("rotation")) {
    const Node r = node.child("rotation");
    if (r.array_size() != 3) r.fail("expected 3 rows of 3 numbers");
    for (std::size_t i = 0; i < 3; ++i) {
      const auto row = r.child(i).numbers(3);
      for (int j = 0; j < 3; ++j) rotation(static_cast<int>(i), j) = row[static_cast<std::size_t>(j)];
    }
    try {
      return RigidTransform::checked(rotation, translation, 1e-6);
    } catch (const std::invalid_argument& e) {
      r.fail(std::string("not a rotation: ") + e.what());
    }
  }
  if (node.has("axis_angle_deg")) {
    const Node aa = node.child("axis_angle_deg");
    const auto v = aa.numbers(4);
    const std::optional<Mat3> r = axis_angle_rotation(Vec3(v[0], v[1], v[2]), v[3]);
    if (!r) aa.fail("the rotation axis must be finite and not zero");
    try {
      return RigidTransform::checked(*r, translation, 1e-9);
    } catch (const std::invalid_argument& e) {
      aa.fail(std::string("not a rotation: ") + e.what());
    }
  }
  return RigidTransform{rotation, translation};
}

std::vector<Budget> parse_budgets(const Node& budgets) {
  std::vector<Budget> out;
  for (std::size_t k = 0, m = budgets.array_size(); k < m; ++k) {
    const Node b = budgets.child(k);
    b.expect_object({"bv_tests", "deadline_us"});
    Budget budget;
    if (b.has("bv_tests"))
      budget.max_bv_tests =
          static_cast<std::uint64_t>(b.child("bv_tests")
                                         .integer(static_cast<long long>(limits::kBvTests.min),
                                                  static_cast<long long>(limits::kBvTests.max)));
    if (b.has("deadline_us")) {
      budget.deadline_us = b.child("deadline_us").number(limits::kDeadlineUs.min, limits::kDeadlineUs.max);
      if (!(budget.deadline_us > 0))
        b.child("deadline_us").fail("expected a positive number of microseconds");
    }
    if (budget.unlimited()) b.fail("expected \"bv_tests\" and/or \"deadline_us\"");
    out.push_back(budget);
  }
  return out;
}

}  // namespace bvhlab::scene_json
