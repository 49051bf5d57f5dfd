// bvhlab.run_scene: the scene runner (bench/run.hpp) with its results as results.json holds them; the
// policies' tables.
#include "bench/experiment.hpp"
#include "engine/policies.hpp"
#include "python/bindings.hpp"

#include <pybind11/stl.h>
#include <nlohmann/json.hpp>

#include <iostream>

namespace bvhlab::python {

namespace {

py::object from_json(const nlohmann::json& document) {
  return py::module_::import("json").attr("loads")(document.dump());
}

/// A scene file's path, or a dict in the scene format (its relative paths taken from the working folder).
Scene scene_from(const py::object& scene) {
  if (py::isinstance<py::dict>(scene)) {
    const std::string text = py::str(py::module_::import("json").attr("dumps")(scene));
    return parse_scene(text, std::filesystem::current_path(), "<dict>");
  }
  const std::filesystem::path file = path_argument(scene, "run_scene (a scene file or a dict)");
  require_file(file, "run_scene");
  return load_scene(file);
}

py::object run(const py::object& scene_argument, const py::object& cache, int threads, bool quiet,
               const std::string& per_pose) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores)");
  RunOptions options;
  try {
    options.per_pose = parse_per_pose(per_pose);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(std::string("per_pose: ") + e.what());
  }
  const Scene scene = scene_from(scene_argument);
  if (!cache.is_none()) options.cache_dir = path_argument(cache, "cache");
  options.threads = static_cast<unsigned>(threads);
  options.log = [quiet](const std::string& line) {
    if (!quiet) std::cerr << line << '\n';
  };
  const auto experiment = make_experiment(scene);
  if (const auto option = experiment->refused_option(options, false))
    throw py::value_error(*option + ": does not apply to a " + std::string(experiment->kind()) + " scene");
  nlohmann::json document;
  {
    py::gil_scoped_release release;
    experiment->run(options);
    document = experiment->document();
  }
  return from_json(document);
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
