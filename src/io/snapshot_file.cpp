// src/io/snapshot_file.cpp: the HDF5 snapshot file of the offline stage (creation under a temporary
// name, restart checks, crash-safe per-snapshot writes, reading) and the import of snapshot
// matrices from other codes (HDF5 dataset or PETSc binary Mat). Only rank 0 touches files in the
// collective calls; it broadcasts the status so that every rank fails together, never hangs.
//
// File layout (format_version 2; also in docs/snapshot_file.md). ntrain = training points,
// nparams = parameters, ndofs = length of u, nmult = length of lambda. All reals IEEE float64 LE.
//   / attributes      format = "rbcontact-snapshots" (string), format_version = 2 (int32; version 1 files,
//                     which also held every snapshot's contact matrix dense, are read, and a restart upgrades
//                     them),
//                     scene, code_version, options (strings), scene_hash, mesh_checksum (uint64),
//                     ntrain, nparams, ndofs, nmult (int64). options longer than 32 KiB: the
//                     attribute says "@/options" and the text is the scalar string dataset /options.
//   /params/names     nparams fixed-length strings (null-terminated)
//   /params/min, /params/max           nparams
//   /train/points                      ntrain x nparams
//   /snapshots/u                       ntrain x ndofs    (row i = snapshot of training point i)
//   /snapshots/lambda                  ntrain x nmult
//   /snapshots/mu                      ntrain x nparams  (NaN until written)
//   /snapshots/kacanov_iterations      ntrain, int64     (-1 until written)
//   /snapshots/kkt                     ntrain x 4        (primal, dual, complementarity,
//                                                         stationarity; NaN until written)
//   /snapshots/seconds                 ntrain            (NaN until written)
//   /snapshots/done                    ntrain, int8      (0/1; 1 = row i of every dataset valid)
//   /snapshots/extra/<name>            ntrain x len      (created by the first Write carrying it)
// Every dataset has its final shape at creation, contiguous layout, space allocated at creation
// (u, lambda and the extras without writing fill values: the file stays sparse). A Write therefore
// changes raw data only, never HDF5 metadata (except the first Write of a new extra, which creates
// its dataset and flushes before writing data): rows of u, lambda, mu, ..., then H5Fflush + fsync,
// then done[i] = 1, H5Fflush + fsync. A killed job loses only the snapshot in progress. The file
// uses the default (oldest) HDF5 file format, which has no "file open for writing" flag, so a file
// left by a killed job opens normally.
#include "rbcontact/provenance.hpp"
#include "rbcontact/report.hpp"
#include "rbcontact/scene.hpp"
#include "rbcontact/snapshot_file.hpp"
#include "h5util.hpp"
#include <hdf5.h>
#include <petscmat.h>
#include <petscviewer.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>
#include <iomanip>
#include <sstream>
#include <type_traits>

namespace rbc {

static_assert(std::is_same<PetscReal, double>::value, "the snapshot file stores PetscReal as float64");

namespace {

constexpr const char *kFormat        = "rbcontact-snapshots";
constexpr int         kFormatVersion = 2;
// Version 1 (until 2026-11-27) also stored the contact matrix on the contact dofs dense (the extras contact_K and
// contact_dofs: 434 MB a snapshot at 5.4e5 3D dofs); the offline stage now reassembles it from u (offline_bases.cpp).
// Such files are read (those two extras skipped) and upgraded to version 2 when a restart writes to them.
constexpr int         kOldestReadableVersion = 1;
const char *const     kDroppedExtras[]       = {"contact_K", "contact_dofs"};
constexpr size_t      kMaxAttrString = 32768;
const double          kNaN           = std::numeric_limits<double>::quiet_NaN();
const char *const     kPendingSet    = "/snapshots/pending"; // greedy training: the round's picks (SnapshotFile::SetPending)

using namespace rbc::h5;

Ctx FileCtx(const std::string &path) { return Ctx{"Snapshot file '" + path + "'", std::string()}; }

bool WriteHeaderAndLayout(Ctx &c, hid_t f, const SnapshotHeader &h)
{
  const hsize_t            ntrain = h.trainingPoints.size(), np = h.paramNames.size();
  const long long          i64[4] = {(long long)ntrain, (long long)np, (long long)h.ndofs, (long long)h.nmult};
  const char              *i64names[4] = {"ntrain", "nparams", "ndofs", "nmult"};
  const unsigned long long sh = h.sceneHash, mc = h.meshChecksum;
  const int                version = kFormatVersion;

  if (!WriteStringAttr(c, f, "format", kFormat)) return false;
  if (!WriteAttr(c, f, "format_version", H5T_STD_I32LE, H5T_NATIVE_INT, &version)) return false;
  if (!WriteStringAttr(c, f, "scene", h.scene)) return false;
  if (!WriteAttr(c, f, "scene_hash", H5T_STD_U64LE, H5T_NATIVE_ULLONG, &sh)) return false;
  if (!WriteAttr(c, f, "mesh_checksum", H5T_STD_U64LE, H5T_NATIVE_ULLONG, &mc)) return false;
  if (!WriteStringAttr(c, f, "code_version", h.codeVersion)) return false;
  for (const auto &a : ProvenanceAttributes(LocalProvenance())) // the commit, PETSc/SLEPc versions, the date (the options: below)
    if (a.first != "code_version" && a.first != "run_options" && !WriteStringAttr(c, f, a.first.c_str(), a.second)) return false;
  if (h.optionsText.size() <= kMaxAttrString) {
    if (!WriteStringAttr(c, f, "options", h.optionsText)) return false;
  } else {
    H5Id t, sp(H5Screate(H5S_SCALAR), H5Sclose), d;
    if (!sp.ok()) return c.Fail("cannot create a scalar dataspace");
    if (!MakeStringType(c, h.optionsText.size(), &t)) return false;
    d = H5Id(H5Dcreate2(f, "/options", t.get(), sp.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
    if (!d.ok() || H5Dwrite(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, h.optionsText.c_str()) < 0) return c.Fail("cannot write dataset /options");
    if (!WriteStringAttr(c, f, "options", "@/options")) return false;
  }
  for (int k = 0; k < 4; ++k)
    if (!WriteAttr(c, f, i64names[k], H5T_STD_I64LE, H5T_NATIVE_LLONG, &i64[k])) return false;

  // /params/names: fixed-length strings.
  size_t len = 0;
  for (const auto &s : h.paramNames) len = std::max(len, s.size());
  std::vector<char> names(np * (len + 1) + 1, 0);
  for (size_t j = 0; j < np; ++j) std::memcpy(&names[j * (len + 1)], h.paramNames[j].c_str(), h.paramNames[j].size());
  H5Id st;
  if (!MakeStringType(c, len, &st)) return false;
  if (!WriteWhole(c, f, "/params/names", st.get(), {np}, st.get(), names.data())) return false;
  if (!WriteWhole(c, f, "/params/min", H5T_IEEE_F64LE, {np}, H5T_NATIVE_DOUBLE, h.paramMin.data())) return false;
  if (!WriteWhole(c, f, "/params/max", H5T_IEEE_F64LE, {np}, H5T_NATIVE_DOUBLE, h.paramMax.data())) return false;
  std::vector<double> pts;
  for (const auto &x : h.trainingPoints) pts.insert(pts.end(), x.begin(), x.end());
  if (!WriteWhole(c, f, "/train/points", H5T_IEEE_F64LE, {ntrain, np}, H5T_NATIVE_DOUBLE, pts.data())) return false;

  // Per-snapshot datasets, final shape. The file is built in memory (MemoryFile), and HDF5's core driver extends its
  // image to the whole allocated file at the close: so the large ones (u, lambda, the declared extras), whose rows are
  // not written here, are allocated late, at the first write, which AllocateLarge does on disk before the file is
  // renamed into place, in the zeros Save reserved for them (allocated here, a snapshot file of 1.4 GB took 1.4 GB of
  // rank 0's memory at its creation: measured 2026-12-04).
  const long long   minus1 = -1;
  const signed char zero   = 0;
  if (!CreateDataset(c, f, "/snapshots/mu", H5T_IEEE_F64LE, {ntrain, np}, H5T_NATIVE_DOUBLE, &kNaN, nullptr)) return false;
  if (!CreateDataset(c, f, "/snapshots/kacanov_iterations", H5T_STD_I64LE, {ntrain}, H5T_NATIVE_LLONG, &minus1, nullptr)) return false;
  if (!CreateDataset(c, f, "/snapshots/kkt", H5T_IEEE_F64LE, {ntrain, 4}, H5T_NATIVE_DOUBLE, &kNaN, nullptr)) return false;
  if (!CreateDataset(c, f, "/snapshots/seconds", H5T_IEEE_F64LE, {ntrain}, H5T_NATIVE_DOUBLE, &kNaN, nullptr)) return false;
  if (!CreateDataset(c, f, "/snapshots/done", H5T_STD_I8LE, {ntrain}, H5T_NATIVE_SCHAR, &zero, nullptr)) return false;
  if (!CreateDataset(c, f, kPendingSet, H5T_STD_I8LE, {ntrain}, H5T_NATIVE_SCHAR, &zero, nullptr)) return false;
  H5Id g(H5Gcreate2(f, "/snapshots/extra", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (!g.ok()) return c.Fail("cannot create group /snapshots/extra");
  if (!CreateDataset(c, f, "/snapshots/u", H5T_IEEE_F64LE, {ntrain, (hsize_t)h.ndofs}, H5T_NATIVE_DOUBLE, nullptr, nullptr, true)) return false;
  if (!CreateDataset(c, f, "/snapshots/lambda", H5T_IEEE_F64LE, {ntrain, (hsize_t)h.nmult}, H5T_NATIVE_DOUBLE, nullptr, nullptr, true)) return false;
  // the extras the run declares (SnapshotHeader::extras): created now, so that no Write creates a dataset (metadata
  // written while the disk may be full: HDF5 1.10.8 then crashes at its shutdown); their names checked by Open
  for (const auto &e : h.extras)
    if (!CreateDataset(c, f, "/snapshots/extra/" + e.first, H5T_IEEE_F64LE, {ntrain, (hsize_t)e.second}, H5T_NATIVE_DOUBLE, nullptr, nullptr, true)) return false;
  return true;
}

// The datasets WriteHeaderAndLayout allocates late, and their bytes.
std::vector<std::string> LargeDatasets(const SnapshotHeader &h, unsigned long long *bytes)
{
  const unsigned long long nt = h.trainingPoints.size();
  std::vector<std::string> names = {"/snapshots/u", "/snapshots/lambda"};
  *bytes                         = 8 * nt * ((unsigned long long)h.ndofs + (unsigned long long)h.nmult);
  for (const auto &e : h.extras) {
    names.push_back("/snapshots/extra/" + e.first);
    *bytes += 8 * nt * (unsigned long long)e.second;
  }
  return names;
}

// Opens an existing file and checks that it is an rbcontact snapshot file.
bool OpenExisting(Ctx &c, const std::string &path, bool rdwr, H5Id *file, int *versionOut = nullptr)
{
  if (!FileExists(path)) return c.Fail("does not exist", false);
  const htri_t is = H5Fis_hdf5(path.c_str());
  if (is < 0) return c.Fail("cannot be read");
  if (is == 0) return c.Fail("is not an HDF5 file (not an rbcontact snapshot file)", false);
  // Readers do not lock the file: a Write changes raw data and flags only, so reading the done
  // snapshots of a file being written is safe, and a reader on another rank never makes the
  // writer's open fail. The writer locks (HDF5's default), so two writers cannot share a file.
  H5Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.ok() || (!rdwr && H5Pset_file_locking(fapl.get(), 0, 1) < 0)) return c.Fail("cannot create a file access property list");
  *file = H5Id(H5Fopen(path.c_str(), rdwr ? H5F_ACC_RDWR : H5F_ACC_RDONLY, fapl.get()), H5Fclose);
  if (!file->ok() && rdwr) { // locked by another writer, or unreadable (a truncated file was blamed on another job)
    H5Id ro(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    const bool readable = ro.ok() && H5Pset_file_locking(ro.get(), 0, 1) >= 0 && H5Id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, ro.get()), H5Fclose).ok();
    return c.Fail(readable ? "cannot be opened for writing: another job is writing it (HDF5's file lock), or it is read-only" : "cannot be opened (truncated or corrupt?)");
  }
  if (!file->ok()) return c.Fail("cannot be opened");
  bool exists = false;
  if (!AttrExists(c, file->get(), "format", &exists)) return false;
  if (!exists) return c.Fail("is an HDF5 file but not an rbcontact snapshot file (no 'format' attribute)", false);
  std::string fmt;
  if (!ReadStringAttr(c, file->get(), "format", &fmt)) return false;
  if (fmt != kFormat) return c.Fail("is not an rbcontact snapshot file (format '" + fmt + "', expected '" + kFormat + "')", false);
  int version = 0;
  if (!ReadAttr(c, file->get(), "format_version", H5T_NATIVE_INT, &version)) return false;
  if (version < kOldestReadableVersion || version > kFormatVersion) return c.Fail("has format_version " + std::to_string(version) + "; this build reads versions " + std::to_string(kOldestReadableVersion) + " to " + std::to_string(kFormatVersion), false);
  if (versionOut) *versionOut = version;
  return true;
}

bool ReadHeaderH5(Ctx &c, hid_t f, SnapshotHeader *h)
{
  long long          i64[4];
  const char        *i64names[4] = {"ntrain", "nparams", "ndofs", "nmult"};
  unsigned long long sh = 0, mc = 0;

  if (!ReadStringAttr(c, f, "scene", &h->scene)) return false;
  if (!ReadAttr(c, f, "scene_hash", H5T_NATIVE_ULLONG, &sh) || !ReadAttr(c, f, "mesh_checksum", H5T_NATIVE_ULLONG, &mc)) return false;
  h->sceneHash    = sh;
  h->meshChecksum = mc;
  if (!ReadStringAttr(c, f, "code_version", &h->codeVersion) || !ReadStringAttr(c, f, "options", &h->optionsText)) return false;
  if (h->optionsText == "@/options") {
    H5Id d;
    if (!OpenDataset(c, f, "/options", &d)) return false;
    H5Id t(H5Dget_type(d.get()), H5Tclose);
    if (!t.ok()) return c.Fail("cannot get the type of dataset /options");
    // one fixed-length string, as written: a dataspace of n values would be read n x its size into the buffer (a heap
    // overflow), a variable-length one as a pointer, and a declared size beyond the file's is not stored in it
    std::vector<hsize_t> od;
    if (!DatasetDims(c, d.get(), "/options", &od)) return false;
    hsize_t n = 1;
    for (hsize_t x : od) n *= x;
    if (n != 1 || H5Tget_class(t.get()) != H5T_STRING || H5Tis_variable_str(t.get()) != 0 || H5Tget_size(t.get()) > FileSizeOf(f))
      return c.Fail("dataset /options is not one fixed-length string of the file's (shape " + ShapeString(od) + "): a corrupt file", false);
    std::vector<char> buf(H5Tget_size(t.get()) + 1, 0);
    if (H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) < 0) return c.Fail("cannot read dataset /options");
    h->optionsText = buf.data();
  }
  for (int k = 0; k < 4; ++k) {
    if (!ReadAttr(c, f, i64names[k], H5T_NATIVE_LLONG, &i64[k])) return false;
    if (i64[k] < 0) return c.Fail(std::string("attribute '") + i64names[k] + "' is negative (corrupt file?)", false);
  }
  // (bounds before anything is allocated from them: a training set holds at most 1e7 points, as -train_size and
  // -train_file; dofs and multipliers are PetscInts. A zero-width /train/points passed the stored-size guard with
  // 1e12 rows: review of 2026-12-04)
  if (i64[0] > 10000000 || i64[2] > 2147483647LL || i64[3] > 2147483647LL)
    return c.Fail("attributes ntrain " + std::to_string(i64[0]) + ", ndofs " + std::to_string(i64[2]) + ", nmult " + std::to_string(i64[3]) + ": beyond any training set or mesh (corrupt file?)", false);
  const hsize_t ntrain = (hsize_t)i64[0], np = (hsize_t)i64[1];
  h->ndofs = (PetscInt)i64[2];
  h->nmult = (PetscInt)i64[3];

  // /params/names
  {
    H5Id d;
    if (!OpenDataset(c, f, "/params/names", &d)) return false;
    std::vector<hsize_t> dims;
    if (!DatasetDims(c, d.get(), "/params/names", &dims)) return false;
    if (dims != std::vector<hsize_t>{np}) return c.Fail("dataset /params/names has shape " + ShapeString(dims) + ", expected " + std::to_string((unsigned long long)np), false);
    H5Id t(H5Dget_type(d.get()), H5Tclose);
    if (!t.ok() || H5Tget_class(t.get()) != H5T_STRING || H5Tis_variable_str(t.get()) != 0) return c.Fail("dataset /params/names is not a fixed-length string array");
    const size_t      sz = H5Tget_size(t.get());
    std::vector<char> buf(np * sz + 1, 0);
    if (np > 0 && H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) < 0) return c.Fail("cannot read dataset /params/names");
    h->paramNames.clear();
    for (hsize_t j = 0; j < np; ++j) h->paramNames.push_back(std::string(&buf[j * sz], strnlen(&buf[j * sz], sz)));
  }
  std::vector<double> v;
  if (!ReadWhole(c, f, "/params/min", {np}, &h->paramMin) || !ReadWhole(c, f, "/params/max", {np}, &h->paramMax)) return false;
  if (!ReadWhole(c, f, "/train/points", {ntrain, np}, &v)) return false;
  h->trainingPoints.assign(ntrain, std::vector<PetscReal>(np));
  for (hsize_t i = 0; i < ntrain; ++i)
    for (hsize_t j = 0; j < np; ++j) h->trainingPoints[i][j] = v[i * np + j];
  return true;
}

bool ReadDone(Ctx &c, hid_t f, hsize_t ntrain, std::vector<signed char> *done)
{
  H5Id d;
  if (!OpenDataset(c, f, "/snapshots/done", &d)) return false;
  std::vector<hsize_t> dims;
  if (!DatasetDims(c, d.get(), "/snapshots/done", &dims)) return false;
  if (dims != std::vector<hsize_t>{ntrain}) return c.Fail("dataset /snapshots/done has shape " + ShapeString(dims) + ", expected " + std::to_string((unsigned long long)ntrain), false);
  done->assign(ntrain, 0);
  if (ntrain > 0 && H5Dread(d.get(), H5T_NATIVE_SCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, done->data()) < 0) return c.Fail("cannot read dataset /snapshots/done");
  for (hsize_t i = 0; i < ntrain; ++i) // a flag of 5 or -1 counted as done
    if ((*done)[i] != 0 && (*done)[i] != 1) return c.Fail("dataset /snapshots/done has the value " + std::to_string((int)(*done)[i]) + " at row " + std::to_string((unsigned long long)i) + " (0 or 1): a corrupt file", false);
  return true;
}

// The greedy round's picks being solved: /snapshots/pending, int8 per training point (1: picked by the round being
// solved), allocated with the other datasets so that a write changes raw data only (files of before 2026-11-29 get it
// at their first greedy round, before any pick is marked). Absent: no pick pending.
bool ReadPending(Ctx &c, hid_t f, hsize_t ntrain, std::vector<PetscInt> *pending)
{
  pending->clear();
  bool exists = false;
  if (!LinkExists(c, f, kPendingSet, &exists)) return false;
  if (!exists) return true;
  H5Id                 d;
  std::vector<hsize_t> dims;
  if (!OpenDataset(c, f, kPendingSet, &d) || !DatasetDims(c, d.get(), kPendingSet, &dims)) return false;
  if (dims != std::vector<hsize_t>{ntrain}) return c.Fail(std::string("dataset ") + kPendingSet + " has shape " + ShapeString(dims) + ", expected " + std::to_string((unsigned long long)ntrain), false);
  std::vector<signed char> flag(ntrain, 0);
  if (ntrain > 0 && H5Dread(d.get(), H5T_NATIVE_SCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, flag.data()) < 0) return c.Fail(std::string("cannot read dataset ") + kPendingSet);
  for (hsize_t i = 0; i < ntrain; ++i)
    if (flag[i]) pending->push_back((PetscInt)i);
  return true;
}

bool WritePending(Ctx &c, hid_t f, hsize_t ntrain, const std::vector<PetscInt> &pending)
{
  std::vector<signed char> flag(ntrain, 0);
  for (PetscInt i : pending) flag[(size_t)i] = 1;
  bool exists = false;
  if (!LinkExists(c, f, kPendingSet, &exists)) return false;
  if (!exists) { // an older file: created (metadata) and flushed before any pick is marked
    const signed char zero = 0;
    if (!CreateDataset(c, f, kPendingSet, H5T_STD_I8LE, {ntrain}, H5T_NATIVE_SCHAR, &zero, nullptr) || !FlushSync(c, f)) return false;
  }
  H5Id d(H5Dopen2(f, kPendingSet, H5P_DEFAULT), H5Dclose);
  if (!d.ok() || (ntrain > 0 && H5Dwrite(d.get(), H5T_NATIVE_SCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, flag.data()) < 0)) return c.Fail(std::string("cannot write dataset ") + kPendingSet);
  return FlushSync(c, f);
}

bool CloseFile(Ctx &c, H5Id *file)
{
  const hid_t id = file->Release();
  if (id >= 0 && H5Fclose(id) < 0) return c.Fail("cannot close the file");
  return true;
}

// Allocates the late datasets of a new file (its rows: zeros written to the first, which allocates the whole
// contiguous dataset in the zeros Save reserved after the file's end), then flush + fsync: from here on a Write
// changes raw data only.
bool AllocateLarge(Ctx &c, const std::string &path, const SnapshotHeader &h)
{
  unsigned long long             bytes = 0;
  const std::vector<std::string> names = LargeDatasets(h, &bytes);
  H5Id                           f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  if (!f.ok()) return c.Fail("cannot be reopened to allocate its rows");
  for (const auto &n : names) {
    H5Id                 d;
    std::vector<hsize_t> dims;
    if (!OpenDataset(c, f.get(), n, &d) || !DatasetDims(c, d.get(), n, &dims)) return false;
    if (dims[0] == 0 || dims[1] == 0) continue;
    const std::vector<double> zeros((size_t)dims[1], 0.0);
    d.Reset();
    if (!RowIO(c, f.get(), n, H5T_NATIVE_DOUBLE, 0, dims[1], const_cast<double *>(zeros.data()), true)) return false;
  }
  if (!FlushSync(c, f.get()) || !CloseFile(c, &f)) return false;
  // the close may still write (the superblock, the truncation of the unused reserve): fsync what it left
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  const int rc = fd < 0 ? -1 : ::fsync(fd);
  const int er = errno;
  if (fd >= 0) ::close(fd);
  if (rc != 0) return c.Fail(std::string("cannot fsync the file after allocating its rows: ") + std::strerror(er), false);
  return true;
}

std::string Hex(unsigned long long v)
{
  char b[32];
  std::snprintf(b, sizeof b, "0x%016llx", v);
  return b;
}

// The shortest decimal that reads back as v (scene.hpp).
std::string Num(double v) { return ShortestReal(v); }

std::string Join(const std::vector<std::string> &v)
{
  std::string s;
  for (const auto &x : v) s += (s.empty() ? "" : ",") + x;
  return s.empty() ? "(none)" : s;
}

bool Close14(double a, double b) { return std::fabs(a - b) <= 1e-14 * std::max(1.0, std::max(std::fabs(a), std::fabs(b))); }


// Large broadcasts in pieces (MPI counts are int).
PetscErrorCode BcastReals(MPI_Comm comm, PetscReal *v, size_t n)
{
  const size_t piece = (size_t)1 << 26;

  PetscFunctionBeginUser;
  for (size_t off = 0; off < n; off += piece) PetscCallMPI(MPI_Bcast(v + off, (PetscMPIInt)std::min(piece, n - off), MPIU_REAL, 0, comm));
  PetscFunctionReturn(0);
}

// The file this run writes is no longer the one at path (another job created the same -snapshots over it, or it
// was removed): its writes would go to an unlinked file and be lost with exit 0.
bool CheckNotReplaced(Ctx &c, hid_t f, const std::string &path)
{
  void       *h = nullptr;
  struct stat a, b;
  if (H5Fget_vfd_handle(f, H5P_DEFAULT, &h) < 0 || !h || fstat(*static_cast<int *>(h), &a) != 0) return true; // (not the sec2 driver: no check)
  if (stat(path.c_str(), &b) == 0 && a.st_ino == b.st_ino && a.st_dev == b.st_dev) return true;
  return c.Fail("was replaced or removed while this run was writing it (another job given the same file?): this run's snapshots since then are not in the file at that path; stopping", false);
}

// Before a file is created over path: a snapshot file another job holds open for writing (HDF5's lock) is not replaced
// under it (that job would go on writing into the unlinked file and end with exit 0, its snapshots lost).
bool CheckNotLocked(Ctx &c, const std::string &path)
{
  if (!FileExists(path)) return true;
  if (H5Id(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose).ok()) return true;
  H5Id ro(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  const bool readable = ro.ok() && H5Pset_file_locking(ro.get(), 0, 1) >= 0 && H5Id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, ro.get()), H5Fclose).ok();
  KeepQuiet() = KeepQuiet() || !readable; // (a failed open of a corrupt file: HDF5's complaint at exit, h5util.hpp)
  if (!readable || access(path.c_str(), W_OK) != 0) return true; // not an HDF5 file we could open, or read-only: replaced as asked
  return c.Fail("exists and another job is writing it (HDF5's file lock): not replaced under that job; wait for it to end, or give another file", false);
}

// Rank 0's part of Open: create (temp file + rename) or reopen and check. Returns the open file.
bool OpenOnRoot(Ctx &c, const std::string &path, const SnapshotHeader &h, bool restart, H5Id *file, std::vector<signed char> *done, std::vector<PetscInt> *pending)
{
  pending->clear();
  if (restart && FileExists(path)) {
    int version = 0;
    if (!OpenExisting(c, path, true, file, &version)) return false;
    SnapshotHeader fh;
    if (!ReadHeaderH5(c, file->get(), &fh)) return false;
    const std::string diff = SnapshotHeaderDiff(fh, h);
    if (!diff.empty()) {
      c.err = "Snapshot file '" + path + "' was made for another scene/mesh/parameter box: " + diff + "; delete it, give another file (-rom or -snapshots), or start afresh with -snapshots_restart 0";
      return false;
    }
    if (version < kFormatVersion) { // the snapshots written from now on lack the version-1 contact matrices: a
      // version-1 reader would take their stale rows, so the file says version 2 before the first write
      H5Id a(H5Aopen(file->get(), "format_version", H5P_DEFAULT), H5Aclose);
      const int v = kFormatVersion;
      if (!a.ok() || H5Awrite(a.get(), H5T_NATIVE_INT, &v) < 0) return c.Fail("cannot upgrade attribute format_version to " + std::to_string(v));
      a.Reset();
      if (!FlushSync(c, file->get())) return false;
    }
    return ReadDone(c, file->get(), h.trainingPoints.size(), done) && ReadPending(c, file->get(), h.trainingPoints.size(), pending);
  }
  const std::string target = OutputTarget(path), tmp = TemporaryPath(path);
  Ctx               ct{"Snapshot file '" + path + "' (being created as '" + tmp + "')", std::string()};
  if (!CheckNotLocked(c, target)) return false;
  {
    MemoryFile mem;
    H5Id       f(mem.Create(tmp), H5Fclose);
    bool       ok = f.ok() || ct.Fail("cannot create the file");
    unsigned long long large = 0;
    (void)LargeDatasets(h, &large);
    // (1 MB beyond what the rows take: HDF5's own allocations there; its close truncates the file to what it uses)
    ok = ok && WriteHeaderAndLayout(ct, f.get(), h) && mem.Save(ct, &f, tmp, large + (1ull << 20)) && AllocateLarge(ct, tmp, h);
    if (ok && std::rename(tmp.c_str(), target.c_str()) != 0) ok = ct.Fail(std::string("cannot rename '") + tmp + "' to '" + target + "': " + std::strerror(errno), false);
    if (!ok) {
      f.Reset();
      std::remove(tmp.c_str());
      c.err = ct.err;
      return false;
    }
  }
  // Make the rename durable (best effort: a directory that cannot be opened is not an error).
  {
    const auto        slash = path.find_last_of('/');
    const std::string dir   = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
    const int         fd    = open(dir.c_str(), O_RDONLY);
    if (fd >= 0) {
      (void)fsync(fd);
      close(fd);
    }
  }
  *file = H5Id(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  if (!file->ok()) return c.Fail("cannot be reopened for writing after its creation");
  done->assign(h.trainingPoints.size(), 0);
  return true;
}

// Rank 0's part of Write. *doneState: the done flag of s.index in the file afterwards.
bool WriteOnRoot(Ctx &c, hid_t f, const std::string &path, const SnapshotHeader &h, bool wasDone, const Snapshot &s, signed char *doneState)
{
  const PetscInt ntrain = (PetscInt)h.trainingPoints.size();
  const size_t   np     = h.paramNames.size();
  *doneState            = wasDone ? 1 : 0;
  if (!CheckNotReplaced(c, f, path)) return false;
  std::ostringstream m;
  if (s.index < 0 || s.index >= ntrain) m << "Write: snapshot index " << s.index << " outside the training set [0, " << ntrain << ")";
  else if (s.u.size() != (size_t)h.ndofs) m << "Write: snapshot " << s.index << " has " << s.u.size() << " values of u; the file stores ndofs = " << h.ndofs;
  else if (s.lambda.size() != (size_t)h.nmult) m << "Write: snapshot " << s.index << " has " << s.lambda.size() << " multipliers; the file stores nmult = " << h.nmult;
  else if (!s.mu.empty() && s.mu.size() != np) m << "Write: snapshot " << s.index << " has " << s.mu.size() << " parameter values; the file has " << np << " parameters";
  else if (s.kkt.size() > 4) m << "Write: snapshot " << s.index << " has " << s.kkt.size() << " KKT residuals (at most 4)";
  if (m.str().empty() && !s.mu.empty())
    for (size_t j = 0; j < np; ++j)
      if (std::fabs(s.mu[j] - h.trainingPoints[s.index][j]) > 1e-12 * std::max(1.0, std::fabs(h.trainingPoints[s.index][j]))) {
        m.precision(17);
        m << "Write: snapshot " << s.index << " has " << h.paramNames[j] << " = " << s.mu[j] << " but training point " << s.index << " has " << h.trainingPoints[s.index][j];
        break;
      }
  if (m.str().empty())
    for (const auto &kv : s.extra)
      if (kv.first.empty() || kv.first.find('/') != std::string::npos || kv.first == "." || kv.first == "..") {
        m << "Write: extra array name '" << kv.first << "' is not a valid dataset name";
        break;
      }
  if (!m.str().empty()) return c.Fail(m.str(), false);

  const hsize_t     row = (hsize_t)s.index;
  const signed char zero = 0, one = 1;
  // Rewriting a done snapshot: clear its flag first, so a crash mid-write cannot leave a mix.
  if (wasDone) {
    if (!RowIO(c, f, "/snapshots/done", H5T_NATIVE_SCHAR, row, 1, const_cast<signed char *>(&zero), true) || !FlushSync(c, f)) return false;
    *doneState = 0;
  }
  // New extras: create their datasets (metadata) and flush before any data is written.
  bool created = false;
  for (const auto &kv : s.extra) {
    const std::string name = "/snapshots/extra/" + kv.first;
    bool              e    = false;
    if (!LinkExists(c, f, name, &e)) return false;
    if (!e) {
      if (!CreateDataset(c, f, name, H5T_IEEE_F64LE, {(hsize_t)ntrain, (hsize_t)kv.second.size()}, H5T_NATIVE_DOUBLE, nullptr, nullptr)) return false;
      created = true;
    }
  }
  if (created && !FlushSync(c, f)) return false;

  std::vector<double> mu = s.mu.empty() ? h.trainingPoints[s.index] : s.mu;
  std::vector<double> kkt(4, kNaN);
  for (size_t k = 0; k < s.kkt.size(); ++k) kkt[k] = s.kkt[k];
  long long it  = s.kacanovIterations;
  double    sec = s.seconds;
  if (!RowIO(c, f, "/snapshots/mu", H5T_NATIVE_DOUBLE, row, np, mu.data(), true)) return false;
  if (!RowIO(c, f, "/snapshots/u", H5T_NATIVE_DOUBLE, row, s.u.size(), const_cast<double *>(s.u.data()), true)) return false;
  if (!RowIO(c, f, "/snapshots/lambda", H5T_NATIVE_DOUBLE, row, s.lambda.size(), const_cast<double *>(s.lambda.data()), true)) return false;
  if (!RowIO(c, f, "/snapshots/kacanov_iterations", H5T_NATIVE_LLONG, row, 1, &it, true)) return false;
  if (!RowIO(c, f, "/snapshots/kkt", H5T_NATIVE_DOUBLE, row, 4, kkt.data(), true)) return false;
  if (!RowIO(c, f, "/snapshots/seconds", H5T_NATIVE_DOUBLE, row, 1, &sec, true)) return false;
  for (const auto &kv : s.extra)
    if (!RowIO(c, f, "/snapshots/extra/" + kv.first, H5T_NATIVE_DOUBLE, row, kv.second.size(), const_cast<double *>(kv.second.data()), true)) {
      c.err += " (extra arrays have a fixed length per name, set when the dataset was created: with the file when declared, else by the first snapshot written)";
      return false;
    }
  if (!FlushSync(c, f)) return false;
  if (!RowIO(c, f, "/snapshots/done", H5T_NATIVE_SCHAR, row, 1, const_cast<signed char *>(&one), true) || !FlushSync(c, f)) return false;
  *doneState = 1;
  return true;
}

} // namespace

std::string SnapshotHeaderDiff(const SnapshotHeader &file, const SnapshotHeader &now)
{
  auto differs = [](const std::string &field, const std::string &a, const std::string &b) { return field + " differs (file: " + a + ", now: " + b + ")"; };
  if (file.sceneHash != now.sceneHash) return differs("scene_hash", Hex(file.sceneHash), Hex(now.sceneHash));
  if (file.meshChecksum != now.meshChecksum) return differs("mesh_checksum", Hex(file.meshChecksum), Hex(now.meshChecksum));
  if (file.paramNames != now.paramNames) return differs("parameter names", Join(file.paramNames), Join(now.paramNames));
  for (size_t j = 0; j < now.paramNames.size(); ++j) {
    const double fmin = j < file.paramMin.size() ? file.paramMin[j] : kNaN, fmax = j < file.paramMax.size() ? file.paramMax[j] : kNaN;
    const double nmin = j < now.paramMin.size() ? now.paramMin[j] : kNaN, nmax = j < now.paramMax.size() ? now.paramMax[j] : kNaN;
    if (!Close14(fmin, nmin)) return differs("params/min of '" + now.paramNames[j] + "'", Num(fmin), Num(nmin));
    if (!Close14(fmax, nmax)) return differs("params/max of '" + now.paramNames[j] + "'", Num(fmax), Num(nmax));
  }
  if (file.trainingPoints.size() != now.trainingPoints.size()) return differs("number of training points", std::to_string(file.trainingPoints.size()), std::to_string(now.trainingPoints.size()));
  for (size_t i = 0; i < now.trainingPoints.size(); ++i) {
    if (file.trainingPoints[i].size() != now.trainingPoints[i].size()) return differs("train/points row " + std::to_string(i) + " length", std::to_string(file.trainingPoints[i].size()), std::to_string(now.trainingPoints[i].size()));
    for (size_t j = 0; j < now.trainingPoints[i].size(); ++j)
      if (!Close14(file.trainingPoints[i][j], now.trainingPoints[i][j])) return differs("train/points[" + std::to_string(i) + "][" + std::to_string(j) + "]", Num(file.trainingPoints[i][j]), Num(now.trainingPoints[i][j]));
  }
  if (file.ndofs != now.ndofs) return differs("ndofs (length of u)", std::to_string(file.ndofs), std::to_string(now.ndofs));
  if (file.nmult != now.nmult) return differs("nmult (length of lambda)", std::to_string(file.nmult), std::to_string(now.nmult));
  return std::string();
}

SnapshotFile::~SnapshotFile()
{
  if (file_ >= 0) {
    H5Quiet q;
    H5Fclose((hid_t)file_);
    file_ = -1;
  }
}

PetscErrorCode SnapshotFile::Open(MPI_Comm comm, const std::string &path, const SnapshotHeader &header, bool restart)
{
  PetscMPIInt rank;
  std::string err;

  PetscFunctionBeginUser;
  PetscCheck(!open_, comm, PETSC_ERR_ARG_WRONGSTATE, "SnapshotFile::Open('%s'): this object has '%s' open; Close() it first", path.c_str(), path_.c_str());
  PetscCheck(!path.empty(), comm, PETSC_ERR_ARG_WRONG, "SnapshotFile::Open: empty file name");
  const size_t np = header.paramNames.size();
  PetscCheck(header.paramMin.size() == np && header.paramMax.size() == np, comm, PETSC_ERR_ARG_SIZ, "Snapshot file '%s': the header has %zu parameter names but %zu/%zu box bounds", path.c_str(), np, header.paramMin.size(), header.paramMax.size());
  PetscCheck(!header.trainingPoints.empty(), comm, PETSC_ERR_ARG_SIZ, "Snapshot file '%s': the training set is empty", path.c_str());
  for (size_t i = 0; i < header.trainingPoints.size(); ++i) PetscCheck(header.trainingPoints[i].size() == np, comm, PETSC_ERR_ARG_SIZ, "Snapshot file '%s': training point %zu has %zu values for %zu parameters", path.c_str(), i, header.trainingPoints[i].size(), np);
  PetscCheck(header.ndofs >= 0 && header.nmult >= 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "Snapshot file '%s': negative ndofs %" PetscInt_FMT " or nmult %" PetscInt_FMT, path.c_str(), header.ndofs, header.nmult);
  for (size_t k = 0; k < header.extras.size(); ++k) {
    const auto &e   = header.extras[k];
    bool        dup = false;
    for (size_t j = 0; j < k; ++j) dup = dup || header.extras[j].first == e.first;
    PetscCheck(!e.first.empty() && e.first.find('/') == std::string::npos && e.first != "." && e.first != ".." && e.second >= 0 && !dup, comm, PETSC_ERR_ARG_WRONG, "Snapshot file '%s': declared extra array '%s' (length %" PetscInt_FMT ") is not a valid dataset name and length%s", path.c_str(), e.first.c_str(), e.second, dup ? " (declared twice)" : "");
  }

  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  std::vector<signed char> done(header.trainingPoints.size(), 0);
  std::vector<PetscInt>    pending;
  H5Id                     file;
  if (rank == 0) {
    H5Quiet q;
    Ctx     c = FileCtx(path);
    if (!OpenOnRoot(c, path, header, restart, &file, &done, &pending)) {
      err = c.err;
      file.Reset();
    }
  }
  PetscCall(BcastString(comm, &err));
  PetscCheck(err.empty(), comm, PETSC_ERR_FILE_UNEXPECTED, "%s", err.c_str());
  PetscCallMPI(MPI_Bcast(done.data(), (PetscMPIInt)done.size(), MPI_SIGNED_CHAR, 0, comm));
  {
    PetscInt np = (PetscInt)pending.size();
    PetscCallMPI(MPI_Bcast(&np, 1, MPIU_INT, 0, comm));
    pending.resize(np);
    if (np) PetscCallMPI(MPI_Bcast(pending.data(), (PetscMPIInt)np, MPIU_INT, 0, comm));
  }
  pending_ = pending;
  comm_   = comm;
  path_   = path;
  header_ = header;
  file_   = file.Release();
  done_   = done;
  open_   = true;
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::DoneIndices(std::vector<PetscInt> *done) const
{
  PetscFunctionBeginUser;
  PetscCheck(open_, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "SnapshotFile::DoneIndices: no snapshot file is open");
  done->clear();
  for (size_t i = 0; i < done_.size(); ++i)
    if (done_[i]) done->push_back((PetscInt)i);
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::Write(const Snapshot &s)
{
  PetscMPIInt rank;
  std::string err;
  long long   state[2] = {-1, 0}; // index, done flag afterwards

  PetscFunctionBeginUser;
  PetscCheck(open_, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "SnapshotFile::Write: no snapshot file is open");
  PetscCallMPI(MPI_Comm_rank(comm_, &rank));
  if (rank == 0) {
    H5Quiet     q;
    Ctx         c  = FileCtx(path_);
    const bool  ok = s.index >= 0 && s.index < (PetscInt)done_.size();
    signed char st = ok ? done_[s.index] : 0;
    if (!WriteOnRoot(c, (hid_t)file_, path_, header_, ok && done_[s.index], s, &st)) err = c.err;
    state[0] = ok ? s.index : -1;
    state[1] = st;
  }
  PetscCall(BcastString(comm_, &err));
  PetscCallMPI(MPI_Bcast(state, 2, MPI_LONG_LONG, 0, comm_));
  if (state[0] >= 0) done_[state[0]] = (signed char)state[1];
  PetscCheck(err.empty(), comm_, PETSC_ERR_FILE_WRITE, "%s", err.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::RowsWithoutExtra(const std::string &name, std::vector<PetscInt> *rows) const
{
  PetscMPIInt        rank;
  std::string        err;
  std::vector<long long> missing; // rank 0's answer, broadcast

  PetscFunctionBeginUser;
  PetscCheck(open_, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "SnapshotFile::RowsWithoutExtra: no snapshot file is open");
  PetscCallMPI(MPI_Comm_rank(comm_, &rank));
  if (rank == 0) {
    H5Quiet           q;
    Ctx               c    = FileCtx(path_);
    const std::string dn   = "/snapshots/extra/" + name;
    bool              has  = false; // (an unreadable link is an error, not a missing extra: every row would lack it)
    if (!LinkExists(c, (hid_t)file_, dn, &has)) err = c.err;
    std::vector<hsize_t> dims;
    if (has) {
      H5Id d(H5Dopen2((hid_t)file_, dn.c_str(), H5P_DEFAULT), H5Dclose);
      if (!(d.ok() || c.Fail("cannot open dataset " + dn)) || !DatasetDims(c, d.get(), dn, &dims) || (dims.size() != 2 && !c.Fail("dataset " + dn + " is not ntrain x len", false))) err = c.err;
      // (a shape of 0 x 2^50 stores nothing, so it passed DatasetDims, and a row of 2^50 values was allocated)
      else if (dims[0] != done_.size()) err = (c.Fail("dataset " + dn + " has shape " + ShapeString(dims) + ", expected ntrain (" + std::to_string(done_.size()) + ") x len: a corrupt file", false), c.err);
    }
    std::vector<double> row;
    for (size_t i = 0; err.empty() && i < done_.size(); ++i) {
      if (!done_[i]) continue;
      bool written = false; // a row never written holds the dataset's fill value, 0, everywhere
      if (has) {
        row.assign((size_t)dims[1], 0.0);
        if (!RowIO(c, (hid_t)file_, dn, H5T_NATIVE_DOUBLE, i, dims[1], row.data(), false)) err = c.err;
        for (double x : row) written = written || x != 0;
      }
      if (!written) missing.push_back((long long)i);
    }
  }
  PetscCall(BcastString(comm_, &err));
  PetscCheck(err.empty(), comm_, PETSC_ERR_FILE_READ, "%s", err.c_str());
  long long n = (long long)missing.size();
  PetscCallMPI(MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm_));
  missing.resize((size_t)n);
  if (n) PetscCallMPI(MPI_Bcast(missing.data(), (PetscMPIInt)n, MPI_LONG_LONG, 0, comm_));
  rows->assign(missing.begin(), missing.end());
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::SetPending(const std::vector<PetscInt> &picks)
{
  PetscMPIInt rank;
  std::string err;

  PetscFunctionBeginUser;
  PetscCheck(open_, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "SnapshotFile::SetPending: no snapshot file is open");
  for (PetscInt i : picks) PetscCheck(i >= 0 && i < (PetscInt)done_.size(), comm_, PETSC_ERR_ARG_OUTOFRANGE, "SnapshotFile::SetPending: index %" PetscInt_FMT " outside the training set", i);
  PetscCallMPI(MPI_Comm_rank(comm_, &rank));
  if (rank == 0) {
    H5Quiet q;
    Ctx     c = FileCtx(path_);
    if (!WritePending(c, (hid_t)file_, done_.size(), picks)) err = c.err;
  }
  PetscCall(BcastString(comm_, &err));
  PetscCheck(err.empty(), comm_, PETSC_ERR_FILE_WRITE, "%s", err.c_str());
  pending_ = picks;
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::Close()
{
  PetscMPIInt rank;
  std::string err;

  PetscFunctionBeginUser;
  if (!open_) PetscFunctionReturn(0);
  PetscCallMPI(MPI_Comm_rank(comm_, &rank));
  if (rank == 0 && file_ >= 0) {
    H5Quiet q;
    Ctx     c = FileCtx(path_);
    H5Id    f((hid_t)file_, H5Fclose);
    file_ = -1;
    if (!CheckNotReplaced(c, f.get(), path_)) err = c.err;
    if (!CloseFile(c, &f)) err = err.empty() ? c.err : err;
  }
  MPI_Comm comm = comm_;
  open_         = false;
  comm_         = MPI_COMM_NULL;
  done_.clear();
  pending_.clear();
  PetscCall(BcastString(comm, &err));
  PetscCheck(err.empty(), comm, PETSC_ERR_FILE_WRITE, "%s", err.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::DoneCount(MPI_Comm comm, const std::string &path, PetscInt *ndone, PetscInt *ntrain)
{
  PetscMPIInt rank;
  PetscInt    v[2] = {-1, 0};

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0 && FileExists(path)) {
    H5Quiet                  q;
    Ctx                      c = FileCtx(path);
    H5Id                     f;
    SnapshotHeader           h;
    std::vector<signed char> done;
    if (OpenExisting(c, path, false, &f) && ReadHeaderH5(c, f.get(), &h) && ReadDone(c, f.get(), h.trainingPoints.size(), &done)) {
      v[0] = (PetscInt)std::count(done.begin(), done.end(), (signed char)1);
      v[1] = (PetscInt)done.size();
    }
  }
  PetscCallMPI(MPI_Bcast(v, 2, MPIU_INT, 0, comm));
  *ndone  = v[0];
  *ntrain = v[1];
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::CheckImport(MPI_Comm comm, const std::string &from, const SnapshotHeader &header)
{
  PetscMPIInt rank;
  std::string err;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    H5Quiet        q;
    Ctx            c{"Snapshot file '" + from + "' (-snapshots_from)", std::string()};
    SnapshotHeader fh;
    H5Id           f;
    bool           ok = FileExists(from) || c.Fail("no such file", false);
    ok                = ok && OpenExisting(c, from, false, &f) && ReadHeaderH5(c, f.get(), &fh) && CloseFile(c, &f);
    if (ok) { // as Import: every header field but the training set
      SnapshotHeader now  = header;
      now.trainingPoints  = fh.trainingPoints;
      const std::string d = SnapshotHeaderDiff(fh, now);
      if (!d.empty()) ok = c.Fail("was made for another scene/mesh/parameter box: " + d, false);
    }
    if (!ok) err = c.err + " (checked before the snapshot file of this run was opened: it is untouched)";
  }
  PetscCall(BcastString(comm, &err));
  PetscCheck(err.empty(), comm, PETSC_ERR_FILE_READ, "%s", err.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::ReadHeader(const std::string &path, SnapshotHeader *header)
{
  std::string err;

  PetscFunctionBeginUser;
  {
    H5Quiet q;
    Ctx     c = FileCtx(path);
    H5Id    f;
    if (!OpenExisting(c, path, false, &f) || !ReadHeaderH5(c, f.get(), header) || !CloseFile(c, &f)) err = c.err;
  }
  PetscCheck(err.empty(), PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "%s", err.c_str());
  PetscFunctionReturn(0);
}

namespace {

// ReadAll's work (any rank): the header and every done snapshot of path; false with c.err on failure.
bool ReadAllH5(Ctx &c, const std::string &path, SnapshotHeader *hOut, std::vector<Snapshot> *snaps)
{
  snaps->clear();
  {
    H5Id                     f;
    SnapshotHeader          &h = *hOut;
    std::vector<signed char> done;
    std::vector<std::pair<std::string, hsize_t>> extras; // name, length
    bool ok = OpenExisting(c, path, false, &f) && ReadHeaderH5(c, f.get(), &h) && ReadDone(c, f.get(), h.trainingPoints.size(), &done);
    if (ok) {
      H5Id g(H5Gopen2(f.get(), "/snapshots/extra", H5P_DEFAULT), H5Gclose);
      H5G_info_t info{};
      ok = (g.ok() && H5Gget_info(g.get(), &info) >= 0) || c.Fail("cannot open group /snapshots/extra");
      for (hsize_t k = 0; ok && k < info.nlinks; ++k) {
        const ssize_t n = H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, k, nullptr, 0, H5P_DEFAULT);
        if (n < 0) {
          ok = c.Fail("cannot list group /snapshots/extra");
          break;
        }
        std::vector<char> name((size_t)n + 1, 0);
        if (H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, k, name.data(), (size_t)n + 1, H5P_DEFAULT) < 0) {
          ok = c.Fail("cannot list group /snapshots/extra");
          break;
        }
        const std::string    dn = std::string("/snapshots/extra/") + name.data();
        H5Id                 d(H5Dopen2(f.get(), dn.c_str(), H5P_DEFAULT), H5Dclose);
        std::vector<hsize_t> dims;
        ok = (d.ok() || c.Fail("cannot open dataset " + dn)) && DatasetDims(c, d.get(), dn, &dims);
        if (ok && (dims.size() != 2 || dims[0] != h.trainingPoints.size())) ok = c.Fail("dataset " + dn + " has shape " + ShapeString(dims) + ", expected ntrain x len", false);
        bool dropped = false; // a version-1 file's dense contact matrices: not read (the offline stage reassembles them)
        for (const char *x : kDroppedExtras) dropped = dropped || !strcmp(name.data(), x);
        if (ok && !dropped) extras.emplace_back(name.data(), dims[1]);
      }
    }
    const hsize_t np = h.paramNames.size();
    // the row datasets' shapes before any row is sized from the header (a /snapshots/u of 0 rows stores nothing and
    // passes DatasetDims whatever its header's ndofs: rows of ndofs values were allocated before the shape was seen)
    const hsize_t nt = done.size();
    ok = ok && HasShape(c, f.get(), "/snapshots/mu", {nt, np}) && HasShape(c, f.get(), "/snapshots/u", {nt, (hsize_t)h.ndofs}) && HasShape(c, f.get(), "/snapshots/lambda", {nt, (hsize_t)h.nmult});
    for (size_t i = 0; ok && i < done.size(); ++i) {
      if (!done[i]) continue;
      Snapshot  s;
      long long it = 0;
      s.index      = (PetscInt)i;
      s.mu.resize(np);
      s.u.resize(h.ndofs);
      s.lambda.resize(h.nmult);
      s.kkt.resize(4);
      ok = RowIO(c, f.get(), "/snapshots/mu", H5T_NATIVE_DOUBLE, i, np, s.mu.data(), false) && RowIO(c, f.get(), "/snapshots/u", H5T_NATIVE_DOUBLE, i, s.u.size(), s.u.data(), false) &&
           RowIO(c, f.get(), "/snapshots/lambda", H5T_NATIVE_DOUBLE, i, s.lambda.size(), s.lambda.data(), false) && RowIO(c, f.get(), "/snapshots/kacanov_iterations", H5T_NATIVE_LLONG, i, 1, &it, false) &&
           RowIO(c, f.get(), "/snapshots/kkt", H5T_NATIVE_DOUBLE, i, 4, s.kkt.data(), false) && RowIO(c, f.get(), "/snapshots/seconds", H5T_NATIVE_DOUBLE, i, 1, &s.seconds, false);
      s.kacanovIterations = (PetscInt)it;
      for (size_t k = 0; ok && k < extras.size(); ++k) {
        std::vector<PetscReal> &x = s.extra[extras[k].first];
        x.resize(extras[k].second);
        ok = RowIO(c, f.get(), "/snapshots/extra/" + extras[k].first, H5T_NATIVE_DOUBLE, i, x.size(), x.data(), false);
      }
      // a finished row must be finite and below 1e150 (as a ROM file's values: a 1e300 made a validate error NaN and
      // the POD call the snapshots zero): name the row, the dataset and the entry (never NaN into a basis)
      auto finite = [&](const std::string &name, const std::vector<PetscReal> &x) {
        for (size_t k = 0; k < x.size(); ++k)
          if (!std::isfinite(x[k]) || std::fabs(x[k]) >= 1e150) {
            std::ostringstream m;
            m << "row " << i << " (training point " << i + 1 << " of " << done.size() << ") of " << name << " holds a " << (std::isfinite(x[k]) ? "huge (>= 1e150)" : "non-finite") << " value (entry " << k << ", " << x[k]
              << ") although the row is marked done: the file is corrupt; recompute that snapshot (-snapshots_restart 0 recomputes all, or clear /snapshots/done[" << i << "])";
            return c.Fail(m.str(), false);
          }
        return true;
      };
      ok = ok && finite("/snapshots/mu", s.mu) && finite("/snapshots/u", s.u) && finite("/snapshots/lambda", s.lambda);
      // the provenance of a finished row: its solve time (validate's FOM time and speedup with -test_snapshots: a NaN
      // there made them NaN) and its KKT residuals (NaN: not given), norms >= 0
      auto provenance = [&](const std::string &name, const std::vector<PetscReal> &x, bool nanAllowed) {
        for (size_t k = 0; k < x.size(); ++k)
          if (!(std::isnan(x[k]) && nanAllowed) && !(x[k] >= 0 && x[k] < 1e150)) {
            std::ostringstream m;
            m << "row " << i << " (training point " << i + 1 << " of " << done.size() << ") of " << name << " holds " << x[k] << " (entry " << k << ") although the row is marked done; "
              << (nanAllowed ? "a KKT residual is a norm (NaN: not given)" : "a solve time is a finite number of seconds >= 0") << ": the file is corrupt; recompute that snapshot (-snapshots_restart 0 recomputes all, or clear /snapshots/done[" << i << "])";
            return c.Fail(m.str(), false);
          }
        return true;
      };
      ok = ok && provenance("/snapshots/seconds", {s.seconds}, false) && provenance("/snapshots/kkt", s.kkt, true);
      for (const auto &e : s.extra) ok = ok && finite("/snapshots/extra/" + e.first, e.second);
      // the row's parameter is its training point (resumed and imported rows are matched to 1e-14), and its
      // multipliers are those of a contact solution (>= 0): a row that says otherwise would build the bases wrong
      bool same = s.mu.size() == h.trainingPoints[i].size();
      for (size_t k = 0; same && k < s.mu.size(); ++k) same = Close14(s.mu[k], h.trainingPoints[i][k]);
      if (ok && !same) {
        std::ostringstream m;
        m << std::setprecision(17) << "row " << i << " of /snapshots/mu (" << (s.mu.empty() ? 0.0 : s.mu[0]) << (s.mu.size() > 1 ? ", ..." : "") << ") is not training point " << i + 1
          << " of /train/points (" << (h.trainingPoints[i].empty() ? 0.0 : h.trainingPoints[i][0]) << (h.trainingPoints[i].size() > 1 ? ", ..." : "") << "): the file is corrupt; recompute that snapshot";
        ok = c.Fail(m.str(), false);
      }
      for (size_t k = 0; ok && k < s.lambda.size(); ++k)
        if (s.lambda[k] < 0) {
          std::ostringstream m;
          m << "row " << i << " of /snapshots/lambda holds a negative multiplier (entry " << k << ", " << s.lambda[k] << "): not a contact solution; the file is corrupt, recompute that snapshot";
          ok = c.Fail(m.str(), false);
        }
      if (ok) snaps->push_back(std::move(s));
    }
    if (ok) ok = CloseFile(c, &f);
    return ok;
  }
}

} // namespace

PetscErrorCode SnapshotFile::ReadAll(const std::string &path, std::vector<Snapshot> *snaps)
{
  std::string err;

  PetscFunctionBeginUser;
  {
    H5Quiet        q;
    Ctx            c = FileCtx(path);
    SnapshotHeader h;
    if (!ReadAllH5(c, path, &h, snaps)) err = c.err;
  }
  PetscCheck(err.empty(), PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "%s", err.c_str());
  PetscFunctionReturn(0);
}

PetscErrorCode SnapshotFile::Import(const std::string &from, const std::vector<std::string> &extras, PetscInt *imported, PetscInt *outside)
{
  PetscMPIInt           rank;
  std::string           err;
  std::vector<Snapshot> take; // rank 0: the snapshots to write, their index in this file's training set
  PetscInt              counts[2] = {0, 0}; // imported, outside this training set

  PetscFunctionBeginUser;
  PetscCheck(open_, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "SnapshotFile::Import: no snapshot file is open");
  PetscCallMPI(MPI_Comm_rank(comm_, &rank));
  if (rank == 0) {
    H5Quiet               q;
    Ctx                   c{"Snapshot file '" + from + "' (-snapshots_from)", std::string()};
    SnapshotHeader        fh;
    std::vector<Snapshot> all;
    bool                  ok = FileExists(from) || c.Fail("no such file", false);
    ok                       = ok && ReadAllH5(c, from, &fh, &all);
    if (ok) { // the same problem: every header field but the training set
      SnapshotHeader now  = header_;
      now.trainingPoints  = fh.trainingPoints;
      const std::string d = SnapshotHeaderDiff(fh, now);
      if (!d.empty()) ok = c.Fail("was made for another scene/mesh/parameter box: " + d, false);
    }
    for (auto &s : all) {
      if (!ok) break;
      for (const auto &e : extras)
        if (!s.extra.count(e)) {
          ok = c.Fail("snapshot " + std::to_string(s.index) + " has no /snapshots/extra/" + e + ", which this run stores with every snapshot (-snapshots_sensitivities on one side only?)", false);
          break;
        }
      for (auto it = s.extra.begin(); it != s.extra.end();) // only what this run writes: no half-filled extra
        it = std::find(extras.begin(), extras.end(), it->first) == extras.end() ? s.extra.erase(it) : std::next(it);
      PetscInt i = -1;
      for (size_t j = 0; i < 0 && j < header_.trainingPoints.size(); ++j) {
        bool same = s.mu.size() == header_.trainingPoints[j].size();
        for (size_t k = 0; same && k < s.mu.size(); ++k) same = Close14(s.mu[k], header_.trainingPoints[j][k]);
        if (same) i = (PetscInt)j;
      }
      if (i < 0) ++counts[1];
      else if (!done_[i]) {
        s.index = i;
        take.push_back(std::move(s));
      }
    }
    if (!ok) {
      err = c.err;
      take.clear();
    }
    counts[0] = (PetscInt)take.size();
  }
  PetscCall(BcastString(comm_, &err));
  PetscCheck(err.empty(), comm_, PETSC_ERR_FILE_READ, "%s", err.c_str());
  PetscCallMPI(MPI_Bcast(counts, 2, MPIU_INT, 0, comm_));
  for (PetscInt k = 0; k < counts[0]; ++k) PetscCall(Write(rank == 0 ? take[k] : Snapshot()));
  *imported = counts[0];
  *outside  = counts[1];
  PetscFunctionReturn(0);
}

// ---------------------------------------------------------------------------------------------
// Import of snapshot matrices from other codes.

namespace {

// Splits "file.h5:/dataset" at the first ":/" whose left part is an existing file.
void SplitSpec(const std::string &spec, std::string *file, std::string *dset)
{
  *file = spec;
  dset->clear();
  for (size_t p = spec.find(":/"); p != std::string::npos; p = spec.find(":/", p + 1))
    if (FileExists(spec.substr(0, p))) {
      *file = spec.substr(0, p);
      *dset = spec.substr(p + 1);
      return;
    }
  const size_t p = spec.find(":/"); // no such file: still name the file part in the error
  if (p != std::string::npos) {
    *file = spec.substr(0, p);
    *dset = spec.substr(p + 1);
  }
}

// HDF5 dataset -> column-major (nrows = dofs) data.
bool ImportH5(Ctx &c, const std::string &file, const std::string &dset, bool transpose, unsigned long long *nr, unsigned long long *nc, std::vector<double> *data)
{
  const htri_t is = H5Fis_hdf5(file.c_str());
  if (is <= 0) return c.Fail("is not an HDF5 file", is < 0);
  H5Id f(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!f.ok()) return c.Fail("cannot be opened");
  bool e = false;
  if (!LinkExists(c, f.get(), dset, &e)) return false;
  if (!e) return c.Fail("has no dataset " + dset, false);
  H5Id d(H5Dopen2(f.get(), dset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!d.ok()) return c.Fail("cannot open dataset " + dset + " (a group?)");
  H5Id t(H5Dget_type(d.get()), H5Tclose);
  if (!t.ok()) return c.Fail("cannot get the type of dataset " + dset);
  const H5T_class_t cls = H5Tget_class(t.get());
  if (cls != H5T_FLOAT && cls != H5T_INTEGER) return c.Fail("dataset " + dset + " is not numeric (float or integer)", false);
  std::vector<hsize_t> dims;
  if (!DatasetDims(c, d.get(), dset, &dims)) return false;
  if (dims.size() != 2) return c.Fail("dataset " + dset + " has shape " + ShapeString(dims) + "; a 2D matrix is expected (rows = dofs, columns = snapshots; -import_transpose for the transpose)", false);
  // (a shape of 0 x 2^40 stores nothing, so it passed DatasetDims, and asked for 2^40 empty snapshot columns)
  if (dims[0] == 0 || dims[1] == 0) return c.Fail("dataset " + dset + " has shape " + ShapeString(dims) + ": it holds no snapshots", false);
  std::vector<double> raw(dims[0] * dims[1]);
  if (!raw.empty() && H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw.data()) < 0) return c.Fail("cannot read dataset " + dset);
  // raw is row-major dims[0] x dims[1].
  const hsize_t ndof = transpose ? dims[1] : dims[0], nsnap = transpose ? dims[0] : dims[1];
  data->assign(ndof * nsnap, 0.0);
  for (hsize_t i = 0; i < dims[0]; ++i)
    for (hsize_t j = 0; j < dims[1]; ++j) {
      const hsize_t dof = transpose ? j : i, snap = transpose ? i : j;
      (*data)[snap * ndof + dof] = raw[i * dims[1] + j];
    }
  *nr = ndof;
  *nc = nsnap;
  return true;
}

// Checks a PETSc binary Mat file header (big-endian PetscInt classid, M, N, nz) and its size.
bool CheckPetscBinary(Ctx &c, const std::string &file, PetscInt *nz)
{
  std::FILE *fp = std::fopen(file.c_str(), "rb");
  if (!fp) return c.Fail(std::string("cannot be opened: ") + std::strerror(errno), false);
  PetscInt      hdr[4] = {0, 0, 0, 0};
  unsigned char raw[4 * sizeof(PetscInt)];
  const size_t  got = std::fread(raw, 1, sizeof raw, fp);
  std::fseek(fp, 0, SEEK_END);
  const long long size = std::ftell(fp);
  std::fclose(fp);
  if (got == sizeof raw)
    for (int k = 0; k < 4; ++k) {
      unsigned long long v = 0;
      for (size_t b = 0; b < sizeof(PetscInt); ++b) v = (v << 8) | raw[k * sizeof(PetscInt) + b];
      hdr[k] = (PetscInt)(std::make_unsigned<PetscInt>::type)v; // two's complement
    }
  if (got != sizeof raw || hdr[0] != MAT_FILE_CLASSID) {
    std::ostringstream m;
    m << "is neither a PETSc binary Mat file (no Mat class id " << MAT_FILE_CLASSID << " at its start) nor given as file.h5:/dataset";
    return c.Fail(m.str(), false);
  }
  // in long double: M * N * 8 of a corrupt dense header overflowed 64 bits (negative: passed the size check)
  const long long   M = hdr[1], N = hdr[2], NZ = hdr[3], I = sizeof(PetscInt), S = sizeof(PetscScalar);
  const long double need = NZ == -1 ? 4.0L * I + (long double)M * N * S : 4.0L * I + (long double)M * I + (long double)NZ * (I + S);
  if (M < 0 || N < 0 || NZ < -1 || (long double)size < need) {
    std::ostringstream m;
    m << "PETSc binary Mat header says " << M << " x " << N << " (nz " << NZ << ") but the file is truncated or corrupt (" << size << " bytes, need " << (double)need << ")";
    return c.Fail(m.str(), false);
  }
  // The import is dense (an AIJ file is converted, then copied into the snapshot columns: 3 dense copies at once on
  // rank 0). A sparse file declaring 46340 x 46340 in 185 kB asked MatConvert for 17 GB; refused against the memory.
  const long double dense = (long double)M * N * S, mem = (long double)sysconf(_SC_PHYS_PAGES) * (long double)sysconf(_SC_PAGE_SIZE);
  if (NZ != -1 && mem > 0 && 3 * dense > mem) {
    std::ostringstream m;
    m << "PETSc binary Mat header says " << M << " x " << N << " (nz " << NZ << "): its import is dense, " << (double)dense << " bytes a copy (3 copies at once), more than this machine's memory (" << (double)mem << " bytes); a corrupt header, or a matrix too large to import";
    return c.Fail(m.str(), false);
  }
  *nz = (PetscInt)NZ;
  return true;
}

} // namespace

PetscErrorCode ImportSnapshotMatrix(MPI_Comm comm, const std::string &spec, std::vector<std::vector<PetscReal>> *cols)
{
  PetscBool           transpose = PETSC_FALSE;
  PetscMPIInt         rank;
  std::string         err, file, dset;
  unsigned long long  dim[3] = {0, 0, 0}; // rows (dofs), columns (snapshots), 1 = PETSc binary
  std::vector<double> data;
  PetscInt            nz = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-import_transpose", &transpose, NULL));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    H5Quiet q;
    SplitSpec(spec, &file, &dset);
    Ctx c{"Snapshot matrix file '" + file + "'", std::string()};
    if (!FileExists(file)) c.Fail("does not exist (give file.h5:/dataset or a PETSc binary Mat file)", false);
    else if (!dset.empty()) ImportH5(c, file, dset, transpose, &dim[0], &dim[1], &data);
    else if (H5Fis_hdf5(file.c_str()) > 0) c.Fail("is an HDF5 file: name the dataset as '" + file + ":/path/to/dataset'", false);
    else if (CheckPetscBinary(c, file, &nz)) dim[2] = 1;
    H5Eclear2(H5E_DEFAULT);
    err = c.err;
  }
  PetscCall(BcastString(comm, &err));
  PetscCheck(err.empty(), comm, PETSC_ERR_FILE_READ, "%s", err.c_str());
  if (rank == 0 && dim[2] == 1) {
    // The header was checked above, so MatLoad does not fail on rank 0 alone.
    Mat                A, D = NULL;
    PetscViewer        v;
    PetscInt           M, N, lda;
    const PetscScalar *a;
    PetscCall(PetscViewerCreate(PETSC_COMM_SELF, &v));
    PetscCall(PetscViewerSetType(v, PETSCVIEWERBINARY));
    PetscCall(PetscViewerBinarySetSkipInfo(v, PETSC_TRUE)); // never read options from file.info
    PetscCall(PetscViewerFileSetMode(v, FILE_MODE_READ));
    PetscCall(PetscViewerFileSetName(v, file.c_str()));
    PetscCall(MatCreate(PETSC_COMM_SELF, &A));
    PetscCall(MatSetType(A, nz == -1 ? MATSEQDENSE : MATSEQAIJ));
    PetscCall(MatLoad(A, v));
    PetscCall(PetscViewerDestroy(&v));
    if (nz == -1) D = A;
    else {
      PetscCall(MatConvert(A, MATSEQDENSE, MAT_INITIAL_MATRIX, &D));
      PetscCall(MatDestroy(&A));
    }
    PetscCall(MatGetSize(D, &M, &N));
    PetscCall(MatDenseGetLDA(D, &lda));
    PetscCall(MatDenseGetArrayRead(D, &a));
    dim[0] = transpose ? N : M;
    dim[1] = transpose ? M : N;
    data.assign(dim[0] * dim[1], 0.0);
    for (PetscInt j = 0; j < N; ++j)
      for (PetscInt i = 0; i < M; ++i) {
        const size_t dof = transpose ? j : i, snap = transpose ? i : j;
        data[snap * dim[0] + dof] = PetscRealPart(a[i + j * lda]);
      }
    PetscCall(MatDenseRestoreArrayRead(D, &a));
    PetscCall(MatDestroy(&D));
  }
  PetscCallMPI(MPI_Bcast(dim, 3, MPI_UNSIGNED_LONG_LONG, 0, comm));
  cols->assign(dim[1], std::vector<PetscReal>(dim[0]));
  for (unsigned long long j = 0; j < dim[1]; ++j) {
    if (rank == 0) std::copy(data.begin() + j * dim[0], data.begin() + (j + 1) * dim[0], (*cols)[j].begin());
    PetscCall(BcastReals(comm, (*cols)[j].data(), dim[0]));
  }
  PetscFunctionReturn(0);
}

} // namespace rbc
