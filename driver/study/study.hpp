#pragma once
// Study files (README.md, "Studies"): a base case, groups that override it, and a [matrix]
// (cartesian product) and [zip] (lists zipped) expanded within every group. Every expanded case
// is validated and identified by case_id() of its fully resolved parameters, so that renaming or
// reordering a study never reruns a finished case. `replicas = N` runs every case with N seeds.
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/case_params.hpp"

namespace boycott::driver {

struct StudyCase {
  std::string group;
  std::string id;  ///< case_id(params)
  CaseParams params;
  /// The keys set by the group, the matrix and the zip, with their values as TOML text.
  std::vector<std::pair<std::string, std::string>> swept;
  /// Replica k of a point of the study runs with the point's seed + k; replica 0 is the case as
  /// it is without replicas, and point_id is its id.
  int replica = 0;
  std::string point_id;
  /// -1 for a case the study file lists; k for a point [refine] added in round k of its curve.
  int refine_round = -1;
};

/// How many replicas each point of a group runs: `replicas = N` (top level or in a [[group]]);
/// with `replicas_target_rel_error`, `study run` adds replicas in rounds until each point's
/// between-replica error is below that fraction of |<<w_p>>|, up to `replicas_max`.
struct ReplicaPlan {
  int replicas = 1;
  std::optional<double> target_rel_error;
  int max = 1;  ///< replicas_max (default kDefaultReplicasMax with a target, else replicas)
  static constexpr int kDefaultReplicasMax = 10;
  static constexpr int kStageOneMin = 3;  ///< replicas an adaptive point starts with, at least
};

/// A study's [refine] table (driver/study/refine.hpp): points of `key` added around each curve's
/// maximum until its position is known to `resolution` (68 %), the points around it cannot be told
/// apart, or `max_points` are added.
struct RefinePlan {
  std::string key;
  std::string objective = "max_abs_settling";  ///< or max_r_acc
  double resolution = 0.0;
  int max_points = 4;
  /// Keys set on the added points (those zipped with `key`: a new angle's time.end), TOML text.
  std::vector<std::pair<std::string, std::string>> set;
  /// A group's own values of such keys (its `refine_set`), where its zip differs from the other
  /// groups' (one group zips a packed-bed limit with the angle): by group name, over `set`.
  std::map<std::string, std::vector<std::pair<std::string, std::string>>> group_set;
  /// What the added points of `group` set: `set` with the group's own values in place of (or
  /// after) its entries.
  std::vector<std::pair<std::string, std::string>> set_for(const std::string& group) const;
  static constexpr int kMaxPointsLimit = 50;
};

/// A study may list at most this many cases (groups x matrix x zip x replicas): every command
/// holds each case's parameters (1.1 kB) and checks each one, 3-4.5 kB and 0.1-0.15 ms of CPU a
/// case all told (docs/performance.md, "Large studies"); a larger one is refused, from its axes'
/// lengths, before a case is made or anything is written.
inline constexpr long long kMaxStudyCases = 100000;

struct Study {
  std::string name;
  std::string source_text;          ///< the study file as read, stored in the database
  std::vector<std::string> groups;  ///< in file order
  std::vector<StudyCase> cases;     ///< group by group, matrix x zip within each, then replicas
  std::map<std::string, ReplicaPlan> replica_plans;  ///< by group
  std::optional<RefinePlan> refine;
};

/// Replica k of the point whose replica 0 is `replica0`: the same case with seed + k. InputError
/// when the scene does not read the seed.
StudyCase replica_of(const StudyCase& replica0, int k);

/// Parses and expands a study; every error (malformed TOML, unknown key, bad value, unequal zip
/// lengths, two cases with one id) is an InputError naming the key.
Study expand_study_string(const std::string& toml_text, const std::string& origin = "<string>");
Study expand_study_file(const std::string& path);
/// The replica plan of each group of a study, read without expanding (or checking) its cases:
/// for readers of a stored study that need only the plans.
std::map<std::string, ReplicaPlan> study_replica_plans(const std::string& toml_text,
                                                       const std::string& origin = "<string>");

/// The file a study gives its solver in each run folder: the case as data, its canonical JSON
/// (`boycott case run FILE.runs/<id>/case.json` reads it back to the same id, unchanged).
inline constexpr const char* kCaseFileName = "case.json";
std::string case_file_text(const CaseParams& p);

/// A swept value (TOML text) as people read it: a double's full binary expansion
/// (0.80000000000000004) becomes the shortest text that reads back the same (0.8); anything else
/// is returned as it is.
std::string readable_value(const std::string& toml_text);

}  // namespace boycott::driver
