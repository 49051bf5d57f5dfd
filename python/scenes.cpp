// bvhlab.run_scene: the scene runner's one entry (bench/run_scene.hpp), its results as results.json holds
// them; the policies' tables.
#include "bench/run_scene.hpp"
#include "engine/policies.hpp"
#include "python/bindings.hpp"

#include <pybind11/stl.h>
#include <nlohmann/json.hpp>

#include <iostream>

namespace bvhlab::python {

namespace {

py::object from_json_text(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

py::object from_json(const nlohmann::json& document) {
  return from_json_text(document.dump());
}

/// A scene file's path, or a dict in the scene format (its relative paths taken from the working folder).
py::object run(const py::object& scene, const py::object& cache, int threads, bool quiet,
               const std::string& per_pose) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores)");
  SceneRunRequest request;
  request.per_pose = per_pose;
  if (!cache.is_none()) request.cache_dir = path_argument(cache, "cache");
  request.threads = static_cast<unsigned>(threads);
  if (!quiet) request.log = [](const std::string& line) { std::cerr << line << '\n'; };
  std::string document;
  if (py::isinstance<py::dict>(scene)) {
    const std::string text = py::str(py::module_::import("json").attr("dumps")(scene));
    py::gil_scoped_release release;
    document = run_scene_text(text, std::filesystem::current_path(), request);
  } else {
    const std::filesystem::path file = path_argument(scene, "run_scene (a scene file or a dict)");
    require_file(file, "run_scene");
    py::gil_scoped_release release;
    document = run_scene_file(file, request);
  }
  return from_json_text(document);
}

}  // namespace

void bind_scenes(py::module_& m) {
  m.def("run_scene", &run, py::arg("scene"), py::kw_only(), py::arg("cache") = py::none(),
        py::arg("threads") = 0, py::arg("quiet") = true, py::arg("per_pose") = "none",
        "Runs a scene (a scene file, or a dict in the same format: bench/scenes/README.md) and returns what "
        "results.json holds: a dict with its rows (one per mesh pair, hierarchy, strategy variant and "
        "distance, keyed like the columns of results.csv), models, stats, ground truth and calibration. "
        "cache: a "
        "folder for trees and ground truth (default: none); quiet=False prints the runner's messages; "
        "per_pose=\"all\" or \"wrong\" adds \"poses\", the records of poses.csv (`bvhlab run --per-pose`), "
        "one dict per query or per wrong answer. A world scene (\"world\") returns its rows instead: "
        "\"series\" (per frame, hierarchy and series: candidates, colliding, missed, false_pairs, flagged, "
        "micros), \"broad_phase\" and \"scaling\", keyed like the columns of its CSV files, and with "
        "per_pose \"pairs\" (world_pairs.csv: per candidate pair and series, every answer or the wrong "
        "ones). A deform scene "
        "(\"deform\") returns \"rows\" (per frame, hierarchy, update and strategy), keyed like "
        "deform_frames.csv. A points scene (\"points\") returns \"rows\" and \"summary\", keyed like "
        "points_rows.csv and points_summary.csv.");
  m.def(
      "policies", [] { return from_json(policies_json()); },
      "The registered densities and strategies with their parameters (what `bvhlab policies` prints).");
  m.def("volumes", &volume_names, "The registered bounding volumes.");
  m.def("densities", &density_names, "The registered densities.");
  m.def("strategies", &strategy_names, "The registered traversal strategies.");
}

}  // namespace bvhlab::python
