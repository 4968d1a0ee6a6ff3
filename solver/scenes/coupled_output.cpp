#include "scenes/coupled_output.hpp"

#include <utility>

#include <fmt/format.h>

#include "io/png_image.hpp"

namespace boycott::scenes {

io::SnapshotData coupled_snapshot(const coupling::CoupledSystem& run) {
  io::SnapshotData d;
  d.time_s = run.time_s();
  const auto& s = run.dem().particles();
  const std::size_t n = s.n_local;
  for (auto [dst, src] : {std::pair{&d.x, &s.x}, {&d.y, &s.y}, {&d.z, &s.z}, {&d.vx, &s.vx}, {&d.vy, &s.vy},
                          {&d.vz, &s.vz}, {&d.radius, &s.radius}})
    dst->assign(src->begin(), src->begin() + static_cast<std::ptrdiff_t>(n));
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

CoupledSceneOutput::CoupledSceneOutput(const coupling::CoupledSystem& run, const RunContext& ctx, ModelTimers& timers,
                                       std::vector<std::string> columns, bool resumed, double next_out_s)
    : run_(run),
      ctx_(ctx),
      timers_(timers),
      csv_(ctx.out_dir / "timeseries.csv", std::move(columns), resumed),
      next_out_s_(next_out_s),
      checkpoints_(run.params().time.checkpoint_every_s, run.time_s()),
      snapshots_(run.params().output.snapshot_times_s, run.time_s()),
      images_(run.params().output.image_times_s, run.time_s()) {
  const auto& p = run.params();
  out_every_s_ = is_set(p.output.timeseries_every_s) ? p.output.timeseries_every_s : 0.0;
  timers.activate("checkpoints", fmt::format("HDF5 every {} s, newest {} kept", p.time.checkpoint_every_s,
                                             p.output.keep_checkpoints));
  if (snapshots_.size()) timers.activate("snapshots", fmt::format("HDF5 + XDMF at {} times", snapshots_.size()));
  if (images_.size()) timers.activate("images", fmt::format("PNG of the x-z plane at {} times", images_.size()));
}

void CoupledSceneOutput::write_pictures(double t) {
  snapshots_.reached(t, [&](std::size_t index, double) {
    ModelTimers::Scope sc(timers_, "snapshots");
    io::write_snapshot(ctx_.out_dir, static_cast<int>(index), coupled_snapshot(run_), run_.fluid().settings().grid);
  });
  images_.reached(t, [&](std::size_t, double time) {
    ModelTimers::Scope sc(timers_, "images");
    const auto& p = run_.params();
    const auto& s = run_.dem().particles();
    const io::ParticleView view{&s.x, &s.y, &s.z, &s.radius, s.n_local, p.domain.length_x_m, p.domain.width_y_m,
                                p.domain.height_z_m};
    io::write_particle_png(ctx_.out_dir / fmt::format("particles_t{:.3f}.png", time), view);
  });
}

}  // namespace boycott::scenes
