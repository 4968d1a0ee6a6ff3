#pragma once
// How clustered a set of particles is: the index of dispersion of their counts in M equal cells,
// against N particles placed independently and uniformly (an ideal gas of points). Each cell's
// count is then binomial, n_c ~ B(N, p) with p = 1/M, so the spread of the counts over the cells,
//   S = (1/M) sum_c (n_c - N/M)^2,
// has the expectation N p (1 - p) exactly (the finite-size factor 1 - p: the counts of a fixed
// total are not independent Poisson counts), and
//   I = S / (N p (1 - p)) = X^2 / (M - 1),
// with X^2 Pearson's statistic of the counts against equal cells. I is 1 on average for the
// random arrangement, with standard deviation sqrt(2 (1 - 1/N) / (M - 1)) (the multinomial's exact
// variance of X^2 for equal cells, 2 (M - 1)(1 - 1/N); the unit test samples it); 0 for a lattice with
// the same number in every cell; m for clumps of m particles placed at random (the counts are m
// times those of N/m points). Hard spheres at a finite solid fraction exclude each other, which
// lowers I below 1 in a well-mixed suspension (the structure factor's long-wave limit).
#include <cstdint>
#include <vector>

namespace boycott::stats {

/// I of the counts (one per cell, every cell the same size); NaN with fewer than 2 cells or no
/// particles.
double dispersion_index(const std::vector<std::int64_t>& counts);

/// The standard deviation of I for N particles placed at random in M cells (NaN for M < 2 or
/// N < 1): what one sample's scatter about 1 is.
double dispersion_index_random_sd(std::int64_t particles, std::int64_t cells);

}  // namespace boycott::stats
