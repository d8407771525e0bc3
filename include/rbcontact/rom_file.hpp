// rbcontact/rom_file.hpp: the ROM file (one HDF5 file holding everything the online stage needs):
// root attributes (format "rbcontact-rom", format_version, provenance) and named float64 datasets.
// Written by rank 0 only, to a temporary file renamed into place once complete (a killed job never
// leaves a half-written ROM file). Read back dataset by dataset on any rank.
// Layout written by the offline stage so far: docs/rom_file.md.
#pragma once
#include <petscsys.h>
#include <string>
#include <vector>

namespace rbc {

class RomWriter {
public:
  void Attr(const std::string &name, const std::string &value) { attrs_.emplace_back(name, value); }
  // path like "/pod/modes"; dims row-major (the last index fastest), data.size() = prod(dims); a path given again replaces it
  void Dataset(const std::string &path, const std::vector<unsigned long long> &dims, const std::vector<double> &data);
  // Largest dataset written so far: its path and number of entries.
  std::pair<std::string, unsigned long long> Largest() const;
  int version = 1; // format_version: 1 = bases only (-offline_stop bases), 2 = online ROM
  // Collective: rank 0 writes path (temp file + rename), errors reach every rank.
  PetscErrorCode Write(MPI_Comm comm, const std::string &path) const;

private:
  struct Item {
    std::string                     path;
    std::vector<unsigned long long> dims;
    std::vector<double>             data;
  };
  std::vector<std::pair<std::string, std::string>> attrs_;
  std::vector<Item>                                items_;
};

// Reads a dataset (any rank, independent); errors name the file and the dataset.
PetscErrorCode RomReadDataset(const std::string &path, const std::string &name, std::vector<unsigned long long> *dims, std::vector<double> *data);
PetscErrorCode RomReadAttr(const std::string &path, const std::string &name, std::string *value);
// An optional dataset: *found false (and no error) when the file lacks it (the dataset or a group on its path); any
// other failure to read it, and non-finite values, are an error. dims: its shape, when given.
PetscErrorCode RomReadOptional(const std::string &path, const std::string &name, std::vector<double> *data, bool *found, std::vector<unsigned long long> *dims = nullptr);
// Every value of a dataset read from a model file (what: "ROM file x.h5", "basis file b.h5") finite and below 1e150 in
// magnitude: no value of a model comes near (moduli, coordinates, reduced operators), and a larger one is a corrupt
// file whose products overflow to inf and NaN online. Errors name the file, the dataset and the entry.
PetscErrorCode RomCheckValues(const std::string &what, const std::string &name, const std::vector<double> &data);
// The integer format_version attribute.
PetscErrorCode RomReadVersion(const std::string &path, int *version);

} // namespace rbc
