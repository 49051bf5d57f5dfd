// Comparing two series of a report: the same work, or a speed-up with its interval; and the summaries the
// comparisons read.
#include "bench/pairs/report.hpp"
#include "bench/report_tables.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <tuple>

namespace bvhlab {
namespace {

bool within_one_percent(double a, double b) {
  if (!std::isfinite(a) || !std::isfinite(b)) return false;  // FCL counts nothing: no claim of equal work
  return std::abs(a - b) <= 0.01 * std::max(std::abs(a), std::abs(b));
}

std::string series_key(const ResultRow& r) {
  return r.mesh + '\x1f' + r.hierarchy + '\x1f' + r.label;
}

SeriesSummary first_summary(const ResultRow& r) {
  SeriesSummary s;
  s.mesh = r.mesh;
  s.hierarchy = r.hierarchy;
  s.bv = r.bv;
  s.annotation = r.annotation;
  s.strategy = r.strategy;
  s.label = r.label;
  s.exact_strategy = r.exact_strategy;
  s.budget = r.budget;
  s.p_min = r.p_min;
  s.bytes_per_triangle = r.bytes_per_triangle;
  return s;
}

/// Query-weighted means of the rows `keep` admits, one summary per series.
std::vector<SeriesSummary> summarize_if(const std::vector<ResultRow>& rows,
                                        const std::function<bool(const ResultRow&)>& keep) {
  std::vector<SeriesSummary> out;
  std::map<std::string, std::size_t> index;
  for (const ResultRow& r : rows) {
    if (r.queries == 0 || !keep(r)) continue;
    auto it = index.find(series_key(r));
    if (it == index.end()) {
      it = index.emplace(series_key(r), out.size()).first;
      out.push_back(first_summary(r));
    }
    SeriesSummary& s = out[it->second];
    const double q = double(r.queries);
    s.queries += r.queries;
    s.mean_time_us += r.mean_time_us * q;
    s.fp_rate += r.fp_rate * q;
    s.fn_rate += r.fn_rate * q;
    s.bv_tests_per_query += r.bv_tests_per_query * q;  // NaN (FCL: no counters) stays NaN
    s.triangle_tests_per_query += r.triangle_tests_per_query * q;
    s.estimates_per_query += r.estimates_per_query * q;
    s.max_time_us = std::max(s.max_time_us, r.max_time_us);
    s.pose_times_us.insert(s.pose_times_us.end(), r.pose_times_us.begin(), r.pose_times_us.end());
  }
  for (SeriesSummary& s : out) {
    const double q = double(s.queries);
    for (double* v : {&s.mean_time_us, &s.fp_rate, &s.fn_rate, &s.bv_tests_per_query,
                      &s.triangle_tests_per_query, &s.estimates_per_query})
      *v /= q;
    s.median_time_us = report_tables::median(s.pose_times_us);
    s.p99_time_us = report_tables::quantile(s.pose_times_us, 0.99);
  }
  return out;
}

}  // namespace

std::vector<SeriesSummary> summarize(const std::vector<ResultRow>& rows, double lo, double hi) {
  return summarize_if(
      rows, [&](const ResultRow& r) { return r.distance >= lo - 1e-12 && r.distance <= hi + 1e-12; });
}

std::vector<SeriesSummary> summarize_band(const std::vector<ResultRow>& rows) {
  return summarize_if(rows, [](const ResultRow& r) { return r.in_summary; });
}

bool same_work(const SeriesSummary& a, const SeriesSummary& b) {
  return within_one_percent(a.bv_tests_per_query, b.bv_tests_per_query) &&
         within_one_percent(a.triangle_tests_per_query, b.triangle_tests_per_query) &&
         within_one_percent(a.estimates_per_query, b.estimates_per_query);
}

Interval time_ratio(const SeriesSummary& slow, const SeriesSummary& fast) {
  if (slow.pose_times_us.empty() || fast.pose_times_us.empty()) {  // summaries made without per-pose times
    const double r = fast.mean_time_us > 0 ? slow.mean_time_us / fast.mean_time_us : std::nan("");
    return {r, std::nan(""), std::nan("")};
  }
  return ratio_of_means(slow.pose_times_us, fast.pose_times_us);
}

std::string speedup_text(const Interval& ratio, bool same, bool bold) {
  const std::string b = bold ? "**" : "";
  const bool has_interval = std::isfinite(ratio.lo) && std::isfinite(ratio.hi);
  const std::string interval =
      has_interval ? fmt::format("95% interval {:.2f}–{:.2f}×", ratio.lo, ratio.hi) : "no interval";
  if (same)
    return b + "same work" + b +
           fmt::format(
               " (BV tests, triangle tests and estimates within 1%; time ratio {:.2f}×, {}): not a speed-up",
               ratio.value, interval);
  if (!std::isfinite(ratio.value) || ratio.value <= 0) return "n/a";
  if (has_interval && ratio.contains(1))
    return b + "no measurable difference" + b + fmt::format(" ({:.2f}×, {})", ratio.value, interval);
  if (ratio.value >= 1) return b + fmt::format("{:.2f}× faster", ratio.value) + b + " (" + interval + ")";
  const std::string inverted =  // a slow-down is stated as its own ratio, so its interval is inverted too
      has_interval ? fmt::format("95% interval {:.2f}–{:.2f}×", 1 / ratio.hi, 1 / ratio.lo) : interval;
  return b + fmt::format("{:.2f}× slower", 1 / ratio.value) + b + " (" + inverted + ")";
}

namespace {

/// A label without its "p_min=..." word: the name of the curve the series is a point of.
std::string without_p_min(const std::string& label) {
  const std::size_t at = label.find("p_min=");
  if (at == std::string::npos) return label;
  std::size_t end = label.find(' ', at);
  end = end == std::string::npos ? label.size() : end + 1;
  std::string out = label.substr(0, at) + label.substr(end);
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

CurveStep curve_step(const SeriesSummary& a, const SeriesSummary& b, const std::string& curve) {
  CurveStep step;
  step.mesh = a.mesh;
  step.hierarchy = a.hierarchy;
  step.curve = curve;
  step.p_min = a.p_min;
  step.next_p_min = b.p_min;
  step.bv_tests = a.bv_tests_per_query;
  step.next_bv_tests = b.bv_tests_per_query;
  step.time_ratio = time_ratio(b, a);
  step.same_work = same_work(a, b);
  const Interval& t = step.time_ratio;
  const bool measured = std::isfinite(t.lo) && std::isfinite(t.hi);
  const bool changed = !within_one_percent(a.bv_tests_per_query, b.bv_tests_per_query);
  const bool more_work = changed && b.bv_tests_per_query > a.bv_tests_per_query;
  const bool less_work = changed && b.bv_tests_per_query < a.bv_tests_per_query;
  step.against_work = measured && ((more_work && t.hi < 1) || (less_work && t.lo > 1));
  return step;
}

}  // namespace

std::vector<CurveStep> pmin_curve_steps(const std::vector<SeriesSummary>& series) {
  using Key = std::tuple<std::string, std::string, std::string>;  // mesh, hierarchy, curve
  std::map<Key, std::vector<const SeriesSummary*>> curves;
  std::vector<Key> order;
  for (const SeriesSummary& s : series) {
    if (s.exact_strategy || s.p_min < 0) continue;
    Key key{s.mesh, s.hierarchy, without_p_min(s.label)};
    auto& points = curves[key];
    if (points.empty()) order.push_back(std::move(key));
    points.push_back(&s);
  }
  std::vector<CurveStep> steps;
  for (const Key& key : order) {
    auto& points = curves[key];
    std::stable_sort(points.begin(), points.end(),
                     [](const SeriesSummary* x, const SeriesSummary* y) { return x->p_min < y->p_min; });
    for (std::size_t k = 1; k < points.size(); ++k)
      steps.push_back(curve_step(*points[k - 1], *points[k], std::get<2>(key)));
  }
  return steps;
}

}  // namespace bvhlab
