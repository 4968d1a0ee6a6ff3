#include "core/error.hpp"
#include "scenes/scenes_list.hpp"

namespace boycott::scenes {
int run_channel_flow(const CaseParams&, RunContext&) {
  throw InputError("scene 'channel_flow' is not implemented yet");
}
}  // namespace boycott::scenes
