#pragma once
// `boycott query validation`: what every finished case measured against its reference (the
// summary keys that contain "error", stored by record_result in validation_errors_json).
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "driver/report/curve.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"

namespace boycott::driver {

struct ValidationRow {
  std::string study, group;  ///< "-" for a finished case that no study lists any more
  std::string case_id, scene;
  std::vector<SweptValue> values;  ///< what the study set on the case
  /// Every entry of validation_errors_json as stored: numbers, null (a scene without a reference
  /// value there), or nested arrays/objects.
  std::vector<std::pair<std::string, nlohmann::json>> errors;
  std::optional<double> w_m_s;  ///< <<w_p>>; unset for scenes without settling
  std::optional<double> wall_time_s;
};

/// One row per finished case and study group it belongs to, in study order (study empty: every
/// study). An unknown study name is an InputError.
std::vector<ValidationRow> query_validation(Database& db, const std::string& study = "");

/// Table: relative errors (keys containing "rel") as signed percentages, null as "-". CSV: one
/// column per error key found in any row, raw numbers, nested values as JSON. JSON: raw values.
std::string format_validation(const std::vector<ValidationRow>& rows, ListingFormat f);

}  // namespace boycott::driver
