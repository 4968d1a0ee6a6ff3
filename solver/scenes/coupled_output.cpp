#include "scenes/coupled_output.hpp"

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <utility>

#include <fmt/format.h>

#include "io/png_image.hpp"

namespace boycott::scenes {

std::vector<std::vector<double>> gather_particles(const coupling::CoupledSystem& run,
                                                  const std::vector<const std::vector<double>*>& arrays) {
  const auto& s = run.dem().particles();
  const std::size_t n = s.n_local;
  std::vector<std::vector<double>> out;
  if (!run.dem().decomposition().parallel()) {
    std::vector<std::size_t> order(n);
    for (std::size_t k = 0; k < n; ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s.id[a] < s.id[b]; });
    for (const auto* a : arrays) {
      std::vector<double> sorted(n);
      for (std::size_t k = 0; k < n; ++k) sorted[k] = (*a)[order[k]];
      out.push_back(std::move(sorted));
    }
    return out;
  }
  // Gathered to rank 0, then put in id order (each rank stores its own in spatial order).
  const MPI_Comm comm = run.fluid().comm();
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const int mine = static_cast<int>(n);
  std::vector<int> counts(size), displs(size);
  MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  int total = 0;
  for (int r = 0; r < size; ++r) displs[r] = total, total += counts[r];
  std::vector<std::int64_t> ids(rank == 0 ? static_cast<std::size_t>(total) : 0);
  MPI_Gatherv(s.id.data(), mine, MPI_INT64_T, ids.data(), counts.data(), displs.data(), MPI_INT64_T, 0, comm);
  std::vector<std::size_t> order(ids.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return ids[a] < ids[b]; });
  for (const auto* a : arrays) {
    std::vector<double> all(ids.size());
    MPI_Gatherv(a->data(), mine, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, comm);
    std::vector<double> sorted(all.size());
    for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = all[order[k]];
    out.push_back(std::move(sorted));
  }
  return out;
}

io::SnapshotData coupled_snapshot(const coupling::CoupledSystem& run) {
  io::SnapshotData d;
  d.time_s = run.time_s();
  const auto& s = run.dem().particles();
  const std::vector<double> ids(s.id.begin(),
                                s.id.begin() + static_cast<std::ptrdiff_t>(s.n_local));  // exact < 2^53
  auto parts =
      gather_particles(run, {&s.x, &s.y, &s.z, &s.vx, &s.vy, &s.vz, &s.wx, &s.wy, &s.wz, &s.radius, &ids});
  d.x = std::move(parts[0]), d.y = std::move(parts[1]), d.z = std::move(parts[2]);
  d.vx = std::move(parts[3]), d.vy = std::move(parts[4]), d.vz = std::move(parts[5]);
  d.wx = std::move(parts[6]), d.wy = std::move(parts[7]), d.wz = std::move(parts[8]);
  d.radius = std::move(parts[9]);
  d.id.assign(parts[10].begin(), parts[10].end());
  const auto& g = run.fluid().settings().grid;
  const int nx = (int)g.n[0], ny = (int)g.n[1], nz = (int)g.n[2];
  const bool walls = !g.periodic[1];
  d.cell_fields.emplace_back("alpha_f", run.fluid().gather(5));
  d.cell_fields.emplace_back("pressure", run.fluid().gather(3));
  const char* names[3] = {"u", "v", "w"};
  for (int c = 0; c < 3; ++c) {
    const auto f = run.fluid().gather(c);  // lower faces
    std::vector<double> cc(f.size());
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int i1 = c == 0 ? (i + 1) % nx : i, j1 = c == 1 ? j + 1 : j, k1 = c == 2 ? (k + 1) % nz : k;
          const double lo = f[i + nx * (j + ny * k)];
          double hi = 0.0;
          if (c == 1 && j1 == ny)
            hi = walls ? 0.0 : f[i + nx * (0 + ny * k)];
          else
            hi = f[i1 + nx * (j1 + ny * k1)];
          cc[i + nx * (j + ny * k)] = 0.5 * (lo + hi);
        }
    d.cell_fields.emplace_back(names[c], std::move(cc));
  }
  return d;
}

CoupledSceneOutput::CoupledSceneOutput(const coupling::CoupledSystem& run, const RunContext& ctx,
                                       ModelTimers& timers, std::vector<std::string> columns, bool resumed,
                                       double next_out_s)
    : run_(run),
      ctx_(ctx),
      timers_(timers),
      first_quantity_(columns.size() > 1 ? columns[1] : ""),
      csv_(ctx.out_dir / "timeseries.csv", std::move(columns), resumed),
      next_out_s_(next_out_s),
      checkpoints_(run.params().time.checkpoint_every_s, run.time_s()),
      snapshots_(run.params().output.snapshot_times_s, run.time_s()),
      images_(run.params().output.image_times_s, run.time_s()) {
  const auto& p = run.params();
  out_every_s_ = is_set(p.output.timeseries_every_s) ? p.output.timeseries_every_s : 0.0;
  timers.activate("checkpoints", fmt::format("HDF5 every {} s, newest {} kept", p.time.checkpoint_every_s,
                                             p.output.keep_checkpoints));
  if (snapshots_.size())
    timers.activate("snapshots", fmt::format("HDF5 + XDMF at {} times", snapshots_.size()));
  if (images_.size())
    timers.activate("images", fmt::format("PNG of the x-z plane at {} times", images_.size()));
}

void CoupledSceneOutput::write_pictures(double t) {
  snapshots_.reached(t, [&](std::size_t index, double) {
    ModelTimers::Scope sc(timers_, "snapshots");
    const auto d = coupled_snapshot(run_);  // collective
    if (output_rank())
      io::write_snapshot(ctx_.out_dir, static_cast<int>(index), d, run_.fluid().settings().grid);
  });
  images_.reached(t, [&](std::size_t, double time) {
    ModelTimers::Scope sc(timers_, "images");
    const auto& p = run_.params();
    const auto& s = run_.dem().particles();
    const auto parts = gather_particles(run_, {&s.x, &s.y, &s.z, &s.radius});
    if (!output_rank()) return;
    const io::ParticleView view{&parts[0],          &parts[1],           &parts[2],
                                &parts[3],          parts[0].size(),     p.domain.length_x_m,
                                p.domain.width_y_m, p.domain.height_z_m, time};
    io::write_particle_png(ctx_.out_dir / fmt::format("particles_t{:.3f}.png", time), view);
  });
}

}  // namespace boycott::scenes
