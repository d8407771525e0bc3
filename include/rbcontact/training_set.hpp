// rbcontact/training_set.hpp: parameter samples in a box: tensor grids, uniform random and Latin
// hypercube samples (seeded, reproducible on any machine), or read from a text file. Used for the
// training set (prefix train_) and the test set (prefix test_) of the offline and validation stages.
#pragma once
#include <petscsys.h>
#include <string>
#include <vector>
#include "rbcontact/scene.hpp"

namespace rbc {

struct ParameterSet {
  std::vector<std::string>            names;  // parameter names (scene order)
  std::vector<std::vector<PetscReal>> points; // points[i][j]: value of parameter j in sample i
  std::string                         type;   // grid, random, lhs or file (ParameterSetFromOptions)
  PetscInt                            seed = 0; // of a random or lhs sample
};

// Reads -<prefix>type grid|random|lhs|file, -<prefix>size n (grid: per dimension, or a list with
// one count per parameter), -<prefix>seed s, -<prefix>file path (type file: one sample per line,
// whitespace/comma separated, '#' comments). Every point is checked against the scene's boxes:
// a point outside is an error naming the file/line or option. Same result on every rank.
// (Added) Defaults: type grid, size 10, seed 0. Grid: endpoints exact, one point = the box centre,
// last parameter fastest; random/lhs: xoshiro256** seeded by splitmix64(seed).
// defType, defSize, defSeed: the type, size and seed when the options do not give them (the greedy's
// candidate and initial sets have other defaults than a training set).
PetscErrorCode ParameterSetFromOptions(MPI_Comm comm, const std::vector<ParamSpec> &params, const char *prefix, ParameterSet *set, const char *defType = "grid", PetscInt defSize = 10, PetscInt defSeed = 0);

// Pure generators (no options): deterministic for a given seed, independent of the platform's
// std::uniform_real_distribution (use an explicit 64-bit generator, e.g. splitmix64/xoshiro).
std::vector<std::vector<PetscReal>> GridSample(const std::vector<ParamSpec> &params, const std::vector<PetscInt> &counts);
std::vector<std::vector<PetscReal>> RandomSample(const std::vector<ParamSpec> &params, PetscInt n, unsigned long long seed);
std::vector<std::vector<PetscReal>> LatinHypercubeSample(const std::vector<ParamSpec> &params, PetscInt n, unsigned long long seed);

} // namespace rbc
