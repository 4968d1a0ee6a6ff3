#include "io/state_io.hpp"

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::io {

void save(CheckpointWriter& w, const std::string& prefix, const particles::DemState& s) {
  particles::ParticleStore store = s.store;  // for_each_array walks a mutable store
  int k = 0;
  store.for_each_array([&](std::vector<double>& a) { w.put(fmt::format("{}array{:02d}", prefix, k++), a); });
  w.put(prefix + "n_arrays", static_cast<double>(k));
  w.put(prefix + "id", store.id);
  w.put_int(prefix + "n_local", static_cast<std::int64_t>(store.n_local));
  w.put(prefix + "ref_x", s.ref_x);
  w.put(prefix + "ref_y", s.ref_y);
  w.put(prefix + "ref_z", s.ref_z);
  w.put(prefix + "pair_id_a", s.pair_id_a);
  w.put(prefix + "pair_id_b", s.pair_id_b);
  w.put(prefix + "pair_hx", s.pair_hx);
  w.put(prefix + "pair_hy", s.pair_hy);
  w.put(prefix + "pair_hz", s.pair_hz);
  w.put(prefix + "wall_h", s.wall_h);
  w.put_int(prefix + "steps", s.steps);
  w.put(prefix + "time_s", s.time_s);
  if (s.n_ranks > 1) {
    w.put_int(prefix + "n_ranks", s.n_ranks);
    w.put(prefix + "owner_rank", s.owner_rank);
  }
}

void load(const CheckpointReader& r, const std::string& prefix, particles::DemState& s) {
  const int n_arrays = static_cast<int>(r.scalar(prefix + "n_arrays"));
  if (n_arrays > particles::ParticleStore::kArrays)
    throw CheckpointError(fmt::format("{}: {} particle arrays stored, this program knows {} (newer version?)",
                                      r.path().string(), n_arrays, particles::ParticleStore::kArrays));
  s.store.id = r.int64s(prefix + "id");
  // Arrays added after a checkpoint was written (the coupling's, the last ones) start at zero.
  int k = 0;
  s.store.for_each_array([&](std::vector<double>& a) {
    if (k < n_arrays)
      a = r.doubles(fmt::format("{}array{:02d}", prefix, k));
    else
      a.assign(s.store.id.size(), 0.0);
    ++k;
  });
  s.store.n_local = static_cast<std::size_t>(r.integer(prefix + "n_local"));
  s.ref_x = r.doubles(prefix + "ref_x");
  s.ref_y = r.doubles(prefix + "ref_y");
  s.ref_z = r.doubles(prefix + "ref_z");
  s.pair_id_a = r.int64s(prefix + "pair_id_a");
  s.pair_id_b = r.int64s(prefix + "pair_id_b");
  s.pair_hx = r.doubles(prefix + "pair_hx");
  s.pair_hy = r.doubles(prefix + "pair_hy");
  s.pair_hz = r.doubles(prefix + "pair_hz");
  s.wall_h = r.doubles(prefix + "wall_h");
  s.steps = r.integer(prefix + "steps");
  s.time_s = r.scalar(prefix + "time_s");
  s.n_ranks = r.has(prefix + "n_ranks") ? static_cast<int>(r.integer(prefix + "n_ranks")) : 1;
  s.owner_rank = s.n_ranks > 1 ? r.int64s(prefix + "owner_rank") : std::vector<std::int64_t>{};
}

void save(CheckpointWriter& w, const std::string& prefix, const fluid::FluidState& s) {
  w.put(prefix + "box", std::vector<std::int64_t>{s.box.lo[0], s.box.lo[1], s.box.lo[2], s.box.size[0],
                                                  s.box.size[1], s.box.size[2]});
  w.put(prefix + "time_s", s.time_s);
  w.put(prefix + "dt_prev_s", s.dt_prev_s);
  w.put_int(prefix + "steps", s.steps);
  w.put(prefix + "mean_pressure_gradient_pa_m", s.mean_pressure_gradient_pa_m);
  save(w, prefix + "field.", s.fields);
}

void load(const CheckpointReader& r, const std::string& prefix, fluid::FluidState& s) {
  const auto box = r.int64s(prefix + "box");
  if (box.size() != 6) throw CheckpointError(fmt::format("{}: bad fluid box", r.path().string()));
  for (int d = 0; d < 3; ++d) s.box.lo[d] = box[d], s.box.size[d] = box[3 + d];
  s.time_s = r.scalar(prefix + "time_s");
  s.dt_prev_s = r.scalar(prefix + "dt_prev_s");
  s.steps = static_cast<int>(r.integer(prefix + "steps"));
  s.mean_pressure_gradient_pa_m = r.scalar(prefix + "mean_pressure_gradient_pa_m");
  s.fields = load_arrays(r, prefix + "field.");
}

void save(CheckpointWriter& w, const std::string& prefix, const stats::BatchMeans& b) {
  w.put(prefix + "ints", std::vector<std::int64_t>{b.min_batches_, b.count_, b.batch_len_, b.open_n_});
  w.put(prefix + "total", b.total_);
  w.put(prefix + "open_sum", b.open_sum_);
  w.put(prefix + "sums", b.sums_);
}

void load(const CheckpointReader& r, const std::string& prefix, stats::BatchMeans& b) {
  const auto i = r.int64s(prefix + "ints");
  if (i.size() != 4) throw CheckpointError(fmt::format("{}: bad batch-means state", r.path().string()));
  b.min_batches_ = static_cast<int>(i[0]);
  b.count_ = i[1];
  b.batch_len_ = i[2];
  b.open_n_ = i[3];
  b.total_ = r.scalar(prefix + "total");
  b.open_sum_ = r.scalar(prefix + "open_sum");
  b.sums_ = r.doubles(prefix + "sums");
}

void save(CheckpointWriter& w, const std::string& prefix, const stats::Histogram& h) {
  w.put(prefix + "range", std::vector<double>{h.lo_, h.hi_, h.outside_, h.total_});
  w.put(prefix + "counts", h.counts_);
}

void load(const CheckpointReader& r, const std::string& prefix, stats::Histogram& h) {
  const auto range = r.doubles(prefix + "range");
  const auto counts = r.doubles(prefix + "counts");
  if (range.size() != 4 || range[0] != h.lo_ || range[1] != h.hi_ || counts.size() != h.counts_.size())
    throw CheckpointError(
        fmt::format("{}: histogram '{}' has another range or bin count", r.path().string(), prefix));
  h.outside_ = range[2];
  h.total_ = range[3];
  h.counts_ = counts;
}

void save(CheckpointWriter& w, const std::string& prefix, const std::vector<std::vector<double>>& arrays) {
  w.put_int(prefix + "count", static_cast<std::int64_t>(arrays.size()));
  for (std::size_t k = 0; k < arrays.size(); ++k) w.put(fmt::format("{}{:02d}", prefix, k), arrays[k]);
}

std::vector<std::vector<double>> load_arrays(const CheckpointReader& r, const std::string& prefix) {
  const auto n = r.integer(prefix + "count");
  std::vector<std::vector<double>> out;
  for (std::int64_t k = 0; k < n; ++k) out.push_back(r.doubles(fmt::format("{}{:02d}", prefix, k)));
  return out;
}

}  // namespace boycott::io
