#pragma once
// `study run`'s rounds of replicas (study keys replicas_target_rel_error and replicas_max): when a
// round has run, each point of a group with a target whose replicas all have a result, whose
// between-replica standard error is above the target fraction of |<<w_p>>|, and which has fewer
// than replicas_max replicas gets one more replica (seed + N); the study runs those and looks
// again, until no point needs one. Seeds are deterministic, so a rerun of `study run` finds the
// replicas of earlier rounds done and ends where the first run ended.
#include <vector>

#include "driver/database.hpp"
#include "driver/study.hpp"

namespace boycott::driver {

struct ReplicaRound {
  std::vector<StudyCase> added;  ///< the next round's new replicas
  int precise = 0;               ///< points whose between-replica error meets the target
  int at_max = 0;                ///< points above the target that have replicas_max replicas
  int waiting = 0;               ///< points with a replica without a result (failed, or not run)
};

/// Whether any group of the study has replicas_target_rel_error.
bool has_replica_target(const Study& s);
/// The replicas the next round adds to `s`, from the results in `db`.
ReplicaRound next_replica_round(Database& db, const Study& s);

}  // namespace boycott::driver
