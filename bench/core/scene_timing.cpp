// Scene fields that say how a run measures: "timing", the workload's "axis", and the check that the summary
// distances hold poses. Refused before any mesh is loaded, naming the field.
#include "bench/core/scene_json.hpp"

namespace bvhlab {

const char* statistic_name(TimingSpec::Statistic statistic) {
  return statistic == TimingSpec::Statistic::Min ? "min" : "median";
}

namespace scene_json {

void parse_timing(const Node& root, Scene& scene) {
  if (!root.has("timing")) return;
  const Node t = root.child("timing");
  t.expect_object({"repeats", "statistic"});
  if (t.has("repeats")) {
    const Node r = t.child("repeats");
    if (r.value().is_number_integer() && r.value().get<long long>() < 1)
      r.fail("expected at least 1 timed pass over the poses; " + r.got());
    scene.timing.repeats = static_cast<int>(r.integer(1, 1000));
  }
  if (t.has("statistic"))
    scene.timing.statistic = t.child("statistic").choice({"median", "min"}) == "min"
                                 ? TimingSpec::Statistic::Min
                                 : TimingSpec::Statistic::Median;
}

void parse_axis(const Node& workload, WorkloadSpec& spec) {
  if (spec.kind == WorkloadSpec::Kind::Protocol) {
    if (workload.has("axis"))
      workload.child("axis").fail(
          "the protocol's axis is its distances; \"axis\" applies to random and pose-file workloads");
    spec.axis = WorkloadSpec::Axis::Distance;
    return;
  }
  spec.axis = WorkloadSpec::Axis::Separation;
  if (!workload.has("axis")) return;
  const Node a = workload.child("axis");
  if (spec.kind == WorkloadSpec::Kind::Random) {
    (void)a.choice({"separation"});  // a random workload has no groups of its own
    return;
  }
  if (a.choice({"separation", "group"}) == "group") spec.axis = WorkloadSpec::Axis::Group;
}

void check_quality_band(const Node& root, const Scene& scene) {
  const ReportSpec& report = scene.report;
  const WorkloadSpec& workload = scene.workload;
  if (!report.quality_given || workload.axis == WorkloadSpec::Axis::Separation) return;
  std::size_t inside = 0;
  std::vector<std::string> distances;
  for (const PoseGroup& g : workload.groups) {
    if (g.distance >= report.quality_min - 1e-12 && g.distance <= report.quality_max + 1e-12)
      inside += g.poses.size();
    if (distances.size() < 12) distances.push_back(number_text(g.distance));
  }
  if (inside > 0) return;
  root.child("report")
      .child("quality_distances")
      .fail("no pose of the workload lies in [" + number_text(report.quality_min) + ", " +
            number_text(report.quality_max) + "]; its " +
            (workload.kind == WorkloadSpec::Kind::Protocol ? "distances" : "groups") + " are " +
            join(distances) + (workload.groups.size() > distances.size() ? ", ..." : ""));
}

}  // namespace scene_json
}  // namespace bvhlab
