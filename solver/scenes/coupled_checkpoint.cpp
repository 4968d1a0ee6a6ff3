#include "scenes/coupled_checkpoint.hpp"

#include <mpi.h>

#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"
#include "io/state_io.hpp"
#include "scenes/run_common.hpp"

namespace boycott::scenes {

namespace {

/// The fluid's state over the whole grid on rank 0, in natural order: the ranks' z-slabs are
/// consecutive blocks of whole planes in rank order, so their owned arrays follow each other.
fluid::FluidState gather_fluid(const fluid::FluidSolver& f) {
  fluid::FluidState st = f.export_state();
  int size = 1, rank = 0;
  MPI_Comm_size(f.comm(), &size);
  MPI_Comm_rank(f.comm(), &rank);
  if (size == 1) return st;
  const auto& g = f.settings().grid;
  for (auto& field : st.fields) {
    const int n = static_cast<int>(field.size());
    std::vector<int> counts(size), displs(size);
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, f.comm());
    int total = 0;
    for (int r = 0; r < size; ++r) displs[r] = total, total += counts[r];
    std::vector<double> all(rank == 0 ? static_cast<std::size_t>(total) : 0);
    MPI_Gatherv(field.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0,
                f.comm());
    field.swap(all);
  }
  st.box.lo = {0, 0, 0};
  st.box.size = {g.n[0], g.n[1], g.n[2]};
  return st;
}

/// This rank's planes of a whole-grid fluid state.
fluid::FluidState own_part(const fluid::FluidState& whole, const fluid::FluidSolver& f,
                           const std::string& file) {
  const auto box = f.owned_box();
  const auto& g = f.settings().grid;
  if (whole.box.lo != box.lo || whole.box.size != box.size) {
    const bool whole_grid = whole.box.lo == std::array<std::int64_t, 3>{0, 0, 0} &&
                            whole.box.size == std::array<std::int64_t, 3>{g.n[0], g.n[1], g.n[2]};
    if (!whole_grid || box.lo[0] != 0 || box.lo[1] != 0 || box.size[0] != g.n[0] || box.size[1] != g.n[1])
      throw CheckpointError(fmt::format("{}: the fluid grid was decomposed differently", file));
  } else {
    return whole;
  }
  fluid::FluidState st = whole;
  st.box = box;
  const std::size_t plane = static_cast<std::size_t>(g.n[0] * g.n[1]);
  for (auto& field : st.fields) {
    const auto first =
        field.begin() + static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(box.lo[2]));
    field = std::vector<double>(
        first, first + static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(box.size[2])));
  }
  return st;
}

}  // namespace

void save_coupled(io::CheckpointWriter* w, const coupling::CoupledSystem& run) {
  const auto c = run.counters();
  // Collective: every rank contributes, rank 0 writes.
  const auto dem = run.dem().export_state();
  const auto fluid = gather_fluid(run.fluid());
  const auto coupler = run.coupler().export_state();
  if (!w) return;
  w->put("run.time_s", c.time_s);
  w->put("run.dt_prev_s", c.dt_prev_s);
  w->put_int("run.steps", c.steps);
  w->put_int("run.unconverged_fluid_steps", c.unconverged_fluid_steps);
  w->put_int("run.pressure_fallbacks", c.pressure_fallbacks);
  io::save(*w, "dem.", dem);
  io::save(*w, "fluid.", fluid);
  io::save(*w, "coupler.", coupler);
}

void load_coupled(const io::CheckpointReader& r, coupling::CoupledSystem& run) {
  coupling::CoupledCounters c;
  c.time_s = r.scalar("run.time_s");
  c.dt_prev_s = r.scalar("run.dt_prev_s");
  c.steps = r.integer("run.steps");
  // absent from checkpoints written before these counters existed
  c.unconverged_fluid_steps =
      r.has("run.unconverged_fluid_steps") ? r.integer("run.unconverged_fluid_steps") : 0;
  c.pressure_fallbacks = r.has("run.pressure_fallbacks") ? r.integer("run.pressure_fallbacks") : 0;
  run.restore_counters(c);
  run.decompose();
  particles::DemState ds;
  io::load(r, "dem.", ds);
  run.dem().import_state(ds);
  fluid::FluidState fs;
  io::load(r, "fluid.", fs);
  run.fluid().import_state(own_part(fs, run.fluid(), r.path().string()));
  run.coupler().import_state(io::load_arrays(r, "coupler."), run.dem());
}

std::optional<double> resume_coupled(coupling::CoupledSystem& run, const std::filesystem::path& run_dir,
                                     bool quiet,
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
  if (!quiet && output_rank())
    std::fprintf(stderr, "resuming from %s at t = %g s\n", ck->c_str(), run.time_s());
  return r.scalar("run.wall_time_s");
}

void checkpoint_coupled(const coupling::CoupledSystem& run, const std::filesystem::path& run_dir,
                        double wall_time_s, const std::function<void(io::CheckpointWriter&)>& save_scene) {
  // One file for all ranks, written by rank 0 from the gathered state.
  std::optional<io::CheckpointWriter> w;
  if (output_rank()) {
    w.emplace(io::checkpoint_path(run_dir, run.steps()));
    w->put_string("case_id", case_id(run.params()));
    w->put_string("case_json", to_json(run.params()).dump());
    w->put_string("program_version", std::string(kVersion));
  }
  save_coupled(w ? &*w : nullptr, run);
  if (!w) return;
  save_scene(*w);
  w->put("run.wall_time_s", wall_time_s);
  w->commit();
  io::prune_checkpoints(run_dir, static_cast<int>(run.params().output.keep_checkpoints));
}

}  // namespace boycott::scenes
