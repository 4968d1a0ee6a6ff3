#include "scenes/coupled_checkpoint.hpp"

#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"
#include "io/state_io.hpp"
#include "scenes/run_common.hpp"

namespace boycott::scenes {

void save_coupled(io::CheckpointWriter& w, const coupling::CoupledSystem& run) {
  const auto c = run.counters();
  w.put("run.time_s", c.time_s);
  w.put("run.dt_prev_s", c.dt_prev_s);
  w.put_int("run.steps", c.steps);
  w.put_int("run.unconverged_fluid_steps", c.unconverged_fluid_steps);
  w.put_int("run.pressure_fallbacks", c.pressure_fallbacks);
  io::save(w, "dem.", run.dem().export_state());
  io::save(w, "fluid.", run.fluid().export_state());
  io::save(w, "coupler.", run.coupler().export_state());
}

void load_coupled(const io::CheckpointReader& r, coupling::CoupledSystem& run) {
  coupling::CoupledCounters c;
  c.time_s = r.scalar("run.time_s");
  c.dt_prev_s = r.scalar("run.dt_prev_s");
  c.steps = r.integer("run.steps");
  // absent from checkpoints written before these counters existed
  c.unconverged_fluid_steps = r.has("run.unconverged_fluid_steps") ? r.integer("run.unconverged_fluid_steps") : 0;
  c.pressure_fallbacks = r.has("run.pressure_fallbacks") ? r.integer("run.pressure_fallbacks") : 0;
  run.restore_counters(c);
  particles::DemState ds;
  io::load(r, "dem.", ds);
  run.dem().import_state(ds);
  fluid::FluidState fs;
  io::load(r, "fluid.", fs);
  const auto box = run.fluid().owned_box();
  if (fs.box.lo != box.lo || fs.box.size != box.size)
    throw CheckpointError(fmt::format("{}: the fluid grid was decomposed differently (other rank count?)", r.path().string()));
  run.fluid().import_state(fs);
  run.coupler().import_state(io::load_arrays(r, "coupler."));
}

std::optional<double> resume_coupled(coupling::CoupledSystem& run, const std::filesystem::path& run_dir, bool quiet,
                                     const std::function<void(const io::CheckpointReader&)>& load_scene) {
  const auto ck = io::latest_checkpoint(run_dir);
  if (!ck) return std::nullopt;
  io::CheckpointReader r(*ck);
  const std::string id = case_id(run.params());
  if (r.string("case_id") != id)
    throw CheckpointError(fmt::format("{} belongs to case {}, not {}; it is left in place", ck->string(),
                                      r.string("case_id"), id));
  load_coupled(r, run);
  load_scene(r);
  truncate_csv_after(run_dir / "timeseries.csv", run.time_s());
  if (!quiet) std::fprintf(stderr, "resuming from %s at t = %g s\n", ck->c_str(), run.time_s());
  return r.scalar("run.wall_time_s");
}

void checkpoint_coupled(const coupling::CoupledSystem& run, const std::filesystem::path& run_dir, double wall_time_s,
                        const std::function<void(io::CheckpointWriter&)>& save_scene) {
  io::CheckpointWriter w(io::checkpoint_path(run_dir, run.steps()));
  w.put_string("case_id", case_id(run.params()));
  w.put_string("case_json", to_json(run.params()).dump());
  w.put_string("program_version", std::string(kVersion));
  save_coupled(w, run);
  save_scene(w);
  w.put("run.wall_time_s", wall_time_s);
  w.commit();
  io::prune_checkpoints(run_dir, static_cast<int>(run.params().output.keep_checkpoints));
}

}  // namespace boycott::scenes
