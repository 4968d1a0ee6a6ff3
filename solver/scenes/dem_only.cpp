#include "core/error.hpp"
#include "scenes/scenes_list.hpp"

namespace boycott::scenes {
int run_dem_only(const CaseParams&, RunContext&) { throw InputError("scene 'dem_only' is not implemented yet"); }
}  // namespace boycott::scenes
