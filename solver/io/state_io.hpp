#pragma once
// Writing and reading the solver states a run resumes from, as datasets of a checkpoint file.
// Each state goes under a prefix ("dem.", "fluid.", ...), so one file holds the whole run.
#include <string>
#include <vector>

#include "fluid/fluid_solver.hpp"
#include "io/checkpoint_file.hpp"
#include "particles/dem_system.hpp"
#include "stats/running.hpp"

namespace boycott::io {

void save(CheckpointWriter& w, const std::string& prefix, const particles::DemState& s);
void load(const CheckpointReader& r, const std::string& prefix, particles::DemState& s);

/// One rank: the owned box is the whole grid. (The box is stored and checked on load.)
void save(CheckpointWriter& w, const std::string& prefix, const fluid::FluidState& s);
void load(const CheckpointReader& r, const std::string& prefix, fluid::FluidState& s);

void save(CheckpointWriter& w, const std::string& prefix, const stats::BatchMeans& b);
void load(const CheckpointReader& r, const std::string& prefix, stats::BatchMeans& b);

void save(CheckpointWriter& w, const std::string& prefix, const stats::Histogram& h);
void load(const CheckpointReader& r, const std::string& prefix, stats::Histogram& h);

void save(CheckpointWriter& w, const std::string& prefix, const std::vector<std::vector<double>>& arrays);
std::vector<std::vector<double>> load_arrays(const CheckpointReader& r, const std::string& prefix);

}  // namespace boycott::io
