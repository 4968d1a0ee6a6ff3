#include "checks/check_case.hpp"

#include "core/error.hpp"

namespace boycott::checks {

Preflight preflight_case(const CaseParams& validated, int ranks, bool refuse) {
  Preflight pre = preflight(validated, ranks);
  if (refuse && !pre.errors.empty()) throw InputError(pre.errors.front());
  return pre;
}

Preflight check_case(CaseParams& p, int ranks, bool refuse) {
  validate(p);
  return preflight_case(p, ranks, refuse);
}

}  // namespace boycott::checks
