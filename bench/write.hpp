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
void write_calibration_csv(const RunOutput& run, const std::filesystem::path& file);
/// results.json's document: scene, environment, stats, models, ground truth, rows, calibration and policies.
nlohmann::json results_document(const RunOutput& run);
void write_results_json(const RunOutput& run, const std::filesystem::path& file);

}  // namespace bvhlab
