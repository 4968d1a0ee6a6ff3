#pragma once
// `study run`'s rounds of replicas (study keys replicas_target_rel_error and replicas_max), by
// Stein's two-stage rule (stats/point_error.hpp): every point of a group with a target starts
// with `replicas` (at least 3); once those have results, their scatter fixes how many replicas the
// point needs to meet the target with an error that covers ~68 %, at most replicas_max, and the
// next round adds them all. Seeds are deterministic, so a rerun of `study run` finds the replicas
// of earlier rounds done and ends where the first run ended.
#include <vector>

#include "driver/store/database.hpp"
#include "driver/study/study.hpp"

namespace boycott::driver {

struct ReplicaRound {
  std::vector<StudyCase> added;  ///< the next round's new replicas
  int precise = 0;               ///< points that have the replicas the target needs
  int at_max = 0;                ///< points that would need more than replicas_max
  int waiting = 0;               ///< points with a replica without a result (failed, or not run)
};

/// Whether any group of the study has replicas_target_rel_error.
bool has_replica_target(const Study& s);
/// The replicas the next round adds to `s`, from the results in `db`.
ReplicaRound next_replica_round(Database& db, const Study& s);

}  // namespace boycott::driver
