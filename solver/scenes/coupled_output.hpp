#pragma once
// What a coupled scene writes at the end of each step, written once for all of them: a row of
// timeseries.csv every output.timeseries_every (and at the last step), snapshots at
// output.snapshot_times, particle images at output.image_times, and a checkpoint on its clock,
// at the end and on a stop request.
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/case_params.hpp"
#include "core/timers.hpp"
#include "coupling/coupled_system.hpp"
#include "io/snapshot.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {

/// Particles (in id order) and cell-centred fluid fields (alpha_f, p, u, v, w) of a coupled run
/// now; collective, complete on rank 0.
io::SnapshotData coupled_snapshot(const coupling::CoupledSystem& run);
/// The local particles' values of some arrays, gathered in id order on rank 0 (as they are on
/// one rank); collective.
std::vector<std::vector<double>> gather_particles(const coupling::CoupledSystem& run,
                                                  const std::vector<const std::vector<double>*>& arrays);

/// What a coupled run has spent so far, each model's wall time included (its engines' phases as
/// report_timers adds them at the end): what its checkpoints record.
inline RunSpent spent_so_far(const RunClock& clock, const ModelTimers& timers,
                             const coupling::CoupledSystem& run) {
  ModelTimers now = timers;
  run.report_timers(now);
  RunSpent s = clock.spent();
  s.model_wall_s = now.totals();
  s.models_from_s = now.counted_from_s();
  return s;
}

class CoupledSceneOutput {
 public:
  /// After the run started or resumed. columns: the scene's time-series columns, "time_s" first;
  /// next_out_s: when the next row is due (0 on a fresh run, the checkpoint's value on a resumed
  /// one, whose rows up to the checkpoint are kept).
  CoupledSceneOutput(const coupling::CoupledSystem& run, const RunContext& ctx, ModelTimers& timers,
                     std::vector<std::string> columns, bool resumed, double next_out_s);

  /// At the end of a step: row() gives the row's values when one is due; write_checkpoint()
  /// writes a checkpoint when one is due. Returns true when the scene must leave its loop (a
  /// stop request; the summary is then marked interrupted).
  template <class Row, class WriteCheckpoint>
  bool after_step(Row&& row, WriteCheckpoint&& write_checkpoint, SummaryBase& summary) {
    const double t = run_.time_s(), end = run_.params().time.end_s;
    // The last step's row is written whenever it falls, but it does not move the schedule: a
    // run continued to a later end keeps the rows a run straight to that end writes.
    const bool scheduled = t >= next_out_s_ - 1e-12;
    if (scheduled || reached_end(t, end)) {
      report_row(row(), scheduled);
    }
    write_pictures(t);
    return checkpoint_or_stop(ctx_.should_stop(), ctx_.quiet, checkpoints_, t, end, csv_, write_checkpoint,
                              summary);
  }
  /// Instead of after_step, at the end of the step after which a run stops before time.end
  /// (time.target_rel_error met): the step's row (whenever it falls; it does not move the
  /// schedule), its pictures and a checkpoint, from which a stricter target continues.
  template <class Row, class WriteCheckpoint>
  void end_early(Row&& row, WriteCheckpoint&& write_checkpoint) {
    const double t = run_.time_s();
    report_row(row(), t >= next_out_s_ - 1e-12);
    write_pictures(t);
    csv_.flush();
    write_checkpoint();
  }
  /// Instead of after_step, after a step a stop request interrupted inside its particle
  /// sub-steps (CoupledStep::interrupted): no row, a checkpoint as of the step's start, the
  /// summary marked interrupted; the scene then leaves its loop (exit kExitInterrupted).
  template <class WriteCheckpoint>
  void stop_inside_step(const coupling::CoupledStep& st, WriteCheckpoint&& write_checkpoint,
                        SummaryBase& summary) {
    csv_.flush();
    write_checkpoint();
    summary.status = kStatusInterrupted;
    // Collective, so asked on every rank before rank 0 prints.
    const int every = run_.stop_check_substeps();
    const double particles = static_cast<double>(run_.dem().global_count());
    if (!ctx_.quiet && output_rank())
      std::fprintf(stderr,
                   "stopped inside a fluid step after %d of its %d particle sub-steps (asked every %d, "
                   "%.3g particle-steps); the step is dropped and the checkpoint holds t = %g s; run "
                   "again to resume\n",
                   st.substeps_done, st.dem_substeps, every, every * particles, run_.time_s());
  }
  /// When the next time-series row is due (s): part of a scene's checkpoint.
  double next_out_s() const { return next_out_s_; }
  void flush() { csv_.flush(); }

 private:
  /// Writes a time-series row; a scheduled one moves the schedule. The progress callbacks get the
  /// time and the row's first quantity after time.
  template <class Values>
  void report_row(const Values& values, bool scheduled) {
    const double t = run_.time_s();
    csv_.row(values);
    if (scheduled) next_out_s_ = t + out_every_s_;
    if (ctx_.progress_note && !first_quantity_.empty() && values.size() > 1)
      ctx_.progress_note(first_quantity_ + " " + fmt::format("{:.5g}", static_cast<double>(values[1])));
    if (ctx_.progress) ctx_.progress(t);
  }

  void write_pictures(double t);

  const coupling::CoupledSystem& run_;
  const RunContext& ctx_;
  ModelTimers& timers_;
  std::string first_quantity_;  ///< the column after time_s, for the progress line
  CsvWriter csv_;
  double out_every_s_ = 0.0, next_out_s_ = 0.0;
  CheckpointClock checkpoints_;
  OutputTimes snapshots_, images_;
};

/// The time loop of the coupled scenes with checkpoints (inclined_settling, sediment_transport),
/// written once: to time.end, each step preceded by before_step() and followed by
/// measure(step, end_early), in which the scene takes its samples and returns the step's row (a
/// callable, called only when a row is due, that must not refer to measure's locals); it sets
/// end_early when the run is to stop here, before time.end (time.target_rel_error met: the
/// summary's status is then converged). Rows, pictures, checkpoints and stop requests are the
/// output's (after_step, end_early, stop_inside_step). Returns kExitOk, or kExitInterrupted
/// after a stop (the summary marked interrupted).
template <class BeforeStep, class Measure, class WriteCheckpoint>
int run_coupled_steps(coupling::CoupledSystem& run, CoupledSceneOutput& out, BeforeStep&& before_step,
                      Measure&& measure, WriteCheckpoint&& write_checkpoint, SummaryBase& summary) {
  const double end = run.params().time.end_s;
  while (!reached_end(run.time_s(), end)) {
    before_step();
    const coupling::CoupledStep st = run.step();
    if (st.interrupted) {
      out.stop_inside_step(st, write_checkpoint, summary);
      return kExitInterrupted;
    }
    bool end_early = false;
    const auto row = measure(st, end_early);
    if (end_early) {
      out.end_early(row, write_checkpoint);
      summary.status = kStatusConverged;
      return kExitOk;
    }
    if (out.after_step(row, write_checkpoint, summary)) return kExitInterrupted;
  }
  return kExitOk;
}

/// A scene that keeps a record (its measurements and what its checkpoints carry: load,
/// checkpoint, next_out_s) runs its steps here, written once for inclined_settling and
/// sediment_transport: stop requests honoured inside a step, the output with the scene's
/// columns, checkpoints through the record (with what the run has spent, from `clock`, which
/// carries the attempts before a resume), run_coupled_steps, the rows flushed.
template <class Record, class BeforeStep, class Measure>
int run_recorded_steps(coupling::CoupledSystem& run, RunContext& ctx, ModelTimers& timers, Record& record,
                       std::vector<std::string> columns, bool resumed, const RunClock& clock,
                       BeforeStep&& before_step, Measure&& measure, SummaryBase& sb) {
  // A stop request is honoured inside a long fluid step too (thousands of particle sub-steps).
  run.set_interrupt([&ctx] { return ctx.should_stop(); });
  CoupledSceneOutput out(run, ctx, timers, std::move(columns), resumed, record.next_out_s());
  const auto write_checkpoint = [&] {
    ModelTimers::Scope sc(timers, "checkpoints");
    record.checkpoint(run, ctx.out_dir, spent_so_far(clock, timers, run), out.next_out_s());
  };
  const int exit_code = run_coupled_steps(run, out, before_step, measure, write_checkpoint, sb);
  out.flush();
  return exit_code;
}

/// The run totals every coupled scene's summary carries.
inline void set_run_totals(SummaryBase& sb, const coupling::CoupledSystem& run, const RunSpent& spent) {
  sb.simulated_time_s = run.time_s();
  sb.set_spent(spent);
  sb.particle_steps = static_cast<double>(run.dem().global_count()) * static_cast<double>(run.dem().steps());
}

}  // namespace boycott::scenes
