#include "driver/case_commands.hpp"

#include <csignal>
#include <cstdio>

#include <fmt/format.h>

#include "core/case_params.hpp"
#include "core/error.hpp"
#include "fluid/petsc_session.hpp"
#include "scenes/scene.hpp"

namespace boycott::driver {

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop.store(true); }

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

CaseParams load(const std::string& file, const std::vector<std::string>& sets) {
  CaseParams p = parse_case_file(file);
  for (const auto& s : sets) apply_override(p, s);
  validate(p);
  return p;
}
}  // namespace

int case_run(const CaseRunOptions& opt, int argc, char** argv) {
  CaseParams p = load(opt.case_file, opt.overrides);
  std::string petsc_opts = "-no_signal_handler";
  for (const auto& o : opt.petsc_options) petsc_opts += " " + o;
  int pargc = 1;
  char** pargv = argv;
  fluid::PetscSession petsc(&pargc, &pargv, petsc_opts);
  install_stop_handlers();
  scenes::RunContext ctx;
  ctx.out_dir = opt.out_dir;
  ctx.stop_requested = &g_stop;
  ctx.quiet = opt.quiet;
  return scenes::run_case(p, ctx);
}

int case_check(const std::string& file, const std::vector<std::string>& sets) {
  CaseParams p = load(file, sets);
  std::printf("case %s (scene %s): valid\n", case_id(p).c_str(), p.scene.c_str());
  std::printf("  particles %lld, solid fraction %.4f\n", static_cast<long long>(p.particles.count), p.solid_fraction());
  std::printf("  dt_dem %.4g us, spring limit %.4g us (%.1f %%)\n", p.time.dt_dem_s * 1e6, p.dem_spring_limit_s() * 1e6,
              100.0 * p.time.dt_dem_s / p.dem_spring_limit_s());
  return 0;
}

int case_keys() {
  const auto j = to_json(CaseParams{});
  for (const auto& k : case_key_names()) {
    std::string ptr = "/" + k;
    for (auto& c : ptr)
      if (c == '.') c = '/';
    std::printf("%-40s %s\n", k.c_str(), j.at(nlohmann::json::json_pointer(ptr)).dump().c_str());
  }
  return 0;
}

}  // namespace boycott::driver
