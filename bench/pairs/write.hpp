// The write stage of the bench pipeline: a run's rows, calibration bins, models and statistics as files.
#pragma once

#include "bench/run.hpp"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bvhlab {

/// The CSV header of results.csv, in order. The schema test holds the writer to it.
const std::vector<std::string>& results_csv_columns();
void write_results_csv(const RunOutput& run, const std::filesystem::path& file);
/// The CSV header of poses.csv (the per-pose records of `--per-pose`), in order.
const std::vector<std::string>& poses_csv_columns();
/// A pose as poses.csv's `pose` column holds it: the 12 numbers of [R | t] row by row, comma-separated, with
/// 17 significant digits, so that `bvhlab query --pose` reads back the very same transform.
std::string pose_text(const RigidTransform& pose);
/// One row per PoseRecord of the run (nothing but the header if it kept none).
void write_poses_csv(const RunOutput& run, const std::filesystem::path& file);
/// The same records as a JSON array of objects keyed like poses.csv's columns.
nlohmann::json poses_document(const RunOutput& run);
void write_calibration_csv(const RunOutput& run, const std::filesystem::path& file);
/// results.json's document: scene, environment, stats, models, ground truth, rows, calibration and policies.
nlohmann::json results_document(const RunOutput& run);
void write_results_json(const RunOutput& run, const std::filesystem::path& file);

}  // namespace bvhlab
