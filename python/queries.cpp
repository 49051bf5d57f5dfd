// bvhlab.query and bvhlab.query_batch: one strategy variant between two trees, at one pose or over an array
// of poses (checked first, then queried without the GIL, answered as numpy arrays); the protocol's poses.
#include "engine/any_tree.hpp"
#include "engine/protocol.hpp"
#include "python/bindings.hpp"
#include "traversal/coherent_state.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace bvhlab::python {

namespace {

StrategyVariant variant_from(const std::string& strategy, long long bv_tests, double deadline_us,
                             const py::kwargs& parameters) {
  if (bv_tests < 0) throw py::value_error("bv_tests must be >= 0 (0: no budget of BV tests)");
  if (!std::isfinite(deadline_us) || deadline_us < 0)
    throw py::value_error("deadline_us must be finite and >= 0 (0: no deadline)");
  Budget budget;
  budget.max_bv_tests = static_cast<std::uint64_t>(bv_tests);
  budget.deadline_us = deadline_us;
  return strategy_variant(strategy, parameter_values(parameters), budget);
}

/// Poses from a (K, 4, 4) array, or from rotations (K, 3, 3; default: identities) and translations (K, 3).
std::vector<RigidTransform> poses_from(const py::object& poses, const py::object& rotations,
                                       const py::object& translations) {
  std::vector<RigidTransform> out;
  if (!poses.is_none()) {
    if (!rotations.is_none() || !translations.is_none())
      throw py::value_error("give poses, or rotations and translations, not both");
    const auto m = real_array(poses, "poses", {-1, 4, 4}, "(K, 4, 4)");
    for (py::ssize_t k = 0; k < m.shape(0); ++k)
      out.push_back(rigid_from_matrix(m.data(k, 0, 0), "poses[" + std::to_string(k) + "]"));
    return out;
  }
  if (translations.is_none())
    throw py::value_error("give poses (K, 4, 4), or translations (K, 3) and rotations");
  const auto t = real_array(translations, "translations", {-1, 3}, "(K, 3)");
  const py::ssize_t count = t.shape(0);
  const auto r = rotations.is_none() ? py::array_t<double, py::array::c_style>()
                                     : real_array(rotations, "rotations", {count, 3, 3},
                                                  "(K, 3, 3) with K = " + std::to_string(count));
  const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (py::ssize_t k = 0; k < count; ++k)
    out.push_back(
        rigid_from_parts(rotations.is_none() ? identity : r.data(k, 0, 0), t.data(k, 0),
                         "rotations[" + std::to_string(k) + "], translations[" + std::to_string(k) + "]"));
  return out;
}

/// One pose: a 4 x 4 matrix, or a translation and a rotation (default: identity). None at all is refused, as
/// the CLI refuses a query without --pose: an identity no one asked for answers a question no one asked.
RigidTransform pose_from(const py::object& pose, const py::object& rotation, const py::object& translation) {
  if (!pose.is_none()) {
    if (!rotation.is_none() || !translation.is_none())
      throw py::value_error("give pose, or rotation and translation, not both");
    return rigid_from_matrix(real_array(pose, "pose", {4, 4}, "(4, 4)").data(), "pose");
  }
  if (translation.is_none())
    throw py::value_error(
        "give a pose (4, 4), or a translation (3,) and a rotation (3, 3; default identity)");
  const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const auto r = rotation.is_none() ? py::array_t<double, py::array::c_style>()
                                    : real_array(rotation, "rotation", {3, 3}, "(3, 3)");
  const auto t = real_array(translation, "translation", {3}, "(3,)");
  return rigid_from_parts(rotation.is_none() ? identity : r.data(), t.data(), "pose");
}

/// Contacts' geometry as arrays of one row per contact: triangles (K, 2), segments (K, 2, 3: where the two
/// triangles meet), points (K, 3: the segments' midpoints), normals (K, 3), coplanar (K).
py::dict geometry_arrays(std::span<const ContactGeometry> contacts) {
  const auto k = static_cast<py::ssize_t>(contacts.size());
  py::array_t<std::int64_t> triangles({k, py::ssize_t{2}});
  py::array_t<double> segments({k, py::ssize_t{2}, py::ssize_t{3}}), points({k, py::ssize_t{3}}),
      normals({k, py::ssize_t{3}});
  py::array_t<bool> coplanar(k);
  for (py::ssize_t i = 0; i < k; ++i) {
    const ContactGeometry& g = contacts[static_cast<std::size_t>(i)];
    triangles.mutable_at(i, 0) = g.triangles.a;
    triangles.mutable_at(i, 1) = g.triangles.b;
    for (py::ssize_t c = 0; c < 3; ++c) {
      segments.mutable_at(i, 0, c) = g.from[c];
      segments.mutable_at(i, 1, c) = g.to[c];
      points.mutable_at(i, c) = g.point[c];
      normals.mutable_at(i, c) = g.normal[c];
    }
    coplanar.mutable_at(i) = g.coplanar;
  }
  return py::dict(py::arg("triangles") = triangles, py::arg("segments") = segments,
                  py::arg("points") = points, py::arg("normals") = normals, py::arg("coplanar") = coplanar);
}

struct QueryResult {
  Result result;
  bool geometry_asked = false;
  py::object witness() const {
    if (!result.witness) return py::none();
    return py::make_tuple(result.witness->a, result.witness->b);
  }
  py::array_t<std::int64_t> contacts() const {
    py::array_t<std::int64_t> out({static_cast<py::ssize_t>(result.contacts.size()), py::ssize_t{2}});
    for (std::size_t i = 0; i < result.contacts.size(); ++i) {
      out.mutable_at(i, 0) = result.contacts[i].a;
      out.mutable_at(i, 1) = result.contacts[i].b;
    }
    return out;
  }
  /// The distance strategies' fields; None for the others.
  py::object distance() const {
    if (!result.proximity) return py::none();
    return py::float_(result.proximity->distance);
  }
  py::object lower_bound() const {
    if (!result.proximity) return py::none();
    return py::float_(result.proximity->lower_bound);
  }
  py::object points() const {
    if (!result.proximity || !result.proximity->triangles) return py::none();
    py::array_t<double> out({py::ssize_t{2}, py::ssize_t{3}});
    for (int k = 0; k < 3; ++k) {
      out.mutable_at(0, k) = result.proximity->on_a[k];
      out.mutable_at(1, k) = result.proximity->on_b[k];
    }
    return out;
  }
  py::object nearest() const {
    if (!result.proximity || !result.proximity->triangles) return py::none();
    return py::make_tuple(result.proximity->triangles->a, result.proximity->triangles->b);
  }
  /// Per named contact: its triangles, segment, midpoint, normal and whether it is an area contact.
  py::object contact_geometry() const {
    if (!geometry_asked) return py::none();
    return geometry_arrays(result.contact_geometry);
  }
  py::dict counters() const {
    const Counters& c = result.counters;
    return py::dict(py::arg("bv_tests") = c.bv_tests, py::arg("triangle_tests") = c.triangle_tests,
                    py::arg("nodes_visited") = c.nodes_visited,
                    py::arg("probability_evaluations") = c.probability_evaluations);
  }
};

QueryResult query(const AnyTree& a, const AnyTree& b, const py::object& pose, const py::object& rotation,
                  const py::object& translation, const std::string& strategy, long long bv_tests,
                  double deadline_us, bool contact_geometry, bool wide, const py::kwargs& parameters) {
  StrategyVariant variant = variant_from(strategy, bv_tests, deadline_us, parameters);
  variant.contact_geometry = contact_geometry;
  variant.wide = wide;
  check_strategy_options(variant);
  const RigidTransform checked = pose_from(pose, rotation, translation);
  check_same_kind_of_units(a.info(), b.info());
  const std::unique_ptr<PreparedQuery> prepared = a.prepare(b, variant);
  QueryResult out;
  out.geometry_asked = contact_geometry;
  py::gil_scoped_release release;
  prepared->run({&checked, 1}, [&](std::size_t, const Result& r) { out.result = r; });
  return out;
}

/// The batch's answers, one numpy array per field, each of length K.
struct BatchColumns {
  explicit BatchColumns(py::ssize_t k)
      : collides(k),
        exact(k),
        budget_exhausted(k),
        probability(k),
        witness_a(k),
        witness_b(k),
        contacts(k),
        bv_tests(k),
        triangle_tests(k),
        nodes_visited(k),
        probability_evaluations(k),
        distance(k),
        lower_bound(k),
        points({k, py::ssize_t{2}, py::ssize_t{3}}),
        nearest_a(k),
        nearest_b(k) {}
  py::array_t<bool> collides, exact, budget_exhausted;
  py::array_t<double> probability;
  py::array_t<std::int64_t> witness_a, witness_b, contacts, bv_tests, triangle_tests, nodes_visited,
      probability_evaluations;
  py::array_t<double> distance, lower_bound, points;  ///< NaN for the strategies that measure no distance
  py::array_t<std::int64_t> nearest_a, nearest_b;
  /// With contact_geometry=True: each pose's contacts, kept until the batch ends (their number varies).
  std::optional<std::vector<std::vector<ContactGeometry>>> geometry;

  /// Writes result `i` (called without the GIL: raw pointers into arrays this object keeps alive).
  ResultSink sink() {
    return [c = collides.mutable_data(), e = exact.mutable_data(), x = budget_exhausted.mutable_data(),
            p = probability.mutable_data(), wa = witness_a.mutable_data(), wb = witness_b.mutable_data(),
            n = contacts.mutable_data(), bv = bv_tests.mutable_data(), tri = triangle_tests.mutable_data(),
            nodes = nodes_visited.mutable_data(), est = probability_evaluations.mutable_data(),
            d = distance.mutable_data(), lo = lower_bound.mutable_data(), pts = points.mutable_data(),
            na = nearest_a.mutable_data(), nb = nearest_b.mutable_data(),
            g = geometry ? &*geometry : nullptr](std::size_t i, const Result& r) {
      c[i] = r.collides;
      e[i] = r.exact;
      x[i] = r.budget_exhausted;
      p[i] = r.probability;
      wa[i] = r.witness ? std::int64_t{r.witness->a} : -1;
      wb[i] = r.witness ? std::int64_t{r.witness->b} : -1;
      n[i] = static_cast<std::int64_t>(r.contacts.size());
      bv[i] = static_cast<std::int64_t>(r.counters.bv_tests);
      tri[i] = static_cast<std::int64_t>(r.counters.triangle_tests);
      nodes[i] = static_cast<std::int64_t>(r.counters.nodes_visited);
      est[i] = static_cast<std::int64_t>(r.counters.probability_evaluations);
      write_proximity(r, i, d, lo, pts, na, nb);
      if (g) (*g)[i] = r.contact_geometry;
    };
  }
  static void write_proximity(const Result& r, std::size_t i, double* d, double* lo, double* pts,
                              std::int64_t* na, std::int64_t* nb) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Proximity* p = r.proximity ? &*r.proximity : nullptr;
    const bool pair = p && p->triangles;
    d[i] = p ? p->distance : nan;
    lo[i] = p ? p->lower_bound : nan;
    for (int k = 0; k < 3; ++k) {
      pts[6 * i + k] = pair ? p->on_a[k] : nan;
      pts[6 * i + 3 + k] = pair ? p->on_b[k] : nan;
    }
    na[i] = pair ? std::int64_t{p->triangles->a} : -1;
    nb[i] = pair ? std::int64_t{p->triangles->b} : -1;
  }
  py::dict dict() const {
    py::dict out(py::arg("collides") = collides, py::arg("probability") = probability,
                 py::arg("exact") = exact, py::arg("budget_exhausted") = budget_exhausted,
                 py::arg("witness_a") = witness_a, py::arg("witness_b") = witness_b,
                 py::arg("contact_count") = contacts, py::arg("bv_tests") = bv_tests,
                 py::arg("triangle_tests") = triangle_tests, py::arg("nodes_visited") = nodes_visited,
                 py::arg("probability_evaluations") = probability_evaluations, py::arg("distance") = distance,
                 py::arg("lower_bound") = lower_bound, py::arg("points") = points,
                 py::arg("nearest_a") = nearest_a, py::arg("nearest_b") = nearest_b);
    if (geometry) add_geometry(out);
    return out;
  }
  /// Every pose's contacts in one set of arrays (geometry_arrays), pose i's in rows offsets[i] to
  /// offsets[i + 1]: contact_offsets (K + 1), contact_triangles, contact_segments, contact_points,
  /// contact_normals, contact_coplanar.
  void add_geometry(py::dict& out) const {
    std::vector<ContactGeometry> all;
    py::array_t<std::int64_t> offsets(static_cast<py::ssize_t>(geometry->size() + 1));
    offsets.mutable_at(0) = 0;
    for (std::size_t i = 0; i < geometry->size(); ++i) {
      all.insert(all.end(), (*geometry)[i].begin(), (*geometry)[i].end());
      offsets.mutable_at(static_cast<py::ssize_t>(i + 1)) = static_cast<std::int64_t>(all.size());
    }
    out["contact_offsets"] = offsets;
    for (const auto& [key, value] : geometry_arrays(all))
      out[("contact_" + key.cast<std::string>()).c_str()] = value;
  }
};

/// Runs `prepared` over every pose without the GIL, in chunks; between chunks, at least every 50 ms, takes
/// the GIL back and lets Python handle its signals, so that Ctrl-C raises KeyboardInterrupt within a fraction
/// of a second instead of after the whole batch (the results so far are dropped: nothing half-made returns).
void run_interruptibly(const PreparedQuery& prepared, std::span<const RigidTransform> poses,
                       const ResultSink& sink, CoherentState* state) {
  using Clock = std::chrono::steady_clock;
  constexpr std::size_t kChunk = 16;
  constexpr auto kCheckEvery = std::chrono::milliseconds(50);
  py::gil_scoped_release release;
  auto checked = Clock::now();
  for (std::size_t begin = 0; begin < poses.size(); begin += kChunk) {
    const auto chunk = poses.subspan(begin, std::min(kChunk, poses.size() - begin));
    const ResultSink chunk_sink = [&](std::size_t i, const Result& r) { sink(begin + i, r); };
    if (state)
      prepared.run(chunk, chunk_sink, *state);  // the chunks continue one sequence
    else
      prepared.run(chunk, chunk_sink);
    if (Clock::now() - checked < kCheckEvery) continue;
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    checked = Clock::now();
  }
}

py::dict query_batch(const AnyTree& a, const AnyTree& b, const py::object& poses, const py::object& rotations,
                     const py::object& translations, const std::string& strategy, long long bv_tests,
                     double deadline_us, bool coherent, CoherentState* state, bool contact_geometry,
                     bool wide, const py::kwargs& parameters) {
  StrategyVariant variant = variant_from(strategy, bv_tests, deadline_us, parameters);
  if (state && !coherent) throw py::value_error("a state is kept by coherent queries: give coherent=True");
  variant.coherent = coherent;
  variant.contact_geometry = contact_geometry;
  variant.wide = wide;
  check_strategy_options(variant);
  const std::vector<RigidTransform> checked = poses_from(poses, rotations, translations);
  check_same_kind_of_units(a.info(), b.info());
  const std::unique_ptr<PreparedQuery> prepared = a.prepare(b, variant);
  BatchColumns columns(static_cast<py::ssize_t>(checked.size()));
  if (contact_geometry) columns.geometry.emplace(checked.size());
  CoherentState own;
  run_interruptibly(*prepared, checked, columns.sink(), coherent ? (state ? state : &own) : nullptr);
  return columns.dict();
}

/// The options of a state from Python's keywords (CoherenceOptions; validated by the state).
CoherenceOptions coherence_options(double max_jump, std::size_t max_pairs, std::uint32_t max_cold_run,
                                   int raise_hold, const std::string& judge) {
  if (raise_hold < 0 || raise_hold > 255) throw py::value_error("raise_hold must be 0 to 255");
  CoherenceOptions options;
  options.max_jump = max_jump;
  options.max_pairs = max_pairs;
  options.max_cold_run = max_cold_run;
  options.raise_hold = static_cast<std::uint8_t>(raise_hold);
  options.judge = judge_from_string(judge);
  return options;
}

py::dict options_of(const CoherentState& state) {
  const CoherenceOptions& o = state.options();
  py::dict out;
  out["max_jump"] = o.max_jump;
  out["max_pairs"] = o.max_pairs;
  out["max_cold_run"] = o.max_cold_run;
  out["raise_hold"] = int{o.raise_hold};
  out["judge"] = std::string(to_string(o.judge));
  return out;
}

void bind_coherent_state(py::module_& m) {
  const CoherenceOptions defaults;
  py::class_<CoherentState>(m, "CoherentState",
                            "What coherent queries of one pair of trees keep between calls: the front where "
                            "the last query stopped, its contact, its pose. Pass it to query_batch(..., "
                            "coherent=True, state=s) to continue a sequence of poses across calls. It "
                            "belongs to one pair of trees and one caller at a time. The keywords are the "
                            "state's bounds (traversal/README.md, \"Coherent queries\").")
      .def(py::init([](double max_jump, std::size_t max_pairs, std::uint32_t max_cold_run, int raise_hold,
                       const std::string& judge) {
             return CoherentState(coherence_options(max_jump, max_pairs, max_cold_run, raise_hold, judge));
           }),
           py::kw_only(), py::arg("max_jump") = defaults.max_jump, py::arg("max_pairs") = defaults.max_pairs,
           py::arg("max_cold_run") = defaults.max_cold_run, py::arg("raise_hold") = int{defaults.raise_hold},
           py::arg("judge") = std::string(to_string(defaults.judge)))
      .def_property_readonly("options", &options_of, "the keywords the state was made with, as a dict")
      .def("reset", &CoherentState::reset, "Forget the front and the contact: the next query starts cold.")
      .def_property_readonly("front_size", &CoherentState::front_size, "node pairs the next query re-tests")
      .def_property_readonly("jumps", &CoherentState::jumps,
                             "queries that started from the root because the pose jumped")
      .def_property_readonly("witness_hits", &CoherentState::witness_hits,
                             "queries answered by the remembered contact alone")
      .def_property_readonly("cold_queries", &CoherentState::cold_queries,
                             "queries that started from the root because walking the front had cost more");
}

py::array_t<double> protocol_matrices(double distance, int first, int count, int steps) {
  if (!std::isfinite(distance)) throw py::value_error("distance must be finite");
  if (steps < 1) throw py::value_error("steps must be >= 1");
  py::array_t<double> out({py::ssize_t{count}, py::ssize_t{4}, py::ssize_t{4}});
  for (int k = 0; k < count; ++k)
    matrix_from_rigid(protocol_pose(distance, first + k, steps), out.mutable_data(k));
  return out;
}

}  // namespace

void bind_queries(py::module_& m) {
  bind_coherent_state(m);
  py::class_<QueryResult>(m, "Result", "The answer of one query.")
      .def_property_readonly("collides", [](const QueryResult& q) { return q.result.collides; })
      .def_property_readonly(
          "probability", [](const QueryResult& q) { return q.result.probability; },
          "estimated probability of collision; exactly 0 or 1 when exact")
      .def_property_readonly(
          "exact", [](const QueryResult& q) { return q.result.exact; },
          "decided by exact triangle tests (or by exhausting all overlapping pairs)")
      .def_property_readonly(
          "budget_exhausted", [](const QueryResult& q) { return q.result.budget_exhausted; },
          "a budget ran out: the answer is a best effort")
      .def_property_readonly("witness", &QueryResult::witness,
                             "(triangle of A, triangle of B) that intersect, as mesh indices, or None")
      .def_property_readonly("contacts", &QueryResult::contacts,
                             "(K, 2) array of intersecting triangle pairs (strategy all_contacts)")
      .def_property_readonly("distance", &QueryResult::distance,
                             "the distance (strategies distance, distance_anytime: an upper bound), or None")
      .def_property_readonly("lower_bound", &QueryResult::lower_bound,
                             "what is proven: the distance lies in [lower_bound, distance]; or None")
      .def_property_readonly("points", &QueryResult::points,
                             "(2, 3): the closest points on A and on B, in A's frame; or None")
      .def_property_readonly("nearest", &QueryResult::nearest,
                             "(triangle of A, triangle of B) the points lie on, as mesh indices, or None")
      .def_property_readonly(
          "contact_geometry", &QueryResult::contact_geometry,
          "with contact_geometry=True, per contact (all_contacts) or for the witness where its triangles "
          "meet: a dict of arrays "
          "triangles (K, 2), segments (K, 2, 3: where the two triangles meet), points (K, 3: the segments' "
          "midpoints), normals (K, 3: unit, from A into B) and coplanar (K,: they meet in an area), in A's "
          "frame; None when not asked for")
      .def_property_readonly("counters", &QueryResult::counters)
      .def("__repr__", [](const QueryResult& q) {
        return std::string("<bvhlab.Result collides=") + (q.result.collides ? "True" : "False") +
               " probability=" + std::to_string(q.result.probability) +
               " exact=" + (q.result.exact ? "True" : "False") + ">";
      });

  const char* wide_help =
      " wide=True walks the trees' wide layout, four children a node tested at once (strategies exact and "
      "all_contacts on aabb, the k-DOPs, obb and sphere, distance on obb; not with coherent): the same "
      "answers in less time; each tree builds it on first use and keeps it.";
  const char* strategy_help =
      " strategy: a name of bvhlab.strategies(), its parameters as keyword arguments (p_min=0.9); bv_tests "
      "and "
      "deadline_us: the budget of a strategy that takes one (0: none). B is moved by the pose into A's "
      "frame.";
  m.def("query", &query, py::arg("a"), py::arg("b"), py::arg("pose") = py::none(), py::kw_only(),
        py::arg("rotation") = py::none(), py::arg("translation") = py::none(), py::arg("strategy") = "exact",
        py::arg("bv_tests") = 0, py::arg("deadline_us") = 0.0, py::arg("contact_geometry") = false,
        py::arg("wide") = false,
        (std::string(
             "One query between trees a and b at one pose: a 4 x 4 rigid matrix, or translation (3) and "
             "rotation (3 x 3, default identity); a query without either is refused. contact_geometry=True "
             "adds Result.contact_geometry (strategies that test triangles).") +
         wide_help + strategy_help)
            .c_str());
  m.def(
      "query_batch", &query_batch, py::arg("a"), py::arg("b"), py::arg("poses") = py::none(), py::kw_only(),
      py::arg("rotations") = py::none(), py::arg("translations") = py::none(), py::arg("strategy") = "exact",
      py::arg("bv_tests") = 0, py::arg("deadline_us") = 0.0, py::arg("coherent") = false,
      py::arg("state") = static_cast<CoherentState*>(nullptr), py::arg("contact_geometry") = false,
      py::arg("wide") = false,
      (std::string(
           "Queries every pose of poses (K, 4, 4), or of rotations (K, 3, 3; default identities) and "
           "translations (K, 3), without holding the GIL; Ctrl-C interrupts it (KeyboardInterrupt) within a "
           "fraction of a second. Every pose is checked before the first query. coherent=True starts each "
           "pose where the previous one ended: less work on poses close to each other (traversal/README.md, "
           "\"Coherent queries\"); state (a CoherentState) carries that over to the next call. "
           "Returns a dict of arrays of length K: collides, probability, exact, budget_exhausted, "
           "witness_a and witness_b (-1: none), contact_count and the counters; for the distance "
           "strategies distance, lower_bound, points (K, 2, 3: on A, on B, in A's frame) and nearest_a, "
           "nearest_b (NaN and -1 for the others). contact_geometry=True adds every pose's contacts as "
           "Result.contact_geometry has them, in arrays of one row per contact: pose i's are rows "
           "contact_offsets[i] to contact_offsets[i + 1] of contact_triangles, contact_segments, "
           "contact_points, contact_normals and contact_coplanar.") +
       wide_help + strategy_help)
          .c_str());
  m.def(
      "protocol_poses",
      [](double distance, int steps) {
        if (steps < 1) throw py::value_error("steps must be >= 1");
        return protocol_matrices(distance, 0, steps, steps);
      },
      py::arg("distance"), py::arg("steps"),
      "The benchmark protocol's poses of B at one distance: (steps, 4, 4), one full turn (adb/README.md, "
      "section 4).");
  m.def(
      "protocol_pose",
      [](double distance, int step, int steps) {
        if (step < 0 || step >= steps) throw py::value_error("step must lie in [0, steps)");
        return protocol_matrices(distance, step, 1, steps).attr("reshape")(4, 4);
      },
      py::arg("distance"), py::arg("step"), py::arg("steps"),
      "Step `step` of protocol_poses(distance, steps).");
}

}  // namespace bvhlab::python
