// src/io/rom_file.cpp: writing and reading the ROM file (HDF5 C API on rank 0, atomic rename).
#include <algorithm>
#include "rbcontact/report.hpp"
#include "rbcontact/provenance.hpp"
#include "rbcontact/rom_file.hpp"
#include "h5util.hpp"
#include <cstdio>

namespace rbc {

using namespace rbc::h5;

static const char *kRomFormat = "rbcontact-rom";

void RomWriter::Dataset(const std::string &path, const std::vector<unsigned long long> &dims, const std::vector<double> &data)
{
  for (auto &it : items_) // a dataset given again replaces the first (offline -estimate rewrites its calibration)
    if (it.path == path) {
      it = {path, dims, data};
      return;
    }
  items_.push_back({path, dims, data});
}

std::pair<std::string, unsigned long long> RomWriter::Largest() const
{
  std::pair<std::string, unsigned long long> best("", 0);
  for (const auto &it : items_)
    if (it.data.size() > best.second) best = {it.path, (unsigned long long)it.data.size()};
  return best;
}

PetscErrorCode RomWriter::Write(MPI_Comm comm, const std::string &path) const
{
  PetscMPIInt rank;
  char        msg[1024] = "";

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  // provenance attributes, unless the caller set one of the same name
  std::vector<std::pair<std::string, std::string>> attrs = attrs_;
  {
    Provenance prov;
    PetscCall(GetProvenance(comm, &prov));
    for (const auto &a : ProvenanceAttributes(prov))
      if (std::none_of(attrs_.begin(), attrs_.end(), [&](const auto &b) { return b.first == a.first; })) attrs.push_back(a);
  }
  if (rank == 0) {
    H5Quiet           quiet;
    Ctx               c{"ROM file '" + path + "'", std::string()};
    const std::string target = OutputTarget(path), tmp = TemporaryPath(path);
    bool              ok  = true;
    {
      MemoryFile mem;
      H5Id       f(mem.Create(tmp), H5Fclose);
      if (!f.ok()) ok = c.Fail("cannot create the file");
      if (ok) ok = WriteStringAttr(c, f.get(), "format", kRomFormat);
      if (ok) {
        const int v = version;
        ok          = WriteAttr(c, f.get(), "format_version", H5T_STD_I32LE, H5T_NATIVE_INT, &v);
      }
      for (const auto &a : attrs)
        if (ok) ok = WriteStringAttr(c, f.get(), a.first.c_str(), a.second);
      for (const auto &it : items_) {
        if (!ok) break;
        std::vector<hsize_t> dims(it.dims.begin(), it.dims.end());
        ok = WriteWhole(c, f.get(), it.path, H5T_IEEE_F64LE, dims, H5T_NATIVE_DOUBLE, it.data.data());
      }
      if (ok) ok = mem.Save(c, &f, tmp);
    }
    if (ok && std::rename(tmp.c_str(), target.c_str()) != 0) ok = c.Fail("cannot rename the temporary file into place", false);
    if (!ok) {
      std::remove(tmp.c_str());
      std::snprintf(msg, sizeof msg, "%s", c.err.c_str());
    }
  }
  PetscCallMPI(MPI_Bcast(msg, sizeof msg, MPI_CHAR, 0, comm));
  PetscCheck(!msg[0], comm, PETSC_ERR_FILE_WRITE, "%s", msg);
  PetscFunctionReturn(0);
}

static bool OpenRom(Ctx &c, const std::string &path, H5Id *f)
{
  if (!FileExists(path)) return c.Fail("does not exist", false);
  *f = H5Id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!f->ok()) return c.Fail("is not an HDF5 file");
  std::string fmt;
  if (!ReadStringAttr(c, f->get(), "format", &fmt)) return false;
  if (fmt != kRomFormat) return c.Fail("is not a ROM file (format '" + fmt + "')", false);
  return true;
}

PetscErrorCode RomReadDataset(const std::string &path, const std::string &name, std::vector<unsigned long long> *dims, std::vector<double> *data)
{
  H5Quiet quiet;
  Ctx     c{"ROM file '" + path + "'", std::string()};
  H5Id    f;

  PetscFunctionBeginUser;
  bool ok = OpenRom(c, path, &f);
  if (ok) {
    H5Id                 d;
    std::vector<hsize_t> hd;
    ok = OpenDataset(c, f.get(), name, &d) && DatasetDims(c, d.get(), name, &hd);
    if (ok) ok = ReadWhole(c, f.get(), name, hd, data);
    dims->assign(hd.begin(), hd.end());
  }
  PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "%s", c.err.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode RomReadAttr(const std::string &path, const std::string &name, std::string *value)
{
  H5Quiet quiet;
  Ctx     c{"ROM file '" + path + "'", std::string()};
  H5Id    f;

  PetscFunctionBeginUser;
  bool ok = OpenRom(c, path, &f) && ReadStringAttr(c, f.get(), name.c_str(), value);
  PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "%s", c.err.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode RomReadVersion(const std::string &path, int *version)
{
  H5Quiet quiet;
  Ctx     c{"ROM file '" + path + "'", std::string()};
  H5Id    f;

  PetscFunctionBeginUser;
  bool ok = OpenRom(c, path, &f) && ReadAttr(c, f.get(), "format_version", H5T_NATIVE_INT, version);
  PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "%s", c.err.c_str());
  PetscFunctionReturn(0);
}

// An optional dataset: *found false (and no error) when the file lacks it; an unreadable one and non-finite values are an error.
PetscErrorCode RomReadOptional(const std::string &file, const std::string &name, std::vector<double> *data, bool *found, std::vector<unsigned long long> *dimsOut)
{
  std::vector<unsigned long long> dims;
  bool                            exists = false;
  PetscFunctionBeginUser;
  {
    // absent only when the dataset (or a group on its path) does not exist: any error reading one that exists (a string
    // where numbers belong) made it "absent" before 2026-12-01, and another model without a word
    H5Quiet quiet;
    Ctx     c{"ROM file '" + file + "'", std::string()};
    H5Id    f;
    bool    ok = OpenRom(c, file, &f);
    ok         = ok && LinkExists(c, f.get(), name, &exists);
    PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "%s", c.err.c_str());
  }
  *found = exists;
  if (!exists) {
    data->clear();
    PetscFunctionReturn(0);
  }
  PetscCall(RomReadDataset(file, name, &dims, data));
  PetscCall(RomCheckValues("ROM file " + file, name, *data));
  if (dimsOut) *dimsOut = dims;
  PetscFunctionReturn(0);
}

PetscErrorCode RomCheckValues(const std::string &what, const std::string &name, const std::vector<double> &data)
{
  PetscFunctionBeginUser;
  for (size_t i = 0; i < data.size(); ++i) {
    PetscCheck(std::isfinite(data[i]), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: dataset %s holds a non-finite value (entry %zu): a corrupt file", what.c_str(), name.c_str(), i);
    PetscCheck(std::abs(data[i]) < 1e150, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: dataset %s holds the value %g (entry %zu): a corrupt file", what.c_str(), name.c_str(), data[i], i);
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
