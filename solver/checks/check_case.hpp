#pragma once
// The one complete check of a case, made once per command: by a study when it is expanded, by
// `case check`, and by `case run` before anything is written (its key rules when the case file
// is loaded, core/case_params.hpp's load_case_file, its pre-flight on the ranks it runs on).
#include "checks/preflight.hpp"
#include "core/case_params.hpp"

namespace boycott::checks {

/// The key rules (validate(), which resolves the defaults into `p`), then the pre-flight on
/// `ranks` ranks. With `refuse`, the first error is thrown as InputError (a study names the case,
/// a run leaves its folder as it was); without it the report carries the errors (case check
/// prints them all). Machine errors are never thrown here: a study may be meant for larger
/// machines, and `case run` refuses them on the machine it runs on.
Preflight check_case(CaseParams& p, int ranks = 1, bool refuse = true);

/// The pre-flight alone, for a case whose key rules were applied already (load_case_file), with
/// the same `refuse` rule.
Preflight preflight_case(const CaseParams& validated, int ranks = 1, bool refuse = true);

}  // namespace boycott::checks
